"""Polygon meshes: mixed face sizes stored flat, connectivity and measures on demand."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .base import AttributeMap, Geometry, as_xyz, attribute_map, frozen_array, storable

__all__ = ["Mesh"]


@storable
@dataclass(frozen=True, eq=False, init=False)
class Mesh(Geometry):
    """A polygon mesh with mixed face sizes, stored flat.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (sum of face sizes,) int
        Vertex indices of all faces, one face after another.
    face_offsets : (n_faces + 1,) int
        Face ``i`` is ``face_indices[face_offsets[i]:face_offsets[i + 1]]``.
    point_data : mapping name -> (n,) or (n, k) float, optional
        Per-vertex attributes (:class:`~.base.AttributeMap`, read-only, frozen).
    face_data : mapping name -> (n_faces,) or (n_faces, k) float, optional
        Per-face attributes.

    The half-edge connectivity (:attr:`halfedges`) is built on first use, vectorized, and
    raises on non-manifold edges, bad indices and inconsistent orientation.
    """

    vertices: np.ndarray
    face_indices: np.ndarray
    face_offsets: np.ndarray
    point_data: AttributeMap
    face_data: AttributeMap

    def __init__(
        self,
        vertices: Any,
        face_indices: Any,
        face_offsets: Any = None,
        point_data: Any = None,
        face_data: Any = None,
    ):
        v = as_xyz(vertices, "vertices")
        if face_offsets is None:  # a list of faces
            faces = [np.asarray(f, dtype=np.int64).ravel() for f in face_indices]
            sizes = np.array([len(f) for f in faces], dtype=np.int64)
            fi = np.concatenate(faces) if faces else np.zeros(0, np.int64)
            fo = np.concatenate([[0], np.cumsum(sizes)])
        else:
            fi = _indices(face_indices, "face_indices")
            fo = _indices(face_offsets, "face_offsets")
        if fo.size == 0 or fo[0] != 0 or fo[-1] != fi.size or np.any(np.diff(fo) < 0):
            raise ValueError(
                "face_offsets must start at 0, never decrease and end at len(face_indices)"
            )
        sizes = np.diff(fo)
        if sizes.size and sizes.min() < 3:
            bad = int(np.argmax(sizes < 3))
            raise ValueError(f"face {bad} has {int(sizes[bad])} vertices; a face needs at least 3")
        if fi.size and (fi.min() < 0 or fi.max() >= len(v)):
            pos = int(np.argmax((fi < 0) | (fi >= len(v))))
            face = int(np.searchsorted(fo, pos, side="right") - 1)
            raise ValueError(
                f"face {face} refers to vertex {int(fi[pos])}, but there are {len(v)} vertices"
            )
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "face_indices", frozen_array(fi, np.int64))
        object.__setattr__(self, "face_offsets", frozen_array(fo, np.int64))
        object.__setattr__(self, "point_data", attribute_map(point_data, len(v), "point attribute"))
        object.__setattr__(
            self, "face_data", attribute_map(face_data, len(fo) - 1, "face attribute")
        )

    @classmethod
    def trusted(
        cls,
        vertices: np.ndarray,
        face_indices: np.ndarray,
        face_offsets: np.ndarray,
        point_data: Any = None,
        face_data: Any = None,
    ) -> Mesh:
        """A mesh of arrays that are valid by construction (e.g. copies of a valid mesh's
        faces, shifted): frozen, but their indices not checked again, which for 10,000
        copies would cost more than building them. Attributes are still validated."""
        out = cls.__new__(cls)
        v = frozen_array(vertices, np.float64)
        fo = frozen_array(face_offsets, np.int64)
        object.__setattr__(out, "vertices", v)
        object.__setattr__(out, "face_indices", frozen_array(face_indices, np.int64))
        object.__setattr__(out, "face_offsets", fo)
        object.__setattr__(out, "point_data", attribute_map(point_data, len(v), "point attribute"))
        object.__setattr__(
            out, "face_data", attribute_map(face_data, len(fo) - 1, "face attribute")
        )
        return out

    def derived(self, kind: str, make: Callable[[], Any]) -> Any:
        """``make()``, computed once per mesh and ``kind`` and kept with the mesh (which
        never changes): an index a node builds to answer many questions about one mesh,
        such as the sections of a stack (the items of a ``repeat:``)."""
        kept = self.__dict__.setdefault("_derived", {})
        if kind not in kept:
            kept[kind] = make()
        return kept[kind]

    @property
    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(vertices, face_indices, face_offsets)``: what the kernels take."""
        return self.vertices, self.face_indices, self.face_offsets

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_faces(self) -> int:
        return len(self.face_offsets) - 1

    @property
    def face_sizes(self) -> np.ndarray:
        return np.diff(self.face_offsets)

    @property
    def faces(self) -> list[np.ndarray]:
        """Each face's vertex indices (a convenience; kernels use the flat arrays)."""
        if self.n_faces == 0:
            return []
        return np.split(self.face_indices, self.face_offsets[1:-1])

    @functools.cached_property
    def halfedges(self) -> Any:
        """Half-edge connectivity (:class:`formgraph.kernels.mesh.halfedge.HalfEdges`)."""
        from ..kernels.mesh import build_halfedges

        return build_halfedges(self.face_indices, self.face_offsets, self.n_vertices)

    # measures (kernels in :mod:`formgraph.kernels.mesh.measure`), computed once per mesh

    @functools.cached_property
    def edge_table(self) -> Any:
        """Undirected edges with their face counts (:class:`~.kernels.mesh.measure.EdgeTable`)."""
        from ..kernels.mesh import measure

        return measure.edge_table(self.face_indices, self.face_offsets, self.n_vertices)

    @functools.cached_property
    def area(self) -> float:
        """Total face area: of the triangles we export (each face fanned from its first corner)."""
        from ..kernels.mesh import measure

        return float(measure.face_areas(*self.arrays).sum())

    @functools.cached_property
    def volume(self) -> float:
        """Signed enclosed volume by the divergence theorem: positive for a closed, outward
        mesh; only meaningful when :attr:`is_watertight`."""
        from ..kernels.mesh import measure

        return float(measure.signed_volume(*self.arrays).sum())

    @functools.cached_property
    def bounds(self) -> np.ndarray:
        """(2, 3) read-only: the lowest and highest corner of the vertices' bounding box."""
        v = self.vertices if self.n_vertices else np.zeros((1, 3))
        return frozen_array([v.min(axis=0), v.max(axis=0)])

    @property
    def is_watertight(self) -> bool:
        """Every edge lies on exactly two faces (no open or non-manifold edge)."""
        return self.n_faces > 0 and bool(np.all(self.edge_table.counts == 2))

    @property
    def euler_characteristic(self) -> int:
        """V - E + F, counting every vertex: 2 for a closed sphere-like mesh."""
        return self.n_vertices - self.edge_table.n_edges + self.n_faces

    @property
    def nbytes(self) -> int:
        arrays = self.vertices.nbytes + self.face_indices.nbytes + self.face_offsets.nbytes
        return arrays + self.point_data.nbytes + self.face_data.nbytes

    def __repr__(self) -> str:
        extra = "".join(
            f", {what}={list(m)}"
            for what, m in (("point_data", self.point_data), ("face_data", self.face_data))
            if m
        )
        return f"Mesh(n_vertices={self.n_vertices}, n_faces={self.n_faces}{extra})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Mesh):
            return NotImplemented
        return self is other or (
            all(np.array_equal(a, b) for a, b in zip(self.arrays, other.arrays, strict=True))
            and self.point_data == other.point_data
            and self.face_data == other.face_data
        )

    def __hash__(self) -> int:
        return self._content_hash()

    def with_data(self, point_data: Any = None, face_data: Any = None) -> Mesh:
        """The same mesh with other attributes (None: none); the arrays are shared."""
        return Mesh(*self.arrays, point_data=point_data, face_data=face_data)

    def to_pyvista(self) -> Any:
        import pyvista as pv

        sizes = self.face_sizes
        cells = np.insert(self.face_indices, self.face_offsets[:-1], sizes)
        poly = pv.PolyData(np.array(self.vertices), faces=cells)
        for name, a in self.point_data.items():
            poly.point_data[name] = np.array(a)
        for name, a in self.face_data.items():
            poly.cell_data[name] = np.array(a)
        return poly

    def state(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "vertices": self.vertices,
            "face_indices": self.face_indices,
            "face_offsets": self.face_offsets,
        }
        # only when present: the state (and so the cache key) of a plain mesh is unchanged
        if self.point_data:
            out["point_data"] = self.point_data.pairs()
        if self.face_data:
            out["face_data"] = self.face_data.pairs()
        return out


def _indices(values: Any, what: str) -> np.ndarray:
    a = np.asarray(values)
    if a.size and a.dtype.kind == "f" and not np.all(a == np.round(a)):
        raise ValueError(f"{what} must be whole numbers")
    if a.size and a.dtype.kind not in "iuf":
        raise ValueError(f"{what} must be whole numbers, got {a.dtype}")
    return a.astype(np.int64, copy=False).ravel()  # (frozen_array copies it once, if need be)
