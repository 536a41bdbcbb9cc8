"""No-fit polygons: where one part may not go near another, on an integer grid.

The no-fit polygon of a fixed part A and a moving part B is the set of translations t for
which B + t overlaps A: the Minkowski sum A (+) (-B). Its boundary is where B slides along
A touching it; a translation outside it (or in one of its holes) is free. Nesting with
no-fit polygons and bottom-left fill is Art's idea (1966), made practical by Bennell and
Oliveira's tutorial (2008) and by Burke et al. (2006, "A new bottom-left-fill heuristic
algorithm for the two-dimensional irregular packing problem", Operations Research 54(3)),
and it is what SVGnest and Deepnest do.

How the sum is made here:

- **Outer rings by convolution.** For two simple polygons P and Q (counter-clockwise), the
  convolution cycle holds the segment ``p_i + [q_j, q_j+1]`` for every vertex p_i of P whose
  turn (from its incoming to its outgoing edge direction, counter-clockwise at a convex
  vertex, clockwise at a reflex one, the start of the turn excluded and its end included)
  passes the direction of the edge q_j q_j+1, run forwards at a convex vertex and backwards
  at a reflex one; and the same with P and Q swapped. P (+) Q is exactly the set of points
  around which the cycle winds a nonzero number of times (Guibas, Ramshaw and Stolfi 1983,
  "A kinetic framework for computational geometry"; Wein 2006, "Exact and efficient
  construction of planar Minkowski sums using the convolution method"). The cycle has
  O(n + m + r m) segments (r reflex vertices), not the n m parallelograms of a union of
  edge sums, and every test is an exact integer cross product. Clipper (Angus Johnson's
  polygon clipper, through pyclipper) takes the cycle's nonzero region.
- **Holes by erosion.** A hole H of A can hold B where B + t lies inside H. For B's convex
  hull K that set is where the convolution of H (run clockwise) with -K winds negatively
  (:func:`pocket`); the hull only ever forbids more than B itself would. Only holes whose
  box can hold B's box are looked at; for the others A is taken filled, and B is always
  taken filled (a part is never placed around one already placed).

Coordinates are integers (Clipper's, and exact cross products): :func:`grid_scale` chooses
the scale so every sum and product stays within int64.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pyclipper
import shapely

__all__ = ["Paths", "feasible", "grid_scale", "minkowski_outer", "no_fit", "orient_ccw", "pocket"]

Paths = list  # list of (k, 2) int64 rings, Clipper's orientation: outer CCW, holes CW

_LIMIT = 2.0**29  # largest |coordinate| on the grid: edge cross products stay in int64


def grid_scale(extent: float) -> float:
    """Grid steps per model unit so that coordinates within ``extent`` of the origin (parts,
    sheets and their sums) stay below 2**29 (cross products of edge vectors in int64)."""
    if not extent > 0 or not np.isfinite(extent):
        raise ValueError(f"the layout's extent must be positive and finite, got {extent}")
    return _LIMIT / (4.0 * extent)


def orient_ccw(ring: np.ndarray) -> np.ndarray:
    """The ring counter-clockwise (reversed when its signed area is negative)."""
    x, y = ring[:, 0].astype(np.float64), ring[:, 1].astype(np.float64)
    twice = np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))
    return ring if twice > 0 else ring[::-1]


def _clean(ring: np.ndarray) -> np.ndarray:
    """An integer ring without repeated points, collinear vertices or spikes (turns of 0 or
    pi, whose cone is empty or ambiguous), as the convolution needs."""
    r = ring
    for _ in range(len(ring)):  # each pass drops every bad vertex at once; rarely two
        if len(r) < 3:
            return r
        e_in = r - np.roll(r, 1, axis=0)
        e_out = np.roll(r, -1, axis=0) - r
        cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]
        bad = (cross == 0) | (~e_in.any(axis=1))
        if not bad.any():
            return r
        # drop every other bad vertex of a run: a neighbour's test changes once one goes
        drop = bad & ~np.roll(bad, 1)
        r = r[~(drop if drop.any() else bad)]
    return r


def _in_turn(u: np.ndarray, v: np.ndarray, d: np.ndarray, later: bool) -> np.ndarray:
    """Whether each direction d[j] lies in the turn from u[i] to v[i] (counter-clockwise at
    a left turn, clockwise at a right turn). Ties are broken as if every d were turned a
    hair counter-clockwise (``later``) or clockwise: the one polygon's edges a hair one
    way, the other's the other, so an edge parallel to an edge of the other polygon is met
    exactly once (a symbolic perturbation). Returns (len(u), len(d)) bool."""
    cross_uv = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    cross_ud = u[:, None, 0] * d[None, :, 1] - u[:, None, 1] * d[None, :, 0]
    cross_dv = d[None, :, 0] * v[:, None, 1] - d[None, :, 1] * v[:, None, 0]
    left = (cross_uv > 0)[:, None]
    # d turned a hair counter-clockwise lies in [u, v) of a left turn, in (u, v] (clockwise)
    # of a right one; turned clockwise, the other way round
    start = (cross_ud >= 0) & (cross_dv > 0), (cross_ud < 0) & (cross_dv <= 0)
    end = (cross_ud > 0) & (cross_dv >= 0), (cross_ud <= 0) & (cross_dv < 0)
    if later:
        return np.where(left, start[0], start[1])
    return np.where(left, end[0], end[1])


def _convolution(p: np.ndarray, q: np.ndarray) -> list[np.ndarray]:
    """The convolution cycle of two counter-clockwise integer rings, as closed paths."""
    n, m = len(p), len(q)
    ep = np.roll(p, -1, axis=0) - p  # edge i runs from vertex i to i + 1
    eq = np.roll(q, -1, axis=0) - q
    # vertex i of p turns from edge i - 1 to edge i; each edge of q inside that turn
    vi, ej = np.nonzero(_in_turn(np.roll(ep, 1, axis=0), ep, eq, True))
    left_p = (np.roll(ep, 1, axis=0)[:, 0] * ep[:, 1] - np.roll(ep, 1, axis=0)[:, 1] * ep[:, 0]) > 0
    # node (i, j) is the point p_i + q_j, numbered i * m + j
    a1 = vi * m + ej
    b1 = vi * m + (ej + 1) % m
    fwd = left_p[vi]
    s1, t1 = np.where(fwd, a1, b1), np.where(fwd, b1, a1)
    vj, ei = np.nonzero(_in_turn(np.roll(eq, 1, axis=0), eq, ep, False))
    left_q = (np.roll(eq, 1, axis=0)[:, 0] * eq[:, 1] - np.roll(eq, 1, axis=0)[:, 1] * eq[:, 0]) > 0
    a2 = ei * m + vj
    b2 = ((ei + 1) % n) * m + vj
    fwd = left_q[vj]
    s2, t2 = np.where(fwd, a2, b2), np.where(fwd, b2, a2)
    start = np.concatenate([s1, s2])
    end = np.concatenate([t1, t2])
    # every node has as many segments in as out: pair the k-th in with the k-th out (any
    # pairing splits the cycle into closed paths with the same winding numbers)
    by_start = np.argsort(start, kind="stable")
    by_end = np.argsort(end, kind="stable")
    if not np.array_equal(start[by_start], end[by_end]):
        raise ValueError("the convolution is not a cycle (a degenerate ring)")
    succ = np.empty(len(start), dtype=np.int64)
    succ[by_end] = by_start
    points = p[start // m] + q[start % m]
    paths: list[np.ndarray] = []
    seen = np.zeros(len(start), dtype=bool)
    nxt = succ.tolist()
    for s in range(len(start)):  # one step per segment: walks the cycles of the pairing
        if seen[s]:
            continue
        cycle = []
        k = s
        while not seen[k]:
            seen[k] = True
            cycle.append(k)
            k = nxt[k]
        if len(cycle) >= 3:
            paths.append(points[cycle])
    return paths


def minkowski_outer(p: np.ndarray, q: np.ndarray) -> Paths:
    """P (+) Q of two simple integer rings (any orientation) as Clipper paths: the nonzero
    region of their convolution cycle (outer rings counter-clockwise, holes clockwise)."""
    p, q = _clean(orient_ccw(p)), _clean(orient_ccw(q))
    if len(p) < 3 or len(q) < 3:
        raise ValueError("a part's outline has fewer than 3 corners on the nesting grid")
    pc = pyclipper.Pyclipper()
    pc.AddPaths(_convolution(p, q), pyclipper.PT_SUBJECT, True)
    return [np.asarray(r, dtype=np.int64) for r in pc.Execute(pyclipper.CT_UNION, 1, 1)]


def _fits(box_b: np.ndarray, ring: np.ndarray) -> bool:
    size = ring.max(axis=0) - ring.min(axis=0)
    return bool(np.all(box_b <= size))


def no_fit(outer: np.ndarray, holes: Sequence[np.ndarray], moving: np.ndarray) -> Paths:
    """The no-fit polygon of a fixed part (``outer`` with ``holes``) and a moving outline.

    Parameters
    ----------
    outer : (n, 2) int64
        The fixed part's outer ring on the grid.
    holes : sequence of (k, 2) int64
        Its holes.
    moving : (m, 2) int64
        The moving part's outer ring, placed by translation t (its reference is the origin).

    Returns
    -------
    Paths
        The translations t at which ``moving + t`` overlaps the fixed part's area: outer
        rings counter-clockwise, holes (the free pockets inside the part's holes) clockwise.
    """
    neg = -moving
    region = minkowski_outer(outer, neg)
    size = moving.max(axis=0) - moving.min(axis=0)
    pockets: list[np.ndarray] = []
    hull = None
    for h in holes:  # one step per hole; only those whose box holds the part's box
        if not _fits(size, h):
            continue
        if hull is None:
            hull = _clean(orient_ccw(_hull(neg)))
        pockets += pocket(h, hull)
    return feasible(region, pockets)


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex hull of integer points, counter-clockwise, on the same grid (its corners
    are input points; Andrew's monotone chain through shapely's GEOS)."""
    hull = shapely.convex_hull(shapely.multipoints(points.astype(np.float64)))
    return np.asarray(shapely.get_coordinates(hull)[:-1], dtype=np.int64)


def pocket(hole: np.ndarray, convex: np.ndarray) -> Paths:
    """Where a convex part (``convex``, the moving part's hull, reflected) fits inside a
    hole: the translations t with -convex + t inside the hole's region, i.e. the points
    around which the convolution of the hole run clockwise with ``convex`` winds
    negatively (Chen and McMains 2005, "Polygon offsetting by computing winding numbers":
    the offset of a region by a convex shape is where the convolution of its boundary
    cycles winds positively; the big box around the hole adds one everywhere near it)."""
    h = _clean(orient_ccw(hole)[::-1])
    if len(h) < 3:
        return []
    pc = pyclipper.Pyclipper()
    pc.AddPaths(_convolution(h, convex), pyclipper.PT_SUBJECT, True)
    return [np.asarray(r, dtype=np.int64) for r in pc.Execute(pyclipper.CT_UNION, 3, 3)]


def feasible(subject: Paths, clips: Sequence[np.ndarray]) -> Paths:
    """``subject`` minus the union of the ``clips`` (nonzero fill on both): the free
    translations left once the no-fit polygons of the parts placed are taken away."""
    if not clips:
        return subject
    pc = pyclipper.Pyclipper()
    pc.AddPaths(subject, pyclipper.PT_SUBJECT, True)
    pc.AddPaths(clips, pyclipper.PT_CLIP, True)
    return [np.asarray(r, dtype=np.int64) for r in pc.Execute(pyclipper.CT_DIFFERENCE, 1, 1)]
