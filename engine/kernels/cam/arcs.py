"""The exact offset of an arc-and-line chain: a rational quadratic NURBS in Bezier form (every
inner knot doubled, as ``nurbs.circle`` and ``curves.rectangle`` make them) whose pieces are
circular arcs or straight segments meeting tangentially.

The offset of a circular arc of centre c and radius R by d is the arc of the same centre
and radius R +- d: its control points scaled about c (the middle weight, the cosine of the
half angle, is unchanged: The NURBS Book section 7.5); a straight piece moves by d along
its normal. Where consecutive pieces meet tangentially the offset pieces meet too, so the
chain stays one curve with the same knots and weights. Where they meet at a corner, or an
arc would shrink to nothing, there is no such offset (a round join or a vanished arc) and
None says so: the caller keeps the polyline offset.
"""

from __future__ import annotations

import numpy as np

__all__ = ["offset_chain"]

_REL = 1e-9  # relative tolerance of the circle and tangency tests


def offset_chain(
    control_points: np.ndarray, knots: np.ndarray, weights: np.ndarray, distance: float
) -> np.ndarray | None:
    """The control points of the chain offset by ``distance`` to the right of its direction
    of travel (outward for a counter-clockwise outer loop or a clockwise hole), or None.

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
    cp = np.asarray(control_points, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    k = np.asarray(knots, dtype=np.float64)
    n = len(cp)
    if n < 3 or (n - 1) % 2 or len(k) != n + 3:
        return None
    inner = k[3:n].reshape(-1, 2)
    if not (np.all(inner[:, 0] == inner[:, 1]) and k[0] == k[2] and k[-1] == k[-3]):
        return None
    p0, p1, p2 = cp[0:-1:2, :2], cp[1::2, :2], cp[2::2, :2]
    w0, w1, w2 = w[0:-1:2], w[1::2], w[2::2]
    scale = float(np.abs(cp[:, :2]).max()) + 1e-300
    a, b = p1 - p0, p2 - p1
    turn = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    la, lb = np.hypot(*a.T), np.hypot(*b.T)
    chord = p2 - p0
    lc = np.hypot(*chord.T)
    straight = np.abs(turn) <= _REL * scale * scale
    wm = w1 / np.sqrt(w0 * w2)
    cos_half = 0.5 * lc / np.maximum(np.maximum(la, lb), 1e-300)
    arc = ~straight & (np.abs(la - lb) <= _REL * scale) & (np.abs(wm - cos_half) <= 1e-7)
    if not np.all(straight | arc) or np.any(lc <= 0):
        return None
    out = cp.copy()
    new = np.empty((len(p0), 3, 2))
    # straight pieces: every control point moves along the right-hand normal
    normal = np.c_[chord[:, 1], -chord[:, 0]] / lc[:, None]
    shift = distance * normal
    new[:] = np.stack([p0, p1, p2], axis=1) + shift[:, None, :]
    # arcs: the centre is on the line from the tangent point T through the chord's middle M,
    # |T c| = t^2 / h with t the tangent length and h = |T M|
    m = 0.5 * (p0 + p2)
    tm = m - p1
    h2 = np.einsum("ij,ij->i", tm, tm)
    with np.errstate(divide="ignore", invalid="ignore"):
        centre = p1 + tm * (la * la / h2)[:, None]
        radius = np.hypot(*(p0 - centre).T)
        # the centre is on the left at a left turn: the right-hand side is away from it
        grown = radius + np.where(turn > 0, distance, -distance)
        ratio = grown / radius
    if np.any(arc & ~(grown > 1e-9 * scale)):
        return None
    pts = np.stack([p0, p1, p2], axis=1)
    scaled = centre[:, None, :] + (pts - centre[:, None, :]) * ratio[:, None, None]
    new[arc] = scaled[arc]
    # tangent joints: each piece's end is the next piece's start
    ends, starts = new[:, 2], np.roll(new[:, 0], -1, axis=0)
    closed = bool(np.allclose(cp[0, :2], cp[-1, :2], rtol=0, atol=_REL * scale))
    gap = np.hypot(*(ends - starts).T)
    joints = gap if closed else gap[:-1]
    if np.any(joints > 1e-7 * (scale + abs(distance))):
        return None
    out[0:-1:2, :2] = new[:, 0]
    out[1::2, :2] = new[:, 1]
    out[2::2, :2] = new[:, 2]
    if closed:
        out[-1, :2] = out[0, :2]
    return out
