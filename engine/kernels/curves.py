"""Curve kernels: Bezier chains, Catmull-Rom splines, subdivision, resampling, bisector offset.

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
from collections.abc import Callable

import numpy as np

__all__ = [
    "CurveTuple",
    "SurfaceTuple",
    "SPACINGS",
    "ENDS",
    "bezier_chain",
    "catmull_rom",
    "catmull_rom_surface",
    "subdivide_polygon",
    "subdivided_count",
    "polyline_length",
    "resample_count",
    "resample_polyline",
    "arc_length_table",
    "parameters_at_lengths",
    "bisector_offset",
]

CurveTuple = tuple[np.ndarray, int, np.ndarray, "np.ndarray | None"]
SurfaceTuple = tuple[np.ndarray, int, int, np.ndarray, np.ndarray, "np.ndarray | None"]

#: knot-interval exponent alpha of each Catmull-Rom spacing: interval = |P[i+1] - P[i]| ** alpha
SPACINGS = {"uniform": 0.0, "centripetal": 0.5, "chordal": 1.0}
ENDS = ("processing", "clamped")


# --------------------------------------------------------------------------- helpers


def _as_points(points: object, name: str = "points") -> np.ndarray:
    """``points`` as an (n, 3) float64 array (a view when it already is one), checked
    finite; (n, 2) gets z = 0. Callers never write into it."""
    try:
        a = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an (n, 3) array of coordinates: {exc}") from None
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise ValueError(
            f"{name} must be an (n, 3) or (n, 2) array of coordinates, got shape {a.shape}"
        )
    if a.shape[1] == 2:
        a = np.concatenate([a, np.zeros((a.shape[0], 1))], axis=1)
    if not np.isfinite(a).all():
        i = int(np.argmin(np.isfinite(a).all(axis=1)))
        raise ValueError(f"{name} must be finite, but point {i} is {a[i].tolist()}")
    return a


def _norms(d: np.ndarray) -> np.ndarray:
    """Row lengths of ``d`` (m, D); rows whose squares would underflow or overflow are
    measured again after scaling, so a tiny non-zero step never reads as zero."""
    n = np.sqrt(np.einsum("ij,ij->i", d, d))
    if n.size and not (n.min() > 1e-150 and n.max() < 1e150):
        scale = np.abs(d).max(axis=1)
        q = d / np.where(scale > 0.0, scale, 1.0)[:, None]
        n = scale * np.sqrt(np.einsum("ij,ij->i", q, q))
    return n


def _span_vectors(p: np.ndarray, closed: bool) -> np.ndarray:
    """p[i+1] - p[i] for each span, the closing span p[0] - p[-1] last when closed."""
    d = np.diff(p, axis=0)
    return np.concatenate([d, p[:1] - p[-1:]]) if closed else d


def _keep_mask(p: np.ndarray, closed: bool) -> np.ndarray:
    """Mask of the points that differ from the one before them; when closed, trailing
    copies of the first point are dropped too."""
    keep = np.ones(len(p), dtype=bool)
    if len(p) < 2:
        return keep
    keep[1:] = _norms(np.diff(p, axis=0)) > 0.0
    if closed:
        idx = np.flatnonzero(keep)
        while len(idx) > 1 and not _norms(p[idx[:1]] - p[idx[-1:]])[0] > 0.0:
            keep[idx[-1]] = False
            idx = idx[:-1]
    return keep


def _spans(p: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drop each point equal to the one before it (and, when closed, trailing copies of the
    first point), so no span has zero length.

    Returns
    -------
    points : (N, D), spans : (S, D) span vectors, lengths : (S,) all > 0 (S = N - 1, or N
    when closed; S = 0 when a single point is left).
    """
    d = _span_vectors(p, closed)
    length = _norms(d)
    if len(p) < 2 or length.min() > 0.0:
        return p, d, length
    q = p[_keep_mask(p, closed)]
    if len(q) < 2:
        return q, d[:0], length[:0]
    d = _span_vectors(q, closed)
    return q, d, _norms(d)


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
    p = _as_points(points)
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
    q = _as_points(points)
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
        p, d, length = _spans(q, closed=True)
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
        p, d, length = _spans(q[1:-1], closed=False)
    else:
        p, d, length = _spans(q, closed=False)
    if len(p) < 2:
        raise ValueError(
            "a Catmull-Rom curve needs at least 2 distinct points to pass through, got 1"
        )
    h = intervals(length)
    if ends == "processing":
        d_first, d_last = p[0] - q[0], q[-1] - p[-1]
        h_first, h_last = intervals(_norms(np.stack([d_first, d_last])))
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
    d = _span_vectors(p, closed)
    ones = np.ones(len(p))
    if closed:
        return _hermite_bezier(p, np.roll(d, 1, axis=0), d, ones, ones, True, tension)
    d_prev = np.concatenate([d[:1], d])
    d_next = np.concatenate([d, d[-1:]])
    return _hermite_bezier(p, d_prev, d_next, ones, ones, False, tension)


# --------------------------------------------------------------------------- subdivision


def subdivided_count(n: int, closed: bool, iterations: int) -> int:
    """Number of points after ``iterations`` rounds of :func:`subdivide_polygon`.

    Each round adds one point per edge: open n -> 2 n - 1, so 2**k (n - 1) + 1; closed
    n -> 2 n, so 2**k n. Exact Python integers (no overflow), for the size guard.
    """
    if iterations < 0:
        raise ValueError(f"iterations must be >= 0, got {iterations}")
    return (n << iterations) if closed else ((n - 1) << iterations) + 1


def subdivide_polygon(points: np.ndarray, closed: bool = False, iterations: int = 1) -> np.ndarray:
    """Cubic B-spline subdivision of a polygon (Lane & Riesenfeld 1980; Chaikin's scheme's
    cubic sibling).

    Each round inserts the midpoint of every edge and moves every original vertex to
    1/8 prev + 6/8 itself + 1/8 next. A closed polygon wraps and converges to the uniform
    cubic B-spline with the polygon as control points (a vertex's limit is
    (prev + 4 itself + next) / 6). An open polygon keeps its two end points (the curve
    rule of Catmull-Clark boundaries); its limit is the uniform cubic B-spline of the
    polygon extended by the reflected points 2 P0 - P1 and 2 Pn - Pn-1.

    Parameters
    ----------
    points : (n, 3) float
        n >= 2 open, >= 3 closed. When closed, a last point equal to the first is dropped.
    closed : bool
    iterations : int
        Rounds, >= 0.

    Returns
    -------
    (m, 3) float64
        m = :func:`subdivided_count` (n, closed, iterations); closed output does not repeat
        its first point. Original vertex i sits at index i * 2**iterations.
    """
    p = _as_points(points)
    if closed:
        while len(p) > 1 and np.array_equal(p[0], p[-1]):
            p = p[:-1]
    need = 3 if closed else 2
    if len(p) < need:
        kind = "closed" if closed else "open"
        raise ValueError(
            f"subdividing an {kind} polygon needs at least {need} points, got {len(p)}"
        )
    if iterations < 0:
        raise ValueError(f"iterations must be >= 0, got {iterations}")
    for _ in range(iterations):
        n = len(p)
        if closed:
            nxt = np.concatenate([p[1:], p[:1]])
            mid = 0.5 * (p + nxt)  # mid[i] between p[i] and p[i+1]
            out = np.empty((2 * n, 3))
            out[1::2] = mid
            # 1/8 prev + 6/8 p + 1/8 next == (mid[i-1] + mid[i]) / 4 + p / 2
            out[2::2] = 0.25 * (mid[:-1] + mid[1:]) + 0.5 * p[1:]
            out[0] = 0.25 * (mid[-1] + mid[0]) + 0.5 * p[0]
        else:
            mid = 0.5 * (p[:-1] + p[1:])
            out = np.empty((2 * n - 1, 3))
            out[1::2] = mid
            out[2:-1:2] = 0.25 * (mid[:-1] + mid[1:]) + 0.5 * p[1:-1]
            out[0], out[-1] = p[0], p[-1]
        p = out
    return p.copy() if iterations == 0 else p


# --------------------------------------------------------------------------- resampling


def polyline_length(points: np.ndarray, closed: bool = False) -> float:
    """Total length of a polyline (including the closing edge when ``closed``)."""
    p = _as_points(points)
    return float(_norms(_span_vectors(p, closed)).sum()) if len(p) > 1 else 0.0


def resample_count(length: float, spacing: float, closed: bool = False) -> int:
    """Number of points :func:`resample_polyline` gives for ``spacing`` on a polyline of
    ``length``: the spacing is rounded to the nearest one that divides the length evenly
    (at least 1 segment open, 3 points closed). For the size guard, before allocating."""
    if not (math.isfinite(spacing) and spacing > 0.0):
        raise ValueError(f"spacing must be a positive number, got {spacing}")
    segments = length / spacing
    if not segments < 2.0**53:
        raise ValueError(
            f"spacing {spacing} on a curve of length {length:g} would give more than 2^53 points"
        )
    segments = int(round(segments))
    return max(3, segments) if closed else max(1, segments) + 1


def resample_polyline(
    points: np.ndarray,
    count: int | None = None,
    spacing: float | None = None,
    closed: bool = False,
) -> np.ndarray:
    """Points evenly spaced by arc length along a polyline.

    Parameters
    ----------
    points : (n, 3) float
        Polyline vertices in order. When closed, the closing edge is implied (a last point
        equal to the first is fine too).
    count : int, optional
        Number of points: open >= 2, both end points included; closed >= 3, the first at
        points[0] and not repeated at the end.
    spacing : float, optional
        Target distance along the curve; rounded to divide the length evenly (see
        :func:`resample_count`). Give exactly one of ``count`` and ``spacing``.
    closed : bool

    Returns
    -------
    (count, 3) float64
        Consecutive points are equally far apart measured along the polyline.

    Raises
    ------
    ValueError
        Neither or both of count and spacing, a count too small, or a polyline of zero
        length.
    """
    if (count is None) == (spacing is None):
        raise ValueError("resampling needs exactly one of count and spacing")
    p, d, seg = _spans(_as_points(points), closed)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = float(cum[-1])
    if not total > 0.0:
        raise ValueError("cannot resample a polyline of zero length (all its points coincide)")
    if count is None:
        count = resample_count(total, float(spacing), closed)
    need = 3 if closed else 2
    if count < need:
        kind = "closed" if closed else "open"
        raise ValueError(f"resampling an {kind} polyline needs count >= {need}, got {count}")
    if closed:
        s = np.arange(count) * (total / count)
    else:
        s = np.linspace(0.0, total, count)
    i = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
    f = ((s - cum[i]) / seg[i])[:, None]
    out = p[i] + f * d[i]
    if not closed:
        out[-1] = p[-1]
    return out


_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(8)


def arc_length_table(
    speed: Callable[[np.ndarray], np.ndarray], breaks: np.ndarray, pieces: int = 16
) -> tuple[np.ndarray, np.ndarray]:
    """Cumulative arc length of a curve at a fine partition of its domain.

    Each interval between consecutive ``breaks`` (knot spans, where the speed may have a
    kink) is cut into ``pieces`` equal pieces, and each piece's length, the integral of the
    speed |C'(t)|, is taken by 8-point Gauss-Legendre quadrature: exact for polynomial
    speeds up to degree 15 and accurate to ~1e-12 relative for smooth curves.

    Parameters
    ----------
    speed : callable, (m,) float -> (m,) float
        |C'(t)|, vectorized.
    breaks : (k,) float
        Increasing parameters, the domain's ends first and last.
    pieces : int
        Pieces per interval, >= 1.

    Returns
    -------
    edges : (k - 1) * pieces + 1 float
        The partition.
    cumulative : same shape
        Arc length from ``edges[0]`` to each edge; ``cumulative[-1]`` is the length.
    """
    b = np.unique(np.asarray(breaks, dtype=np.float64))
    f = np.linspace(0.0, 1.0, pieces + 1)[:-1]
    edges = np.append((b[:-1, None] + np.diff(b)[:, None] * f).ravel(), b[-1])
    lo, hi = edges[:-1], edges[1:]
    half = 0.5 * (hi - lo)
    tq = (lo + half)[:, None] + half[:, None] * _GAUSS_X
    length = half * (speed(tq.ravel()).reshape(tq.shape) @ _GAUSS_W)
    return edges, np.concatenate([[0.0], np.cumsum(length)])


def parameters_at_lengths(
    speed: Callable[[np.ndarray], np.ndarray],
    edges: np.ndarray,
    cumulative: np.ndarray,
    lengths: np.ndarray,
    iterations: int = 4,
) -> np.ndarray:
    """Parameters where the arc length from ``edges[0]`` equals each of ``lengths``.

    Inverse of :func:`arc_length_table`: the piece holding each length is found by binary
    search, the parameter is guessed linearly within it and refined by safeguarded Newton
    steps on s(t) - s = 0, s'(t) = |C'(t)| (each step integrates from the piece start by
    Gauss-Legendre; a step is kept inside its piece and skipped where the speed vanishes).

    Returns
    -------
    (m,) float
        Non-decreasing when ``lengths`` is.
    """
    s = np.asarray(lengths, dtype=np.float64)
    k = np.clip(np.searchsorted(cumulative, s, side="right") - 1, 0, len(edges) - 2)
    lo, hi = edges[k], edges[k + 1]
    piece = cumulative[k + 1] - cumulative[k]
    frac = np.divide(s - cumulative[k], piece, out=np.zeros_like(s), where=piece > 0.0)
    t = lo + (hi - lo) * np.clip(frac, 0.0, 1.0)
    for _ in range(iterations):
        half = 0.5 * (t - lo)
        tq = (lo + half)[:, None] + half[:, None] * _GAUSS_X
        s_t = cumulative[k] + half * (speed(tq.ravel()).reshape(tq.shape) @ _GAUSS_W)
        v = speed(t)
        step = np.divide(s_t - s, v, out=np.zeros_like(s), where=v > 1e-300)
        t = np.clip(t - step, lo, hi)
    return t


# --------------------------------------------------------------------------- offset


def bisector_offset(
    points: np.ndarray,
    closed: bool = False,
    distance: float = 0.0,
    miter_limit: float = 4.0,
    return_source: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Offset a polyline in the XY plane by moving each vertex along its corner bisector.

    Each vertex moves by ``distance / sin(a / 2)`` along the bisector of its corner angle a,
    i.e. to the intersection of its two edges' offset lines, so every edge of the result
    lies at exactly ``distance`` from its original edge (a mitre join). Collinear vertices
    (a = 180 degrees) move straight along the normal. Where the corner is convex on the
    offset side and the mitre would reach farther than ``miter_limit * |distance|`` from
    the vertex, it is clipped: two vertices on the two offset lines, on the line
    perpendicular to the bisector at that distance (the "clipped mitre" of GEOS/shapely,
    whose ``offset_curve(join_style="mitre")`` it matches). Concave corners keep the exact
    intersection point.

    Sides: on an open polyline a positive distance is to the left of the direction of
    travel (counter-clockwise normal of each edge), as shapely's ``offset_curve``; on a
    closed one a positive distance grows the curve whichever way it runs (the side follows
    the sign of the signed area).

    This is a local construction: where the offset distance exceeds the local feature size
    the result self-intersects (it has loops); ``offset.marching_squares`` is the tool that
    resolves those. z is carried over from each vertex; repeated points are dropped.

    Parameters
    ----------
    points : (n, 3) float
        Vertices; closed polylines do not repeat the first point (a repeat is dropped).
    closed : bool
    distance : float
    miter_limit : float
        Largest mitre length as a multiple of ``|distance|``; >= 1.
    return_source : bool
        Also return, for each output vertex, the index of the input vertex (after dropping
        repeats) it comes from.

    Returns
    -------
    offset : (m, 3) float64
        m = n plus one per clipped corner.
    source : (m,) int64, only when ``return_source``

    Raises
    ------
    ValueError
        Non-finite input, fewer than 2 (open) / 3 (closed) distinct points, a miter limit
        below 1, or a closed polyline with zero area (it has no outside).
    """
    p = _as_points(points)
    if not math.isfinite(distance):
        raise ValueError(f"distance must be a finite number, got {distance}")
    if not (math.isfinite(miter_limit) and miter_limit >= 1.0):
        raise ValueError(f"miter_limit must be a number >= 1, got {miter_limit}")
    p = p[_keep_mask(p[:, :2], closed)]
    n = len(p)
    need = 3 if closed else 2
    if n < need:
        kind = "closed" if closed else "open"
        raise ValueError(
            f"offsetting an {kind} polyline needs at least {need} distinct points (in XY), got {n}"
        )
    xy = p[:, :2]
    if closed:
        d_left = -distance * _orientation(xy)
        edge = np.concatenate([xy[1:], xy[:1]]) - xy  # edge[i]: i -> i+1
    else:
        d_left = distance
        edge = np.diff(xy, axis=0)
    e = edge / np.hypot(edge[:, 0], edge[:, 1])[:, None]
    if closed:
        e_in, e_out = np.roll(e, 1, axis=0), e
    else:
        e_in = np.concatenate([e[:1], e])
        e_out = np.concatenate([e, e[-1:]])
    n_in = np.stack([-e_in[:, 1], e_in[:, 0]], axis=1)
    n_out = np.stack([-e_out[:, 1], e_out[:, 0]], axis=1)
    c = np.clip(np.einsum("ij,ij->i", e_in, e_out), -1.0, 1.0)
    cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]
    src = np.arange(n)
    if d_left == 0.0:
        return (p.copy(), src) if return_source else p.copy()
    side = math.copysign(1.0, d_left)
    reversal = 1.0 + c <= 1e-12
    convex = (side * cross < 0.0) | reversal
    clip = convex & (1.0 + c < 2.0 / miter_limit**2)
    safe = np.where(reversal, 1.0, 1.0 + c)
    mitre = xy + d_left * (n_in + n_out) / safe[:, None]
    cos_h = np.sqrt(0.5 * (1.0 + c[clip]))
    sin_h = np.sqrt(0.5 * (1.0 - c[clip]))
    lam = (abs(d_left) * (miter_limit - cos_h) / sin_h)[:, None]
    first = xy[clip] + d_left * n_in[clip] + lam * e_in[clip]
    second = xy[clip] + d_left * n_out[clip] - lam * e_out[clip]
    counts = 1 + clip.astype(np.int64)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    out = np.empty((int(counts.sum()), 3))
    out[start, :2] = mitre
    out[start[clip], :2] = first
    out[start[clip] + 1, :2] = second
    source = np.repeat(src, counts)
    out[:, 2] = p[source, 2]
    return (out, source) if return_source else out


def _orientation(xy: np.ndarray) -> float:
    """+1 for a counter-clockwise closed polygon, -1 clockwise (shoelace signed area)."""
    centred = xy - xy.mean(axis=0)
    x, y = centred[:, 0], centred[:, 1]
    area2 = float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    extent = float(np.ptp(centred, axis=0).max())
    if not abs(area2) > 1e-12 * extent**2:
        raise ValueError(
            "a closed polyline with zero signed area has no outside to grow towards; offset "
            "it as an open polyline, or use offset.marching_squares"
        )
    return math.copysign(1.0, area2)
