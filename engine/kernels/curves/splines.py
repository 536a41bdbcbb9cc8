"""Spline kernels: Bezier chains, Catmull-Rom curves and bicubic Catmull-Rom surfaces.

Every function is a pure array function (numpy in, numpy out, inputs never modified).
Curves that are exactly a NURBS come back as the tuple ``(control_points, degree, knots,
weights)`` with ``weights`` ``None`` (non-rational): ``control_points`` (n, 3) float64,
``knots`` (n + degree + 1,) float64, clamped at both ends. A closed curve is a clamped curve
whose first and last control points coincide (and, for the splines here, whose derivative
matches across that seam). Surfaces come back as ``(control_points (mu, mv, 3), degree_u,
degree_v, knots_u, knots_v, weights)``.

Point arrays may be (n, 3) or (n, 2); (n, 2) gets z = 0.
"""

from __future__ import annotations

import math

import numpy as np

from ..nurbs.construct import CurveTuple, SurfaceTuple
from .polylines import (
    as_points,
    norms,
    span_vectors,
    spans,
)

__all__ = [
    "CurveTuple",
    "SurfaceTuple",
    "SPACINGS",
    "ENDS",
    "bezier_chain",
    "catmull_rom",
    "catmull_rom_surface",
]


#: knot-interval exponent alpha of each Catmull-Rom spacing: interval = |P[i+1] - P[i]| ** alpha
SPACINGS = {"uniform": 0.0, "centripetal": 0.5, "chordal": 1.0}
ENDS = ("processing", "clamped")


# --------------------------------------------------------------------------- Bezier pieces


def _bezier_knots(breaks: np.ndarray) -> np.ndarray:
    """Clamped cubic knot vector with every interior breakpoint of multiplicity 3, so each
    span is one Bezier piece (The NURBS Book, sec. 2.2 and 5.6)."""
    return np.concatenate(
        [np.full(4, breaks[0]), np.repeat(breaks[1:-1], 3), np.full(4, breaks[-1])]
    )


def _hermite_bezier(
    p: np.ndarray,
    d_prev: np.ndarray,
    d_next: np.ndarray,
    h_prev: np.ndarray,
    h_next: np.ndarray,
    closed: bool,
    tension: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Bezier control points of a Catmull-Rom spline through ``p`` (N, D).

    ``d_prev`` = P_i - P_{i-1} and ``d_next`` = P_{i+1} - P_i are the chords to the
    neighbours that shape the tangent at each point (phantoms at open ends), ``h_prev`` /
    ``h_next`` their knot intervals. The tangent (derivative with respect to the global
    parameter t) at P_i is the derivative of the Barry-Goldman pyramid, Yuksel, Schaefer &
    Keyser, "Parameterization and applications of Catmull-Rom curves", CAD 43(7), 2011::

        m_i = (P_i - P_{i-1}) / h_prev - (P_{i+1} - P_{i-1}) / (h_prev + h_next)
              + (P_{i+1} - P_i) / h_next
            = (h_next d_prev / h_prev + h_prev d_next / h_next) / (h_prev + h_next)

    scaled by (1 - tension); for unit intervals it is (1 - tension) (P_{i+1} - P_{i-1}) / 2,
    Processing's curveTightness. Segment P_i -> P_{i+1} of interval h is the cubic Hermite
    piece, in Bezier form (P_i, P_i + m_i h / 3, P_{i+1} - m_{i+1} h / 3, P_{i+1}); both
    pieces at a joint share its tangent, so the curve is C1 in t.

    Returns
    -------
    control_points : (3 S + 1, D) with S = N - 1 segments (N when closed)
    breaks : (S + 1,) cumulative parameter at the joints, from 0
    """
    total = h_prev + h_next
    m = d_prev * (h_next / (h_prev * total))[:, None]
    m += d_next * (h_prev / (h_next * total))[:, None]
    n = len(p)
    s = n if closed else n - 1
    h = h_next[:s]
    k = (((1.0 - tension) / 3.0) * h)[:, None]
    cps = np.empty((3 * s + 1, p.shape[1]))
    cps[0:-1:3] = p[:s]
    cps[1::3] = p[:s] + m[:s] * k
    if closed:
        cps[2:-2:3] = p[1:] - m[1:] * k[:-1]
        cps[-2] = p[0] - m[0] * k[-1]
    else:
        cps[2::3] = p[1:] - m[1:] * k
    cps[-1] = p[0] if closed else p[-1]
    breaks = np.empty(s + 1)
    breaks[0] = 0.0
    np.cumsum(h, out=breaks[1:])
    return cps, breaks


# --------------------------------------------------------------------------- Bezier


def bezier_chain(points: np.ndarray) -> CurveTuple:
    """A chain of cubic Bezier segments in Processing's bezierVertex layout, as an exact NURBS.

    Parameters
    ----------
    points : (3 k + 1, 3) float
        The start point, then (control, control, end) for each of the k segments.

    Returns
    -------
    control_points : (3 k + 1, 3) float64
        The points themselves.
    degree : int
        3.
    knots : (3 k + 5,) float64
        ``[0, 0, 0, 0, 1, 1, 1, ..., k, k, k, k]``: interior knots of multiplicity 3, so
        each unit span is one Bezier segment (The NURBS Book, sec. 5.6, a Bezier
        decomposition read backwards).
    weights : None

    Raises
    ------
    ValueError
        When the count is not 3 k + 1 with k >= 1.

    Example
    -------
    >>> cps, p, knots, w = bezier_chain([[0, 0], [1, 1], [2, 1], [3, 0]])
    >>> knots.tolist()
    [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]
    """
    p = as_points(points)
    n = len(p)
    if n < 4 or (n - 1) % 3:
        raise ValueError(
            "a Bezier chain needs 3k+1 points (the start point, then control, control, end "
            f"per segment: 4, 7, 10, ...), got {n}"
        )
    k = (n - 1) // 3
    return p.copy(), 3, _bezier_knots(np.arange(k + 1, dtype=np.float64)), None


# --------------------------------------------------------------------------- Catmull-Rom


def catmull_rom(
    points: np.ndarray,
    closed: bool = False,
    tension: float = 0.0,
    spacing: str = "uniform",
    ends: str = "processing",
) -> CurveTuple:
    """A Catmull-Rom spline through points, converted exactly to a cubic NURBS.

    Each segment is a cubic Hermite piece written as a Bezier piece (interior knots of
    multiplicity 3), with knot intervals ``|P[i+1] - P[i]| ** alpha``: alpha 0 (uniform),
    1/2 (centripetal) or 1 (chordal), the non-uniform Catmull-Rom of Barry & Goldman,
    "A recursive evaluation algorithm for a class of Catmull-Rom splines", SIGGRAPH 1988,
    with tangents as in Yuksel, Schaefer & Keyser, CAD 43(7), 2011. With tension 0 the
    centripetal form never has a cusp or a self-intersection within a segment (Yuksel et
    al., sec. 4). The knots are the true parameter values at the points, so the result is
    C1 in its parameter at every joint (and across the seam of a closed curve).

    Consecutive repeated points are dropped (a zero-length span has no direction).

    Parameters
    ----------
    points : (n, 3) float
    closed : bool
        Join the last point back to the first; the curve is C1 across the seam. A last
        point equal to the first is dropped. ``ends`` is ignored.
    tension : float
        Processing's curveTightness: tangents are scaled by (1 - tension), so 0 is the
        Catmull-Rom spline and 1 is the polyline.
    spacing : {"uniform", "centripetal", "chordal"}
    ends : {"processing", "clamped"}
        Open curves only. ``processing`` is Processing's curveVertex: the curve runs from
        the second point to the second-to-last; the first and last only shape the end
        tangents. ``clamped`` passes through every point; the end tangents come from
        phantom points reflected through the end points (2 P0 - P1), which makes each end
        tangent point along the first (last) chord.

    Returns
    -------
    control_points : (3 S + 1, 3) float64
        S segments; the points passed through are every third control point.
    degree : int
        3.
    knots : (3 S + 5,) float64
        The breakpoints 0 = t_0 < t_1 < ... < t_S, the interior ones three times, the ends
        four times. Uniform spacing gives t_i = i.
    weights : None

    Raises
    ------
    ValueError
        Non-finite points, an unknown option, or too few distinct points: 2 through points
        open (4 points in all for ``ends="processing"``), 3 closed.

    Example
    -------
    >>> cps, p, knots, w = catmull_rom([[0, 0], [1, 0], [2, 1], [3, 1]])
    >>> cps[3:7:3].tolist()
    [[1.0, 0.0, 0.0], [2.0, 1.0, 0.0]]
    """
    q = as_points(points)
    if spacing not in SPACINGS:
        raise ValueError(f"spacing must be one of {list(SPACINGS)}, got {spacing!r}")
    if ends not in ENDS:
        raise ValueError(f"ends must be one of {list(ENDS)}, got {ends!r}")
    if not math.isfinite(tension):
        raise ValueError(f"tension must be a finite number, got {tension}")
    alpha = SPACINGS[spacing]

    def intervals(lengths: np.ndarray) -> np.ndarray:
        if alpha == 0.0:
            h = np.ones_like(lengths)
        else:
            h = np.sqrt(lengths) if alpha == 0.5 else lengths.copy()
        if not np.isfinite(h).all():
            raise ValueError("the points are too far apart to parametrize (near 1e308)")
        return h

    if closed:
        p, d, length = spans(q, closed=True)
        if len(p) < 3:
            raise ValueError(
                f"a closed Catmull-Rom curve needs at least 3 distinct points, got {len(p)}"
                + (f" ({len(q)} before dropping repeats)" if len(q) != len(p) else "")
            )
        h = intervals(length)
        cps, breaks = _hermite_bezier(p, np.roll(d, 1, axis=0), d, np.roll(h, 1), h, True, tension)
        return cps, 3, _bezier_knots(breaks), None

    if ends == "processing":
        if len(q) < 4:
            raise ValueError(
                "a Catmull-Rom curve with ends='processing' needs at least 4 points (the first "
                f"and last only shape the end tangents), got {len(q)}"
            )
        p, d, length = spans(q[1:-1], closed=False)
    else:
        p, d, length = spans(q, closed=False)
    if len(p) < 2:
        raise ValueError(
            "a Catmull-Rom curve needs at least 2 distinct points to pass through, got 1"
        )
    h = intervals(length)
    if ends == "processing":
        d_first, d_last = p[0] - q[0], q[-1] - p[-1]
        h_first, h_last = intervals(norms(np.stack([d_first, d_last])))
        # A phantom point on top of its neighbour takes its neighbour's interval: for
        # uniform spacing nothing changes, otherwise this reproduces Processing's tangent
        # (P[i+1] - P[i-1]) / 2 scaled to the span instead of dividing by zero.
        h_first = h_first if h_first > 0.0 else h[0]
        h_last = h_last if h_last > 0.0 else h[-1]
    else:  # phantoms reflected through the end points: 2 P0 - P1 and 2 Pn - Pn-1
        d_first, d_last = d[0], d[-1]
        h_first, h_last = h[0], h[-1]
    cps, breaks = _hermite_bezier(
        p,
        np.concatenate([d_first[None], d]),
        np.concatenate([d, d_last[None]]),
        np.concatenate([[h_first], h]),
        np.concatenate([h, [h_last]]),
        False,
        tension,
    )
    return cps, 3, _bezier_knots(breaks), None


def catmull_rom_surface(
    grid: np.ndarray, closed_u: bool = False, closed_v: bool = False, tension: float = 0.0
) -> SurfaceTuple:
    """A bicubic surface through every point of a grid: uniform Catmull-Rom in u and in v.

    The uniform conversion (points -> Bezier control points) is linear in the points, so the
    tensor product of the two one-dimensional conversions is exact: applied along u and then
    along v, the surface at the knot pair (u_i, v_j) is grid[i, j]. Open directions use the
    clamped ends of :func:`catmull_rom` (reflected phantom points); repeated points are kept
    (the grid must stay rectangular; uniform spacing never divides by a length).

    Parameters
    ----------
    grid : (nu, nv, 3) float
        Rows of points; nu, nv >= 2 (>= 3 in a closed direction). (nu, nv, 2) gets z = 0.
    closed_u, closed_v : bool
        Wrap rows (columns) back to the first; the surface is C1 across the seam.
    tension : float
        As in :func:`catmull_rom`.

    Returns
    -------
    control_points : (mu, mv, 3) float64
        mu = 3 (nu - 1) + 1 open, 3 nu + 1 closed (likewise mv); grid[i, j] is
        control_points[3 i, 3 j].
    degree_u, degree_v : int
        3, 3.
    knots_u : (mu + 4,) float64
        Breakpoints 0, 1, ..., each interior one three times.
    knots_v : (mv + 4,) float64
    weights : None
    """
    try:
        g = np.array(grid, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"points must be rows of equally many points: {exc}") from None
    if g.ndim != 3 or g.shape[2] not in (2, 3):
        raise ValueError(f"points must be an (nu, nv, 3) grid of points, got shape {g.shape}")
    if g.shape[2] == 2:
        g = np.concatenate([g, np.zeros(g.shape[:2] + (1,))], axis=2)
    if not np.isfinite(g).all():
        i, j = np.argwhere(~np.isfinite(g).all(axis=2))[0]
        raise ValueError(f"points must be finite, but row {i}, point {j} is {g[i, j].tolist()}")
    if not math.isfinite(tension):
        raise ValueError(f"tension must be a finite number, got {tension}")
    nu, nv = g.shape[:2]
    for n, closed, axis in ((nu, closed_u, "u"), (nv, closed_v, "v")):
        need = 3 if closed else 2
        if n < need:
            kind = "closed" if closed else "open"
            raise ValueError(
                f"a bicubic surface needs at least {need} points in {kind} direction {axis}, "
                f"got {nu} x {nv}"
            )
    cu, bu = _uniform_along_first(g.reshape(nu, nv * 3), closed_u, tension)
    mu = len(cu)
    cuv = cu.reshape(mu, nv, 3).transpose(1, 0, 2).reshape(nv, mu * 3)
    cv, bv = _uniform_along_first(cuv, closed_v, tension)
    cps = cv.reshape(len(cv), mu, 3).transpose(1, 0, 2)
    return np.ascontiguousarray(cps), 3, 3, _bezier_knots(bu), _bezier_knots(bv), None


def _uniform_along_first(
    p: np.ndarray, closed: bool, tension: float
) -> tuple[np.ndarray, np.ndarray]:
    """Uniform Catmull-Rom Bezier points of (n, D) rows along axis 0 (clamped ends)."""
    d = span_vectors(p, closed)
    ones = np.ones(len(p))
    if closed:
        return _hermite_bezier(p, np.roll(d, 1, axis=0), d, ones, ones, True, tension)
    d_prev = np.concatenate([d[:1], d])
    d_next = np.concatenate([d, d[-1:]])
    return _hermite_bezier(p, d_prev, d_next, ones, ones, False, tension)
