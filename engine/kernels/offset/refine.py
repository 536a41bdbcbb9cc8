"""Make a traced level set of a distance-to-segments field exact, then tidy it.

A contour traced by marching squares has its vertices on grid edges, placed by linear
interpolation, and cuts the corners of the level set inside cells. Here the level set is
that of the exact distance to a set of segments (`distance.SegmentTree`), whose gradient
at any point is the unit vector from its nearest point on the segments:

* `project` moves a point onto the level along that gradient, a Newton step that is exact
  while the nearest feature does not change (and is checked where it might);
* `refine_chords` bounds the error of each chord by the tangents at its ends and inserts
  exact points where it is too large: a projected chord point on a smooth stretch, else the
  level crossing between the chord and the tangent intersection, else the corner where the
  two end features' offsets meet (the sharp-feature recovery of Kobbelt, Botsch,
  Schwanecke & Seidel, "Feature sensitive surface extraction from volume data",
  SIGGRAPH 2001);
* `smooth` relaxes vertices along the level set (the clean-up and Douglas-Peucker are in
  `loops`).

Every step is vectorized over all vertices of all loops. Distances are unsigned: callers
keep every point they pass within ``0.9 radius`` of the level, which (the signed distance
being 1-Lipschitz) puts it on the level's side of the input.
"""

from __future__ import annotations

import numpy as np

from .distance import Nearest, SegmentTree, point_segment
from .loops import COS30, Loops, drop_covered, drop_folds, segments_cross, tidy, unit

__all__ = ["exact_loops", "project", "refine_chords", "smooth"]


def _feet(tree: SegmentTree, near: Nearest, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nearest points on the input and the unit gradient of the distance at ``p``."""
    seg = np.maximum(near.segment, 0)
    foot = tree.a[seg] + near.t[:, None] * (tree.b[seg] - tree.a[seg])
    return foot, unit(p - foot)


def project(
    tree: SegmentTree, p: np.ndarray, radius: float, band: float, upper: np.ndarray | None = None
):
    """Move points onto the level ``radius`` along the gradient of the distance.

    For a distance function the step ``x -> foot + radius * (x - foot) / |x - foot|`` lands
    exactly on the level while the nearest feature does not change. From beyond the level
    the move goes toward the foot and stays in the foot's Voronoi cell (the segment from a
    point to its nearest point does); a move away from the input is checked with a second
    query, since another feature may come closer than ``radius`` there (near a corner).

    Parameters
    ----------
    p : (m, 2) float
    radius : float
    band : float
        How far from the level the points may be (the query is exact within it).
    upper : (m,) float, optional
        Known upper bounds of the points' distances (inf: none), which prune the search.

    Returns
    -------
    moved : (m, 2) float
    normal : (m, 2) float
        Unit gradient of the distance at ``p``.
    seg : (m,) int64
        A nearest segment of ``p``.
    dist : (m,) float
        Distance of ``p``.
    ok : (m,) bool
        ``moved`` lies on the level.
    """
    near = tree.query(p, radius - band, radius + band, upper=upper)
    foot, normal = _feet(tree, near, p)
    ok = near.exact & (near.dist > 0)
    moved = foot + radius * normal
    inner = np.flatnonzero(ok & (near.dist < radius))
    check = tree.query(moved[inner], radius * (1 - 1e-9), radius)
    ok[inner] &= check.dist >= radius * (1 - 1e-9)
    return moved, normal, near.segment, near.dist, ok


def _crossing(tree, p0, p1, d0, radius, tol, iterations=16):
    """Where the distance equals ``radius`` on the segments ``p0 -> p1``.

    Regula falsi with the Illinois modification (Dowell & Jarratt, BIT 1971) on
    ``g(s) = dist(p0 + s (p1 - p0)) - radius``; only segments whose ends straddle the
    level are solved (or whose far end is on it already, as a corner is to rounding).

    Parameters
    ----------
    p0, p1 : (m, 2) float
    d0 : (m,) float
        Distance at ``p0``, already known.

    Returns
    -------
    found : (m,) bool
    point, normal : (m, 2) float
    seg : (m,) int64
    """
    m = p0.shape[0]
    found = np.zeros(m, dtype=bool)
    point = np.zeros((m, 2))
    normal = np.zeros((m, 2))
    seg = np.zeros(m, dtype=np.int64)
    if m == 0:
        return found, point, normal, seg
    band = 0.9 * radius
    eps = 1e-2 * tol
    g0 = d0 - radius
    end = tree.query(p1, radius - band, radius + band)
    g1 = end.dist - radius
    there = np.flatnonzero(np.abs(g1) <= eps)
    found[there], point[there], seg[there] = True, p1[there], end.segment[there]
    normal[there] = _feet(tree, end, p1)[1][there]
    idx = np.flatnonzero((g0 * g1 < 0) & ~found)
    g0, g1 = g0[idx], g1[idx]
    s0, s1 = np.zeros(idx.size), np.ones(idx.size)
    kept = np.zeros(idx.size, dtype=np.int8)  # which end survived the last step (Illinois)
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
        point[j], normal[j], seg[j] = x, _feet(tree, near, x)[1], near.segment
        hit = np.abs(g) <= eps
        done[act[hit]] = True
        # Replace the end on the same side; halve the other end's value when it survives
        # twice in a row.
        same0 = (np.sign(g) == np.sign(g0[act])) & ~hit
        same1 = ~same0 & ~hit
        a0, a1 = act[same0], act[same1]
        g1[a0] = np.where(kept[a0] == 1, g1[a0] / 2, g1[a0])
        g0[a1] = np.where(kept[a1] == -1, g0[a1] / 2, g0[a1])
        s0[a0], g0[a0], kept[a0] = s[same0], g[same0], 1
        s1[a1], g1[a1], kept[a1] = s[same1], g[same1], -1
    found[idx[done]] = True
    return found, point, normal, seg


def _corner(tree, s1, s2, start, radius, tol, chases=2, iterations=6):
    """Where the offsets of two pieces of the input meet near ``start``: a corner of the level
    set.

    Solves ``dist(x, s1) = dist(x, s2) = radius`` by Newton's method (exact in one step for
    two lines, quadratic for lines and circles). Each step the pair follows the input: each
    member becomes the segment nearest ``x`` among its neighbours in index order (a window of
    `_TRACK` on either side, never reaching past the other member), so two smooth stretches
    of a finely sampled input meet where their offsets do, not where two of their segments'
    offsets would. A query then checks that no other segment comes closer. If one does, it
    replaces the pair member whose gradient at ``x`` is closest to its own (the one on the
    same side of the corner) and the solve repeats.

    Returns
    -------
    found : (m,) bool
    point : (m, 2) float
    normal1 : (m, 2) float
    seg1 : (m,) int64
        The first segment of the final pair and the distance gradient it gives at
        ``point``;
    normal2 : (m, 2) float
    seg2 : (m,) int64
        the same for the second.
    """
    m = start.shape[0]
    found = np.zeros(m, dtype=bool)
    point = start.copy()
    n1_all, n2_all = np.zeros((m, 2)), np.zeros((m, 2))
    s1, s2 = s1.copy(), s2.copy()
    eps = 1e-3 * tol
    act = np.arange(m) if m else np.zeros(0, dtype=np.int64)
    for _ in range(chases):
        if act.size == 0:
            break
        x = point[act]
        p1, p2 = s1[act], s2[act]
        for k in range(iterations):
            p1, d1, t1 = _track(tree, x, p1, p2)
            p2, d2, t2 = _track(tree, x, p2, p1)
            f1, f2 = d1 - radius, d2 - radius
            if k and np.all((np.abs(f1) <= 0.1 * eps) & (np.abs(f2) <= 0.1 * eps)):
                break  # converged (the usual case after one or two steps)
            n1 = unit(x - _foot(tree, p1, t1))
            n2 = unit(x - _foot(tree, p2, t2))
            det = n1[:, 0] * n2[:, 1] - n1[:, 1] * n2[:, 0]
            safe = np.abs(det) > 1e-6
            det = np.where(safe, det, 1.0)
            # Solve [n1; n2] step = -(f1, f2).
            step = np.stack([-(n2[:, 1] * f1 - n1[:, 1] * f2), n2[:, 0] * f1 - n1[:, 0] * f2], -1)
            x = np.where(safe[:, None], x + step / det[:, None], x)
        else:
            p1, d1, t1 = _track(tree, x, p1, p2)
            p2, d2, t2 = _track(tree, x, p2, p1)
        s1[act], s2[act] = p1, p2
        n1 = unit(x - _foot(tree, p1, t1))
        n2 = unit(x - _foot(tree, p2, t2))
        near = tree.query(x, radius - 0.5 * radius, radius + 0.5 * radius)
        nx = _feet(tree, near, x)[1]
        ok = near.exact & (np.abs(near.dist - radius) <= eps) & safe
        ok &= (np.abs(d1 - radius) <= eps) & (np.abs(d2 - radius) <= eps)
        point[act], n1_all[act], n2_all[act] = x, n1, n2
        found[act[ok]] = True
        # Swallowed by a third segment: it takes the place of the member on its side (a
        # member found again changes nothing).
        again = ~ok & near.exact & (near.dist < radius) & safe
        again &= (near.segment != p1) & (near.segment != p2)
        swap1 = np.einsum("ij,ij->i", nx, n1) > np.einsum("ij,ij->i", nx, n2)
        s1[act[again & swap1]] = near.segment[again & swap1]
        s2[act[again & ~swap1]] = near.segment[again & ~swap1]
        act = act[again]
    return found, point, n1_all, s1, n2_all, s2


_TRACK = 16  # neighbours on either side a corner's pair member may move to each step
_OFFSETS = np.concatenate([[0], np.arange(-_TRACK, 0), np.arange(1, _TRACK + 1)])


def _foot(tree: SegmentTree, seg: np.ndarray, t: np.ndarray) -> np.ndarray:
    a = tree.a[seg]
    return a + t[:, None] * (tree.b[seg] - a)


def _track(tree: SegmentTree, x: np.ndarray, seg: np.ndarray, other: np.ndarray):
    """The segment nearest ``x`` among ``seg``'s index neighbours, with its distance and
    nearest-point parameter.

    The neighbours are those up to `_TRACK` either side on the same smooth run of the input
    as ``seg`` (`_smooth_runs`: a member follows its own stretch of curve, never around a
    sharp vertex of the input, where another feature begins), none at or past ``other``.
    """
    run = _smooth_runs(tree)
    window = seg[:, None] + _OFFSETS  # seg itself first: it stays unless another is nearer
    window = np.minimum(np.maximum(window, 0), tree.n - 1)
    gap = other[:, None] - seg[:, None]
    # Keep strictly on seg's side of other (other itself, and beyond, belong to it).
    allowed = np.where(gap > 0, window < other[:, None], window > other[:, None])
    allowed &= run[window] == run[seg][:, None]
    window = np.where(allowed, window, seg[:, None])
    d, t = point_segment(x[:, None], tree.a[window], tree.b[window])
    best = np.argmin(d, axis=1)
    rows = np.arange(x.shape[0])
    return window[rows, best], d[rows, best], t[rows, best]


def _smooth_runs(tree: SegmentTree) -> np.ndarray:
    """Run id of each segment: consecutive segments share one while each starts where the
    previous one ends and turns from it by less than 30 degrees (computed once per tree)."""
    run = getattr(tree, "_smooth_run", None)
    if run is None:
        a, b = tree.a[: tree.n], tree.b[: tree.n]
        u = b - a
        # (Per coordinate: numpy reduces the short axis of an (n, 2) array slowly.)
        joined = (b[:-1, 0] == a[1:, 0]) & (b[:-1, 1] == a[1:, 1])
        length = np.sqrt(u[:, 0] * u[:, 0] + u[:, 1] * u[:, 1])
        cos = u[:-1, 0] * u[1:, 0] + u[:-1, 1] * u[1:, 1]
        smooth = joined & (cos > COS30 * length[:-1] * length[1:]) & (length[:-1] > 0)
        run = np.concatenate([[0], np.cumsum(~smooth)])
        tree._smooth_run = run
    return run


def _between(u: np.ndarray, c: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Whether points ``p`` project strictly inside the chords ``u -> u + c``."""
    along = np.einsum("ij,ij->i", p - u, c)
    return (along > 0) & (along < np.einsum("ij,ij->i", c, c))


def _fits(
    xy: np.ndarray, nxt: np.ndarray, prev: np.ndarray, i: np.ndarray, p: np.ndarray, gap
) -> np.ndarray:
    """Whether ``p`` can go between vertices ``i`` and ``j = nxt[i]`` without a local fold.

    The new chords ``i -> p -> j`` must not cross the chords just before and after, and
    ``p`` must not sit on either end. (``nxt``, ``prev``: the loops' links, computed once
    per round.)
    """
    if i.size == 0:
        return np.zeros(0, dtype=bool)
    j = nxt[i]
    before, u, w, after = xy[prev[i]], xy[i], xy[j], xy[nxt[j]]
    apart = (np.hypot(*(p - u).T) > gap) & (np.hypot(*(p - w).T) > gap)
    # Not back on the chords next to this one (a vertex found again from the other side).
    apart &= (point_segment(p, before, u)[0] > gap) & (point_segment(p, w, after)[0] > gap)
    return apart & ~segments_cross(before, u, p, w) & ~segments_cross(w, after, u, p)


class _Picks:
    """The new vertex chosen for each chord, filled stage by stage."""

    def __init__(self, m: int) -> None:
        self.point = np.zeros((m, 2))
        self.normal = np.zeros((m, 2))
        self.normal_in = np.zeros((m, 2))
        self.seg = np.zeros(m, dtype=np.int64)
        self.seg_in = np.zeros(m, dtype=np.int64)
        self.found = np.zeros(m, dtype=bool)

    def take(self, rows, ok, point, normal, seg, normal_in=None, seg_in=None) -> None:
        """Rows ``rows[ok]`` get their vertex (with other normals before it at a corner)."""
        normal_in = normal if normal_in is None else normal_in
        seg_in = seg if seg_in is None else seg_in
        rows = rows[ok]
        self.point[rows], self.found[rows] = point[ok], True
        self.normal[rows], self.normal_in[rows] = normal[ok], normal_in[ok]
        self.seg[rows], self.seg_in[rows] = seg[ok], seg_in[ok]


def _choose(pick: _Picks, steps, fits) -> None:
    """Give each chord the first candidate of ``steps`` that works.

    ``steps``: in order of preference, tuples ``(rows, ok, point, normal, seg, normal_in,
    seg_in, checked)``; a candidate works where ``ok`` and, if ``checked``, where
    ``fits(rows, point)`` says it makes no local fold (asked once for all candidates).
    """
    rows, ok, point, normal, seg, normal_in, seg_in = (
        np.concatenate([step[k] for step in steps]) for k in range(7)
    )
    checked = np.concatenate([np.full(step[0].size, step[7]) for step in steps])
    ask = np.flatnonzero(ok & checked)
    ok = ok.copy()
    ok[ask] = fits(rows[ask], point[ask])
    good = np.flatnonzero(ok)  # (in order of preference)
    by_row = good[np.argsort(rows[good], kind="stable")]
    first = np.ones(by_row.size, dtype=bool)
    np.not_equal(rows[by_row[1:]], rows[by_row[:-1]], out=first[1:])
    chosen = by_row[first]
    every = np.ones(chosen.size, dtype=bool)
    pick.take(
        rows[chosen],
        every,
        point[chosen],
        normal[chosen],
        seg[chosen],
        normal_in[chosen],
        seg_in[chosen],
    )


def refine_chords(
    tree: SegmentTree,
    loops: Loops,
    radius: float,
    tol: float,
    far_inside: bool,
    rounds: int = 12,
) -> Loops:
    """Insert exact points of the level set until every chord is within ``tol`` of it.

    The tangents at a chord's ends meet at ``k``; a stretch of one sign of curvature lies in
    the triangle they span with the chord, so the height of ``k`` bounds the error (with
    parallel normals, or ``k`` far out, how far the normals are from square to the chord
    does). A chord over ``tol`` gets one new vertex on the level, the first that works of:

    1. ``k`` itself, if it lies on the level: a corner where two features' offsets meet;
    2. where the normals turn sharply, the corner where the end segments' offsets meet
       (`_corner`);
    3. the chord point below ``k`` moved along the gradient (exact on a smooth stretch);
    4. the level crossing between that point and ``k`` (a bulge, a notch);
    5. the level crossing straight across the chord (a notch narrower than a cell);
    6. the projected point of step 3 even if it slid close to a chord end.

    New chords are checked the next round. The region bounded by the loops lies on their
    left; ``far_inside`` says it is where the distance exceeds ``radius`` (an inward offset).
    """
    eps = 1e-3 * tol
    for _ in range(rounds):
        todo = np.flatnonzero(loops.todo)
        if todo.size == 0:
            break
        links = loops.next
        back = np.empty_like(links)
        back[links] = np.arange(links.size)

        def fits(i, p, gap, links=links, back=back, xy=loops.xy):
            return _fits(xy, links, back, i, p, gap)

        nxt = links[todo]
        u, c = loops.xy[todo], loops.xy[nxt] - loops.xy[todo]
        nu, nw = loops.normal[todo], loops.normal_in[nxt]
        clen = np.maximum(np.hypot(c[:, 0], c[:, 1]), 1e-300)
        sin = nu[:, 0] * nw[:, 1] - nu[:, 1] * nw[:, 0]
        # u's tangent (-nu_y, nu_x) meets w's tangent line at u + s * tangent.
        s = np.divide(np.einsum("ij,ij->i", nw, c), sin, out=np.zeros_like(sin), where=sin != 0)
        k = u + s[:, None] * np.stack([-nu[:, 1], nu[:, 0]], axis=-1)
        ku = k - u
        height = np.abs(c[:, 0] * ku[:, 1] - c[:, 1] * ku[:, 0]) / clen
        along = np.einsum("ij,ij->i", c, ku) / clen**2
        skew = np.maximum(
            np.abs(np.einsum("ij,ij->i", nu, c)), np.abs(np.einsum("ij,ij->i", nw, c))
        )
        # Tangents meeting over the chord, or just past an end (as from a corner vertex).
        meet = (sin != 0) & (along > -0.25) & (along < 1.25)
        bad = np.where(meet, height > tol, skew > tol)
        # The bound needs one sign of curvature; a chord whose normals turn a lot may hide
        # a line, an arc and a notch (as at the mouth of a V): ask at a chord point.
        suspect = ~bad & (np.einsum("ij,ij->i", nu, nw) < COS30) & (clen > tol)
        reach_k = (sin != 0) & (np.hypot(*ku.T) < 0.9 * radius)
        reach_k &= np.hypot(*(k - u - c).T) < 0.9 * radius
        inside = reach_k & (along > 0) & (along < 1)
        # The chord point below k (kept off the chord's ends), moved onto the level along
        # the gradient: step 3 below. A suspect chord is asked at a quarter, half and three
        # quarters of its length (a notch may sit near an end), and its worst point serves.
        ask = np.flatnonzero(bad | suspect)
        at = np.where(inside, np.clip(along, 0.2, 0.8), 0.5)[ask]
        sus = np.flatnonzero(suspect[ask])
        m_at = np.concatenate([at, np.full(sus.size, 0.25), np.full(sus.size, 0.75)])
        rows = np.concatenate([ask, ask[sus], ask[sus]])
        m = u[rows] + m_at[:, None] * c[rows]
        p3, n3, s3, dist_m, ok3 = project(tree, m, radius, 0.9 * radius)
        stray = np.where(ok3, np.hypot(*(p3 - m).T), np.inf)
        # Per chord, the sample that strays most.
        worst = np.arange(ask.size)
        for extra in (1, 2):
            alt = ask.size + (extra - 1) * sus.size + np.arange(sus.size)
            better = stray[alt] > stray[worst[sus]]
            worst[sus[better]] = alt[better]
        m, p3, n3, s3, dist_m, ok3 = (x[worst] for x in (m, p3, n3, s3, dist_m, ok3))
        bad[ask] |= suspect[ask] & (stray[worst] > tol)
        loops.todo[todo] = False
        if not bad.any():
            break
        keep = bad[ask]
        m, p3, n3, s3, dist_m, ok3 = m[keep], p3[keep], n3[keep], s3[keep], dist_m[keep], ok3[keep]
        todo, nxt, u, c, k, along = todo[bad], nxt[bad], u[bad], c[bad], k[bad], along[bad]
        clen, nu, nw = clen[bad], nu[bad], nw[bad]
        reach_k, inside = reach_k[bad], inside[bad]
        # New vertices keep clear of the chord's ends.
        gap = np.maximum(eps, 1e-3 * clen)
        pick = _Picks(todo.size)
        found = pick.found

        def choose(candidates, todo=todo, gap=gap, pick=pick, fits=fits):
            _choose(pick, candidates, lambda r, p: fits(todo[r], p, gap[r]))

        # Each step's candidates are checked together (`_choose`: the first step that works
        # wins): steps 1 to 3, then 4 to 6 on the chords left.
        # 1. A corner: the tangent intersection on the level, and on the offsets of both
        # end segments (so both stretches run straight to it, or round one arc).
        rows = np.flatnonzero(reach_k)
        su, sw = loops.seg[todo[rows]], loops.seg_in[nxt[rows]]
        kr = k[rows]
        du, tu = point_segment(kr, tree.a[su], tree.b[su])
        dw, tw = point_segment(kr, tree.a[sw], tree.b[sw])
        ok = (np.abs(du - radius) <= eps) & (np.abs(dw - radius) <= eps)
        # (Only those need a query: that no other segment comes closer.)
        near = tree.query(kr[ok], radius - eps, radius + eps)
        ok[ok] = near.exact & (np.abs(near.dist - radius) <= eps)
        n_in = unit(kr - (tree.a[su] + tu[:, None] * (tree.b[su] - tree.a[su])))
        n_out = unit(kr - (tree.a[sw] + tw[:, None] * (tree.b[sw] - tree.a[sw])))
        steps = [(rows, ok, kr, n_out, sw, n_in, su, True)]
        # 2. Where the normals turn sharply, the corner where the end segments' offsets
        # meet (chasing a third segment that comes closer). (Solved for every such chord,
        # whatever step 1 gives: a few more rows cost the solve no more numpy calls.)
        rows = np.flatnonzero(
            (np.einsum("ij,ij->i", nu, nw) < COS30) & (loops.seg[todo] != loops.seg_in[nxt])
        )
        if rows.size:
            start = np.where(reach_k[rows, None], k[rows], u[rows] + c[rows] / 2)
            ends = loops.seg[todo[rows]], loops.seg_in[nxt[rows]]
            ok, p2, n_in, s_in, n_out, s_out = _corner(tree, *ends, start, radius, tol)
            ok &= np.hypot(*(p2 - u[rows]).T) < 0.9 * radius
            steps.append((rows, ok, p2, n_out, s_out, n_in, s_in, True))
        # 3. The chord point below k, moved along the gradient (projected above).
        at = np.einsum("ij,ij->i", p3 - u, c) / clen**2
        slid = ok3 & ~((at > 0.1) & (at < 0.9))
        rows = np.arange(todo.size)
        steps.append((rows, ok3 & ~slid, p3, n3, s3, n3, s3, False))
        choose(steps)
        # 4. Near a corner that point slides toward a chord end: look between it and k,
        # where the distance crosses the level.
        rest = np.flatnonzero(~found)
        r4 = rest[inside[rest]]
        # 5. Straight across the chord, toward the level: out of the region (on the
        # loop's left) if the chord point is in it, else into it. This also finds a spike
        # of the region narrower than a cell. (Both solved at once.)
        left = np.stack([-c[rest, 1], c[rest, 0]], axis=-1) / clen[rest, None]
        region = (dist_m[rest] > radius) == far_inside
        reach = 0.85 * radius - np.hypot(*(m - u)[rest].T)
        end = m[rest] + np.where(region, -1.0, 1.0)[:, None] * reach[:, None] * left
        both = np.concatenate([r4, rest])
        ok, p45, n45, s45 = _crossing(
            tree, m[both], np.concatenate([k[r4], end]), dist_m[both], radius, tol
        )
        # (That segment may meet the level again past the chord's ends, folding the loop.)
        ok &= _between(u[both], c[both], p45)
        ok[r4.size :] &= reach > 0
        four, five = slice(0, r4.size), slice(r4.size, None)
        steps = [
            (r4, ok[four], p45[four], n45[four], s45[four], n45[four], s45[four], True),
            (rest, ok[five], p45[five], n45[five], s45[five], n45[five], s45[five], True),
        ]
        # 6. A projection that slid toward an end is still a point of the level.
        rows = np.flatnonzero(slid & ~found)
        last = _between(u[rows], c[rows], p3[rows])
        steps.append((rows, last, p3[rows], n3[rows], s3[rows], n3[rows], s3[rows], True))
        choose(steps)
        loops = loops.insert(todo[found], pick, np.flatnonzero(found))
    return loops


def exact_loops(
    tree: SegmentTree,
    xy: np.ndarray,
    offsets: np.ndarray,
    radius: float,
    band: float,
    tol: float,
    far_inside: bool,
    upper: np.ndarray | None = None,
) -> Loops:
    """Traced loops made exact: vertices on the level ``radius``, chords within ``tol``.

    Parameters
    ----------
    tree : SegmentTree
    xy : (n, 2) float
        Traced vertices, loop after loop, each within ``band`` of the level.
    offsets : (n_loops + 1,) int
    radius : float
        The level (an unsigned distance), > 0.
    band : float
        How far the traced vertices may be from the level, < 0.9 radius.
    tol : float
        Largest distance allowed between a chord and the level set.
    far_inside : bool
        The region (on the loops' left) is where the distance exceeds ``radius``.
    upper : (n,) float, optional
        Known upper bounds of the traced vertices' distances (inf: none).

    Returns
    -------
    Loops
    """
    n = xy.shape[0]
    loop = np.repeat(np.arange(offsets.size - 1), np.diff(offsets))
    moved, normal, seg, _, ok = project(tree, xy, radius, band, upper)
    # Where the contour passes within a hair of a sample, marching squares puts two or
    # three vertices on top of each other; projection could then fold them.
    prev = np.arange(n) - 1
    nonempty = np.diff(offsets) > 0
    prev[offsets[:-1][nonempty]] = offsets[1:][nonempty] - 1
    ok &= np.hypot(*(xy - xy[prev]).T) > 1e-3 * band
    # Interpolation puts a vertex within a small fraction of a cell of the level; one that
    # moves far went to a feature across a part thinner than a cell, and would fold.
    ok &= np.hypot(*(moved - xy).T) < 0.2 * band
    loops = Loops(moved, normal, seg, loop, np.ones(n, dtype=bool))
    # A vertex whose projection another feature swallows sits next to a corner of the
    # offset: it goes, and the chord across the corner recovers the corner.
    loops = drop_folds(loops, xy, ok)
    loops = refine_chords(tree, loops, radius, tol, far_inside)
    # A piece of a thin spike's tip that the grid cut off lies under the recovered tip.
    return drop_covered(tidy(loops, 1e-3 * tol), band * band)


def smooth(tree: SegmentTree, loops: Loops, radius: float, passes: int) -> Loops:
    """Laplacian smoothing that keeps every vertex on the level set.

    Each pass moves each vertex halfway to the midpoint of its neighbours, then back onto
    the level along the gradient (`project`): vertices spread evenly along the offset
    without leaving it. Corners (a turn of more than 30 degrees) stay where they are.
    """
    for _ in range(passes):
        nxt = loops.next
        prev = np.empty_like(nxt)
        prev[nxt] = np.arange(nxt.size)
        xy = loops.xy
        turn = np.einsum("ij,ij->i", unit(xy - xy[prev]), unit(xy[nxt] - xy))
        move = np.flatnonzero(turn > COS30)
        target = (xy[move] + (xy[prev[move]] + xy[nxt[move]]) / 2) / 2
        moved, normal, seg, _, ok = project(tree, target, radius, 0.9 * radius)
        # Keep the order: the vertex must stay between its neighbours.
        ok &= _between(xy[prev[move]], xy[nxt[move]] - xy[prev[move]], moved)
        move = move[ok]
        loops = loops.select(np.ones(xy.shape[0], dtype=bool))  # a copy
        loops.xy[move], loops.normal[move], loops.seg[move] = moved[ok], normal[ok], seg[ok]
        loops.normal_in[move], loops.seg_in[move] = normal[ok], seg[ok]
    return loops
