"""A bounding-volume hierarchy of triangles or segments, and the exact nearest-primitive query.

This is the compiled core of :class:`formgraph.kernels.geometry.meshdist.Nearest` (numba,
imported on first use so ``import formgraph`` stays fast; the machine code is cached on
disk after the first run). The walk of a tree is one point at a time by nature: each
point's own stack decides what it opens next, nearest first, and prunes by its own best
distance so far. Vectorized numpy can only approximate that by passes over (point, node)
pairs, which cost 10-40x more here (see ``bench/bench_proximity.py``), so this one loop is
compiled.

* :func:`build`: a binary tree by median splits along the longest axis of the primitives'
  centres (top-down), a leaf holding at most ``LEAF`` primitives. Every node has its box
  and a slab: the unit mean normal of its triangles, the half-thickness of the slab across
  it round the box's middle that holds them, and the radius of the ball round the middle
  that holds them.
  The distance to the slab cut by the ball bounds the distance to a curved patch far more
  tightly than its box when the point is far from it (a box's corner sticks out; the slab
  follows the surface).
* :func:`query`: for each point (in Morton order, so that consecutive points share the
  tree's paths in the cache and each starts from its predecessor's nearest primitive as a
  first bound), a depth-first walk, the nearer child first, skipping every node whose bound
  (the larger of box and slab) is not below the best so far. The distance to a triangle is
  Ericson's closest point ("Real-Time Collision Detection", 5.1.5), with the barycentric
  (v, w) of the closest point; a triangle without area falls back to its three edges.

Plain arrays in, plain arrays out.
"""

from __future__ import annotations

import numpy as np

__all__ = ["LEAF", "Tree", "build", "morton_codes", "morton_order"]

LEAF = 8  # primitives per leaf: 4 tests 1.3x more boxes, 16 1.5x more triangles


class Tree:
    """The hierarchy of primitives ``corners`` (m, k, 3): k = 3 triangles, k = 2 segments.

    Attributes
    ----------
    order : (m,) int
        The caller's index of each primitive in the tree's order.
    rows : (m, 12) float
        Per primitive (tree order): a, b - a, c - a (segments: b - a twice), |b - a|^2,
        (b - a).(c - a), |c - a|^2.
    """

    def __init__(self, corners: np.ndarray):
        c = np.ascontiguousarray(corners, dtype=np.float64)
        if c.ndim != 3 or c.shape[1] not in (2, 3) or c.shape[2] != 3 or not len(c):
            raise ValueError("need at least one triangle or segment")
        from . import bvh_jit

        self.k = c.shape[1]
        self.order, self.box, self.child, self.start, self.count = bvh_jit.split(c, LEAF)
        c = c[self.order]
        a, e1 = c[:, 0], c[:, 1] - c[:, 0]
        e2 = c[:, 2] - c[:, 0] if self.k == 3 else e1
        dots = np.einsum("ij,ij->i", e1, e1), np.einsum("ij,ij->i", e1, e2)
        self.rows = np.ascontiguousarray(
            np.column_stack([a, e1, e2, dots[0], dots[1], np.einsum("ij,ij->i", e2, e2)])
        )
        self.slab = bvh_jit.slabs(c, self.box, self.start, self.count)

    def query(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """For each of ``points`` (n, 3): the distance to the nearest primitive, its index
        (the caller's), and the closest point's (v, w): ``a + v (b - a) + w (c - a)`` on a
        triangle, ``a + v (b - a)`` on a segment (w = 0)."""
        p = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
        if not len(p):
            return np.zeros(0), np.zeros(0, np.int64), np.zeros(0), np.zeros(0)
        from .bvh_jit import walk

        o = morton_order(p)
        d, prim, v, w = walk(
            p[o], self.rows, self.k, self.box, self.slab, self.child, self.start, self.count
        )
        out = [np.empty_like(x) for x in (d, prim, v, w)]
        for x, y in zip(out, (d, prim, v, w), strict=True):
            x[o] = y
        return out[0], self.order[out[1]], out[2], out[3]


def build(corners: np.ndarray) -> Tree:
    """The :class:`Tree` of primitives ``corners`` (m, k, 3)."""
    return Tree(corners)


def morton_codes(q: np.ndarray) -> np.ndarray:
    """Morton (Z-order) codes of 10-bit integer coordinates (n, 3) -> (n,) int64."""
    code = np.zeros(len(q), dtype=np.int64)
    for bit in range(10):
        for k in range(3):
            code |= ((q[:, k] >> bit) & 1) << (3 * bit + k)
    return code


def morton_order(p: np.ndarray) -> np.ndarray:
    """The order of points ``p`` (n, 3) along a Z-order curve of 2^10 cells a side."""
    lo = p.min(axis=0)
    span = float((p.max(axis=0) - lo).max())
    q = np.floor((p - lo) * (1023.999 / span if span > 0 else 0.0)).astype(np.int64)
    return np.argsort(morton_codes(q), kind="stable")
