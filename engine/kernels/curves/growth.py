"""Differential growth of a polyline in the plane: one step, on plain arrays.

One step (:func:`grow_step`) moves every vertex by the sum of

- attraction: a spring along each edge toward half the split length;
- alignment: a pull toward the midpoint of its two neighbours (Laplacian smoothing);
- repulsion: a push away from every non-adjacent vertex nearer than ``radius``, falling off
  linearly to zero at ``radius`` (and from ``bounds``, when given, sampled at least every
  ``split``);
- jitter: an optional random push (seeded; the same on every run), which breaks the
  symmetry of a regular seed;

then limits each vertex's move so that the curve cannot cross itself or its bounds, and
divides every edge longer than ``split`` into equal parts (the growth: the repulsion
lengthens edges, the division adds vertices, and the curve buckles into folds).

The guarantee against crossing: let C(e) be the smallest clearance between edge e and any
other edge (their distance, or for two edges sharing a vertex the distance from the far end
of each to the other), searched within ``radius``. Every vertex moves less than a quarter
of min(radius, C(e)) over its edges e. A point of a segment moves no further than its
farthest end, so two segments D apart come no nearer than D / 2 during the step; two edges
sharing a vertex each turn, about it, by less than half the angle between them (asin(0.48
sin t) < t / 2). The curve stays simple, and a seed that is not simple is refused.

Neighbours come from a uniform hash grid (:func:`pairs_within`): points sorted by cell,
the ranges of the neighbouring cells found by ``searchsorted``, each pair produced once
from half the 3 x 3 neighbourhood. A step costs O(n log n) for n vertices (the sort), with
a constant set by how many vertices lie within ``radius`` of each.

Points are (n, 2) (an (n, 3) array has its z ignored); a closed curve does not repeat its
first point.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "pairs_within",
    "divide_long_edges",
    "grow_step",
    "QUARTER",
]

#: the fraction of the clearance a vertex may move in one step (see the module docstring)
QUARTER = 0.24

_MAX_CELLS = 1 << 30  # cells per axis; beyond this the grid keys would overflow


def _xy(points: object, name: str) -> np.ndarray:
    try:
        a = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an (n, 2) array of coordinates: {exc}") from None
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise ValueError(f"{name} must be an (n, 2) array of coordinates, got shape {a.shape}")
    a = a[:, :2]
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite")
    return a


def pairs_within(points: np.ndarray, r: float) -> tuple[np.ndarray, np.ndarray]:
    """Every pair of points nearer than ``r``, each once.

    Parameters
    ----------
    points : (n, 2) float
    r : float
        The distance, > 0 (pairs at exactly ``r`` are left out).

    Returns
    -------
    i, j : (k,) int64
        The pairs, ``i < j``, in no particular order.

    Raises
    ------
    ValueError
        ``r`` is not positive, or so small against the points' extent that the grid would
        need more than 2**30 cells a side.
    """
    i, j, _, _, _ = _pairs(np.asarray(points, dtype=np.float64), r)
    return i, j


def _pairs(
    points: np.ndarray, r: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`pairs_within`, with each pair's p[i] - p[j] (x and y) and distance."""
    p = points[:, :2]
    n = len(p)
    if not r > 0:
        raise ValueError(f"the search radius must be > 0, got {r}")
    if n < 2:
        e, f = np.zeros(0, np.int64), np.zeros(0)
        return e, e, f, f, f
    lo = p.min(axis=0)
    span = (p.max(axis=0) - lo) / r
    if not (span < _MAX_CELLS).all():
        raise ValueError(
            f"a search radius of {r:g} is too small for points spanning "
            f"{(span * r).max():g} (over {_MAX_CELLS:,} cells a side)"
        )
    cell = np.floor((p - lo) / r).astype(np.int64)
    ny = int(cell[:, 1].max()) + 3  # a margin row: the neighbour y - 1 / y + 1 never aliases
    key = (cell[:, 0] + 1) * ny + (cell[:, 1] + 1)
    order = np.argsort(key, kind="stable")
    sk = key[order]
    sx, sy = p[order, 0], p[order, 1]
    pos = np.arange(n, dtype=np.int64)
    # half the neighbourhood, as two runs of the sorted keys: the rest of the own cell
    # with the cell above it (y + 1), and the three cells of the next column (x + 1,
    # y - 1 .. y + 1); every unordered pair of neighbouring cells is visited once
    start = np.concatenate([pos + 1, np.searchsorted(sk, sk + (ny - 1), side="left")])
    end = np.concatenate(
        [
            np.searchsorted(sk, sk + 1, side="right"),
            np.searchsorted(sk, sk + (ny + 1), side="right"),
        ]
    )
    counts = np.maximum(end - start, 0)
    total = int(counts.sum())
    if total == 0:
        e, f = np.zeros(0, np.int64), np.zeros(0)
        return e, e, f, f, f
    a = np.repeat(np.concatenate([pos, pos]), counts)
    b = np.repeat(start - (np.cumsum(counts) - counts), counts) + np.arange(total)
    dx, dy = sx[a] - sx[b], sy[a] - sy[b]
    d2 = dx * dx + dy * dy
    near = d2 < r * r
    a, b, dx, dy = order[a[near]], order[b[near]], dx[near], dy[near]
    flip = a > b  # i < j, and the vectors follow
    sign = np.where(flip, -1.0, 1.0)
    return (
        np.where(flip, b, a),
        np.where(flip, a, b),
        dx * sign,
        dy * sign,
        np.sqrt(d2[near]),
    )


def divide_long_edges(points: np.ndarray, closed: bool, split: float) -> np.ndarray:
    """Divide every edge longer than ``split`` into the fewest equal parts not longer.

    Parameters
    ----------
    points : (n, 2) float
    closed : bool
        The last point joins the first.
    split : float
        The longest edge kept whole, > 0.

    Returns
    -------
    (m, 2) float
        The old vertices in order with the new ones between them (a new array).
    """
    p = np.asarray(points, dtype=np.float64)
    if not split > 0:
        raise ValueError(f"split must be > 0, got {split}")
    if len(p) < 2:
        return p.copy()
    q = np.roll(p, -1, axis=0) if closed else p[1:]
    base = p if closed else p[:-1]
    v = q - base
    length = np.sqrt(np.einsum("ij,ij->i", v, v))
    parts = np.maximum(np.ceil(length / split), 1.0)
    if (parts == 1).all():
        return p.copy()
    k = parts.astype(np.int64)
    edge = np.repeat(np.arange(len(k)), k)
    step = np.arange(edge.size) - np.repeat(np.cumsum(k) - k, k)
    out = base[edge] + v[edge] * (step / parts[edge])[:, None]
    return out if closed else np.vstack([out, p[-1:]])


def _point_edge_distances(
    x: np.ndarray, y: np.ndarray, ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray
) -> np.ndarray:
    """Distances from points (x, y) to segments (a, b), row by row, in separate
    coordinate columns (faster than (k, 2) rows for the many rows of a step)."""
    ex, ey = bx - ax, by - ay
    px, py = x - ax, y - ay
    den = ex * ex + ey * ey
    t = (px * ex + py * ey) / np.where(den > 0, den, 1.0)
    np.clip(t, 0.0, 1.0, out=t)
    px -= t * ex
    py -= t * ey
    return np.sqrt(px * px + py * py)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def _edges(n: int, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    e0 = np.arange(n if closed else n - 1)
    return e0, (e0 + 1) % n


def _inside(point: np.ndarray, polygon: np.ndarray) -> bool:
    """Even-odd test of one point against a closed polygon (k, 2)."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    x, y = point
    spans = (a[:, 1] > y) != (b[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return bool(np.count_nonzero(spans & (x < xc)) % 2)


def grow_step(
    points: np.ndarray,
    closed: bool = True,
    *,
    split: float,
    radius: float,
    repulsion: float = 0.5,
    attraction: float = 0.2,
    alignment: float = 0.1,
    bounds: np.ndarray | None = None,
    jitter: float = 0.0,
    seed: int = 0,
) -> np.ndarray:
    """One step of differential growth (see the module docstring).

    Parameters
    ----------
    points : (n, 2) float
        A simple polyline (n >= 3 closed, >= 2 open).
    closed : bool
    split : float
        Edges longer than this are divided; the springs rest at half of it.
    radius : float
        Vertices nearer than this (and not neighbours along the curve) repel.
    repulsion, attraction, alignment : float
        The strengths, >= 0: a pair at distance d moves apart by ``repulsion * (radius -
        d)`` (half each); an edge moves toward its rest length by ``attraction`` of the
        difference; a vertex toward its neighbours' midpoint by ``alignment`` of the way.
    bounds : (k, 2) float, optional
        A closed simple polygon the curve starts and stays inside (its edges also repel).
    jitter : float
        A random push of up to ``jitter * split / 2`` along each axis, from ``seed``.
    seed : int

    Returns
    -------
    (m, 2) float
        The moved curve, its long edges divided (m >= n).

    Raises
    ------
    ValueError
        The curve is not simple (crosses or touches itself, or its bounds), starts outside
        ``bounds``, or a parameter is out of range.
    """
    p = _xy(points, "points")
    if not (split > 0 and radius > 0):
        raise ValueError(f"split and radius must be > 0, got {split} and {radius}")
    if min(repulsion, attraction, alignment, jitter) < 0:
        raise ValueError("repulsion, attraction, alignment and jitter must be >= 0")
    if len(p) < (3 if closed else 2):
        raise ValueError(f"a {'closed' if closed else 'open'} curve to grow needs more points")
    p = divide_long_edges(p, closed, split)
    n = len(p)
    e0, e1 = _edges(n, closed)
    d = np.zeros_like(p)

    v = p[e1] - p[e0]
    length = np.sqrt(np.einsum("ij,ij->i", v, v))
    if not (length > 0).all():
        raise ValueError("the curve repeats a point (a zero-length edge)")
    pull = v * (0.5 * attraction * (length - 0.5 * split) / length)[:, None]
    _scatter(d, e0, pull)
    _scatter(d, e1, -pull)

    prv, nxt = np.roll(np.arange(n), 1), np.roll(np.arange(n), -1)
    smooth = alignment * (0.5 * (p[prv] + p[nxt]) - p)
    if not closed:
        smooth[[0, -1]] = 0.0
    d += smooth

    fence = np.zeros((0, 2))
    if bounds is not None:
        fence = divide_long_edges(_xy(bounds, "bounds"), True, split)
        if len(fence) < 3:
            raise ValueError("bounds must be a closed curve of at least 3 points")
        if not _inside(p[0], fence):
            raise ValueError("the curve starts outside its bounds")
    if jitter > 0:
        rng = np.random.default_rng(seed)
        d += rng.uniform(-0.5, 0.5, size=p.shape) * (jitter * split)

    # one neighbour search serves the repulsion (pairs nearer than radius) and the
    # clearances (a vertex nearer than `reach` to an edge is nearer than reach + longest
    # to one of its ends)
    everything = np.vstack([p, fence])
    ring = np.roll(fence, -1, axis=0) - fence
    longest = max(float(length.max()), float(np.sqrt((ring * ring).sum(1)).max(initial=0.0)))
    reach = min(radius, split)
    i, j, dx, dy, dist = _pairs(everything, max(radius, reach + longest))
    gap = j - i
    # the fence's own pairs never matter; neighbours along the curve are handled apart
    apart = (i < n) & ((j >= n) | ((gap != 1) & ~(closed & (gap == n - 1))))
    i, j, dist = i[apart], j[apart], dist[apart]
    dv = np.stack([dx[apart], dy[apart]], axis=1)

    repel = (dist < radius) & (dist > 0)
    w = 0.5 * repulsion * (radius - dist[repel]) / dist[repel]
    push = dv[repel] * w[:, None]
    _scatter(d, i[repel], push)
    on_curve = j[repel] < n
    _scatter(d, j[repel][on_curve], -push[on_curve])

    near = dist < reach + longest
    d = _limit(everything, n, d, closed, reach, longest, i[near], j[near], dist[near])
    return divide_long_edges(p + d, closed, split)


def _scatter(out: np.ndarray, index: np.ndarray, values: np.ndarray) -> None:
    """out[index] += values, summing repeats (bincount per column: faster than add.at)."""
    n = len(out)
    for c in range(out.shape[1]):
        out[:, c] += np.bincount(index, values[:, c], minlength=n)


def _incident(v: np.ndarray, n: int, k: int, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    """The two edges at each vertex (-1 where an open curve's end has none). Curve vertex
    v < n has edges v - 1 and v (edge e joins e and e + 1); fence vertex n + w has edges
    m + w - 1 and m + w, m the curve's edge count."""
    m = n if closed else n - 1
    on_fence = v >= n
    before = np.where(on_fence, m + (v - n - 1) % max(k, 1), v - 1)
    after = np.where(on_fence, v - n + m, v)
    if closed:
        before = np.where(before < 0, m - 1, before)
    else:
        after = np.where(on_fence | (v < n - 1), after, -1)
    return before, after


def _limit(
    pts: np.ndarray,
    n: int,
    d: np.ndarray,
    closed: bool,
    reach: float,
    longest: float,
    i: np.ndarray,
    j: np.ndarray,
    dist: np.ndarray,
) -> np.ndarray:
    """The moves ``d`` scaled down so that no two edges can meet (see the module
    docstring). ``pts`` are the curve's n vertices then the fence's; ``i, j`` the pairs of
    vertices nearer than ``reach`` plus the longest edge that are not neighbours along the
    curve (i on the curve, j on the curve or the fence), ``dist`` their distances.

    Each vertex u and edge f not at u give a distance delta that bounds the clearance of f
    and of both edges at u: the clearance of two edges is the least such distance (or 0
    when they cross). The pairs give the vertices near the far edges; the neighbours along
    the curve give, for each u, the edges one further on either side.
    """
    k = len(pts) - n
    m = n if closed else n - 1
    a = np.vstack([pts[:m], pts[n:]])
    b = np.vstack([pts[(np.arange(m) + 1) % n], np.roll(pts[n:], -1, axis=0)])
    ib, ia = _incident(i, n, k, closed)
    jb, ja = _incident(j, n, k, closed)
    on_curve = j < n
    v = np.arange(n)
    vb, va = _incident(v, n, k, closed)
    # rows (vertex u, edge f, the edges ub and ua at u): u = i against the edge after j,
    # u = j (on the curve) against the edge after i (a vertex within reach of an edge is
    # within reach + longest of the edge's first end), and each vertex against the edges
    # after next and before last (where a fold would lie)
    ahead = np.where(va >= 0, (v + 1) % n, -1) if closed else np.where(v < n - 2, v + 1, -1)
    behind = (v - 2) % n if closed else np.where(v >= 2, v - 2, -1)
    if closed and n == 3:  # the edge after next is the edge before last
        behind = np.full(n, -1)
    u = np.concatenate([i, j[on_curve], v, v])
    f = np.concatenate([ja, ia[on_curve], ahead, behind])
    ub = np.concatenate([ib, jb[on_curve], vb, vb])
    ua = np.concatenate([ia, ja[on_curve], va, va])
    keep = f >= 0
    u, f, ub, ua = u[keep], f[keep], ub[keep], ua[keep]
    # contiguous columns: gathers from a strided column view are several times slower
    px, py, ax, ay, bx, by = (np.ascontiguousarray(c) for c in (*pts.T, *a.T, *b.T))
    delta = _point_edge_distances(px[u], py[u], ax[f], ay[f], bx[f], by[f])
    if (delta <= 0).any():
        x = int(np.argmax(delta <= 0))
        what = "its bounds" if f[x] >= m or u[x] >= n else "itself"
        raise ValueError(f"the curve touches {what} (at {pts[u[x]].round(6).tolist()})")
    close = dist < longest
    _refuse_crossings(
        a,
        b,
        m,
        np.concatenate([ib[close], ib[close], ia[close], ia[close], vb]),
        np.concatenate([jb[close], ja[close], jb[close], ja[close], ahead]),
    )
    clearance = np.full(m + k + 1, reach)  # the last slot takes the ends' missing edges
    np.minimum.at(clearance, f, delta)
    np.minimum.at(clearance, ub, delta)
    np.minimum.at(clearance, ua, delta)
    clearance = clearance[:m]
    # a vertex's room: the smaller clearance of its edges (edge v - 1 and edge v)
    if closed:
        room = np.minimum(clearance, np.roll(clearance, 1))
    else:
        room = np.concatenate(
            [clearance[:1], np.minimum(clearance[1:], clearance[:-1]), clearance[-1:]]
        )
    room *= QUARTER
    move = np.sqrt(np.einsum("ij,ij->i", d, d))
    scale = np.where(move > room, room / np.where(move > 0, move, 1.0), 1.0)
    return d * scale[:, None]


def _refuse_crossings(a: np.ndarray, b: np.ndarray, m: int, f: np.ndarray, g: np.ndarray) -> None:
    """Raise when edges f and g (row by row) cross at interior points; touching is caught
    by the distances. Two crossing edges no longer than L have ends nearer than L, so the
    close pairs' edges (and each edge against the one after next) are all to test."""
    keep = (f >= 0) & (g >= 0) & (f != g)
    f, g = f[keep], g[keep]
    c0, c1, e0, e1 = a[f], b[f], a[g], b[g]
    u, w = c1 - c0, e1 - e0
    crossing = (_cross(u, e0 - c0) * _cross(u, e1 - c0) < 0) & (
        _cross(w, c0 - e0) * _cross(w, c1 - e0) < 0
    )
    if crossing.any():
        x = int(np.argmax(crossing))
        what = "its bounds" if max(f[x], g[x]) >= m else "itself"
        raise ValueError(f"the curve crosses {what} (near {c0[x].round(6).tolist()})")
