"""Booleans of closed meshes through manifold3d (constructive solid geometry on meshes).

manifold3d (Emmett Lalish et al., the Manifold library) guarantees a manifold result for
manifold input, in float64 through ``Mesh64``. This adapter hands it our arrays as they
are: float64 vertices and int64 triangle indices viewed as uint64, without a copy, for a
mesh of triangles (other polygons are triangulated first). Anything that is not a closed,
consistently oriented, outward solid is refused with a sentence that counts the defects
and names one of them, never with the library's own exception text; the check comes from
our edge table, before manifold3d sees the mesh, because manifold3d 3.5 can crash the
process (not only refuse) on open, messy input.
"""

from __future__ import annotations

from collections.abc import Sequence
from enum import Enum

import numpy as np

from .measure import is_closed_oriented, signed_volume, solid_report
from .meshops import triangulate

__all__ = [
    "NotSolidError",
    "Operation",
    "boolean",
    "combine",
    "from_manifold",
    "to_manifold",
    "union",
]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]


class NotSolidError(ValueError):
    """A mesh handed to a boolean does not bound a solid."""


class Operation(str, Enum):
    """The boolean operations."""

    union = "union"
    difference = "difference"
    intersection = "intersection"


def _why_not_solid(v: np.ndarray, fi: np.ndarray, fo: np.ndarray, what: str) -> str:
    report = solid_report(fi, fo, len(v))
    if report.example is not None:
        a, b = report.example
        at = ", ".join(f"{x:.6g}" for x in 0.5 * (v[a] + v[b]))
        if report.open_edges:
            hint = "mesh.weld joins duplicate vertices, mesh.cap closes open loops"
        elif report.nonmanifold_edges:
            hint = "an edge on more than two faces comes from duplicated or touching parts"
        else:
            hint = "mesh.orient makes the faces agree"
        return (
            f"{what} is not a closed solid: it has {report.problems()} (e.g. edge {a}-{b} "
            f"at ({at})); {hint}"
        )
    return f"{what} is not a valid solid for the boolean (it may intersect itself)"


class _Interface:
    """Exposes an array's memory through the array interface with the read-only flag off."""

    def __init__(self, a: np.ndarray):
        self.base = a
        self.__array_interface__ = {**a.__array_interface__, "data": (a.ctypes.data, False)}


def _alias(a: np.ndarray) -> np.ndarray:
    """A writable-flagged alias of a C-contiguous array, for bindings that only read it.

    manifold3d's nanobind signature asks for writable arrays although ``Mesh64`` only
    copies them into its own buffers; our meshes are read-only, and copying 100k-triangle
    inputs just to flip a flag would be the one needless copy of the conversion. Nothing
    writes through the alias (the tests check the input is unchanged).
    """
    if a.flags.writeable:
        return a
    return np.asarray(_Interface(a))


def to_manifold(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray, what: str = "the mesh"
) -> object:
    """A ``manifold3d.Manifold`` of a closed outward mesh (float64, no copy of triangles).

    Raises
    ------
    NotSolidError
        Open, non-manifold, misoriented or inside-out input, as a sentence.
    """
    import manifold3d

    v = np.ascontiguousarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    if fo.size < 2:
        raise NotSolidError(f"{what} has no faces")
    # our own check first: manifold3d can crash (not only refuse) on open, messy input
    if not is_closed_oriented(fi, fo, len(v)):
        raise NotSolidError(_why_not_solid(v, fi, fo, what))
    tris = fi
    if not (fo[-1] == 3 * (fo.size - 1) and np.all(np.diff(fo) == 3)):
        _, tris, _ = triangulate(v, fi, fo)
    tris = np.ascontiguousarray(tris).view(np.uint64).reshape(-1, 3)
    m = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=_alias(v), tri_verts=_alias(tris)))
    if m.status() != manifold3d.Error.NoError:
        raise NotSolidError(
            f"{what} is not a valid solid for the boolean (manifold3d: {m.status().name}); it "
            "may be degenerate or intersect itself"
        )
    if m.volume() < 0:
        vol = float(signed_volume(v, fi, fo).sum())
        raise NotSolidError(
            f"{what} is inside out (its volume is {vol:.6g}); mesh.orient turns it outward"
        )
    return m


def from_manifold(m: object) -> MeshArrays:
    """Flat arrays of a ``manifold3d.Manifold`` (triangles)."""
    mesh = m.to_mesh64()  # type: ignore[attr-defined]
    v = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    tri = np.ascontiguousarray(mesh.tri_verts).view(np.int64).reshape(-1)  # indices < 2**63
    return v, tri, np.arange(0, tri.size + 1, 3, dtype=np.int64)


def boolean(a: MeshArrays, b: MeshArrays, operation: Operation | str = "union") -> MeshArrays:
    """Union, difference (a minus b) or intersection of two closed outward meshes.

    Parameters
    ----------
    a, b : (vertices, face_indices, face_offsets)
    operation : Operation or str

    Returns
    -------
    vertices, face_indices, face_offsets
        A manifold triangle mesh (possibly empty).

    Raises
    ------
    NotSolidError
        Either input is not a closed outward solid.
    """
    return from_manifold(combine(to_manifold(*a, "input a"), to_manifold(*b, "input b"), operation))


def combine(a: object, b: object, operation: Operation | str = "union") -> object:
    """The boolean of two ``manifold3d.Manifold`` values."""
    op = Operation(operation)
    if op is Operation.union:
        return a + b  # type: ignore[operator]
    if op is Operation.difference:
        return a - b  # type: ignore[operator]
    return a ^ b  # type: ignore[operator]


def union(meshes: Sequence[MeshArrays]) -> MeshArrays:
    """Union of several closed outward meshes, and of the separate parts within each.

    Each mesh is split into its connected parts first, so parts of one mesh that overlap
    (e.g. boxes merged by ``mesh.merge``) are fused too; then manifold3d's batch boolean
    adds them all at once.
    """
    import manifold3d

    parts = [p for i, m in enumerate(meshes) for p in to_manifold(*m, what=f"mesh {i}").decompose()]
    if not parts:
        return np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(1, np.int64)
    return from_manifold(manifold3d.Manifold.batch_boolean(parts, manifold3d.OpType.Add))
