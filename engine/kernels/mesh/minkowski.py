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
the other's agrees with the edge's direction).
"""

from __future__ import annotations

import numpy as np

from .measure import edge_table
from .meshops import triangulate

__all__ = ["cost", "is_convex", "minkowski"]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]


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
    same = np.all(n[f0] == n[f1], axis=1)
    turn = np.einsum("ij,ij->i", edge, np.cross(n[f0], n[f1]))
    return bool(np.all(same | (turn > 0)))


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


def minkowski(a: object, b: object) -> object:
    """``a + b`` of two ``manifold3d.Manifold`` solids (the Minkowski sum)."""
    return a.minkowski_sum(b)  # type: ignore[attr-defined]
