"""NURBS curves: evaluation, derivatives, knot vectors, periodic curves, circles and arcs.

Evaluation is vectorized over all parameters (The NURBS Book A2.1/A2.2 for the basis,
A3.1/A4.1 for points, A3.2/A4.2 for derivatives); rational curves are evaluated in
homogeneous coordinates and projected.
"""

from __future__ import annotations

import math

import numpy as np

from .basis import (
    CHUNK,
    _basis_from_table,
    _span_table,
    basis_function_derivatives,
    basis_workspace,
    domain_spans,
    find_spans,
)

__all__ = [
    "arc",
    "circle",
    "clamped_uniform_knots",
    "curve_derivatives",
    "curve_evaluate",
    "evaluate_homogeneous",
    "homogeneous",
    "periodic_curve",
    "plane_frame",
    "project",
]


def homogeneous(control_points: np.ndarray, weights: np.ndarray | None) -> np.ndarray:
    """Weighted control points ``(w x, w y, w z, w)``; the points themselves if non-rational.

    Parameters
    ----------
    control_points : (..., 3) float
    weights : (...) float or None

    Returns
    -------
    (..., 4) float, or (..., 3) when ``weights`` is None.
    """
    cp = np.asarray(control_points, dtype=np.float64)
    if weights is None:
        return cp
    w = np.asarray(weights, dtype=np.float64)[..., None]
    return np.concatenate([cp * w, w], axis=-1)


def project(pw: np.ndarray, rational: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """Split homogeneous points into ``(points, weights)``; identity when non-rational."""
    if not rational:
        return pw, None
    w = pw[..., 3]
    return pw[..., :3] / w[..., None], w


def evaluate_homogeneous(
    degree: int, knots: np.ndarray, pw: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """``sum_r N_{s-p+r}(t) pw[s-p+r]`` for all parameters: A3.1 on (homogeneous) points.

    Each span's constants (A2.2's knots and reciprocal denominators, and its ``p + 1``
    control points) are tabulated once per span; each block of parameters takes its
    columns with one gather, then runs the triangular scheme and the weighted sum as array
    operations over the block.

    Parameters
    ----------
    degree : int
    knots : (n + p + 1,) float
    pw : (n, d) float
        Control points (d = 3) or weighted control points (d = 4).
    t : (m,) float

    Returns
    -------
    (d, m) float
    """
    p = degree
    knots = np.asarray(knots, dtype=np.float64)
    d = pw.shape[1]
    basis, first = _span_table(p, knots)
    _, last = domain_spans(p, knots)
    s = np.arange(first, last + 1)
    local = pw[s[None, :] - p + np.arange(p + 1)[:, None]]  # (p+1, n_spans, d)
    local = np.moveaxis(local, 2, 1).reshape((p + 1) * d, len(s))  # row r*d + c
    table = np.concatenate([basis, local])
    base = basis.shape[0]
    out = np.empty((d, t.shape[0]))
    size = min(CHUNK, t.shape[0])
    work = basis_workspace(p, size)
    temp = np.empty(size)
    for s0 in range(0, t.shape[0], CHUNK):
        tt = t[s0 : s0 + CHUNK]
        spans = np.searchsorted(knots, tt, side="right") - 1
        np.clip(spans, first, last, out=spans)
        k = np.take(table, spans - first, axis=1)
        N = _basis_from_table(p, k, tt, work)
        block = out[:, s0 : s0 + CHUNK]
        tmp = temp[: len(tt)]
        for c in range(d):
            acc = block[c]
            np.multiply(N[0], k[base + c], out=acc)
            for r in range(1, p + 1):
                np.multiply(N[r], k[base + r * d + c], out=tmp)
                acc += tmp
    return out


def curve_evaluate(
    control_points: np.ndarray,
    degree: int,
    knots: np.ndarray,
    weights: np.ndarray | None,
    t: float | np.ndarray,
) -> np.ndarray:
    """Points of a (rational) B-spline curve at all parameters at once (A3.1, A4.1).

    Parameters
    ----------
    control_points : (n, 3) float
    degree : int
    knots : (n + degree + 1,) float
    weights : (n,) float or None
        None for a non-rational curve.
    t : float or (...) float
        Parameters in the domain ``[knots[p], knots[n]]``.

    Returns
    -------
    points : (..., 3) float
        ``(3,)`` for a scalar ``t``.

    Example
    -------
    >>> cp = np.array([[0, 0, 0], [1, 2, 0], [2, 0, 0.0]])
    >>> curve_evaluate(cp, 2, [0, 0, 0, 1, 1, 1], None, 0.5)
    array([1., 1., 0.])
    """
    knots = np.asarray(knots, dtype=np.float64)
    tt = np.asarray(t, dtype=np.float64)
    flat = tt.reshape(-1)
    pw = homogeneous(control_points, weights)
    out = evaluate_homogeneous(degree, knots, pw, flat)
    if weights is not None:
        out = out[:3] / out[3]
    return out.T.reshape(tt.shape + (3,))


def curve_derivatives(
    control_points: np.ndarray,
    degree: int,
    knots: np.ndarray,
    weights: np.ndarray | None,
    t: np.ndarray,
    order: int,
) -> np.ndarray:
    """Point and derivatives up to ``order`` at all parameters (A3.2; rational by A4.2).

    Parameters
    ----------
    control_points : (n, 3) float
    degree : int
    knots : (n + degree + 1,) float
    weights : (n,) float or None
    t : (m,) float
    order : int
        Highest derivative (>= 0).

    Returns
    -------
    ders : (order + 1, m, 3) float
        ``ders[k]`` is the k-th derivative with respect to t; ``ders[0]`` the points.
    """
    knots = np.asarray(knots, dtype=np.float64)
    tt = np.atleast_1d(np.asarray(t, dtype=np.float64)).reshape(-1)
    p = degree
    spans = find_spans(p, knots, tt)
    nders = basis_function_derivatives(p, knots, spans, tt, order)  # (order+1, m, p+1)
    pw = homogeneous(control_points, weights)
    idx = spans[:, None] - p + np.arange(p + 1)
    ck = np.einsum("kmr,mrd->kmd", nders, pw[idx])
    if weights is None:
        return ck
    a, w = ck[..., :3], ck[..., 3]
    out = np.empty_like(a)
    for k in range(order + 1):
        v = a[k].copy()
        for i in range(1, k + 1):
            v -= math.comb(k, i) * w[i][:, None] * out[k - i]
        out[k] = v / w[0][:, None]
    return out


# ---------------------------------------------------------------------------- knot vectors


def clamped_uniform_knots(n: int, degree: int) -> np.ndarray:
    """Clamped uniform knots on [0, 1] for ``n`` control points of ``degree``.

    ``degree + 1`` zeros, evenly spaced interior knots, ``degree + 1`` ones; the curve
    starts at the first control point and ends at the last.

    Example
    -------
    >>> clamped_uniform_knots(5, 2).tolist()
    [0.0, 0.0, 0.0, 0.3333333333333333, 0.6666666666666666, 1.0, 1.0, 1.0]
    """
    if degree < 1:
        raise ValueError(f"degree must be at least 1, got {degree}")
    if n < degree + 1:
        raise ValueError(f"degree {degree} needs at least {degree + 1} control points, got {n}")
    inner = np.linspace(0.0, 1.0, n - degree + 1)
    return np.concatenate([np.zeros(degree), inner, np.ones(degree)])


def periodic_curve(points: np.ndarray, degree: int) -> tuple[np.ndarray, np.ndarray, None]:
    """A closed, smooth (C^{degree-1}) uniform B-spline with ``points`` as its control polygon.

    The polygon is wrapped: the first ``degree`` points are repeated at the end, and the
    knots are unclamped and uniform, so the curve closes with full continuity. The domain
    is [0, 1].

    Parameters
    ----------
    points : (k, 3) float
        The closed control polygon (the last point is not a repeat of the first);
        k >= max(3, degree + 1).
    degree : int

    Returns
    -------
    control_points : (k + degree, 3) float
    knots : (k + 2 * degree + 1,) float
        ``(i - degree) / k``, so that ``knots[degree] = 0`` and ``knots[k + degree] = 1``.
    weights : None
    """
    pts = np.asarray(points, dtype=np.float64)
    k = len(pts)
    if degree < 1:
        raise ValueError(f"degree must be at least 1, got {degree}")
    if k < max(3, degree + 1):
        raise ValueError(
            f"a closed curve of degree {degree} needs at least {max(3, degree + 1)} points, got {k}"
        )
    cp = np.concatenate([pts, pts[:degree]], axis=0)
    knots = (np.arange(k + 2 * degree + 1) - degree) / k
    return cp, knots, None


# --------------------------------------------------------------------------- circles, arcs


def plane_frame(normal: np.ndarray) -> np.ndarray:
    """An orthonormal frame ``(x, y, n)`` of the plane with unit ``normal`` (rows).

    The in-plane x axis follows the DXF "arbitrary axis algorithm" (so the exporters and
    ``nurbs.circle`` agree): ``x = Y x n`` if ``|n_x|, |n_y| < 1/64``, else ``Z x n``;
    then ``y = n x x``. For ``n = +z`` the frame is the world's (x, y, z).

    Parameters
    ----------
    normal : (3,) float, non-zero

    Returns
    -------
    frame : (3, 3) float
    """
    n = np.asarray(normal, dtype=np.float64).reshape(-1)
    if n.shape != (3,) or not np.all(np.isfinite(n)):
        raise ValueError(f"a normal must be a finite [x, y, z] vector, got {normal!r}")
    length = float(np.linalg.norm(n))
    if length == 0.0:
        raise ValueError("the normal must be a non-zero vector, got [0, 0, 0]")
    n = n / length
    if abs(n[0]) < 1.0 / 64.0 and abs(n[1]) < 1.0 / 64.0:
        x = np.cross([0.0, 1.0, 0.0], n)
    else:
        x = np.cross([0.0, 0.0, 1.0], n)
    x /= np.linalg.norm(x)
    y = np.cross(n, x)
    return np.stack([x, y, n])


def _arc_local(sweep_rad: float, start_rad: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rational quadratic arc of unit radius in the xy plane (A7.1): cp (2k+1, 2), w, knots."""
    k = max(1, math.ceil(abs(sweep_rad) / (math.pi / 2) - 1e-12))
    d = sweep_rad / k
    ends = start_rad + d * np.arange(k + 1)
    mids = start_rad + d * (np.arange(k) + 0.5)
    w_mid = math.cos(d / 2)
    cp = np.empty((2 * k + 1, 2))
    cp[0::2] = np.stack([np.cos(ends), np.sin(ends)], -1)
    cp[1::2] = np.stack([np.cos(mids), np.sin(mids)], -1) / w_mid
    w = np.ones(2 * k + 1)
    w[1::2] = w_mid
    inner = np.repeat(np.arange(1, k) / k, 2)
    knots = np.concatenate([[0.0] * 3, inner, [1.0] * 3])
    return cp, w, knots


def arc(
    radius: float,
    start_deg: float,
    end_deg: float,
    center: np.ndarray = (0.0, 0.0, 0.0),
    normal: np.ndarray = (0.0, 0.0, 1.0),
) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:
    """An exact circular arc as a rational quadratic NURBS curve (A7.1).

    Angles are measured counter-clockwise around ``normal`` from the plane's local +x
    axis (:func:`plane_frame`; for normal +z that is the world +x axis). The arc is split
    into equal pieces of at most 90 degrees, each a rational quadratic Bezier whose middle
    weight is ``cos(piece / 2)``, joined by double knots; a full circle is the classic
    9-point circle. ``end_deg < start_deg`` runs clockwise.

    Parameters
    ----------
    radius : float
        Positive.
    start_deg, end_deg : float
        Start and end angles; ``0 < |end - start| <= 360``.
    center : (3,) float
    normal : (3,) float

    Returns
    -------
    control_points : (2k + 1, 3) float
    degree : int
        2.
    knots : (2k + 4,) float
        On [0, 1].
    weights : (2k + 1,) float
    """
    radius = float(radius)
    if not math.isfinite(radius) or radius <= 0:
        raise ValueError(f"radius must be a positive number, got {radius:g}")
    sweep = float(end_deg) - float(start_deg)
    if not math.isfinite(sweep) or sweep == 0 or abs(sweep) > 360 + 1e-9:
        raise ValueError(
            f"an arc must sweep more than 0 and at most 360 degrees, got {start_deg:g} to "
            f"{end_deg:g} ({sweep:g} degrees)"
        )
    frame = plane_frame(normal)
    c = np.asarray(center, dtype=np.float64).reshape(-1)
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise ValueError(f"center must be a finite [x, y, z] point, got {center!r}")
    local, w, knots = _arc_local(math.radians(sweep), math.radians(float(start_deg)))
    if abs(abs(sweep) - 360.0) < 1e-9:
        local[-1] = local[0]  # close exactly
    cp = c + radius * (local[:, :1] * frame[0] + local[:, 1:] * frame[1])
    return cp, 2, knots, w


def circle(
    radius: float = 1.0,
    center: np.ndarray = (0.0, 0.0, 0.0),
    normal: np.ndarray = (0.0, 0.0, 1.0),
) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:
    """An exact circle: the 9-point rational quadratic (A7.1 with four 90-degree pieces).

    Starts at the plane's local +x axis and runs counter-clockwise around ``normal``
    (:func:`plane_frame`); the parameter is on [0, 1].

    Returns
    -------
    control_points : (9, 3), degree 2, knots (12,), weights (9,)
    """
    return arc(radius, 0.0, 360.0, center, normal)
