"""The exact offset of an arc-and-line chain: a rational quadratic NURBS in Bezier form (every
inner knot doubled, as ``nurbs.circle`` and ``curves.rectangle`` make them) whose pieces are
circular arcs or straight segments.

The offset of a circular arc of centre c and radius R by d is the arc of the same centre
and radius R +- d: its control points scaled about c (the middle weight, the cosine of the
half angle, is unchanged: The NURBS Book section 7.5); a straight piece moves by d along
its normal. Where consecutive pieces meet tangentially the offset pieces meet too
(:func:`offset_chain`: the chain stays one curve with the same knots and weights).

Where a closed loop has corners (a polygon, a rectangle without rounding, a chain of arcs
meeting at an angle), :func:`offset_loop` builds the raw offset with round joins (Tiller
and Hanson, "Offsets of two-dimensional profiles", IEEE CG&A 1984; the round join is the
Minkowski sum's boundary, as GEOS's buffer draws it with chords): at a corner the offset
pieces leave a gap (a convex corner on the side of the offset) it is closed by an arc of
radius |d| centred on the corner, tangent to both; where they overlap each is cut at their
intersection (line with line, line with circle, circle with circle, in closed form). A loop
whose trims run past a piece's other end has no such simple offset and gets None: the
caller compares what it gets with the offset kernel's loop and keeps the polyline
otherwise.
"""

from __future__ import annotations

import numpy as np

__all__ = ["offset_chain", "offset_loop", "polygon_chain"]

_REL = 1e-9  # relative tolerance of the circle and tangency tests
_HAIRPIN = 1e-6  # a corner turning within this (radians) of a full reversal has no join


def _pieces(control_points, knots, weights):
    """The Bezier pieces of a rational quadratic in Bezier form, classified: (p (k, 3, 2),
    straight (k,), centre (k, 2), radius (k,), turn (k,), scale) or None where a piece is
    neither an arc nor straight."""
    cp = np.asarray(control_points, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    k = np.asarray(knots, dtype=np.float64)
    n = len(cp)
    if n < 3 or (n - 1) % 2 or len(k) != n + 3 or len(w) != n:
        return None
    inner = k[3:n].reshape(-1, 2)
    if not (np.all(inner[:, 0] == inner[:, 1]) and k[0] == k[2] and k[-1] == k[-3]):
        return None
    p = np.stack([cp[0:-1:2, :2], cp[1::2, :2], cp[2::2, :2]], axis=1)
    p0, p1, p2 = p[:, 0], p[:, 1], p[:, 2]
    wm = w[1::2] / np.sqrt(w[0:-1:2] * w[2::2])
    scale = float(np.abs(cp[:, :2]).max()) + 1e-300
    a, b = p1 - p0, p2 - p1
    turn = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    la, lb = np.hypot(*a.T), np.hypot(*b.T)
    lc = np.hypot(*(p2 - p0).T)
    straight = np.abs(turn) <= _REL * scale * scale
    cos_half = 0.5 * lc / np.maximum(np.maximum(la, lb), 1e-300)
    arc = ~straight & (np.abs(la - lb) <= _REL * scale) & (np.abs(wm - cos_half) <= 1e-7)
    if not np.all(straight | arc) or np.any(lc <= 0):
        return None
    # arcs: the centre is on the line from the tangent point T through the chord's middle M,
    # |T c| = t^2 / h with t the tangent length and h = |T M|
    tm = 0.5 * (p0 + p2) - p1
    h2 = np.einsum("ij,ij->i", tm, tm)
    with np.errstate(divide="ignore", invalid="ignore"):
        centre = np.where(arc[:, None], p1 + tm * (la * la / h2)[:, None], np.nan)
    radius = np.hypot(*(p0 - centre).T)
    return p, straight, centre, radius, turn, scale


def _moved(p, straight, centre, radius, turn, scale, distance):
    """Every piece offset by ``distance`` to the right of travel: (k, 3, 2), and the new
    radii; None where an arc shrinks to nothing."""
    p0, p2 = p[:, 0], p[:, 2]
    chord = p2 - p0
    lc = np.hypot(*chord.T)
    normal = np.c_[chord[:, 1], -chord[:, 0]] / lc[:, None]
    new = p + (distance * normal)[:, None, :]
    # the centre is on the left at a left turn: the right-hand side is away from it
    with np.errstate(invalid="ignore"):
        grown = radius + np.where(turn > 0, distance, -distance)
    arc = ~straight
    if np.any(arc & ~(grown > 1e-9 * scale)):
        return None
    ratio = grown / np.where(arc, radius, 1.0)
    scaled = centre[:, None, :] + (p - centre[:, None, :]) * ratio[:, None, None]
    new[arc] = scaled[arc]
    return new, grown


def offset_chain(
    control_points: np.ndarray, knots: np.ndarray, weights: np.ndarray, distance: float
) -> np.ndarray | None:
    """The control points of a chain whose pieces meet tangentially, offset by ``distance``
    to the right of its direction of travel (outward for a counter-clockwise outer loop or
    a clockwise hole), or None.

    Parameters
    ----------
    control_points : (2k + 1, 3) float
        A rational quadratic in Bezier form, k pieces; z is kept.
    knots : (2k + 4,) float
    weights : (2k + 1,) float
    distance : float

    Returns
    -------
    (2k + 1, 3) float or None
        The offset's control points (same knots and weights), or None where the chain has
        a piece that is neither an arc nor straight, a corner, or an arc the offset
        shrinks to nothing.
    """
    got = _pieces(control_points, knots, weights)
    if got is None:
        return None
    p, straight, centre, radius, turn, scale = got
    moved = _moved(p, straight, centre, radius, turn, scale, distance)
    if moved is None:
        return None
    new = moved[0]
    cp = np.asarray(control_points, dtype=np.float64)
    # tangent joints: each piece's end is the next piece's start
    ends, starts = new[:, 2], np.roll(new[:, 0], -1, axis=0)
    closed = bool(np.allclose(cp[0, :2], cp[-1, :2], rtol=0, atol=_REL * scale))
    gap = np.hypot(*(ends - starts).T)
    joints = gap if closed else gap[:-1]
    if np.any(joints > 1e-7 * (scale + abs(distance))):
        return None
    out = cp.copy()
    out[0:-1:2, :2] = new[:, 0]
    out[1::2, :2] = new[:, 1]
    out[2::2, :2] = new[:, 2]
    if closed:
        out[-1, :2] = out[0, :2]
    return out


def polygon_chain(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed polygon as a rational quadratic chain of straight pieces (the middle control
    point halfway, weight 1): (control points (2k + 1, 3), knots (2k + 4,), weights).

    Parameters
    ----------
    points : (k, 2 or 3) float
        The corners, the closing one not repeated; repeated points are dropped.
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.shape[1] == 2:
        pts = np.c_[pts, np.zeros(len(pts))]
    keep = np.any(pts != np.roll(pts, 1, axis=0), axis=1)
    pts = pts[keep] if keep.any() else pts[:1]
    closed = np.r_[pts, pts[:1]]
    cp = np.empty((2 * len(pts) + 1, 3))
    cp[0::2] = closed
    cp[1::2] = 0.5 * (closed[:-1] + closed[1:])
    return cp, _bezier_knots(len(pts)), np.ones(len(cp))


def _bezier_knots(k: int) -> np.ndarray:
    inner = np.repeat(np.arange(1, k, dtype=np.float64), 2)
    return np.r_[[0.0] * 3, inner, [float(k)] * 3]


def offset_loop(
    control_points: np.ndarray, knots: np.ndarray, weights: np.ndarray, distance: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The raw offset of a closed chain of arcs and straight pieces that may meet at corners,
    by ``distance`` to the right of travel, with round joins: (control points, knots,
    weights) of a rational quadratic in Bezier form (end weights 1), or None.

    Parameters
    ----------
    control_points : (2k + 1, 3) float
        A closed rational quadratic in Bezier form, k pieces (z of the first point kept).
    knots : (2k + 4,) float
    weights : (2k + 1,) float
    distance : float

    Returns
    -------
    tuple or None
        The offset: each piece moved, a join arc of radius |distance| about every corner
        where the moved pieces part, the moved pieces cut at their intersection where they
        cross. None where a piece is neither an arc nor straight, the loop is open, an arc
        shrinks to nothing, a corner turns back on itself, or a cut runs past a piece's
        other end (the raw offset is not simple there).
    """
    got = _pieces(control_points, knots, weights)
    if got is None or distance == 0:
        return None
    p, straight, centre, radius, turn, scale = got
    cp = np.asarray(control_points, dtype=np.float64)
    if not np.allclose(cp[0, :2], cp[-1, :2], rtol=0, atol=_REL * scale):
        return None
    moved = _moved(p, straight, centre, radius, turn, scale, distance)
    if moved is None:
        return None
    new, grown = moved
    nxt = np.roll(np.arange(len(p)), -1)
    # the joint between piece j and piece j + 1: the tangents there
    u = p[:, 2] - p[:, 1]
    v = p[nxt, 1] - p[nxt, 0]
    u /= np.hypot(*u.T)[:, None]
    v /= np.hypot(*v.T)[:, None]
    cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    dot = np.einsum("ij,ij->i", u, v)
    if np.any(np.abs(p[:, 2] - p[nxt, 0]) > _REL * scale) or np.any(dot < -np.cos(_HAIRPIN)):
        return None
    tangent = (np.abs(cross) <= 1e-9) & (dot > 0)
    opens = ~tangent & (cross * distance > 0)  # the moved pieces part: a round join
    crosses = ~tangent & ~opens  # they overlap: cut both at their intersection
    start, end = new[:, 0].copy(), new[:, 2].copy()
    if crosses.any():
        j = np.flatnonzero(crosses)
        x = _meet(new, straight, centre, grown, j, nxt[j], p[j, 2])
        if x is None:
            return None
        end[j] = x
        start[nxt[j]] = x
    pieces = _rebuilt(start, end, straight, centre, grown, turn)
    if pieces is None:
        return None
    seg, wm = pieces
    # the pieces still run the way they ran: no cut went past a piece's other end
    before = p[:, 2] - p[:, 0]
    after = end - start
    same = np.einsum("ij,ij->i", before, after) > 0
    if not np.all(same):
        return None
    # join arcs about each corner where the pieces part, after piece j
    j = np.flatnonzero(opens)
    join, jw = _arcs(new[j, 2], new[nxt[j], 0], p[j, 2], abs(distance))
    if join is None:
        return None
    order = np.r_[np.arange(len(p)), j + 0.5].argsort(kind="stable")
    allseg = np.concatenate([seg, join])[order]
    allw = np.r_[wm, jw][order]
    k = len(allseg)
    out = np.empty((2 * k + 1, 3))
    out[:, 2] = cp[0, 2]
    out[0:-1:2, :2] = allseg[:, 0]
    out[1::2, :2] = allseg[:, 1]
    out[-1, :2] = allseg[0, 0]
    w = np.ones(2 * k + 1)
    w[1::2] = allw
    return out, _bezier_knots(k), w


def _arcs(a, b, c, r):
    """Arcs of centre c and radius r from a to b, each under half a turn: (pieces (m, 3, 2),
    middle weights (m,)), None where one is degenerate. The middle control point is the
    pole of the chord: c + (m - c) r^2 / |m - c|^2, the weight |m - c| / r = cos(half)."""
    mid = 0.5 * (a + b)
    cm = mid - c
    h2 = np.einsum("ij,ij->i", cm, cm)
    r = np.broadcast_to(np.asarray(r, dtype=np.float64), h2.shape)
    if np.any(h2 <= (1e-12 * r) ** 2):
        return None, None
    pole = c + cm * (r * r / h2)[:, None]
    return np.stack([a, pole, b], axis=1), np.sqrt(h2) / r


def _rebuilt(start, end, straight, centre, radius, turn):
    """Every piece from its (possibly cut) ends: a straight piece with its middle point
    halfway, an arc rebuilt about its centre, turning as it turned and under half a turn."""
    seg = np.stack([start, 0.5 * (start + end), end], axis=1)
    wm = np.ones(len(start))
    arc = ~straight
    if arc.any():
        c = centre[arc]
        a, b = start[arc] - c, end[arc] - c
        sweep = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        if np.any(sweep * turn[arc] <= 0):
            return None
        pieces, w = _arcs(start[arc], end[arc], c, radius[arc])
        if pieces is None:
            return None
        seg[arc], wm[arc] = pieces, w
    return seg, wm


def _meet(new, straight, centre, radius, i, j, corner):
    """Where moved piece i meets moved piece j (line or circle each), the crossing nearest
    the corner they came from; None where they do not meet."""
    # each carrier as a circle (centre, radius) or a line (a point, a unit direction)
    li, lj = straight[i], straight[j]
    pi, pj = new[i, 0], new[j, 0]
    di = new[i, 2] - new[i, 0]
    dj = new[j, 2] - new[j, 0]
    di = di / np.hypot(*di.T)[:, None]
    dj = dj / np.hypot(*dj.T)[:, None]
    out = np.full((len(i), 2), np.nan)
    both = li & lj
    if both.any():  # line with line: p_i + s d_i = p_j + t d_j
        den = di[both, 0] * dj[both, 1] - di[both, 1] * dj[both, 0]
        q = pj[both] - pi[both]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (q[:, 0] * dj[both, 1] - q[:, 1] * dj[both, 0]) / den
        out[both] = pi[both] + s[:, None] * di[both]
    one = li ^ lj
    if one.any():  # line with circle
        lp = np.where(li[one, None], pi[one], pj[one])
        ld = np.where(li[one, None], di[one], dj[one])
        c = np.where(li[one, None], centre[j[one]], centre[i[one]])
        r = np.where(li[one], radius[j[one]], radius[i[one]])
        f = lp - c
        bq = np.einsum("ij,ij->i", f, ld)
        disc = bq * bq - (np.einsum("ij,ij->i", f, f) - r * r)
        root = np.sqrt(np.maximum(disc, 0))
        cand = np.stack([lp + (-bq - root)[:, None] * ld, lp + (-bq + root)[:, None] * ld], 1)
        out[one] = np.where(
            disc[:, None] >= -1e-12 * r[:, None] ** 2, _nearest(cand, corner[one]), np.nan
        )
    none = ~li & ~lj
    if none.any():  # circle with circle
        c0, c1 = centre[i[none]], centre[j[none]]
        r0, r1 = radius[i[none]], radius[j[none]]
        dc = c1 - c0
        dd = np.hypot(*dc.T)
        with np.errstate(divide="ignore", invalid="ignore"):
            a = (dd * dd + r0 * r0 - r1 * r1) / (2 * dd)
            h = np.sqrt(np.maximum(r0 * r0 - a * a, 0))
            e = dc / dd[:, None]
        base = c0 + a[:, None] * e
        perp = np.c_[-e[:, 1], e[:, 0]]
        cand = np.stack([base + h[:, None] * perp, base - h[:, None] * perp], 1)
        ok = (dd > 0) & (r0 * r0 - a * a >= -1e-12 * r0 * r0)
        out[none] = np.where(ok[:, None], _nearest(cand, corner[none]), np.nan)
    if not np.isfinite(out).all():
        return None
    return out


def _nearest(cand, point):
    """Of two candidates (m, 2, 2) the one nearest each point (m, 2)."""
    d = np.linalg.norm(cand - point[:, None, :], axis=2)
    return cand[np.arange(len(cand)), d.argmin(axis=1)]
