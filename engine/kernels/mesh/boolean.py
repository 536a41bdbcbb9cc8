"""Booleans of closed meshes through manifold3d (constructive solid geometry on meshes).

manifold3d (Emmett Lalish et al., the Manifold library) guarantees a manifold result for
manifold input, in float64 through ``Mesh64``. This adapter hands it our arrays as they
are: float64 vertices and int64 triangle indices viewed as uint64, without a copy, for a
mesh of triangles (other polygons are triangulated first). Anything that is not a closed,
consistently oriented, outward solid is refused with a sentence that counts the defects
and names one of them, never with the library's own exception text; the check comes from
our edge table, before manifold3d sees the mesh, because manifold3d 3.5 can crash the
process (not only refuse) on open, messy input.

What passes the edge table can still be wrong for manifold3d, silently: an unused vertex far
away widens the bounding box its tolerance is taken from (1e-12 of the largest coordinate),
coordinates past :data:`MAX_COORDINATE` overflow its volumes, a solid smaller than the other
operand's tolerance is erased, a mesh whose faces all collapsed bounds nothing, and parts that
overlap (two coincident copies of a box) are read as a double shell. So unused vertices are
dropped, overlapping parts of one mesh are fused first (their union, as ``mesh.union`` does),
a collapsed mesh is the empty solid (:func:`collapsed`), and the rest is refused with a
sentence.
"""

from __future__ import annotations

from collections.abc import Sequence
from enum import Enum

import numpy as np

from .measure import is_closed_oriented, signed_volume, solid_report
from .meshops import triangulate

__all__ = [
    "MAX_COORDINATE",
    "NotSolidError",
    "Operation",
    "check_precision",
    "collapsed",
    "boolean",
    "combine",
    "from_manifold",
    "to_manifold",
    "union",
]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]


MAX_COORDINATE = 1e100
"""The largest coordinate a boolean takes: a cube that size has a volume of 1e300, near the
largest float64; beyond it manifold3d's volumes and tolerances are inf or nan."""

#: a solid must be this many times manifold3d's tolerance across, or the boolean erases it
_RESOLVED = 1e3


class NotSolidError(ValueError):
    """A mesh handed to a boolean does not bound a solid (``operand``: which one, if known)."""

    operand: int | None = None


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
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    what: str = "the mesh",
    max_tests: int | None = None,
    fuse: bool = True,
) -> object:
    """A ``manifold3d.Manifold`` of a closed outward mesh (float64, no copy of triangles).

    Unused vertices are dropped; overlapping parts are fused when ``fuse`` (see
    :func:`_fused`). ``max_tests`` limits the ear clipping of faces that are not triangles (see
    :func:`~.meshops.triangulate`).

    Raises
    ------
    NotSolidError
        Open, non-manifold, misoriented, inside-out, overlapping or out-of-range input, as
        a sentence (a collapsed one is the empty manifold).
    WorkLimitError
        Triangulating its faces would need more than ``max_tests`` corner tests.
    """
    import manifold3d

    v = np.ascontiguousarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    if fo.size < 2:
        raise NotSolidError(f"{what} has no faces")
    v, fi = _drop_unused(v, fi)
    big = float(np.abs(v).max())
    if not big <= MAX_COORDINATE:
        raise NotSolidError(
            f"{what} reaches a coordinate of {big:.3g}, beyond the {MAX_COORDINATE:.0e} a "
            "boolean can represent (its volume would overflow float64); scale it down"
        )
    # our own check first: manifold3d can crash (not only refuse) on open, messy input
    if not is_closed_oriented(fi, fo, len(v)):
        raise NotSolidError(_why_not_solid(v, fi, fo, what))
    tris = fi
    if not (fo[-1] == 3 * (fo.size - 1) and np.all(np.diff(fo) == 3)):
        _, tris, _ = triangulate(v, fi, fo, max_tests=max_tests)
    tris = np.ascontiguousarray(tris).view(np.uint64).reshape(-1, 3)
    m = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=_alias(v), tri_verts=_alias(tris)))
    if m.status() != manifold3d.Error.NoError:
        raise NotSolidError(
            f"{what} is not a valid solid for the boolean (manifold3d: {m.status().name}); it "
            "may be degenerate or intersect itself"
        )
    if collapsed(m):
        import manifold3d

        return manifold3d.Manifold()  # no volume: the empty solid, not a degenerate shell
    if m.volume() < 0:
        vol = float(signed_volume(v, fi, fo).sum())
        raise NotSolidError(
            f"{what} is inside out (its volume is {vol:.6g}); mesh.orient turns it outward"
        )
    return _fused(m, what) if fuse else m


def collapsed(m: object) -> bool:
    """Whether a manifold bounds no volume: no triangles left, or thinner (volume over
    area) than its tolerance -- e.g. a box with every vertex at one point, which manifold3d
    keeps as 12 degenerate triangles at the origin (tolerance 0) and then cuts wrongly."""
    if m.is_empty():  # type: ignore[attr-defined]
        return True
    area = m.surface_area()  # type: ignore[attr-defined]
    return area == 0 or abs(m.volume()) <= m.get_tolerance() * area  # type: ignore[attr-defined]


def _drop_unused(v: np.ndarray, fi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The vertices the faces use, renumbered (an unused vertex still sets the tolerance)."""
    used = np.zeros(len(v), bool)
    used[fi] = True
    if used.all():
        return v, fi
    new = np.cumsum(used) - 1
    return np.ascontiguousarray(v[used]), new[fi]


def _fused(m: object, what: str) -> object:
    """``m`` with its overlapping parts fused (two coincident copies read as one solid).

    manifold3d assumes its input does not intersect itself; a mesh of parts that overlap is
    read as a multiple cover and its booleans come out wrong (a difference that removes
    nothing). Parts of positive volume are fused by their union; a mesh with cavities (parts
    of negative volume) is kept when its positive parts are disjoint and refused otherwise.
    """
    import manifold3d

    parts = m.decompose()  # type: ignore[attr-defined]
    if len(parts) < 2:
        return m
    volumes = np.array([p.volume() for p in parts])
    solids = [p for p, vol in zip(parts, volumes, strict=True) if vol > 0]
    fused = manifold3d.Manifold.batch_boolean(solids, manifold3d.OpType.Add)
    total = float(volumes[volumes > 0].sum())
    overlap = total - fused.volume()
    if overlap <= 1e-9 * total:
        return m
    if len(solids) == len(parts):
        return fused
    raise NotSolidError(
        f"{what} has {len(solids)} solid parts that overlap (by a volume of {overlap:.6g}) "
        f"and {len(parts) - len(solids)} cavities; mesh.union the parts before cutting cavities"
    )


def check_precision(manifolds: Sequence[object], whats: Sequence[str]) -> None:
    """Refuse a boolean whose smallest operand is below the tolerance of the largest.

    manifold3d merges what is closer than its tolerance, 1e-12 of the largest coordinate of
    an operand; in a boolean the larger tolerance holds for both, so a unit box beside a
    box 1e13 across would come out empty, or whole, depending on the order.
    """
    tol = max(m.get_tolerance() for m in manifolds)  # type: ignore[attr-defined]
    for i, (m, what) in enumerate(zip(manifolds, whats, strict=True)):
        if m.is_empty():  # type: ignore[attr-defined]
            continue  # the empty solid is exact at any scale
        box = np.asarray(m.bounding_box()).reshape(2, 3)  # type: ignore[attr-defined]
        size = float(np.linalg.norm(box[1] - box[0]))
        if size < _RESOLVED * tol:
            exc = NotSolidError(
                f"{what} is {size:.3g} across, too small beside the other operand: manifold3d "
                f"works to {tol:.3g} there (1e-12 of the largest coordinate), so the result "
                "would be meaningless; scale the parts closer in size or move them near the "
                "origin"
            )
            exc.operand = i
            raise exc


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


def combine(
    a: object, b: object, operation: Operation | str = "union", whats: Sequence[str] = ("a", "b")
) -> object:
    """The boolean of two ``manifold3d.Manifold`` values (see :func:`check_precision`)."""
    op = Operation(operation)
    check_precision((a, b), whats)
    if op is Operation.union:
        return a + b  # type: ignore[operator]
    if op is Operation.difference:
        return a - b  # type: ignore[operator]
    return a ^ b  # type: ignore[operator]


def union(meshes: Sequence[MeshArrays], max_tests: int | None = None) -> MeshArrays:
    """Union of several closed outward meshes, and of the separate parts within each.

    Each mesh is split into its connected parts first, so parts of one mesh that overlap
    (e.g. boxes merged by ``mesh.merge``) are fused too; then manifold3d's batch boolean
    adds them all at once.
    """
    import manifold3d

    solids = [
        to_manifold(*m, what=f"mesh {i}", max_tests=max_tests, fuse=False)
        for i, m in enumerate(meshes)
    ]
    if solids:
        check_precision(solids, [f"mesh {i}" for i in range(len(solids))])
    parts = [p for m in solids for p in m.decompose()]
    if not parts:
        return np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(1, np.int64)
    return from_manifold(manifold3d.Manifold.batch_boolean(parts, manifold3d.OpType.Add))
