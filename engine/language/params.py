"""Graph params: the scalar type a param is read as, its values checked against type and
range, the warnings about guessed types, and "did you mean" for names."""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from typing import Any

from ..core.errors import Problem, Where
from ..core.types import Kind, PortType, TypeMismatch, number_text
from .model import ParamDef

__all__ = ["check_param_value", "param_kind", "param_warnings", "suggest"]


def suggest(name: str, options: Any) -> str:
    close = difflib.get_close_matches(name, list(options), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


def _whole(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def param_kind(p: ParamDef) -> type | None:
    """The scalar type of a param without a declared ``type:``, read from how it is written.

    A number is an ``int`` only when its default, min and max are all written as whole
    numbers (``{default: 3, min: 0.5, max: 10}`` is a float); None for anything else.
    """
    if p.type is not None:
        return None
    d = p.default
    if isinstance(d, (bool, str)):
        return type(d)
    if _whole(d):
        return int if all(_whole(b) for b in (p.min, p.max) if b is not None) else float
    if isinstance(d, float):
        return float
    return None


def check_param_value(p: ParamDef, value: Any) -> Any:
    """The value of param ``p`` as the graph uses it, or TypeMismatch."""
    kind = param_kind(p)
    if p.type is not None:
        if value is None:
            return None
        out = p.type.coerce(value)
    elif kind is not None:
        out = PortType((Kind(kind),)).coerce(value)
    else:
        out = value
    if isinstance(out, (int, float)) and not isinstance(out, bool):
        if p.min is not None and out < p.min:
            raise TypeMismatch(f"must be >= {number_text(p.min)}, got {number_text(out)}")
        if p.max is not None and out > p.max:
            raise TypeMismatch(f"must be <= {number_text(p.max)}, got {number_text(out)}")
    return out


def param_warnings(params: Mapping[str, ParamDef], file: str) -> list[Problem]:
    """Params whose type was guessed where a guess could be wrong: a slider-ready number
    (with a min or max) read as int because everything about it is written whole."""
    out = []
    for p in params.values():
        if param_kind(p) is int and (p.min is not None or p.max is not None):
            out.append(
                Problem(
                    Where(file, p.line),
                    f"param '{p.name}' is read as int (its default, min and max are whole "
                    f"numbers); write 'type: int' to confirm, or 'type: float' to allow fractions",
                )
            )
    return out
