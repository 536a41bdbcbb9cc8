"""Surfaces built from curves: loft (skinning), extrusion, revolution and sweep.

A surface is returned as ``(control_points (nu, nv, 3), degree_u, degree_v, knots_u,
knots_v, weights (nu, nv) | None)``; u always runs along the input curves (the profile)
and v across them (between sections, around the axis, along the path).

References: L. Piegl and W. Tiller, *The NURBS Book*, 2nd ed., sections 8.3 (extrusion),
8.5 and A8.1 (revolution), 10.3 (skinning); W. Wang, B. Juttler, D. Zheng and Y. Liu,
"Computation of rotation minimizing frames", ACM TOG 27(1), 2008 (double reflection).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .basis import validate_curve
from .curve import _arc_local, homogeneous, plane_frame, project
from .fit import fit_columns, interpolation_parameters
from .knots import make_compatible

__all__ = [
    "extrude",
    "loft",
    "revolve",
    "rotation_minimizing_frames",
    "skin",
    "sweep",
]

CurveTuple = tuple[np.ndarray, int, np.ndarray, "np.ndarray | None"]
SurfaceTuple = tuple[np.ndarray, int, int, np.ndarray, np.ndarray, "np.ndarray | None"]


def _vec3(value: object, what: str) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64).reshape(-1)
    if v.shape == (2,):
        v = np.append(v, 0.0)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{what} must be a finite [x, y, z] vector, got {value!r}")
    return v


def skin(
    sections: np.ndarray,
    weights: np.ndarray | None,
    degree_u: int,
    knots_u: np.ndarray,
    degree_v: int,
    params: np.ndarray,
    closed: bool = False,
) -> SurfaceTuple:
    """Interpolate compatible sections across v: the surface through every section.

    Parameters
    ----------
    sections : (K, n, 3) float
        Control points of K compatible curves (one degree, one knot vector).
    weights : (K, n) float or None
    degree_u : int
    knots_u : (n + degree_u + 1,) float
    degree_v : int
        Already capped (<= K - 1).
    params : (K,) float
        v of each section, increasing in [0, 1] (below 1 when closed).
    closed : bool
        Periodic in v.

    Returns
    -------
    surface tuple; at ``v = params[k]`` it is exactly section k (the homogeneous
    control points are interpolated, so rational sections are kept exactly).
    """
    pw = homogeneous(sections, weights)  # (K, n, d)
    ctrl, knots_v = fit_columns(pw, params, degree_v, closed)  # (nv, n, d)
    ctrl = np.swapaxes(ctrl, 0, 1)  # (n, nv, d): u first
    cp, w = project(ctrl, weights is not None)
    if w is not None and np.any(w <= 0):
        raise ValueError(
            "the weights of these rational curves cannot be blended smoothly between them "
            "(interpolating them gives non-positive weights); use fewer or more similar "
            "sections, or a lower degree_v"
        )
    return cp, degree_u, degree_v, np.asarray(knots_u, dtype=np.float64), knots_v, w


def loft(
    curves: Sequence[CurveTuple],
    degree_v: int = 3,
    closed: bool = False,
    parametrization: str = "chord",
) -> SurfaceTuple:
    """A surface through every curve, in order (skinning, The NURBS Book section 10.3).

    The curves are made compatible (one degree, one knot vector: clamped, reparametrized
    to [0, 1], degree-elevated and refined, shapes unchanged), then each column of control
    points is interpolated across the curves. Their v parameters are the chord lengths
    between consecutive curves' control polygons, averaged over the columns (Eq. 10.8).

    Parameters
    ----------
    curves : sequence of (control_points, degree, knots, weights)
        At least 2 (at least 3 when closed); they may differ in degree, knots, count and
        rationality.
    degree_v : int
        Degree across the curves, capped at ``len(curves) - 1`` (2 curves: a ruled surface).
    closed : bool
        Close the surface in v: after the last curve it returns smoothly to the first.
    parametrization : {"chord", "centripetal", "uniform"}

    Returns
    -------
    (control_points (nu, nv, 3), degree_u, degree_v, knots_u, knots_v, weights or None)
        u along the curves (domain [0, 1]), v across them (domain [0, 1] for an open loft).
    """
    curves = list(curves)
    need = 3 if closed else 2
    if len(curves) < need:
        kind = "a closed loft" if closed else "a loft"
        raise ValueError(f"{kind} needs at least {need} curves, got {len(curves)}")
    if isinstance(degree_v, bool) or int(degree_v) != degree_v or degree_v < 1:
        raise ValueError(f"degree_v must be a whole number >= 1, got {degree_v!r}")
    same = make_compatible(curves)
    sections = np.stack([c[0] for c in same])
    rational = same[0][3] is not None
    weights = np.stack([c[3] for c in same]) if rational else None
    q, knots_u = same[0][1], same[0][2]
    if closed and np.allclose(sections[0], sections[-1], rtol=0, atol=1e-12 * _extent(sections)):
        sections, weights = sections[:-1], None if weights is None else weights[:-1]
    K = len(sections)
    try:
        params = interpolation_parameters(sections, closed, parametrization)
    except ValueError:
        raise ValueError(
            "two consecutive curves of the loft coincide; a loft needs distinct curves"
        ) from None
    return skin(sections, weights, q, knots_u, min(int(degree_v), K - 1), params, closed)


def _extent(points: np.ndarray) -> float:
    pts = points.reshape(-1, 3)
    return max(float(np.ptp(pts, axis=0).max()), 1e-300)


def extrude(curve: CurveTuple, direction: np.ndarray = (0.0, 0.0, 1.0)) -> SurfaceTuple:
    """The curve swept along a straight vector: a ruled surface of degree 1 in v (section
    8.3 of The NURBS Book).

    Parameters
    ----------
    curve : (control_points, degree, knots, weights)
    direction : (3,) float
        Non-zero; its length is the height.

    Returns
    -------
    surface tuple with ``nv = 2``; v = 0 is the curve, v = 1 the curve moved by direction.
    """
    cp, p, U, w = curve
    validate_curve(cp, p, U, w)
    d = _vec3(direction, "direction")
    if not np.any(d):
        raise ValueError("direction must be a non-zero vector, got [0, 0, 0]")
    cp = np.asarray(cp, dtype=np.float64)
    net = np.stack([cp, cp + d], axis=1)
    ww = None if w is None else np.stack([w, w], axis=1).astype(np.float64)
    return net, p, 1, np.asarray(U, dtype=np.float64).copy(), np.array([0.0, 0, 1, 1]), ww


def revolve(
    curve: CurveTuple,
    axis_point: np.ndarray = (0.0, 0.0, 0.0),
    axis: np.ndarray = (0.0, 0.0, 1.0),
    angle_deg: float = 360.0,
) -> SurfaceTuple:
    """The exact surface of revolution of a curve about an axis (A8.1).

    Every control point sweeps a rational quadratic arc (pieces of at most 90 degrees)
    about the axis, counter-clockwise around ``axis`` (right-hand rule); the weights
    multiply. Each point of the profile stays at its distance from the axis exactly.

    Parameters
    ----------
    curve : (control_points, degree, knots, weights)
        The profile; u runs along it.
    axis_point : (3,) float
    axis : (3,) float, non-zero
    angle_deg : float
        Sweep angle, ``0 < |angle| <= 360`` (negative turns clockwise).

    Returns
    -------
    surface tuple, rational; degree_v 2, v in [0, 1] around the axis.
    """
    cp, p, U, w = curve
    validate_curve(cp, p, U, w)
    o = _vec3(axis_point, "axis_point")
    a = _vec3(axis, "axis")
    norm = float(np.linalg.norm(a))
    if norm == 0:
        raise ValueError("axis must be a non-zero vector, got [0, 0, 0]")
    a = a / norm
    angle = float(angle_deg)
    if not math.isfinite(angle) or angle == 0 or abs(angle) > 360 + 1e-9:
        raise ValueError(f"angle must be more than 0 and at most 360 degrees, got {angle:g}")
    local, w_arc, knots_v = _arc_local(math.radians(angle), 0.0)
    if abs(abs(angle) - 360) < 1e-9:
        local[-1] = local[0]
    cp = np.asarray(cp, dtype=np.float64)
    rel = cp - o
    foot = o + (rel @ a)[:, None] * a  # projection of each control point on the axis
    x = cp - foot
    y = np.cross(a, x)
    net = foot[:, None, :] + local[None, :, :1] * x[:, None, :] + local[None, :, 1:] * y[:, None, :]
    w_prof = np.ones(len(cp)) if w is None else np.asarray(w, dtype=np.float64)
    weights = w_prof[:, None] * w_arc[None, :]
    return net, p, 2, np.asarray(U, dtype=np.float64).copy(), knots_v, weights


def rotation_minimizing_frames(
    points: np.ndarray,
    tangents: np.ndarray,
    closed: bool = False,
    initial: np.ndarray | None = None,
) -> np.ndarray:
    """Rotation-minimizing frames along sampled points (double reflection, Wang et al. 2008).

    Each step's frame is the previous one reflected in the bisector plane of the two
    points, then in the plane that maps the reflected tangent onto the next tangent. The
    two reflections form a rotation that depends only on the data, so all steps are
    computed at once and chained by a parallel prefix product of the 3x3 matrices (a loop
    over log2(m) levels), not by a loop over the points.

    Parameters
    ----------
    points : (m, 3) float
    tangents : (m, 3) float
        Non-zero; normalized here.
    closed : bool
        The path is a loop (from the last point back to the first): the frames are turned
        progressively, in proportion to arc length, by the holonomy angle the transport
        leaves after one loop, so the frame comes back to itself.
    initial : (3,) float, optional
        First frame's normal direction (projected onto the plane normal to the first
        tangent); by default the plane's x axis of :func:`plane_frame`.

    Returns
    -------
    frames : (m, 3, 3) float
        ``frames[i] = (r_i, s_i, t_i)``: unit normal, binormal ``t x r`` and tangent, a
        right-handed orthonormal frame.
    """
    x = np.asarray(points, dtype=np.float64)
    t = np.asarray(tangents, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or t.shape != x.shape:
        raise ValueError(
            f"points and tangents must both be (m, 3) arrays, got {x.shape} and {t.shape}"
        )
    m = len(x)
    if m < 1:
        raise ValueError("rotation-minimizing frames need at least one point")
    tl = np.linalg.norm(t, axis=1)
    if np.any(~np.isfinite(tl)) or np.any(tl == 0):
        raise ValueError("tangents must be finite and non-zero")
    t = t / tl[:, None]
    if initial is None:
        r0 = plane_frame(t[0])[0]
    else:
        r0 = _vec3(initial, "initial")
        r0 = r0 - (r0 @ t[0]) * t[0]
        if np.linalg.norm(r0) < 1e-12:
            raise ValueError("the initial normal must not be parallel to the first tangent")
        r0 /= np.linalg.norm(r0)
    nxt = np.arange(1, m + 1) % m if closed else np.arange(1, m)
    steps = _reflection_steps(x[: len(nxt)], t[: len(nxt)], x[nxt], t[nxt])  # (s, 3, 3)
    chain = _prefix_products(steps)  # chain[i] = M_i ... M_0
    r = np.empty((m, 3))
    r[0] = r0
    r[1:] = chain[: m - 1] @ r0
    if closed:
        back = chain[m - 1] @ r0  # transported once around, at the first point again
        phi = math.atan2(float(np.cross(back, r0) @ t[0]), float(back @ r0))
        seg = np.linalg.norm(x[nxt] - x, axis=1)
        total = float(seg.sum())
        frac = (
            np.concatenate([[0.0], np.cumsum(seg)[:-1]]) / total if total > 0 else np.arange(m) / m
        )
        r = _rotate_about(r, t, phi * frac)
    r = r - np.sum(r * t, axis=1)[:, None] * t  # remove rounding drift
    r /= np.linalg.norm(r, axis=1)[:, None]
    s = np.cross(t, r)
    return np.stack([r, s, t], axis=1)


def _reflection_steps(x0: np.ndarray, t0: np.ndarray, x1: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """The double reflection ``H2 H1`` of each step as a 3x3 matrix (Wang et al., Alg. 1)."""
    eye = np.eye(3)

    def householder(v: np.ndarray) -> np.ndarray:
        vv = np.sum(v * v, axis=1)
        safe = np.where(vv > 0, vv, 1.0)
        h = eye - 2.0 * v[:, :, None] * v[:, None, :] / safe[:, None, None]
        return np.where((vv > 0)[:, None, None], h, eye)

    h1 = householder(x1 - x0)
    tl = np.einsum("sij,sj->si", h1, t0)
    h2 = householder(t1 - tl)
    return h2 @ h1


def _prefix_products(mats: np.ndarray) -> np.ndarray:
    """``out[i] = mats[i] @ mats[i-1] @ ... @ mats[0]`` by Hillis-Steele doubling."""
    out = mats.copy()
    d = 1
    while d < len(out):
        out[d:] = out[d:] @ out[:-d]
        d *= 2
    return out


def _rotate_about(v: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues rotation of each v[i] about the unit axis[i] by angle[i] (radians)."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    dot = np.sum(axis * v, axis=1)[:, None]
    return v * c + np.cross(axis, v) * s + axis * dot * (1 - c)


def sweep(
    profile: CurveTuple,
    path_points: np.ndarray,
    path_tangents: np.ndarray,
    closed: bool | None = None,
    degree_v: int = 3,
) -> SurfaceTuple:
    """A profile swept along a path: placed in the rotation-minimizing frame at each path
    station, the copies skinned across v.

    The profile's XY plane becomes the plane normal to the path: its x axis the frame's
    normal r, its y axis the binormal s and its z axis the tangent, with its origin on
    the path. At every station the surface is exactly the placed profile, so each profile
    point stays at its distance from the path there; between stations the skinning
    interpolates smoothly.

    Parameters
    ----------
    profile : (control_points, degree, knots, weights)
    path_points : (m, 3) float
        Stations along the path, at least 2, consecutive ones distinct.
    path_tangents : (m, 3) float
        Path tangents at the stations (need not be unit length).
    closed : bool, optional
        Close the surface along the path (periodic in v). By default it is closed when
        the last station repeats the first with the same tangent direction.
    degree_v : int
        Degree along the path, capped at the number of stations - 1.

    Returns
    -------
    surface tuple; u along the profile, v along the path (v = station's chord-length
    parameter on [0, 1]).
    """
    cp, p, U, w = profile
    validate_curve(cp, p, U, w)
    x = np.asarray(path_points, dtype=np.float64)
    t = np.asarray(path_tangents, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or len(x) < 2:
        raise ValueError(f"a sweep path needs at least 2 points (m, 3), got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("sweep path points must be finite numbers")
    ext = _extent(x)
    ends_meet = bool(np.linalg.norm(x[0] - x[-1]) <= 1e-9 * ext)
    if closed is None:
        tn = t / np.maximum(np.linalg.norm(t, axis=1), 1e-300)[:, None]
        closed = ends_meet and bool(tn[0] @ tn[-1] > 1 - 1e-6)
    if closed and ends_meet:
        x, t = x[:-1], t[:-1]
    if closed and len(x) < 3:
        raise ValueError(f"a closed sweep path needs at least 3 distinct points, got {len(x)}")
    frames = rotation_minimizing_frames(x, t, closed=closed)
    cp = np.asarray(cp, dtype=np.float64)
    # profile (x, y, z) -> station + x r + y s + z t, for every station at once
    sections = x[:, None, :] + np.einsum("nc,mcd->mnd", cp, frames)
    weights = None if w is None else np.broadcast_to(np.asarray(w, np.float64), sections.shape[:2])
    try:
        params = interpolation_parameters(x, closed, "chord")
    except ValueError:
        raise ValueError("consecutive sweep path points coincide; give distinct stations") from None
    dv = min(int(degree_v), len(x) - 1)
    return skin(sections, weights, p, np.asarray(U, dtype=np.float64), dv, params, closed)
