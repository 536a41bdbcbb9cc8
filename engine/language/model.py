"""The graph as authored: params, nodes and their inputs, with the lines they came from.

An input's authored value is parsed once into one of :class:`Literal`, :class:`Wire`,
:class:`Expr` or :class:`Items` (a list holding wires or expressions), while the raw value
is kept so that ``save()`` writes back exactly what the author wrote.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Union

import numpy as np

from ..core.errors import ExpressionError
from ..core.types import PortType
from .expr import Compiled, compile_expression


@dataclass(frozen=True)
class Literal:
    value: Any


@dataclass(frozen=True)
class Wire:
    node: str
    output: str | None = None

    def __str__(self) -> str:
        return f"@{self.node}" + (f".{self.output}" if self.output else "")


@dataclass(frozen=True)
class Expr:
    compiled: Compiled

    @property
    def text(self) -> str:
        return self.compiled.text

    def value(self, values: Mapping[str, Any]) -> Any:
        """The expression's value over ``values`` (param name -> value).

        A bare name passes its value through, whatever its type; list params act as
        vectors; an array result comes back as a Python number or list.

        Raises
        ------
        ValueError
            The result is NaN or infinite.
        """
        if self.compiled.is_bare_name:
            return values[self.text.strip()]
        env = {
            n: np.asarray(values[n], dtype=np.float64) if isinstance(values[n], list) else values[n]
            for n in self.compiled.names
        }
        value = self.compiled(env)
        if hasattr(value, "ndim"):
            value = value.item() if value.ndim == 0 else value.tolist()
        if isinstance(value, float) and value != value:
            raise ValueError(f"'={self.text}' is not a number (NaN)")
        if isinstance(value, float) and value in (float("inf"), float("-inf")):
            raise ValueError(f"'={self.text}' overflows to infinity")
        return value


@dataclass(frozen=True)
class Items:
    items: tuple[Input, ...]


Input = Union[Literal, Wire, Expr, Items]  # noqa: UP007 (a runtime alias)


_NUMBERS = (int, float, bool)


def parse_input(raw: Any) -> Input:
    """Parse an authored input value.

    ``"@node"`` / ``"@node.output"`` is a wire, ``"=..."`` an expression over the params,
    ``{value: ...}`` an escaped literal; a list holding wires or expressions becomes
    :class:`Items`; anything else is a literal.

    Raises
    ------
    ExpressionError
        For a malformed wire or expression.
    """
    if isinstance(raw, str):
        if raw.startswith("@"):
            target = raw[1:]
            name, _, output = target.partition(".")
            if not name or not _is_name(name) or (output and not _is_name(output)):
                raise ExpressionError(
                    f"{raw!r} is not a wire; write '@node' or '@node.output' (escape a literal "
                    f"string starting with '@' as {{value: {raw!r}}})"
                )
            return Wire(name, output or None)
        if raw.startswith("="):
            return Expr(compile_expression(raw[1:]))
        return Literal(raw)
    if isinstance(raw, dict) and set(raw) == {"value"}:
        return Literal(raw["value"])
    if isinstance(raw, list):
        if all(type(v) in _NUMBERS for v in raw):
            return Literal(raw)  # the common case of coordinates, without a call per number
        items = tuple(parse_input(v) for v in raw)
        if any(not isinstance(i, Literal) for i in items):
            return Items(items)
        return Literal([i.value for i in items])
    return Literal(raw)


def _is_name(text: str) -> bool:
    return text.replace("-", "_").isidentifier()


def wires_of(value: Input) -> list[Wire]:
    if isinstance(value, Wire):
        return [value]
    if isinstance(value, Items):
        return [w for i in value.items for w in wires_of(i)]
    return []


def exprs_of(value: Input) -> list[Expr]:
    if isinstance(value, Expr):
        return [value]
    if isinstance(value, Items):
        return [e for i in value.items for e in exprs_of(i)]
    return []


@dataclass(frozen=True)
class Repeat:
    """A node's ``repeat: {name: source}``: the loop name and what it runs over.

    ``source`` is a count (an int, or an expression giving one: items 0 .. n-1), a list
    (literal, or holding expressions), or a wire to a list or to Points (each point a
    [x, y, z] item).
    """

    name: str
    source: Input


def parse_repeat(raw: Any) -> Repeat:
    """Parse an authored ``repeat:`` mapping.

    Raises
    ------
    ExpressionError
        For anything but one ``name: source`` pair, or a malformed wire or expression.
    """
    if not isinstance(raw, dict) or len(raw) != 1:
        raise ExpressionError(
            "repeat takes one loop name and what it runs over, e.g. repeat: {i: 5}, "
            '{i: "=n"}, {r: [1, 2, 5]} or {p: "@points"}'
        )
    ((name, source),) = raw.items()
    name = str(name)
    return Repeat(name, parse_input(source))


@dataclass(frozen=True)
class Simulate:
    """A node's ``simulate: {state, from, steps}``: the node runs ``steps`` times, each
    step's output the next step's ``state`` input, ``from`` its value at step 0.

    ``source`` (the ``from``) is any input (mostly a wire); ``steps`` a count (an int, or an
    expression giving one). The node's expressions see the step index as ``step``.
    """

    state: str
    source: Input
    steps: Input


#: the name a simulated node's expressions see the step index under (1, 2, ... steps)
STEP = "step"
#: the output of a simulated node that holds every step's output, in order
FRAMES = "frames"

_SIMULATE_KEYS = ("state", "from", "steps")


def parse_simulate(raw: Any) -> Simulate:
    """Parse an authored ``simulate:`` mapping.

    Raises
    ------
    ExpressionError
        For anything but ``{state: port, from: ..., steps: ...}``, or a malformed wire or
        expression.
    """
    example = 'e.g. simulate: {state: curve, from: "@seed", steps: "=steps"}'
    if not isinstance(raw, dict):
        raise ExpressionError(f"simulate takes state, from and steps, {example}")
    missing = [k for k in _SIMULATE_KEYS if k not in raw]
    extra = sorted(str(k) for k in raw if k not in _SIMULATE_KEYS)
    if missing or extra:
        what = f"needs {', '.join(missing)}" if missing else f"has no '{extra[0]}'"
        raise ExpressionError(f"simulate {what}: it takes state, from and steps, {example}")
    state = raw["state"]
    if not isinstance(state, str) or not _is_name(state):
        raise ExpressionError(f"simulate's state is the name of an input, got {state!r}")
    if isinstance(raw["steps"], bool):
        raise ExpressionError(f"simulate's steps is a count, got {raw['steps']!r}")
    return Simulate(state, parse_input(raw["from"]), parse_input(raw["steps"]))


@dataclass
class ParamDef:
    """A graph parameter: default, optional declared type, range and doc."""

    name: str
    default: Any = None
    type: PortType | None = None
    type_name: str | None = None
    min: float | None = None
    max: float | None = None
    doc: str = ""
    line: int | None = None
    long_form: bool = False
    choices: tuple[Any, ...] | None = None  # the only values it takes (a choice control)
    # what the ports its expressions feed ask for (set by the check): a whole-number param
    # that feeds only float ports is a float, so ``--set r=2.5`` works on ``r: 2``
    fed: type | None = field(default=None, compare=False)

    def to_yaml(self) -> Any:
        if not self.long_form:
            return self.default
        out: dict[str, Any] = {}
        if self.type_name is not None:
            out["type"] = self.type_name
        if self.default is not None or self.type_name is None:
            out["default"] = self.default
        if self.min is not None:
            out["min"] = self.min
        if self.max is not None:
            out["max"] = self.max
        if self.choices is not None:
            out["choices"] = list(self.choices)
        if self.doc:
            out["doc"] = self.doc
        return out


@dataclass
class NodeDef:
    """A node as authored: its name, type, raw inputs (in author order) and lines."""

    name: str
    type: str
    raw: dict[str, Any] = field(default_factory=dict)
    inputs: dict[str, Input] = field(default_factory=dict)
    line: int | None = None
    input_lines: dict[str, int] = field(default_factory=dict)
    parse_errors: dict[str, str] = field(default_factory=dict)
    repeat: Repeat | None = None
    repeat_raw: Any = None  # as authored, for save()
    simulate: Simulate | None = None
    simulate_raw: Any = None  # as authored, for save()

    @classmethod
    def make(
        cls,
        name: str,
        type_: str,
        raw: dict[str, Any],
        line: int | None = None,
        input_lines: dict[str, int] | None = None,
    ) -> NodeDef:
        raw = dict(raw)
        nd = cls(name, type_, raw, {}, line, dict(input_lines or {}))
        if "repeat" in raw:
            nd.set_repeat(raw.pop("repeat"))
        if "simulate" in raw:
            nd.set_simulate(raw.pop("simulate"))
        for port, value in raw.items():
            try:
                nd.inputs[port] = parse_input(value)
            except ExpressionError as exc:
                nd.parse_errors[port] = str(exc.problems[0].message)
        return nd

    def moved(self, lines: int = 0) -> NodeDef:
        """A copy with dicts of its own, written ``lines`` lines further down: a node in a
        graph is not changed in place (graphs read from one text share their nodes)."""
        return NodeDef(
            self.name, self.type, dict(self.raw), dict(self.inputs),
            None if self.line is None else self.line + lines,
            {p: n + lines for p, n in self.input_lines.items()}, dict(self.parse_errors),
            self.repeat, self.repeat_raw, self.simulate, self.simulate_raw,
        )  # fmt: skip

    def set_repeat(self, raw: Any) -> None:
        """Set (or with None, remove) the node's ``repeat:``."""
        self.parse_errors.pop("repeat", None)
        self.repeat, self.repeat_raw = None, raw
        if raw is None:
            return
        try:
            self.repeat = parse_repeat(raw)
        except ExpressionError as exc:
            self.parse_errors["repeat"] = str(exc.problems[0].message)

    def set_simulate(self, raw: Any) -> None:
        """Set (or with None, remove) the node's ``simulate:``."""
        self.parse_errors.pop("simulate", None)
        self.simulate, self.simulate_raw = None, raw
        if raw is None:
            return
        try:
            self.simulate = parse_simulate(raw)
        except ExpressionError as exc:
            self.parse_errors["simulate"] = str(exc.problems[0].message)

    def upstream(self) -> list[str]:
        wires = [w.node for v in self.inputs.values() for w in wires_of(v)]
        if self.repeat is not None:
            wires += [w.node for w in wires_of(self.repeat.source)]
        if self.simulate is not None:
            wires += [
                w.node for s in (self.simulate.source, self.simulate.steps) for w in wires_of(s)
            ]
        return wires

    def to_yaml(self) -> dict[str, Any]:
        out: dict[str, Any] = {"type": self.type}
        if self.repeat_raw is not None:
            out["repeat"] = self.repeat_raw
        if self.simulate_raw is not None:
            out["simulate"] = self.simulate_raw
        return {**out, **self.raw}
