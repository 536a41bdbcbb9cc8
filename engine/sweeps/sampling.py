"""Which variants a sweep runs: the values each varied param may take, and sampling them.

A domain is read from SPEC text (``1:12``, ``0.5:2:7``, ``1,2,5``) or given as values, and
checked against the param's type, min, max and (for a text param feeding enum ports) its
choices before anything runs. Variants come from a grid (every combination), plain random
sampling or a Latin hypercube (McKay, Beckman & Conover, "A comparison of three methods for
selecting values of input variables in the analysis of output from a computer code",
Technometrics 21(2), 1979), all seeded through :func:`numpy.random.default_rng`.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.errors import ParamError, Problem, Where
from ..core.types import TypeMismatch
from ..evaluation.graph import Graph
from ..language.params import check_param_value, suggest

__all__ = ["Domain", "domain", "param_kind", "parse_spec", "sample"]

METHODS = ("grid", "random", "lhs")
MAX_VARIANTS = 1_000_000


@dataclass(frozen=True)
class Domain:
    """The values a varied param may take: a list, or an interval of a float param."""

    name: str
    values: tuple[Any, ...] | None = None  # discrete values, in order
    low: float | None = None  # a continuous interval (float params, random and lhs)
    high: float | None = None
    text: str = ""

    def pick(self, u: np.ndarray) -> list[Any]:
        """The values at positions ``u`` in [0, 1): strata of a list, or of the interval."""
        if self.values is None:
            return (self.low + u * (self.high - self.low)).tolist()
        k = len(self.values)
        idx = np.minimum((u * k).astype(np.int64), k - 1)
        return [self.values[i] for i in idx]


def param_kind(p: Any) -> type | None:
    """bool, int, float or str for a param a sweep can vary, else None."""
    if p.type is not None:
        k = p.type.kinds[0]
        ok = len(p.type.kinds) == 1 and not k.is_list and k.base in (bool, int, float, str)
        return k.base if ok else None
    for t in (bool, int, float, str):
        if isinstance(p.default, t):
            return t
    return None


def enum_choices(g: Graph, name: str) -> list[str] | None:
    """The choices of the enum ports param ``name`` feeds by a bare ``=name``, if any."""
    registry = g.node_types()  # the registry and the graph files it names
    choices: list[str] | None = None
    for node, type_name in g.nodes.items():
        spec = registry.get(type_name)
        for port, raw in g.node_inputs(node).items():
            if not (isinstance(raw, str) and raw[1:].strip() == name and raw.startswith("=")):
                continue
            enum = spec.inputs[port].type.enum if spec and port in spec.inputs else None
            if enum is not None:
                members = [str(m.value) for m in enum]
                choices = members if choices is None else [c for c in choices if c in members]
    return choices


def _number(text: str, kind: type) -> Any:
    t = text.strip()
    if kind is int:
        try:
            return int(t)
        except ValueError:
            raise ValueError(f"{t!r} is not a whole number") from None
    try:
        return float(t)
    except ValueError:
        raise ValueError(f"{t!r} is not a number") from None


def _scalar(text: str, kind: type) -> Any:
    t = text.strip()
    if kind is bool:
        low = t.lower()
        if low in ("true", "yes", "on", "1"):
            return True
        if low in ("false", "no", "off", "0"):
            return False
        raise ValueError(f"{t!r} is not true or false")
    if kind is str:
        return t
    return _number(t, kind)


def parse_spec(text: str, kind: type) -> Domain:
    """A domain from SPEC text, read by the param's kind.

    ``1:12`` is each whole number from 1 to 12 (int params) or the interval [1, 12] (float
    params; random and lhs sampling only), ``0.5:2:7`` is 7 evenly spaced values from 0.5
    to 2, ``1,2,5`` a list (``true,false``; ``a,b`` for text and enum params).

    Raises
    ------
    ValueError
        With a sentence saying what SPEC looks like.
    """
    parts = text.split(":")
    if len(parts) == 1:
        items = text.split(",")
        if any(not i.strip() for i in items):
            raise ValueError(f"{text!r} has an empty item; write a list as 1,2,5")
        return Domain("", tuple(_scalar(i, kind) for i in items), text=text)
    if kind not in (int, float):
        raise ValueError(f"a range {text!r} is for number params; list the values: a,b,c")
    if len(parts) not in (2, 3):
        raise ValueError(f"{text!r} is not a range; write FROM:TO or FROM:TO:COUNT")
    low, high = (_number(p, float if len(parts) == 3 else kind) for p in parts[:2])
    if high < low:
        raise ValueError(f"{text!r} runs backwards; write FROM:TO with FROM <= TO")
    if len(parts) == 2:
        if kind is float:
            return Domain("", None, float(low), float(high), text=text)
        if high - low + 1 > MAX_VARIANTS:
            raise ValueError(f"{text!r} holds more than {MAX_VARIANTS:,} values")
        return Domain("", tuple(range(low, high + 1)), text=text)
    count = _number(parts[2], int)
    if not 1 <= count <= MAX_VARIANTS:
        raise ValueError(f"{text!r}: the count must be 1 to {MAX_VARIANTS:,}, got {count}")
    # 12 significant digits: 0.3, not 0.30000000000000004, in the table and the labels
    values = [float(f"{v:.12g}") for v in np.linspace(low, high, count)]
    if kind is int:
        if any(abs(v - round(v)) > 1e-9 for v in values):
            raise ValueError(
                f"{text!r} gives values that are not whole numbers for an int param; "
                f"write FROM:TO for each whole number, or a count that lands on them"
            )
        values = [int(round(v)) for v in values]
    return Domain("", tuple(values), text=text)


def domain(g: Graph, name: str, spec: Any) -> Domain:
    """The domain of varied param ``name``: SPEC text, or values (a range, a list, one value).

    Raises
    ------
    ParamError
        For an unknown param, one a sweep cannot vary, or values out of its type, range
        (the param's min and max) or choices, naming the file and the param's line.
    """
    defs = g.param_defs
    if name not in defs:
        raise ParamError(
            Problem(
                Where(g.file_label),
                f"vary: unknown param '{name}'{suggest(name, defs)}; params are "
                f"{', '.join(defs) or 'none'}",
            )
        )
    p = defs[name]
    where = Where(g.file_label, p.line)
    shown = spec if isinstance(spec, str) else _short(spec)

    def problem(message: str) -> ParamError:
        return ParamError(Problem(where, f"param '{name}': vary {name}={shown}: {message}"))

    kind = param_kind(p)
    if kind is None:
        raise problem("only bool, int, float, text and enum params can be varied")
    if isinstance(spec, str):
        try:
            d = parse_spec(spec, kind)
        except ValueError as exc:
            raise problem(str(exc)) from None
    elif isinstance(spec, (bool, int, float, np.generic)) or not isinstance(spec, Iterable):
        d = Domain("", (spec,))
    else:
        d = Domain("", tuple(spec))
    if d.values is not None and not d.values:
        raise problem("no values")
    raw = d.values if d.values is not None else (d.low, d.high)
    numbers = [v for v in raw if isinstance(v, (int, float, np.number)) and not isinstance(v, bool)]
    if numbers and kind in (int, float):  # the whole range named at once, before each value
        low, high = min(numbers), max(numbers)
        if p.min is not None and low < p.min:
            raise problem(f"goes down to {low:g}, below the param's min {p.min:g}")
        if p.max is not None and high > p.max:
            raise problem(f"reaches {high:g}, above the param's max {p.max:g}")
    choices = enum_choices(g, name) if kind is str else None
    checked = []
    for v in raw:
        try:
            v = check_param_value(p, v.item() if isinstance(v, np.generic) else v)
        except TypeMismatch as exc:
            raise problem(str(exc)) from None
        if choices is not None and v not in choices:
            raise problem(f"{v!r} is not one of its choices {', '.join(choices)}")
        checked.append(v)
    if d.values is None:
        return Domain(name, None, float(checked[0]), float(checked[1]), d.text)
    return Domain(name, tuple(checked), text=d.text)


def _short(value: Any) -> str:
    if isinstance(value, range):
        return f"range({value.start}, {value.stop})" + (
            f"[step {value.step}]" if value.step != 1 else ""
        )
    text = str(list(value)) if isinstance(value, (list, tuple)) else str(value)
    return text if len(text) <= 60 else text[:57] + "..."


def sample(
    domains: Sequence[Domain], method: str = "grid", samples: int | None = None, seed: int = 0
) -> list[dict[str, Any]]:
    """The variants: every combination (grid), or ``samples`` random or Latin hypercube ones.

    Grid order is the order of ``domains``, the last varying fastest. Latin hypercube: for
    each param a random permutation of the ``samples`` strata of [0, 1), a uniform point in
    each, mapped onto the param's interval or list (McKay, Beckman & Conover, 1979).

    Raises
    ------
    ValueError
        For an unknown method, a grid over an interval, a missing sample count, or more
        than a million variants.
    """
    names = [d.name for d in domains]
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
    if method == "grid":
        if samples is not None:
            raise ValueError("samples is for the random and lhs methods; a grid takes every value")
        for d in domains:
            if d.values is None:
                raise ValueError(
                    f"a grid needs values for '{d.name}': give a count, {d.text}:N, or a list"
                )
        total = int(np.prod([len(d.values) for d in domains], dtype=np.float64))
        if total > MAX_VARIANTS:
            raise ValueError(
                f"the grid holds {total:,} variants (more than {MAX_VARIANTS:,}); sample it "
                f"with method random or lhs"
            )
        combos = itertools.product(*(d.values for d in domains))
        return [dict(zip(names, combo, strict=True)) for combo in combos]
    if samples is None or not 1 <= samples <= MAX_VARIANTS:
        raise ValueError(f"method {method} needs a sample count from 1 to {MAX_VARIANTS:,}")
    rng = np.random.default_rng(seed)
    columns = []
    for d in domains:
        if method == "random":
            u = rng.random(samples)
        else:
            u = (rng.permutation(samples) + rng.random(samples)) / samples
        columns.append(d.pick(u))
    return [dict(zip(names, row, strict=True)) for row in zip(*columns, strict=True)]
