"""Minkowski sums of closed solids through manifold3d, and what they will cost, counted
before they run.

The Minkowski sum of convex solids is the convex hull of every sum of a vertex of one and a
vertex of the other. manifold3d (``Manifold.minkowski_sum``) does that for two convex
solids; a non-convex one it takes apart (into its triangles, in manifold3d 3.x; or into
convex pieces) and unites the hulls of the pieces with the other solid: the union of
``triangles x (hull of 3 n points)``, about ``6 n`` triangles each, which for large inputs
runs for minutes. :func:`cost` counts that work from the face and vertex counts alone, so a
node can refuse it against the element budget before it starts.

:func:`is_convex` follows manifold3d's own test (its ``IsConvex``): genus 0 (V - E + F = 2
on the triangles) and no concave edge (across each edge, the turn from one face's normal to
the other's agrees with the edge's direction), with faces that meet flat up to rounding
taken as flat. Two solids it finds convex are summed here, as the hull of the pairwise
sums of their vertices (manifold3d's own convex path), so the cost counted is the work
done whatever manifold3d would have decided.
"""

from __future__ import annotations

import numpy as np

from .measure import edge_table
from .meshops import triangulate

__all__ = ["cost", "is_convex", "minkowski"]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]

#: faces meeting at an angle whose sine is below this are flat there (the two triangles of
#: a planar quad, whose normals differ by rounding)
_FLAT = 1e-9


def _triangles(v: np.ndarray, fi: np.ndarray, fo: np.ndarray) -> np.ndarray:
    if fo[-1] == 3 * (len(fo) - 1) and np.all(np.diff(fo) == 3):
        return np.asarray(fi, dtype=np.int64).reshape(-1, 3)
    _, tri, _ = triangulate(v, fi, fo)
    return np.asarray(tri, dtype=np.int64).reshape(-1, 3)


def is_convex(vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray) -> bool:
    """Whether a closed, outward mesh bounds a convex solid (manifold3d's test, above)."""
    v = np.asarray(vertices, dtype=np.float64)
    tri = _triangles(v, np.asarray(face_indices), np.asarray(face_offsets))
    t = len(tri)
    fo = np.arange(0, 3 * t + 1, 3)
    table = edge_table(tri.reshape(-1), fo, len(v))
    used = np.unique(tri)
    if len(used) - table.n_edges + t != 2 or np.any(table.counts != 2):
        return False
    a, b, c = v[tri[:, 0]], v[tri[:, 1]], v[tri[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
    first = table.order[table.starts]  # the corner that runs each edge one way
    second = table.order[table.starts + 1]
    f0, f1 = first // 3, second // 3
    flat = tri.reshape(-1)
    nxt = np.where(first % 3 == 2, first - 2, first + 1)
    edge = v[flat[nxt]] - v[flat[first]]
    bend = np.cross(n[f0], n[f1])  # the sine of the angle between the faces
    flat = np.einsum("ij,ij->i", bend, bend) <= _FLAT**2
    turn = np.einsum("ij,ij->i", edge, bend)
    return bool(np.all(flat | (turn > 0)))


def cost(
    a: MeshArrays, b: MeshArrays, convex_a: bool | None = None, convex_b: bool | None = None
) -> int:
    """Elements the sum will make on its way: the points hulled when both are convex,
    else the triangles of the hulls to unite (about 6 n per triangle of a non-convex one
    against n vertices of a convex one; 14 per pair of triangles of two non-convex ones).
    """
    ca = is_convex(*a) if convex_a is None else convex_a
    cb = is_convex(*b) if convex_b is None else convex_b
    va, vb = len(a[0]), len(b[0])
    ta = len(_triangles(*a))
    tb = len(_triangles(*b))
    if ca and cb:
        return va * vb
    if cb:
        return 6 * ta * vb
    if ca:
        return 6 * tb * va
    return 14 * ta * tb


def minkowski(a: MeshArrays, b: MeshArrays, ma: object, mb: object, convex: bool) -> MeshArrays:
    """The Minkowski sum of two closed outward meshes, as flat arrays (triangles).

    ``convex`` (both are, by :func:`is_convex`): the hull of all ``len(a) x len(b)`` vertex
    sums (manifold3d's ``hull_points``); otherwise manifold3d's ``minkowski_sum`` of their
    manifolds ``ma``, ``mb``.
    """
    import manifold3d

    from .boolean import from_manifold

    if convex:
        va, vb = np.asarray(a[0], dtype=np.float64), np.asarray(b[0], dtype=np.float64)
        sums = (va[:, None, :] + vb[None, :, :]).reshape(-1, 3)
        return from_manifold(manifold3d.Manifold.hull_points(sums))
    return from_manifold(ma.minkowski_sum(mb))  # type: ignore[attr-defined]
