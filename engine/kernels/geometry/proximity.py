"""One geometry asked about another: the nearest point of a point set, of polylines, of a
triangle mesh or of a signed distance function, for many query points at once.

Every query returns a :class:`Closest`: the distance, the nearest point itself, and where
it lies (the source point, segment or triangle, with its barycentric weights), so that
``attr.distance`` and ``attr.transfer`` read the same answer.

* :func:`to_points`: scipy's cKDTree, exact (a k-d tree's nearest neighbour is exact).
* :func:`to_segments`, :func:`to_triangles`: the bounding-volume hierarchy of
  :mod:`.meshdist` (exact; Ericson's closest point on each primitive looked at); the sign
  of a distance to triangles by the angle-weighted pseudonormal (Baerentzen & Aanaes 2005)
  on a closed mesh, by the generalized winding number on an open one.
* :func:`to_field`: the field's value (an exact distance for a primitive or a mesh, a
  bound for blends) and the nearest point ``p - f(p) grad f / |grad f|``, the gradient by
  central differences.

Plain arrays in, plain arrays out.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .meshdist import Nearest, SignedDistance

__all__ = ["Closest", "to_field", "to_points", "to_segments", "to_triangles"]


@dataclass(frozen=True)
class Closest:
    """The answer for n query points.

    Attributes
    ----------
    distance : (n,) float
        Euclidean distance to the nearest point (signed where asked: negative inside).
    point : (n, 3) float
        The nearest point.
    index : (n,) int
        The source point, segment or triangle it lies on (-1 for a field).
    weights : (n, 2) float
        Where on it: (v, w) with ``a + v (b - a) + w (c - a)`` on a triangle, (t, 0) with
        ``a + t (b - a)`` on a segment, (0, 0) at a point.
    """

    distance: np.ndarray
    point: np.ndarray
    index: np.ndarray
    weights: np.ndarray


def to_points(query: np.ndarray, points: np.ndarray) -> Closest:
    """The nearest of ``points`` (m, 3) to each of ``query`` (n, 3), by scipy's cKDTree."""
    from scipy.spatial import cKDTree

    q = np.asarray(query, dtype=np.float64).reshape(-1, 3)
    src = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if not len(src):
        raise ValueError("there are no points to be near to")
    d, i = cKDTree(src).query(q, k=1)
    i = np.asarray(i, dtype=np.int64).reshape(-1)
    return Closest(np.asarray(d, np.float64).reshape(-1), src[i], i, np.zeros((len(q), 2)))


def to_segments(query: np.ndarray, segments: np.ndarray) -> Closest:
    """The nearest point of segments ``segments`` (m, 2, 3) to each of ``query`` (n, 3)."""
    near = Nearest(segments)
    d, i, t, _ = near.locate(query)
    point = near.a[i] + t[:, None] * near.e1[i]
    return Closest(d, point, i, np.column_stack([t, np.zeros_like(t)]))


def to_triangles(
    query: np.ndarray, vertices: np.ndarray, triangles: np.ndarray, signed: bool = False
) -> tuple[Closest, bool]:
    """The nearest point of triangles ``vertices[triangles]`` ((t, 3) indices) to each of
    ``query`` (n, 3); with ``signed`` the distance is negative inside. Also returns
    whether the triangles close (every edge on exactly two: the pseudonormal decides the
    sign there; elsewhere the winding number does)."""
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    q = np.asarray(query, dtype=np.float64).reshape(-1, 3)
    if signed:
        sd = SignedDistance(v, t)
        near, closed = sd.nearest, sd.closed
        d, i, a, b = near.locate(q)
        if len(q):
            d = np.where(sd.inside(q, i), -d, d)
    else:
        near, closed = Nearest(v[t]), True
        d, i, a, b = near.locate(q)
    point = near.a[i] + a[:, None] * near.e1[i] + b[:, None] * near.e2[i]
    return Closest(d, point, i, np.column_stack([a, b])), closed


def to_field(
    query: np.ndarray, evaluate: Callable[[np.ndarray], np.ndarray], step: float
) -> Closest:
    """The value of a signed distance function ``evaluate`` at ``query`` (n, 3) and the
    point it names: one step of ``f`` down the unit gradient (central differences of
    ``step``). Exact for an exact distance (a sphere, a box, a mesh); for a blend or a
    scaled field the value is a bound and the point an estimate."""
    q = np.asarray(query, dtype=np.float64).reshape(-1, 3)
    n = len(q)
    offsets = np.concatenate([np.eye(3), -np.eye(3)]) * step
    stacked = np.concatenate([q] + [q + o for o in offsets])
    values = np.asarray(evaluate(stacked), dtype=np.float64).reshape(7, n)
    f = values[0]
    grad = (values[1:4] - values[4:7]).T / (2.0 * step)
    length = np.linalg.norm(grad, axis=1, keepdims=True)
    unit = np.divide(grad, length, out=np.zeros_like(grad), where=length > 0)
    return Closest(f, q - f[:, None] * unit, np.full(n, -1, np.int64), np.zeros((n, 2)))
