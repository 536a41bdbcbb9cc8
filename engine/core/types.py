"""Port types: the Python classes that type node inputs and outputs.

A port's type hint (``int``, ``Vec3``, ``list[Curve]``, ``Mesh | None``,
``Annotated[int, Range(min=1)]``, an ``Enum``) becomes a :class:`PortType`, which knows
how to check a wire (subtypes accepted, a single item where a list is asked) and how to
coerce a YAML literal into the value the node function receives (nothing else is coerced).
"""

from __future__ import annotations

import enum
import functools
import math
import types as _pytypes
import typing
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..geometry import (
    Curve,
    Field,
    Geometry,
    Mesh,
    NurbsCurve,
    NurbsSurface,
    Points,
    Solid,
    Surface,
    as_xyz,
    frozen_array,
)


class Vec3:
    """A 3-vector port: ``[x, y]`` or ``[x, y, z]``; the node gets a read-only (3,) array."""


class Faces(list):
    """A list of faces, each a list of vertex indices (``list[list[int]]``)."""

    port_name = "list[list[int]]"


class Entries(list):
    """The value of a list port that remembers which entry of the port each item came from.

    A list port's YAML list (``curves: ["@cut", "@engrave"]``) joins the lists its wires
    carry into one flat list; ``entries[i]`` is the index, in the port's list, of the entry
    that item i came from (a single wire, ``curves: "@cut"``, is entry 0 for all its items).
    Nodes that care where an item came from (the drawing exports give every wire its layer)
    read it with :func:`entries_of`; every other node sees a plain list.
    """

    __slots__ = ("entries",)

    def __init__(self, items: Any = (), entries: Any = ()):
        super().__init__(items)
        self.entries = tuple(int(e) for e in entries)
        if len(self.entries) != len(self):
            raise ValueError(f"{len(self)} items but {len(self.entries)} entry indices")


def entries_of(values: list[Any]) -> list[int]:
    """Per item of a list port, the index of the port's entry it came on.

    Items given without that record (a list built in Python) are each their own entry.
    """
    if isinstance(values, Entries):
        return list(values.entries)
    return list(range(len(values)))


class Expression(str):
    """An expression port (text in the node's variables and the graph params)."""


class OutputPath(str):
    """A relative output path, checked not to leave the output directory."""


class InputPath(str):
    """A relative path of a file a node reads, checked not to leave the inputs folder; the
    file's bytes are part of the node's cache key."""


def number_text(x: float) -> str:
    """A number for a message: ``%g`` style, and an int too large for a float by its size."""
    if isinstance(x, int) and not -(10**15) < x < 10**15:
        import math

        return f"{'a negative' if x < 0 else 'an'} integer of {int(math.log10(abs(x))) + 1} digits"
    return f"{x:g}"


@dataclass(frozen=True)
class Range:
    """Inclusive bounds of a numeric port, checked at load."""

    min: float | None = None
    max: float | None = None

    def check(self, value: float) -> str | None:
        if self.min is not None and value < self.min:
            return f"must be >= {number_text(self.min)}, got {number_text(value)}"
        if self.max is not None and value > self.max:
            return f"must be <= {number_text(self.max)}, got {number_text(value)}"
        return None


@dataclass(frozen=True)
class SameAs:
    """An output whose type is the type of what flows into input ``port`` (e.g. a transform
    gives back a Curve for a Curve, a list[Mesh] for a list[Mesh]); the checker follows it."""

    port: str


@dataclass(frozen=True)
class Variables:
    """The variables an :class:`Expression` port's text may use besides the params."""

    names: tuple[str, ...]

    def __init__(self, *names: str):
        object.__setattr__(self, "names", tuple(names))


@dataclass(frozen=True)
class PerElement:
    """A port that also takes expressions evaluated once per element of the geometry on
    input ``of`` (over the element's ``x y z``, ``i``, ``count``, its attributes and the
    params): ``scale: "=0.5 + rand(i)"``. A plain value, or an expression of the params
    alone, is an ordinary input."""

    of: str


class TypeMismatch(ValueError):
    """A literal or wire that does not fit a port."""


GEOMETRY_TYPES: dict[str, type] = {
    "Geometry": Geometry,
    "Points": Points,
    "Curve": Curve,
    "NurbsCurve": NurbsCurve,
    "Surface": Surface,
    "NurbsSurface": NurbsSurface,
    "Mesh": Mesh,
    "Field": Field,
    "Solid": Solid,
}
SCALARS: dict[str, type] = {"int": int, "float": float, "bool": bool, "str": str}


@dataclass(frozen=True)
class Kind:
    """One alternative of a port type: a base class, as an item or as a list of items."""

    base: Any
    is_list: bool = False

    @property
    def name(self) -> str:
        if typing.get_origin(self.base) is list:  # a nested list, e.g. list[list[float]]
            n = Kind(typing.get_args(self.base)[0], True).name
        else:
            n = getattr(self.base, "port_name", None) or getattr(
                self.base, "__name__", str(self.base)
            )
        return f"list[{n}]" if self.is_list else n


@dataclass(frozen=True)
class PortType:
    """The type of a port: one or more :class:`Kind` alternatives, maybe optional."""

    kinds: tuple[Kind, ...]
    optional: bool = False
    range: Range | None = None
    variables: tuple[str, ...] = ()
    same_as: str | None = None  # an output typed like one of the node's inputs
    per_element: str | None = None  # takes per-element expressions over this input

    @property
    def name(self) -> str:
        return " | ".join(k.name for k in self.kinds)

    @functools.cached_property
    def _geometry_item(self) -> type | None:
        """The geometry class of a single-kind, non-list port (None otherwise)."""
        if len(self.kinds) == 1 and not self.kinds[0].is_list and _is_geometry(self.kinds[0].base):
            return self.kinds[0].base
        return None

    @functools.cached_property
    def is_expression(self) -> bool:
        return any(k.base is Expression for k in self.kinds)

    @functools.cached_property
    def is_output_path(self) -> bool:
        return any(k.base is OutputPath for k in self.kinds)

    @functools.cached_property
    def is_input_path(self) -> bool:
        return any(k.base is InputPath for k in self.kinds)

    @functools.cached_property
    def is_geometry(self) -> bool:
        return any(_is_geometry(k.base) for k in self.kinds)

    @property
    def enum(self) -> type[enum.Enum] | None:
        for k in self.kinds:
            if isinstance(k.base, type) and issubclass(k.base, enum.Enum):
                return k.base
        return None

    def accepts(self, other: PortType) -> bool:
        """Whether a wire carrying ``other`` may feed this port."""
        if any(k.base is Any for k in self.kinds):
            return True
        return all(any(_kind_accepts(k, o) for k in self.kinds) for o in other.kinds)

    def holds(self, value: Any) -> bool:
        """Whether ``value`` could be this port's output: geometry of the port's class (or a
        list of it), anything but geometry for a number, text or other plain port.

        For values read back from the disk cache, where an entry can be well formed and
        still of another node (a Points where a measure belongs): a mismatch is a miss.
        """
        if self.same_as is not None or (value is None and self.optional):
            return True
        return any(_kind_holds(k, value) for k in self.kinds)

    def coerce(self, value: Any) -> Any:
        """The value a node function receives for the literal ``value``.

        Raises
        ------
        TypeMismatch
            With a sentence saying what was expected and what came.
        """
        if self._geometry_item is not None and isinstance(value, self._geometry_item):
            return value  # the common case of a wire: already the right geometry
        if value is None:
            if self.optional:
                return None
            raise TypeMismatch(f"expected {self.name}, got nothing (null)")
        errors = []
        for k in self.kinds:
            try:
                out = _coerce_kind(k, value)
            except TypeMismatch as exc:
                errors.append(str(exc))
                continue
            if self.range is not None:
                for x in _numbers(out):
                    msg = self.range.check(x)
                    if msg:
                        raise TypeMismatch(msg)
            return out
        if len(errors) == 1:
            raise TypeMismatch(errors[0])
        raise TypeMismatch(f"expected {self.name}, got {describe(value)}")


def _is_geometry(base: Any) -> bool:
    return isinstance(base, type) and issubclass(base, Geometry)


def _kind_holds(k: Kind, value: Any) -> bool:
    if k.base is Any:
        return True
    if k.is_list and isinstance(value, np.ndarray):  # numbers stored as one array
        return not _is_geometry(k.base)
    if k.is_list and not isinstance(value, (list, tuple)):
        return False
    items = value if k.is_list else [value]
    if _is_geometry(k.base):
        return all(isinstance(v, k.base) for v in items)
    return not any(isinstance(v, Geometry) for v in items)


def _kind_accepts(k: Kind, o: Kind) -> bool:
    if not (isinstance(o.base, type) and isinstance(k.base, type)):
        return k.base is o.base
    same = issubclass(o.base, k.base) or (k.base is float and o.base is int)
    if not same:
        return False
    return k.is_list or not o.is_list


def _numbers(value: Any) -> list[float]:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return [value]
    if isinstance(value, list) and all(isinstance(v, (int, float)) for v in value):
        return [v for v in value if not isinstance(v, bool)]
    return []


def describe(value: Any) -> str:
    """A short description of a value for error messages: its type and a glimpse."""
    if isinstance(value, Geometry):
        return type(value).__name__
    if value is None:
        return "None (null)"
    if isinstance(value, bool):
        return f"bool {value}"
    if isinstance(value, (int, float)):
        return f"{type(value).__name__} {value!r}"
    if isinstance(value, str):
        return f"string {value!r}" if len(value) < 40 else f"string {value[:37]!r}..."
    if isinstance(value, list):
        return f"list of {len(value)}"
    if isinstance(value, dict):
        return "mapping"
    return type(value).__name__


def loop_item_problem(items: Any) -> str | None:
    """Why a ``repeat:`` list cannot feed expressions (a bool or a string among its items).

    A loop's items reach the node's expressions, which compute on numbers only; a bool
    would silently count as 1 or 0 there, as it would nowhere else in a graph.
    """
    if not isinstance(items, (list, tuple)):
        return None
    for k, item in enumerate(items):
        stack = [item]
        while stack:
            v = stack.pop()
            if isinstance(v, (list, tuple)):
                stack.extend(v)
            elif isinstance(v, (bool, np.bool_, str)):
                return (
                    f"item {k} is {describe(item)}: a loop's items are numbers, points or "
                    "geometry (write 1 and 0, not true and false)"
                    if not isinstance(v, str)
                    else f"item {k} is {describe(item)}: a loop's items are numbers, points "
                    "or geometry, since its name is read by expressions"
                )
    return None


def _coerce_kind(k: Kind, value: Any) -> Any:
    if k.is_list:
        if isinstance(value, (list, tuple)):
            if k.base is Vec3:
                return _vec_list(value)
            items = [_coerce_kind(Kind(k.base), v) for v in value]
            return Entries(items, value.entries) if isinstance(value, Entries) else items
        if k.base is Vec3 and isinstance(value, np.ndarray) and value.ndim == 2:
            return _vec_list(value)
        # a single item is accepted where a list is asked
        return [_coerce_kind(Kind(k.base), value)]
    base = k.base
    if base is Any:
        return value
    # An item that is itself a list (list[list[float]]); a plain class never is (and asking
    # typing costs every float and wire a call).
    if type(base) is not type and typing.get_origin(base) is list:
        if not isinstance(value, (list, tuple)):
            raise TypeMismatch(f"expected {Kind(base).name}, got {describe(value)}")
        return _coerce_kind(Kind(typing.get_args(base)[0], True), value)
    if base is bool:
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        yaml11 = isinstance(value, str) and value.lower() in ("yes", "no", "on", "off", "y", "n")
        hint = " (YAML 1.2 reads it as text: write true or false)" if yaml11 else ""
        raise TypeMismatch(f"expected bool, got {describe(value)}{hint}")
    if base is int:
        if isinstance(value, (bool, np.bool_)):
            raise TypeMismatch(f"expected int, got {describe(value)}")
        if isinstance(value, (int, np.integer)):
            return int(value)
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            return int(value)
        raise TypeMismatch(f"expected int, got {describe(value)}")
    if base is float:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
            raise TypeMismatch(f"expected float, got {describe(value)}")
        try:
            f = float(value)
        except OverflowError:
            raise TypeMismatch(
                f"expected a float, got a number too large ({describe(value)[:40]})"
            ) from None
        if not math.isfinite(f):
            raise TypeMismatch(f"expected a finite float, got {f}")
        return f
    if base in (str, Expression, OutputPath, InputPath):
        if isinstance(value, str):
            return value
        raise TypeMismatch(f"expected {base.__name__}, got {describe(value)}")
    if base is Vec3:
        return _vec3(value)
    if base is Faces:
        return _faces(value)
    if isinstance(base, type) and issubclass(base, enum.Enum):
        try:
            return base(value)
        except ValueError:
            import difflib

            values = [str(m.value) for m in base]
            options = ", ".join(repr(v) for v in values)
            close = difflib.get_close_matches(str(value), values, n=1, cutoff=0.6)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise TypeMismatch(
                f"{value!r} is not a valid option{hint}, must be one of {options}"
            ) from None
    if base is Points and not isinstance(value, Geometry):
        if _holds_bool(value):
            raise TypeMismatch(f"expected Points (numbers), got true/false in {describe(value)}")
        try:
            return Points(value)
        except ValueError as exc:
            raise TypeMismatch(
                f"expected Points (a list of [x, y, z]), got {describe(value)}: {exc}"
            ) from None
    if isinstance(base, type) and isinstance(value, base):
        return value
    raise TypeMismatch(f"expected {base.__name__}, got {describe(value)}")


def _vec3(value: Any) -> np.ndarray:
    if isinstance(value, (list, tuple)) and any(isinstance(v, (str, bool)) for v in value):
        raise TypeMismatch(f"expected [x, y] or [x, y, z] numbers, got {describe(value)}")
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise TypeMismatch(f"expected [x, y] or [x, y, z], got {describe(value)}") from None
    if a.shape not in ((2,), (3,)):
        raise TypeMismatch(f"expected [x, y] or [x, y, z], got {describe(value)}")
    if not np.all(np.isfinite(a)):
        shown = ", ".join(f"{x:g}" for x in a)
        raise TypeMismatch(f"expected [x, y] or [x, y, z] finite numbers, got [{shown}]")
    return frozen_array(np.append(a, 0.0) if a.size == 2 else a)


def _faces(value: Any) -> Faces:
    if not isinstance(value, (list, tuple)) or not value:
        raise TypeMismatch(
            f"expected a list of faces (lists of vertex indices), got {describe(value)}"
        )
    out = Faces()
    for i, face in enumerate(value):
        if not isinstance(face, (list, tuple)) or not all(
            isinstance(x, (int, np.integer)) and not isinstance(x, bool) for x in face
        ):
            raise TypeMismatch(f"face {i} must be a list of vertex indices, got {describe(face)}")
        out.append([int(x) for x in face])
    return out


def _holds_bool(rows: Any) -> bool:
    """Whether a list of coordinate rows holds a bool (numpy would read True as 1)."""
    if not isinstance(rows, (list, tuple)):
        return False
    return any(
        type(x) is bool for row in rows for x in (row if isinstance(row, (list, tuple)) else (row,))
    )


def _vec_list(value: Any) -> np.ndarray:
    if _holds_bool(value):
        raise TypeMismatch(f"expected [x, y, z] numbers, got true/false in {describe(value)}")
    try:
        return as_xyz(value, "coordinates")
    except ValueError as exc:
        raise TypeMismatch(str(exc)) from None


def port_type(hint: Any) -> PortType:
    """Turn a type hint into a :class:`PortType`."""
    rng: Range | None = None
    variables: tuple[str, ...] = ()
    same_as: str | None = None
    per_element: str | None = None
    if typing.get_origin(hint) is typing.Annotated:
        hint, *extras = typing.get_args(hint)
        for x in extras:
            if isinstance(x, Range):
                rng = x
            elif isinstance(x, Variables):
                variables = x.names
            elif isinstance(x, SameAs):
                same_as = x.port
            elif isinstance(x, PerElement):
                per_element = x.of
    optional = False
    alternatives = [hint]
    if typing.get_origin(hint) in (typing.Union, _pytypes.UnionType):
        alternatives = list(typing.get_args(hint))
    kinds = []
    for alt in alternatives:
        if alt is type(None):
            optional = True
            continue
        if typing.get_origin(alt) is list:
            (item,) = typing.get_args(alt)
            kinds.append(Kind(item, True))
        else:
            kinds.append(Kind(alt, False))
    return PortType(tuple(kinds), optional, rng, variables, same_as, per_element)


def type_by_name(name: str) -> PortType:
    """The port type for a name written in YAML (param ``type:``), e.g. ``list[Curve]``."""
    text = name.strip()
    is_list = text.startswith("list[") and text.endswith("]")
    inner = text[5:-1].strip() if is_list else text
    base = GEOMETRY_TYPES.get(inner) or SCALARS.get(inner) or {"Vec3": Vec3}.get(inner)
    if base is None:
        known = ", ".join([*GEOMETRY_TYPES, *SCALARS, "Vec3"])
        raise TypeMismatch(f"unknown type {name!r} (known: {known}, and list[...] of them)")
    return PortType((Kind(base, is_list),))


def as_list(t: PortType) -> PortType:
    """The type of a list of ``t`` (a list of lists flattens: list[T] stays list[T])."""
    return PortType(tuple(dict.fromkeys(Kind(k.base, True) for k in t.kinds)))


def type_of_value(value: Any) -> PortType:
    """The port type a runtime value has (for params supplied from Python)."""
    if isinstance(value, list) and value and all(isinstance(v, Geometry) for v in value):
        return PortType((Kind(_common_base([type(v) for v in value]), True),))
    if isinstance(value, bool):
        return PortType((Kind(bool),))
    return PortType((Kind(type(value)),))


def _common_base(classes: list[type]) -> type:
    for cls in classes[0].__mro__:
        if all(issubclass(c, cls) for c in classes):
            return cls
    return object
