"""Robust offset of polylines: signed distance field on a grid, then marching squares.

The offset at distance ``d`` is the level set ``f = d`` of the signed distance ``f`` to the
input segments (negative inside the closed polylines by the even-odd rule). ``f`` is never
sampled on the whole grid: a coarse grid is evaluated first and only the cells that the
1-Lipschitz bound ``|f(x) - f(corner)| <= |x - corner|`` cannot rule out are split, level
after level, down to the final cell size -- a quadtree restricted to a band around the
contour, so the work grows with the length of the result, not with the grid area. Each
sample is the exact point-segment distance (`distance.SegmentTree`), signed by the
crossing-number test on its grid row (`distance.RowParity`).

The contour is traced by `contour.trace_crossings` on the sparse samples, then made exact:
every vertex is moved onto the level set along the gradient of its nearest feature (for a
distance field that Newton step is exact), and where consecutive vertices' normals turn
sharply the corner between them is recovered from the two features (the sharp-feature
idea of Kobbelt, Botsch, Schwanecke & Seidel, "Feature sensitive surface extraction from
volume data", SIGGRAPH 2001) or, on a smooth bend, a projected midpoint is inserted.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .contour import split_loops, trace_crossings
from .distance import RowParity, SegmentTree

__all__ = ["default_cell", "offset_polylines"]

DEFAULT_MAX_CELLS = 2**27
_COARSE_CELLS = 32  # cells per side of the first, full level of the quadtree
_TOLERANCE = 1e-3  # default error, as a fraction of the input's extent


def default_cell(extent: float, distance: float, tolerance: float = 1e-3) -> float:
    """The default grid cell for an offset of ``distance`` of an input of size ``extent``.

    Vertices are exact after the projection step, so the error is the chord sag between
    neighbours; for arcs of radius ``R >= |d|`` and chords of at most ``sqrt(2) h`` it is
    ``h**2 / (4 R)``, which ``h = sqrt(|d| * tol)`` keeps under ``tol / 4``. ``h <= |d| / 2``
    keeps every part of the offset region (at least ``2 |d|`` thick) several cells wide.

    Parameters
    ----------
    extent : float
        Largest side of the input's bounding box (if 0, ``2 |distance|`` is used).
    distance : float
        Offset distance, nonzero.
    tolerance : float
        Error target as a fraction of ``extent``.

    Returns
    -------
    float
    """
    d = abs(distance)
    scale = extent if extent > 0 else 2 * d
    return float(min(d / 2, 2 * np.sqrt(d * tolerance * scale)))


def _segments(
    polylines: Sequence[np.ndarray], closed: Sequence[bool]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Concatenated segments ``a -> b`` and whether each belongs to a closed polyline."""
    if len(polylines) == 0:
        raise ValueError("offset needs at least one polyline, got none")
    if len(closed) != len(polylines):
        raise ValueError(
            f"closed must give one flag per polyline: {len(polylines)} polylines, "
            f"{len(closed)} flags"
        )
    a, b, c = [], [], []
    for k, (pts, is_closed) in enumerate(zip(polylines, closed, strict=True)):
        p = np.asarray(pts, dtype=float)
        if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] == 0:
            raise ValueError(f"polyline {k} must be an (n, 2) array with n >= 1, got {p.shape}")
        if not np.isfinite(p).all():
            raise ValueError(f"polyline {k} has NaN or infinite coordinates")
        if p.shape[0] == 1:
            p = np.concatenate([p, p])
        if is_closed:
            p = np.concatenate([p, p[:1]])
        a.append(p[:-1])
        b.append(p[1:])
        c.append(np.full(p.shape[0] - 1, bool(is_closed)))
    return np.concatenate(a), np.concatenate(b), np.concatenate(c)


class _Field:
    """The signed distance ``f`` at grid samples, exact where ``|f - level| <= band``."""

    def __init__(self, tree, parity, origin, cell, level):
        self.tree = tree
        self.parity = parity
        self.origin = origin
        self.cell = cell
        self.level = level

    def at(self, i: np.ndarray, j: np.ndarray, band: float) -> np.ndarray:
        d = self.level
        if self.parity is None:
            inside = np.zeros(i.size, dtype=bool)
        else:
            inside = self.parity.inside(i, j)
        sign = np.where(inside, -1.0, 1.0)
        same = (sign > 0) == (d > 0)
        # Same side as the level: exact within |d| +- band. Other side: |f - d| = dist + |d|,
        # so only a distance below band - |d| can matter.
        lo = np.where(same, abs(d) - band, 0.0)
        hi = np.where(same, abs(d) + band, band - abs(d))
        f = np.zeros(i.size)
        ask = hi >= 0
        if ask.any():
            pts = self.origin + np.stack([j[ask], i[ask]], axis=-1) * self.cell
            f[ask] = self.tree.query(pts, lo[ask], hi[ask]).dist
        return sign * f


def _store_lookup(ids: np.ndarray, values: np.ndarray):
    def value(q: np.ndarray) -> np.ndarray:
        perm = np.argsort(q)
        pos = np.empty(q.size, dtype=np.int64)
        pos[perm] = np.searchsorted(ids, q[perm])
        return values[np.minimum(pos, ids.size - 1)]

    return value


def _band_cells(field: _Field, ncx: int, ncy: int, levels: int):
    """Quadtree descent: the finest cells that may hold the level set, with their samples.

    Returns
    -------
    ids : (m,) int64, sorted
        Flat ids ``i * (ncx + 1) + j`` of the evaluated fine samples.
    values : (m,) float
    cells : (k,) int64
        Flat ids of the lower-left samples of the fine cells that may hold the level set.
    """
    d = field.level
    step = 2**levels
    # Level `levels`: the whole coarse grid.
    ci, cj = np.mgrid[0 : ncy // step, 0 : ncx // step]
    ci, cj = ci.ravel(), cj.ravel()
    value = None
    for lev in range(levels, -1, -1):
        step = 2**lev
        w = ncx // step + 1
        if lev == levels:
            pi, pj = np.mgrid[0 : ncy // step + 1, 0 : ncx // step + 1]
            pid = (pi * w + pj).ravel()
        else:
            # Children of the surviving parents, and their 3 x 3 samples.
            ci = (2 * ci[:, None] + np.array([0, 0, 1, 1])).ravel()
            cj = (2 * cj[:, None] + np.array([0, 1, 0, 1])).ravel()
            pid = np.unique(
                (ci[:, None] + np.array([0, 0, 1, 1])) * w
                + cj[:, None]
                + np.array([0, 1, 0, 1])
            )
        pi, pj = np.divmod(pid, w)
        band = 1.5 * step * field.cell
        if lev == levels:
            values = field.at(pi * step, pj * step, band)
        else:
            # Samples of the previous level were exact in a band twice as wide: reuse them.
            old = (pi % 2 == 0) & (pj % 2 == 0)
            values = np.empty(pid.size)
            values[old] = value((pi[old] // 2) * (w // 2 + 1) + pj[old] // 2)
            new = ~old
            values[new] = field.at(pi[new] * step, pj[new] * step, band)
        value = _store_lookup(pid, values)
        corner = ci * w + cj
        gap = np.abs(
            np.stack([value(corner), value(corner + 1), value(corner + w), value(corner + w + 1)])
            - d
        ).min(axis=0)
        # A cell can hold a point at the level only if a corner is within half a diagonal.
        keep = gap <= step * field.cell * (np.sqrt(0.5) * (1 + 1e-9))
        ci, cj = ci[keep], cj[keep]
    return pid, values, ci * (ncx + 1) + cj


class _Loops:
    """Closed loops stored flat, loop after loop, with per-vertex data for refinement."""

    def __init__(self, xy: np.ndarray, normal: np.ndarray, loop: np.ndarray, todo: np.ndarray):
        self.xy = xy
        self.normal = normal
        self.loop = loop  # loop id of each vertex, nondecreasing
        self.todo = todo  # the chord from this vertex to the next still needs a check

    @property
    def next(self) -> np.ndarray:
        n = self.loop.size
        nxt = np.arange(1, n + 1)
        last = np.flatnonzero(np.diff(self.loop, append=-1) != 0)
        first = np.concatenate([[0], last[:-1] + 1])
        nxt[last] = first
        return nxt

    def offsets(self) -> np.ndarray:
        counts = np.bincount(self.loop)
        return np.concatenate([[0], np.cumsum(counts[counts > 0])])

    def insert(self, after: np.ndarray, xy: np.ndarray, normal: np.ndarray) -> _Loops:
        """New vertices after the given ones; the chords on both sides of each are to do."""
        n = self.loop.size
        key = np.concatenate([np.arange(n, dtype=float), after + 0.5])
        order = np.argsort(key, kind="stable")
        todo = self.todo.copy()
        todo[after] = True
        return _Loops(
            np.concatenate([self.xy, xy])[order],
            np.concatenate([self.normal, normal])[order],
            np.concatenate([self.loop, self.loop[after]])[order],
            np.concatenate([todo, np.ones(after.size, dtype=bool)])[order],
        )

    def select(self, keep: np.ndarray) -> _Loops:
        return _Loops(self.xy[keep], self.normal[keep], self.loop[keep], self.todo[keep])


def _unit(v: np.ndarray) -> np.ndarray:
    length = np.hypot(v[:, 0], v[:, 1])
    return v / np.where(length > 0, length, 1.0)[:, None]


def _project(tree: SegmentTree, p: np.ndarray, radius: float, band: float):
    """Move points onto the offset of their nearest feature; report which stay on it.

    For a distance function the step ``x -> foot + radius * (x - foot) / |x - foot|`` lands
    exactly on the level ``radius`` as long as the nearest feature does not change; the
    result is then checked with a second query: a point that another feature comes closer
    to than ``radius`` (near a corner of the offset) is reported as not on the level.

    Returns
    -------
    moved : (m, 2) float
    normal : (m, 2) float
        Unit gradient of the distance at ``p`` (from its nearest point on the input).
    dist : (m,) float
        Distance of ``p`` itself.
    ok : (m,) bool
        ``p`` was within the band and ``moved`` lies on the level.
    """
    near = tree.query(p, radius - band, radius + band)
    seg = np.maximum(near.segment, 0)
    foot = tree.a[seg] + near.t[:, None] * (tree.b[seg] - tree.a[seg])
    gap = p - foot
    length = np.hypot(gap[:, 0], gap[:, 1])
    ok = near.exact & (length > 0)
    normal = gap / np.where(length > 0, length, 1.0)[:, None]
    moved = foot + radius * normal
    # From beyond the offset the move goes toward the foot and stays in the foot's Voronoi
    # cell (the segment from a point to its nearest point does); only a move away from
    # the input can enter another feature's reach.
    inner = np.flatnonzero(ok & (near.dist < radius))
    check = tree.query(moved[inner], radius * (1 - 1e-9), radius)
    ok[inner] &= check.dist >= radius * (1 - 1e-9)
    return moved, normal, near.dist, ok


def _drop_folds(loops: _Loops, before: np.ndarray, ok: np.ndarray) -> _Loops:
    """Drop the vertices that failed to project, and pairs that projection put in reverse.

    Near a corner of the offset two neighbours can be moved past each other; both go, and
    the chord refinement recovers the corner from their neighbours. A loop that would keep
    fewer than three vertices is kept as it was.
    """
    keep = ok.copy()
    for _ in range(4):
        sub = loops.select(keep)
        idx = np.flatnonzero(keep)
        nxt = sub.next
        step = sub.xy[nxt] - sub.xy
        was = before[idx[nxt]] - before[idx]
        flip = np.einsum("ij,ij->i", step, was) <= 0
        # A chord crossing the chord two or three ahead: the vertices between are reversed.
        n2 = nxt[nxt]
        cross2 = _crosses(sub.xy, nxt, n2, nxt[n2])
        cross3 = _crosses(sub.xy, nxt, nxt[n2], nxt[nxt[n2]])
        if not (flip.any() or cross2.any() or cross3.any()):
            break
        keep[idx[flip]] = False
        keep[idx[nxt[flip | cross2 | cross3]]] = False
        keep[idx[n2[cross2 | cross3]]] = False
        keep[idx[nxt[n2[cross3]]]] = False
    count = np.bincount(loops.loop[keep], minlength=loops.loop.max() + 1)
    keep |= count[loops.loop] < 3
    return loops.select(keep)


def _crosses(xy: np.ndarray, i1: np.ndarray, j0: np.ndarray, j1: np.ndarray) -> np.ndarray:
    """Whether chord ``k -> i1[k]`` properly crosses chord ``j0[k] -> j1[k]``, for every k."""
    a, b, c, d = xy, xy[i1], xy[j0], xy[j1]

    def orient(p, q, r):
        return (q[:, 0] - p[:, 0]) * (r[:, 1] - p[:, 1]) - (q[:, 1] - p[:, 1]) * (r[:, 0] - p[:, 0])

    return (orient(a, b, c) * orient(a, b, d) < 0) & (orient(c, d, a) * orient(c, d, b) < 0)


def _between(u: np.ndarray, c: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Whether points ``p`` project strictly inside the chords ``u -> u + c``."""
    along = np.einsum("ij,ij->i", p - u, c)
    return (along > 0) & (along < np.einsum("ij,ij->i", c, c))


def _crossing(
    tree: SegmentTree,
    p0: np.ndarray,
    p1: np.ndarray,
    d0: np.ndarray,
    radius: float,
    tol: float,
    iterations: int = 30,
):
    """Where the distance equals ``radius`` on the segments ``p0 -> p1``.

    Regula falsi with the Illinois modification (Dowell & Jarratt, BIT 1971) on
    ``g(s) = dist(p0 + s (p1 - p0)) - radius``; only segments whose ends straddle the
    level are solved. Both ends must lie within ``0.9 radius`` of the offset, so every
    distance evaluated is on the offset's side of the input.

    Parameters
    ----------
    p0, p1 : (m, 2) float
    d0 : (m,) float
        Distance at ``p0``, already known.

    Returns
    -------
    found : (m,) bool
    point : (m, 2) float
    normal : (m, 2) float
        Unit gradient of the distance at ``point``.
    """
    m = p0.shape[0]
    found = np.zeros(m, dtype=bool)
    point = np.zeros((m, 2))
    normal = np.zeros((m, 2))
    band = 0.9 * radius
    g0 = d0 - radius
    g1 = tree.query(p1, radius - band, radius + band).dist - radius
    idx = np.flatnonzero((g0 * g1 <= 0) & (g0 != g1))
    g0, g1 = g0[idx], g1[idx]
    s0, s1 = np.zeros(idx.size), np.ones(idx.size)
    side = np.zeros(idx.size, dtype=np.int8)  # which end was kept last time (Illinois)
    done = np.zeros(idx.size, dtype=bool)
    for _ in range(iterations):
        act = np.flatnonzero(~done)
        if act.size == 0:
            break
        s = (s0[act] * g1[act] - s1[act] * g0[act]) / (g1[act] - g0[act])
        j = idx[act]
        x = p0[j] + s[:, None] * (p1[j] - p0[j])
        near = tree.query(x, radius - band, radius + band)
        g = near.dist - radius
        seg = np.maximum(near.segment, 0)
        foot = tree.a[seg] + near.t[:, None] * (tree.b[seg] - tree.a[seg])
        point[j], normal[j] = x, _unit(x - foot)
        hit = np.abs(g) <= 1e-3 * tol
        done[act[hit]] = True
        same0 = np.sign(g) == np.sign(g0[act])
        # Replace the end on the same side; halve the kept end's value if it was kept twice.
        a0, a1 = act[same0 & ~hit], act[~same0 & ~hit]
        g1[a0] = np.where(side[a0] == 1, g1[a0] / 2, g1[a0])
        g0[a1] = np.where(side[a1] == -1, g0[a1] / 2, g0[a1])
        s0[a0], g0[a0], side[a0] = s[same0 & ~hit], g[same0 & ~hit], 1
        s1[a1], g1[a1], side[a1] = s[~same0 & ~hit], g[~same0 & ~hit], -1
    found[idx[done]] = True
    return found, point, normal


def _refine(tree: SegmentTree, loops: _Loops, radius: float, tol: float, rounds: int = 12):
    """Make loop vertices exact and add vertices where the offset leaves the chords.

    A chord between two exact vertices with unit normals ``n0, n1`` is checked by the
    intersection ``k`` of their tangents: a smooth arc between them (of one sign of
    curvature) lies in the triangle they span, so the height of ``k`` above the chord bounds
    the error. Where it exceeds ``tol``, ``k`` is inserted if it lies on the offset (a corner,
    where two features' offsets meet), else its projection onto the offset; new chords are
    checked again, for a few rounds.
    """
    for _ in range(rounds):
        nxt = loops.next
        todo = np.flatnonzero(loops.todo)
        if todo.size == 0:
            break
        u, w = loops.xy[todo], loops.xy[nxt[todo]]
        nu, nw = loops.normal[todo], loops.normal[nxt[todo]]
        c = w - u
        clen = np.hypot(c[:, 0], c[:, 1])
        sin = nu[:, 0] * nw[:, 1] - nu[:, 1] * nw[:, 0]
        # Tangent of u is (-nu_y, nu_x); it meets the tangent line of w at u + s * tangent.
        s = np.divide(
            nw[:, 0] * c[:, 0] + nw[:, 1] * c[:, 1], sin, out=np.zeros_like(sin), where=sin != 0
        )
        k = u + s[:, None] * np.stack([-nu[:, 1], nu[:, 0]], axis=-1)
        ku = k - u
        height = np.abs(c[:, 0] * ku[:, 1] - c[:, 1] * ku[:, 0]) / np.maximum(clen, 1e-300)
        along = (c[:, 0] * ku[:, 0] + c[:, 1] * ku[:, 1]) / np.maximum(clen, 1e-300) ** 2
        # A step between parallel normals, or normals not facing the chord's sides.
        skew = np.maximum(
            np.abs(nu[:, 0] * c[:, 0] + nu[:, 1] * c[:, 1]),
            np.abs(nw[:, 0] * c[:, 0] + nw[:, 1] * c[:, 1]),
        )
        # Tangents meeting over the chord (or just past an end, as from a corner vertex)
        # bound the error by their height; otherwise (parallel normals: a step; meeting far
        # out: an inflection) by how far the normals are from square to the chord.
        meet = (sin != 0) & (along > -0.25) & (along < 1.25)
        bad = np.where(meet, height > tol, skew > tol)
        corner_ok = meet & (along > 0) & (along < 1) & (np.hypot(*ku.T) < 0.9 * radius)
        loops.todo[todo[~bad]] = False
        todo, k, corner_ok = todo[bad], k[bad], corner_ok[bad]
        along = along[bad]
        if todo.size == 0:
            break
        u, c = loops.xy[todo], loops.xy[nxt[todo]] - loops.xy[todo]
        loops.todo[todo] = False
        # First the chord point below the tangent intersection (kept off the chord's ends)
        # moved onto the offset along its gradient: exact in one step on a smooth stretch.
        m = u + np.where(corner_ok, np.clip(along, 0.2, 0.8), 0.5)[:, None] * c
        point, normal, dist, found = _project(tree, m, radius, 0.9 * radius)
        at = np.einsum("ij,ij->i", point - u, c) / np.einsum("ij,ij->i", c, c)
        found &= (at > 0.1) & (at < 0.9)
        # Near a corner it slides toward a chord end instead. Between the chord point and
        # the tangent intersection the distance crosses the level (for a bulge, a notch
        # and a corner alike): find that crossing.
        retry = ~found & corner_ok
        got, cpoint, cnormal = _crossing(tree, m[retry], k[retry], dist[retry], radius, tol)
        # The segment may meet the offset again beyond the chord's ends; such a crossing
        # would fold the loop back on itself.
        got &= _between(u[retry], c[retry], cpoint)
        idx = np.flatnonzero(retry)
        point[idx], normal[idx], found[idx] = cpoint, cnormal, got
        # A projection that slid toward an end is still a point of the offset.
        slid = ~found & ~retry & _between(u, c, point)
        found |= slid & (dist > 0)
        loops = loops.insert(todo[found], point[found], normal[found])
    return loops


def offset_polylines(
    polylines: Sequence[np.ndarray],
    closed: Sequence[bool],
    distance: float,
    cell: float | None = None,
    smooth: int = 0,
    simplify: float = 0.0,
    max_cells: int = DEFAULT_MAX_CELLS,
) -> list[np.ndarray]:
    """Offset polylines by a signed distance: closed loops bounding ``{f < distance}``.

    Parameters
    ----------
    polylines : sequence of (n, 2) float
        Input polylines in the plane. A closed polyline's last vertex joins its first.
    closed : sequence of bool
        One flag per polyline. Closed polylines bound a region by the even-odd rule
        (nested ones make holes, self-intersections are fine); open ones bound nothing.
    distance : float
        Nonzero. Positive grows the region (and turns open polylines into bands of
        half-width ``distance``); negative shrinks the region.
    cell : float, optional
        Grid cell size. Default: `default_cell`, keeping the error below 0.1 % of the
        input's extent.
    smooth : int
        Smoothing passes (Laplacian, each followed by a projection back onto the offset).
    simplify : float
        Douglas-Peucker tolerance (0: none).
    max_cells : int
        Largest grid (in cells) accepted.

    Returns
    -------
    list of (m, 2) float
        Closed loops (first vertex not repeated): counter-clockwise around each island of
        the result, clockwise around its holes.

    Raises
    ------
    ValueError
        If there are no polylines, a polyline is not a finite (n, 2) array, distance is 0 or
        not finite, cell is not positive, or the grid would exceed ``max_cells``.

    Example
    -------
    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    >>> (loop,) = offset_polylines([square], [True], 0.25)
    >>> bool(np.isclose(np.abs(loop).max(), 1.25, atol=1e-3))
    True
    """
    a, b, seg_closed = _segments(polylines, closed)
    distance = float(distance)
    if not np.isfinite(distance) or distance == 0:
        raise ValueError(f"distance must be a nonzero finite number, got {distance}")
    pts = np.concatenate([a, b])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    extent = float((hi - lo).max())
    if cell is None:
        cell = default_cell(extent, distance)
    cell = float(cell)
    if not (np.isfinite(cell) and cell > 0):
        raise ValueError(f"cell must be a positive finite number, got {cell}")

    margin = abs(distance) + 2 * cell
    size = (hi - lo + 2 * margin) / cell
    levels = max(0, int(np.ceil(np.log2(max(size.max() / _COARSE_CELLS, 1.0)))))
    step = 2**levels
    ncx, ncy = (np.ceil(size / step).astype(np.int64) * step).tolist()
    if ncx * ncy > max_cells:
        raise ValueError(
            f"the offset grid would need {ncx} x {ncy} = {ncx * ncy} cells, more than the "
            f"limit of {max_cells}; use a larger cell than {cell:.6g}"
        )
    origin = (lo + hi) / 2 - np.array([ncx, ncy]) * cell / 2

    tree = SegmentTree(a, b)
    parity = (
        RowParity(a[seg_closed], b[seg_closed], origin, cell, ncy + 1, ncx + 1)
        if seg_closed.any()
        else None
    )
    field = _Field(tree, parity, origin, cell, distance)
    ids, values, cells = _band_cells(field, ncx, ncy, levels)

    nx = ncx + 1
    value = _store_lookup(ids, values)
    c00, c01, c10 = value(cells), value(cells + 1), value(cells + nx)
    in00, in01, in10 = c00 < distance, c01 < distance, c10 < distance
    h_edges = np.sort(cells[in00 != in01])
    v_edges = np.sort(cells[in00 != in10])
    cr = trace_crossings(h_edges, v_edges, nx, value, distance, below=True)
    xy = origin + np.stack([cr.col, cr.row], axis=-1)[cr.order] * cell
    tol = _TOLERANCE * (extent if extent > 0 else 2 * abs(distance))
    if cell < 0.9 * abs(distance) and xy.shape[0]:
        loop = np.repeat(np.arange(cr.offsets.size - 1), np.diff(cr.offsets))
        moved, normal, _, ok = _project(tree, xy, abs(distance), 1.5 * cell)
        # A vertex whose projection another feature swallows sits next to a corner of the
        # offset: drop it and let the chord across the corner recover it, unless that
        # would leave its loop without three vertices.
        # Where the contour passes within a hair of a sample, marching squares puts two or
        # three vertices on top of each other; projection could then fold them.
        prev = np.roll(np.arange(xy.shape[0]), 1)
        starts = cr.offsets[:-1][np.diff(cr.offsets) > 0]
        prev[starts] = cr.offsets[1:][np.diff(cr.offsets) > 0] - 1
        ok &= np.hypot(*(xy - xy[prev]).T) > 1e-3 * cell
        loops = _Loops(moved, normal, loop, np.ones(xy.shape[0], dtype=bool))
        loops = _drop_folds(loops, xy, ok)
        loops = _refine(tree, loops, abs(distance), tol / 4)
        xy, offsets = loops.xy, loops.offsets()
    else:
        offsets = cr.offsets
    return split_loops(xy, offsets)
