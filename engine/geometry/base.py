"""What every geometry value shares: the :class:`Geometry` base, frozen arrays, and the
registry of types the disk cache can store and rebuild (:func:`storable`, :func:`from_state`).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any, TypeVar

import numpy as np

from ..kernels.buffers import fill_bytes
from ..kernels.finite import all_finite

__all__ = [
    "STORABLE",
    "AttributeMap",
    "Geometry",
    "all_finite",
    "as_xyz",
    "attribute_map",
    "from_state",
    "frozen_array",
    "is_frozen",
    "storable",
]


def is_frozen(a: Any) -> bool:
    """Whether nobody can ever write to array ``a``: read-only all the way to an immutable
    ``bytes`` buffer (an array that owns its data could be made writable again)."""
    if not isinstance(a, np.ndarray) or a.flags.writeable:
        return False
    base: Any = a
    while isinstance(base, np.ndarray):
        base = base.base
    return isinstance(base, bytes)


def frozen_array(values: Any, dtype: Any = np.float64) -> np.ndarray:
    """A C-contiguous array of ``values`` that nobody can write to, or make writable.

    The data are copied once into an immutable ``bytes`` buffer and viewed from there, so
    ``a.flags.writeable = True`` raises (for ``a`` and for ``a.base``). An array that is
    already frozen is shared as it is, never copied.
    """
    if is_frozen(values) and values.dtype == dtype and values.flags.c_contiguous:
        return values
    if isinstance(values, np.ndarray):  # a large array: cast straight into new bytes
        buf = fill_bytes(values, dtype)
        if buf is not None:
            return np.frombuffer(buf, dtype=dtype).reshape(values.shape)
    a = np.asarray(values, dtype=dtype)
    return np.frombuffer(a.tobytes(order="C"), dtype=a.dtype).reshape(a.shape)


def as_xyz(values: Any, what: str = "points") -> np.ndarray:
    """``(n, 2)`` or ``(n, 3)`` coordinates as a read-only ``(n, 3)`` float64 array (z = 0)."""
    frozen = is_frozen(values) and values.dtype == np.float64 and values.flags.c_contiguous
    if frozen and values.ndim == 2 and values.shape[1] == 3 and all_finite(values):
        return values  # immutable and valid already (another value's coordinates): shared
    try:
        raw = np.asarray(values)
        if raw.dtype.kind not in "biuf":
            raise TypeError  # strings, objects: not coordinates
        a = raw.astype(np.float64, copy=False)
    except (TypeError, ValueError, OverflowError):
        raw = None
        a = _pad_rows(values, what)
    if raw is not None and raw.dtype.kind == "b":
        raise ValueError(f"{what} must be numbers, not true/false")
    if a.ndim == 1 and a.size in (2, 3):
        a = a[None, :]
    if a.size == 0 and a.shape in ((0,), (0, 2), (0, 3)):
        a = a.reshape(0, 3)
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise ValueError(
            f"{what} must be a list of [x, y] or [x, y, z] coordinates, got an array of shape "
            f"{a.shape}"
        )
    if a.shape[1] == 2:
        a = np.column_stack([a, np.zeros(len(a))])
    if not all_finite(a):
        bad = int(np.argwhere(~np.isfinite(a))[0, 0])
        raise ValueError(f"{what}: coordinate {bad} is not finite ({a[bad].tolist()})")
    return frozen_array(a)


def _number(x: Any) -> float:
    if isinstance(x, (str, bytes, bool)) or not isinstance(x, (int, float, np.number)):
        raise TypeError(f"{x!r} is not a number")
    return float(x)


def _pad_rows(values: Any, what: str) -> np.ndarray:
    """Mixed [x, y] and [x, y, z] rows (z = 0 where it is missing)."""
    try:
        rows = [[_number(x) for x in r] for r in values]
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{what} must be a list of [x, y] or [x, y, z] numbers") from None
    for i, r in enumerate(rows):
        if len(r) not in (2, 3):
            raise ValueError(
                f"{what}: point {i} has {len(r)} coordinates; give [x, y] or [x, y, z]"
            )
    return np.array([r + [0.0] * (3 - len(r)) for r in rows], dtype=np.float64).reshape(-1, 3)


MAX_ATTRIBUTE_COMPONENTS = 64


class AttributeMap(Mapping):
    """Named per-element arrays of one geometry value: a read-only mapping name -> frozen
    float64 array of shape ``(n,)`` or ``(n, k)`` (``n`` the number of elements).

    Names are kept sorted, so two maps with the same content compare, hash and store alike.
    Build one with :func:`attribute_map`; a map never changes after that.

    Example
    -------
    >>> m = attribute_map({"h": [0.0, 1.0]}, 2)
    >>> list(m), m["h"].tolist(), m == {"h": [0.0, 1.0]}
    (['h'], [0.0, 1.0], True)
    """

    __slots__ = ("_data", "n")

    def __init__(self, data: dict[str, np.ndarray], n: int):
        object.__setattr__(self, "_data", dict(sorted(data.items())))
        object.__setattr__(self, "n", n)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("attributes are read-only")

    def __getitem__(self, name: str) -> np.ndarray:
        return self._data[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Mapping) or sorted(other) != list(self._data):
            return False
        return all(
            np.shape(other[k]) == v.shape and np.array_equal(np.asarray(other[k]), v)
            for k, v in self._data.items()
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        parts = ", ".join(f"{k}: {v.shape[1:] or 'scalar'}" for k, v in self._data.items())
        return f"AttributeMap({{{parts}}})"

    @property
    def nbytes(self) -> int:
        return sum(v.nbytes for v in self._data.values())

    def pairs(self) -> list[list[Any]]:
        """``[[name, array], ...]`` in name order: the form ``state()`` stores."""
        return [[k, v] for k, v in self._data.items()]

    def take(self, index: Any) -> AttributeMap:
        """Every attribute at the elements ``index`` (an int array): copied from source."""
        index = np.asarray(index, dtype=np.int64)
        return AttributeMap({k: frozen_array(v[index]) for k, v in self._data.items()}, len(index))

    def with_(self, name: str, values: Any, *, finite: bool = False) -> AttributeMap:
        """This map with attribute ``name`` set to ``values`` (added or replaced).

        ``finite=True``: the caller has checked every value finite already (a per-element
        expression's result is: a second pass over a million values is not needed)."""
        data = dict(self._data)
        data[name] = _attribute_array(name, values, self.n, "attribute", finite=finite)
        return AttributeMap(data, self.n)


def _attribute_array(
    name: Any, values: Any, n: int, what: str, *, finite: bool = False
) -> np.ndarray:
    if not isinstance(name, str) or not name.isidentifier() or name.startswith("_"):
        raise ValueError(
            f"{what} name {name!r} must be a name as in expressions: letters, digits and _, "
            f"not starting with a digit or _"
        )
    try:
        raw = np.asarray(values)
        if raw.dtype.kind not in "biuf":
            raise TypeError
        a = raw.astype(np.float64, copy=False)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{what} {name!r} must be numbers") from None
    if a.ndim == 0:
        a = np.broadcast_to(a, (n,))  # one value for every element
    if a.ndim not in (1, 2) or a.shape[0] != n:
        raise ValueError(
            f"{what} {name!r} has shape {a.shape}; it needs one value (or one row) per element, "
            f"({n},) or ({n}, k)"
        )
    if a.ndim == 2 and not 1 <= a.shape[1] <= MAX_ATTRIBUTE_COMPONENTS:
        raise ValueError(
            f"{what} {name!r} has {a.shape[1]} components; 1 to {MAX_ATTRIBUTE_COMPONENTS} allowed"
        )
    if not finite and not all_finite(a):
        bad = int(np.argwhere(~np.isfinite(a.reshape(n, -1)))[0, 0])
        raise ValueError(f"{what} {name!r} is not finite at element {bad}")
    return frozen_array(a)


def attribute_map(values: Any, n: int, what: str = "attribute") -> AttributeMap:
    """A validated, frozen :class:`AttributeMap` for ``n`` elements.

    Parameters
    ----------
    values : mapping name -> array, list of [name, array] pairs, AttributeMap or None
        Each array ``(n,)`` or ``(n, k)``; a single number is repeated for every element.
    n : int
        The number of elements (points, vertices or faces).

    Raises
    ------
    ValueError
        For a bad name, a wrong length, non-numbers or non-finite values, naming the
        attribute.
    """
    if isinstance(values, AttributeMap) and values.n == n:
        return values
    if values is None:
        return AttributeMap({}, n)
    items = values.items() if isinstance(values, Mapping) else values
    data: dict[str, np.ndarray] = {}
    try:
        pairs = [(k, v) for k, v in items]
    except (TypeError, ValueError):
        raise ValueError(f"{what}s must be a mapping of name -> values") from None
    for name, v in pairs:
        if name in data:
            raise ValueError(f"{what} {name!r} is given twice")
        data[name] = _attribute_array(name, v, n, what)
    return AttributeMap(data, n)


def _expression_fingerprint(f: Any) -> Any:
    """A bound expression is its text and the param values it reads; any other callable
    cannot be hashed (its content is code), and says so."""
    text, params = getattr(f, "text", None), getattr(f, "params", None)
    if isinstance(text, str) and params is not None:
        return {"text": text, "params": dict(params)}
    raise TypeError("a curve or surface of plain Python callables has no content hash")


class Geometry:
    """Base of the geometry types."""

    @property
    def nbytes(self) -> int:
        return sum(v.nbytes for v in vars(self).values() if isinstance(v, np.ndarray))

    def to_pyvista(self) -> Any:  # pragma: no cover - overridden
        raise NotImplementedError

    def state(self) -> dict[str, Any]:
        """Arrays and JSON-able scalars that rebuild this value with :func:`from_state`."""
        raise NotImplementedError(f"{type(self).__name__} cannot be stored on disk")

    def fingerprint(self) -> Any:
        """What determines this value, for content hashes (its state, by default)."""
        return self.state()

    def _content_hash(self) -> int:
        """A hash of the state's arrays and scalars (for types that compare by content),
        computed once: values are immutable."""
        cached = self.__dict__.get("_hash")
        if cached is None:
            import hashlib

            h = hashlib.blake2b(type(self).__name__.encode(), digest_size=8)
            stack = [self.state()]
            while stack:
                item = stack.pop()
                if isinstance(item, dict):
                    stack.extend(item[k] for k in sorted(item, reverse=True))
                elif isinstance(item, (list, tuple)):
                    stack.extend(reversed(item))
                elif isinstance(item, np.ndarray):
                    h.update(str(item.shape).encode())
                    h.update(np.ascontiguousarray(item).view(np.uint8).reshape(-1))
                else:
                    h.update(repr(item).encode())
            cached = int.from_bytes(h.digest(), "little", signed=True)
            object.__setattr__(self, "_hash", cached)
        return cached

    def __reduce_ex__(self, protocol: Any) -> Any:
        # pickled (e.g. to a worker process) as its state and rebuilt through the
        # constructor, so the copy is validated and as frozen as the original
        name = type(self).__name__
        if STORABLE.get(name) is type(self):
            return from_state, (name, self.state())
        return super().__reduce_ex__(protocol)


# The types whose ``state()`` rebuilds them: name -> class (the disk cache's table of types).
STORABLE: dict[str, type[Geometry]] = {}

G = TypeVar("G", bound=type)


def storable(cls: G) -> G:
    """Register a geometry type whose :meth:`Geometry.state` rebuilds it (class decorator)."""
    STORABLE[cls.__name__] = cls
    return cls


def from_state(type_name: str, state: dict[str, Any]) -> Geometry:
    """Rebuild a geometry value from :meth:`Geometry.state` (validated like any input)."""
    cls = STORABLE[type_name]
    return cls(**state)
