"""Graph params: the scalar type a param is read as, its values checked against type and
range, the warnings about guessed types, and "did you mean" for names."""

from __future__ import annotations

import difflib
import math
import struct
import zlib
from collections.abc import Mapping, Sequence
from typing import Any

import yaml

from ..core.errors import GraphError, Problem, UsageError, Where
from ..core.registry import DEFAULT_BUDGET
from ..core.types import Kind, PortType, TypeMismatch, number_text
from .model import ParamDef

__all__ = [
    "check_param_value",
    "param_kind",
    "param_step",
    "param_warnings",
    "parse_sets",
    "suggest",
]


def suggest(name: str, options: Any) -> str:
    close = difflib.get_close_matches(name, list(options), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


def _whole(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def param_kind(p: ParamDef) -> type | None:
    """The scalar type of a param without a declared ``type:``, read from how it is written.

    A number is an ``int`` only when its default, min and max are all written as whole
    numbers (``{default: 3, min: 0.5, max: 10}`` is a float) and it feeds no port that
    asks for a float only (``r: 2`` feeding a radius is a float: ``p.fed``, set by the
    check's ``infer_fed``); None for anything else.
    """
    if p.type is not None:
        return None
    d = p.default
    if isinstance(d, (bool, str)):
        return type(d)
    if _whole(d):
        whole = all(_whole(b) for b in (p.min, p.max) if b is not None)
        return int if whole and p.fed is not float else float
    if isinstance(d, float):
        return float
    return None


def param_step(p: ParamDef) -> float | None:
    """The step of a number param with a min and a max (the studio's slider moves by it,
    and shows values rounded to it): 1 for a whole number, else about a hundredth of the
    range rounded to 1, 2 or 5 times a power of ten; None for any other param."""
    if p.choices is not None or p.min is None or p.max is None:
        return None
    d = p.default
    if isinstance(d, bool) or not isinstance(d, (int, float)):
        if p.type is None or p.type.name not in ("int", "float"):
            return None
    if param_kind(p) is int or (p.type is not None and p.type.name == "int"):
        return 1.0
    span = float(p.max) - float(p.min)
    if not span > 0:
        return 1.0
    raw = span / 100.0
    power = 10.0 ** math.floor(math.log10(raw))
    return next(m * power for m in (1.0, 2.0, 5.0, 10.0) if raw <= m * power)


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
    if p.choices is not None and not _among(out, p.choices):
        shown = ", ".join(repr(c) for c in p.choices)
        hint = suggest(str(out), [str(c) for c in p.choices]) if isinstance(out, str) else ""
        raise TypeMismatch(f"must be one of {shown}, got {out!r}{hint}")
    if isinstance(out, (int, float)) and not isinstance(out, bool):
        if p.min is not None and out < p.min:
            raise TypeMismatch(f"must be >= {number_text(p.min)}, got {number_text(out)}")
        if p.max is not None and out > p.max:
            raise TypeMismatch(f"must be <= {number_text(p.max)}, got {number_text(out)}")
    return out


def _among(value: Any, choices: tuple[Any, ...]) -> bool:
    """``value`` is one of ``choices`` (a number equal to a number choice counts: 2 is 2.0;
    True is not 1)."""
    for c in choices:
        if isinstance(c, bool) or isinstance(value, bool):
            if isinstance(c, bool) and isinstance(value, bool) and c == value:
                return True
        elif c == value and isinstance(c, str) == isinstance(value, str):
            return True
    return False


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


def parse_sets(graph: Any, items: Sequence[str]) -> dict[str, Any]:
    """``NAME=VALUE`` pairs parsed by each param's type (YAML scalars, lists allowed)."""
    out: dict[str, Any] = {}
    defs = graph.param_defs
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise UsageError(f"--set takes NAME=VALUE, got {item!r} (node names go before --set)")
        if name not in defs:
            raise GraphError(
                f"--set {name}: unknown param{suggest(name, defs)}; params are "
                f"{', '.join(defs) or 'none'}"
            )
        from .yamlread import load_value

        kind = param_kind(defs[name])
        declared = defs[name].type
        if declared is not None and declared.is_geometry:
            out[name] = file_value(name, declared, text)
            continue
        if kind is str:
            value: Any = text
        elif kind in (int, float):
            value = _number(text)
            if kind is float and isinstance(value, int):
                value = float(value)
        else:
            try:
                value = load_value(text)  # YAML 1.2 numbers, as in the graph file
            except (yaml.YAMLError, ValueError, TypeError, RecursionError) as exc:
                shown = text if len(text) <= 40 else text[:37] + "..."
                why = getattr(exc, "problem", None) or exc
                raise UsageError(f"--set {name}: cannot read {shown!r}: {why}") from None
        out[name] = value
    return out


def file_value(name: str, declared: Any, text: str) -> Any:
    """The geometry a ``--set NAME=FILE`` names, read as the ``read.*`` node would read it.

    The path is the user's own (relative to the working directory, not confined: a graph
    from elsewhere cannot choose it), opened as a regular file under the input size cap.

    Raises
    ------
    GraphError
        A file that cannot be read, or whose content does not fit the param's type.
    """
    from pathlib import Path

    from ..core import safety
    from ..core.errors import PathError
    from ..geometry import Mesh, NurbsCurve, Points
    from ..kernels.io import readers

    kind = declared.kinds[0]
    base, many = kind.base, kind.is_list
    try:
        data = safety.read_input(Path(text).expanduser())
    except PathError as exc:
        raise GraphError(f"--set {name}: {exc}") from None
    try:
        if base is Mesh and not many:
            v, fi, fo, attributes = readers.mesh_data(text, data, DEFAULT_BUDGET)
            return Mesh(v, fi, fo, point_data=attributes or None)
        if base is Points and not many:
            ext = readers.extension(text, readers.POINT_FORMATS)
            attributes = readers.vertex_attributes(text, data)
            return Points(readers.POINT_FORMATS[ext](data), point_data=attributes or None)
        if base.__name__ in ("Curve", "NurbsCurve"):
            ext = readers.extension(text, readers.CURVE_FORMATS)
            found, _ = readers.CURVE_FORMATS[ext](data, DEFAULT_BUDGET)
            curves = [NurbsCurve(*c.curve) for c in found]
            if many:
                return curves
            if len(curves) != 1:
                raise ValueError(
                    f"it holds {len(curves)} curves; a Curve param takes one (declare the "
                    f"param list[Curve] for all of them)"
                )
            return curves[0]
    except (ValueError, IndexError, KeyError, TypeError, OverflowError, RecursionError,
            struct.error, zlib.error) as exc:  # fmt: skip
        raise GraphError(f"--set {name}: cannot read {text!r}: {readers.in_words(exc)}") from None
    raise GraphError(
        f"--set {name}: a {declared.name} param is not read from a file (Mesh, Points, Curve "
        f"and list[Curve] are)"
    )


def _number(text: str) -> Any:
    """A number as people type it: 3, -2.5, 1e3, 0x10 (YAML 1.1 would read 1e3 as text)."""
    for parse in (int, float):
        try:
            return parse(text.strip().replace("_", ""))
        except ValueError:
            pass
    try:
        return int(text.strip(), 0)
    except ValueError:
        return text  # the param's check then says what was expected
