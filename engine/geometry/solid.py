"""`Solid`: an exact boundary representation (OpenCASCADE), immutable, keyed by its recipe.

A solid is one or more closed shells of faces on exact surfaces (planes, cylinders, cones,
spheres, tori, B-splines), trimmed by exact edges: what CAD programs exchange, fillet and
machine. It is held as an OCC shape (:mod:`formgraph.kernels.brep`, the optional extra
``formgraph[brep]``) and known by what built it, as a :class:`~.field.Field` is: its
``key`` is a hash of the operation, its parameters and the keys (or content hashes) of what
it was made from, so two solids made alike compare alike (early cutoff) without anything
being serialised. For the disk cache, pickling and Dask its state is OCC's binary B-rep
(``BinTools``) and that key; reading the state back checks the bytes make solids.

Nothing of OCC is imported until a solid is made or read: ``import formgraph`` does not
need it.
"""

from __future__ import annotations

import functools
import hashlib
import json
from typing import Any

import numpy as np

from .base import Geometry, frozen_array, storable

__all__ = ["Solid", "recipe_key"]


def _canonical(value: Any) -> Any:
    """A JSON-able, order-stable form of a recipe's parameter."""
    if isinstance(value, Solid):
        return {"solid": value.key}
    if isinstance(value, Geometry):
        return {"geometry": type(value).__name__, "hash": value._content_hash()}
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return {"f": float(value).hex()}
    if isinstance(value, np.ndarray):
        a = np.ascontiguousarray(value)
        digest = hashlib.blake2b(a.view(np.uint8).reshape(-1), digest_size=16).hexdigest()
        return {"a": str(a.dtype), "s": list(a.shape), "h": digest}
    if isinstance(value, (list, tuple)):
        return [_canonical(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _canonical(v) for k, v in sorted(value.items())}
    if value is None or isinstance(value, str):
        return value
    text, params = getattr(value, "text", None), getattr(value, "params", None)
    if isinstance(text, str):  # a bound expression: its text and the params it read
        return {"expr": text, "params": _canonical(dict(params or {}))}
    raise TypeError(f"a solid's recipe cannot hold a {type(value).__name__}")


def recipe_key(op: str, **args: Any) -> str:
    """The key of the solid that operation ``op`` makes from ``args`` (hex, 40 digits)."""
    text = json.dumps({"op": op, "args": _canonical(args)}, sort_keys=True, separators=(",", ":"))
    return hashlib.blake2b(text.encode(), digest_size=20).hexdigest()


@storable
class Solid(Geometry):
    """An exact B-rep solid (or several, or none: an empty result), immutable.

    Build one with the ``brep.*`` nodes, or :meth:`of` from an OCC shape and the key of its
    recipe (:func:`recipe_key`). ``Solid(brep, key)`` rebuilds one from its state.

    Parameters
    ----------
    brep : (n,) uint8
        OCC's binary B-rep of the shape.
    key : str
        The recipe's key.

    Raises
    ------
    ValueError
        For bytes that do not hold solids, or when OpenCASCADE is not installed.
    """

    def __init__(self, brep: Any, key: str):
        if not isinstance(key, str) or not key:
            raise ValueError("a solid's key must be a non-empty string")
        data = np.asarray(brep, dtype=np.uint8).tobytes() if not isinstance(brep, bytes) else brep
        from ..kernels import brep as kbrep

        if not kbrep.available():
            raise ValueError(kbrep.missing())
        from ..kernels.brep import exchange

        object.__setattr__(self, "key", key)
        object.__setattr__(self, "shape", exchange.from_bytes(data))
        object.__setattr__(self, "_bytes", data)

    @classmethod
    def of(cls, shape: Any, key: str) -> Solid:
        """The solid of an OCC shape (a solid or a compound of them) made by the recipe
        whose key is ``key``; serialised only when asked (:meth:`state`)."""
        s = object.__new__(cls)
        object.__setattr__(s, "key", key)
        object.__setattr__(s, "shape", shape)
        object.__setattr__(s, "_bytes", None)
        return s

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("a Solid is immutable")

    # ------------------------------------------------------------------ value protocol

    @property
    def brep(self) -> np.ndarray:
        """OCC's binary B-rep of the shape, read-only ``(n,) uint8``."""
        if self._bytes is None:
            from ..kernels.brep import exchange

            object.__setattr__(self, "_bytes", exchange.to_bytes(self.shape))
        return frozen_array(np.frombuffer(self._bytes, dtype=np.uint8), np.uint8)

    def state(self) -> dict[str, Any]:
        return {"brep": self.brep, "key": self.key}

    def fingerprint(self) -> Any:
        return {"key": self.key}

    @property
    def nbytes(self) -> int:
        """The binary B-rep's size once made; before, an estimate from the faces and edges
        (260 bytes each in OCC's format for a filleted box; counted as 512, OCC's own
        structures in memory being larger), so the memory cache's accounting does not
        serialise every solid it holds."""
        if self._bytes is not None:
            return len(self._bytes) + 256
        from ..kernels.brep import occ

        return (
            512 * (len(occ.index_map(self.shape, "face")) + len(occ.index_map(self.shape, "edge")))
            + 256
        )

    def __repr__(self) -> str:
        return f"Solid({self.key[:12]})"

    # ------------------------------------------------------------------ geometry

    @functools.cached_property
    def bounds(self) -> np.ndarray:
        """The axis-aligned box of the solid's surfaces, ``(2, 3)`` (zeros when empty)."""
        from ..kernels.brep import occ

        return frozen_array(occ.bounds(self.shape))

    @property
    def is_empty(self) -> bool:
        from ..kernels.brep import occ

        return not occ.solids_of(self.shape)

    def default_tolerance(self) -> float:
        """The mesh tolerance used when none is given: 1/1000 of the box's diagonal."""
        lo, hi = self.bounds
        return float(np.linalg.norm(hi - lo)) * 1e-3 or 1e-3

    def mesh(self, tolerance: float | None = None, angle: float = 0.35, guard: Any = None) -> Any:
        """The closed, outward triangle mesh within ``tolerance`` of the surfaces, no two
        neighbours on a curved face turning by more than ``angle`` radians (the ``brep.mesh``
        node's kernel, and what the viewer draws), as a :class:`~.mesh.Mesh`; ``guard`` is
        called with the triangle count before they are gathered."""
        from ..kernels.brep import tessellate
        from .mesh import Mesh

        tol = self.default_tolerance() if tolerance is None else float(tolerance)
        v, t = tessellate.tessellate(self.shape, tol, angle, guard)
        return Mesh.trusted(v, t.reshape(-1), np.arange(0, 3 * len(t) + 1, 3, dtype=np.int64))

    @functools.cached_property
    def _display(self) -> Any:
        return self.mesh()

    def display_mesh(self) -> Any:
        """The mesh the viewer and the studio draw (:meth:`mesh` at its defaults)."""
        return self._display

    def to_pyvista(self) -> Any:
        return self.display_mesh().to_pyvista()

    def transformed(self, linear: Any, offset: Any) -> Solid:
        """The solid under ``p -> linear @ p + offset``, exact."""
        from ..kernels.brep import transform

        a, b = np.asarray(linear, float), np.asarray(offset, float)
        shape = transform.transformed(self.shape, a, b)
        return Solid.of(shape, recipe_key("transform", solid=self, linear=a, offset=b))
