"""Chordal sampling of curves to a tolerance: every chord within ``tol`` of its curve.

A NURBS curve is split into its Bezier pieces (The NURBS Book, A5.6); on a piece of
parameter length 1 a chord spanning ``h`` deviates from the curve by at most
``h**2 / 8 * max |C''|`` (the error of linear interpolation), so ``n`` equal steps with
``n >= sqrt(max |C''| / (8 tol))`` suffice. ``max |C''|`` of each rational piece is taken on
a fine grid of its parameter (A(t) / w(t) differentiated twice from the power form of its
homogeneous Bernstein coefficients), with a safety factor, and every chord is then checked
at its parameter midpoint and split where it is still farther than ``tol`` — so the
sampling is never coarser than the tolerance, and not much finer. All pieces are done at
once (vectorized over pieces and samples).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np

from ..nurbs import decompose_bezier, decompose_bezier_batch, validate_curve

__all__ = [
    "bezier_pieces",
    "chord_gap",
    "piece_jet",
    "points_within",
    "polyline_at_lengths",
    "refine_chords",
    "sample_closed_batch",
    "sample_nurbs",
]

_GRID = 32  # parameters per piece where |C''| is looked at
_SAFETY = 1.5  # on the sampled maximum of |C''|
_ROUNDS = 40  # midpoint refinement rounds (each halves the worst chord)


@functools.lru_cache(maxsize=16)
def _power_matrix(p: int) -> np.ndarray:
    """M with Bernstein B_{i,p}(t) = sum_j M[i, j] t**j."""
    m = np.zeros((p + 1, p + 1))
    for i in range(p + 1):  # degree + 1 rows: a tiny constant matrix
        for j in range(i, p + 1):
            m[i, j] = math.comb(p, i) * math.comb(p - i, j - i) * (-1) ** (j - i)
    m.flags.writeable = False  # (kept: one per degree)
    return m


def _steps(curv: np.ndarray, tol: float) -> np.ndarray:
    """Equal parameter steps per piece from the bound on its ``|C''|``; a bound that
    overflowed (coordinates near the end of double precision) is refused, not cast."""
    steps = np.ceil(np.sqrt(_SAFETY * curv / (8.0 * tol)))
    if not np.isfinite(steps).all() or steps.max(initial=0) > 2**53:
        raise ValueError(
            "the curve's numbers overflow double precision when it is sampled (its bound "
            "on the curvature is not a finite number): scale it down"
        )
    return np.maximum(1, steps).astype(np.int64)


def bezier_pieces(
    control_points: np.ndarray,
    degree: int,
    knots: np.ndarray,
    weights: np.ndarray | None,
    validate: bool = True,
) -> np.ndarray:
    """Homogeneous power-form coefficients of each Bezier piece in XY: (k, p + 1, 3).

    Row j of piece k holds the t**j coefficients of (w x, w y, w) on t in [0, 1].
    ``validate=False`` for a curve checked when it was made.
    """
    seg, _ = decompose_bezier(control_points, degree, knots, weights, validate, projected=False)
    if weights is None:  # (w x, w y, w) with w = 1
        hom = np.concatenate([seg[:, :, :2], np.ones(seg.shape[:2] + (1,))], axis=2)
    else:
        hom = seg[:, :, [0, 1, 3]]
    return np.einsum("ij,kic->kjc", _power_matrix(degree), hom)


def _evaluate(coef: np.ndarray, piece: np.ndarray, t: np.ndarray, order: int = 0) -> tuple:
    """Points (and first and second derivatives) of pieces ``piece`` at their ``t``."""
    p = coef.shape[1] - 1
    j = np.arange(p + 1)
    c = coef[piece]  # (m, p + 1, 3)
    powers = t[:, None] ** j  # (m, p + 1)
    h = np.einsum("mj,mjc->mc", powers, c)
    pt = h[:, :2] / h[:, 2:]
    if order == 0:
        return (pt,)
    d1 = np.zeros_like(powers)
    d1[:, 1:] = j[1:] * t[:, None] ** (j[1:] - 1)
    d2 = np.zeros_like(powers)
    if p >= 2:
        d2[:, 2:] = j[2:] * (j[2:] - 1) * t[:, None] ** (j[2:] - 2)
    h1 = np.einsum("mj,mjc->mc", d1, c)
    h2 = np.einsum("mj,mjc->mc", d2, c)
    w, w1, w2 = h[:, 2:], h1[:, 2:], h2[:, 2:]
    v1 = (h1[:, :2] - w1 * pt) / w
    v2 = (h2[:, :2] - 2 * w1 * v1 - w2 * pt) / w
    return pt, v1, v2


def piece_jet(coef: np.ndarray, piece: int, t: float) -> tuple[np.ndarray, np.ndarray]:
    """The point and first derivative (in the piece's parameter on [0, 1]) of Bezier piece
    ``piece`` of :func:`bezier_pieces` at ``t``: a handful of flops, for Newton steps."""
    c = coef[piece]  # (p + 1, 3): power-form rows of (w x, w y, w)
    j = np.arange(len(c))
    h = (t**j) @ c
    h1 = (j[1:] * t ** (j[1:] - 1)) @ c[1:]
    pt = h[:2] / h[2]
    return pt, (h1[:2] - h1[2] * pt) / h[2]


def chord_gap(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Distance from each point ``p`` to the chord ``a -> b`` (all (m, 2) or (m, 3))."""
    ab = b - a
    den = np.einsum("ij,ij->i", ab, ab)
    num = np.einsum("ij,ij->i", p - a, ab)
    s = np.clip(np.divide(num, den, out=np.zeros_like(den), where=den > 0), 0.0, 1.0)
    gap = p - a - s[:, None] * ab
    return np.hypot(*gap.T) if gap.shape[1] == 2 else np.linalg.norm(gap, axis=1)


def refine_chords(
    evaluate: Callable[[np.ndarray], np.ndarray],
    u: np.ndarray,
    points: np.ndarray,
    tol: float,
    guard: Callable[[int], None] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Split every chord whose parameter midpoint is farther than ``tol`` from it.

    Parameters
    ----------
    evaluate : callable (m,) parameters -> (m, 2) or (m, 3) points
    u : (n,) increasing parameters, the last the end of the curve
    points : (n, 2) or (n, 3) the curve at ``u``
    tol : float
    guard : callable of the sample count, called before each round grows the sampling

    Returns
    -------
    u, points : the refined sampling, ends kept.
    """
    for _ in range(_ROUNDS):
        mid = 0.5 * (u[:-1] + u[1:])
        at = evaluate(mid)
        far = chord_gap(points[:-1], points[1:], at) > tol
        if not far.any():
            break
        if guard is not None:
            guard(u.size + int(far.sum()))
        order = np.argsort(np.concatenate([u, mid[far]]), kind="stable")
        u = np.concatenate([u, mid[far]])[order]
        points = np.concatenate([points, at[far]])[order]
    return u, points


def sample_nurbs(
    control_points: np.ndarray,
    degree: int,
    knots: np.ndarray,
    weights: np.ndarray | None,
    tol: float,
    closed: bool,
    guard: Callable[[int], None] | None = None,
    params: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """XY points of a NURBS curve with every chord within ``tol`` of the curve.

    A degree-1 curve is its control polygon (exact). Otherwise each Bezier piece gets
    ``ceil(sqrt(1.5 max|C''| / (8 tol)))`` equal parameter steps, then chords still farther
    than ``tol`` at their midpoints are split (:func:`refine_chords`).

    Parameters
    ----------
    control_points : (n, 3) float
    degree : int
    knots : (n + degree + 1,) float
    weights : (n,) float or None
    tol : float
        Largest distance of a chord from the curve, > 0.
    closed : bool
        The curve returns to its start: the last point (the first again) is left out.
    guard : callable of the sample count, optional
        Called with the count before sampling (and before each refinement round), to
        refuse too many.

    params : bool
        Also give each point's curve parameter.

    Returns
    -------
    (m, 2) float, and with ``params`` the (m,) parameters
    """
    if not tol > 0:
        raise ValueError(f"the sampling tolerance must be positive, got {tol}")
    cp = np.asarray(control_points, dtype=np.float64)
    kn = np.asarray(knots, dtype=np.float64)
    if degree == 1:
        p = cp[:, :2]
        u = np.arange(len(cp), dtype=np.float64)  # degree 1: piece j runs from point j to j + 1
        breaks = kn[1 : len(cp) + 1]
    else:
        n = len(cp)
        breaks = np.unique(kn[degree : n + 1])
        coef = bezier_pieces(cp, degree, knots, weights)
        k = coef.shape[0]
        g = np.tile(np.linspace(0.0, 1.0, _GRID + 1), k)
        piece = np.repeat(np.arange(k), _GRID + 1)
        _, _, d2 = _evaluate(coef, piece, g, order=2)
        curv = np.linalg.norm(d2, axis=1).reshape(k, _GRID + 1).max(axis=1)
        steps = _steps(curv, tol)
        total = int(steps.sum()) + 1
        if guard is not None:
            guard(total)
        piece = np.repeat(np.arange(k), steps)
        first = np.concatenate([[0], np.cumsum(steps)[:-1]])
        t = (np.arange(total - 1) - np.repeat(first, steps)) / np.repeat(steps, steps)
        u = np.append(piece + t, float(k))

        def at(uu: np.ndarray) -> np.ndarray:
            pc = np.minimum(np.floor(uu).astype(np.int64), k - 1)
            return _evaluate(coef, pc, uu - pc)[0]

        u, p = refine_chords(at, u, at(u), tol, guard)
    if closed and len(p) > 1 and np.array_equal(p[0], p[-1]):
        p, u = p[:-1], u[:-1]
    elif closed and len(p) > 1 and np.abs(p[0] - p[-1]).max() <= 1e-12 * max(1.0, np.abs(p).max()):
        p, u = p[:-1], u[:-1]
    if not params:
        return np.ascontiguousarray(p)
    return np.ascontiguousarray(p), _knot_parameter(u, breaks)


def _knot_parameter(u: np.ndarray, breaks: np.ndarray) -> np.ndarray:
    """The curve parameter of piece-space parameters ``u`` (piece j is ``[j, j + 1]``, the
    knot span ``[breaks[j], breaks[j + 1]]``, mapped linearly as the decomposition does)."""
    j = np.minimum(np.floor(u).astype(np.int64), len(breaks) - 2)
    return breaks[j] + (u - j) * (breaks[j + 1] - breaks[j])


def polyline_at_lengths(
    control_points: np.ndarray, knots: np.ndarray, lengths: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Points, parameters and unit tangents of a degree-1 NURBS at arc lengths, exactly.

    A clamped degree-1 curve runs straight from control point i to i + 1 while its
    parameter runs linearly over ``[knots[i + 1], knots[i + 2]]``, so the point at a length
    is found by a binary search in the running chord length and a linear step (a
    zero-length segment is never the one chosen).

    Parameters
    ----------
    control_points : (n, 3) float
    knots : (n + 2,) float
    lengths : (m,) float
        Arc lengths from the start, in ``[0, length]``.

    Returns
    -------
    t : (m,) float
    points : (m, 3) float
    tangents : (m, 3) float
        The unit direction of the segment each point lies on.
    length : float
        The curve's length.
    """
    cp = np.asarray(control_points, dtype=np.float64)
    seg = np.diff(cp, axis=0)
    size = np.sqrt(np.einsum("ij,ij->i", seg, seg))
    cum = np.concatenate([[0.0], np.cumsum(size)])
    s = np.asarray(lengths, dtype=np.float64)
    i = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
    # past a run of zero-length segments at the very end, step back to a real one
    real = np.flatnonzero(size > 0)
    if real.size:
        i = np.minimum(i, real[-1])
    f = np.divide(s - cum[i], size[i], out=np.zeros_like(s), where=size[i] > 0)
    f = np.clip(f, 0.0, 1.0)
    k = np.asarray(knots, dtype=np.float64)
    t = k[i + 1] + f * (k[i + 2] - k[i + 1])
    tangent = np.divide(seg[i], size[i, None], out=np.zeros_like(seg[i]), where=size[i, None] > 0)
    return t, cp[i] + f[:, None] * seg[i], tangent, float(cum[-1])


def sample_closed_batch(
    curves: list[tuple[np.ndarray, int, np.ndarray, np.ndarray | None]],
    tol: float,
    guard: Callable[[int], None] | None = None,
    params: bool = False,
    validate: bool = True,
) -> list[np.ndarray] | list[tuple[np.ndarray, np.ndarray]]:
    """:func:`sample_nurbs` of many closed curves of one degree (>= 2) at once
    (``validate=False`` for curves checked when they were made).

    Every curve's Bezier pieces go into one array, so the curvature bound, the sampling and
    each round of midpoint refinement are one vectorized pass over all of them (a line of
    text is hundreds of glyph contours). Curve c's parameter is laid out on
    ``[base_c, base_c + k_c]`` with a gap of 1 before the next, so one sorted array holds
    every curve's samples and no chord joins two curves.

    Returns
    -------
    list of (m_i, 2) float
        Each curve's samples, its closing point left out.
    """
    if not tol > 0:
        raise ValueError(f"the sampling tolerance must be positive, got {tol}")
    if not curves:
        return []
    degrees = {int(c[1]) for c in curves}
    if len(degrees) != 1 or min(degrees) < 2:
        raise ValueError(f"a batch is of one degree >= 2, got degrees {sorted(degrees)}")
    if validate:
        for cp, p, kn, w in curves:
            validate_curve(np.asarray(cp, dtype=np.float64), p, kn, w)
    # every curve's Bezier pieces in one pass of the blossoms, then (w x, w y, w) in power form
    seg, k = decompose_bezier_batch(curves)
    coef_all = np.einsum("ij,kic->kjc", _power_matrix(int(curves[0][1])), seg[:, :, [0, 1, 3]])
    first_piece = np.concatenate([[0], np.cumsum(k)[:-1]])
    base = first_piece + np.arange(len(k))  # the gap of 1 before each next curve
    # the curvature bound per piece, then equal steps
    total_pieces = int(k.sum())
    g = np.tile(np.linspace(0.0, 1.0, _GRID + 1), total_pieces)
    _, _, d2 = _evaluate(coef_all, np.repeat(np.arange(total_pieces), _GRID + 1), g, order=2)
    curv = np.linalg.norm(d2, axis=1).reshape(total_pieces, _GRID + 1).max(axis=1)
    steps = _steps(curv, tol)
    if guard is not None:
        guard(int(steps.sum()) + len(k))
    piece_curve = np.repeat(np.arange(len(k)), k)
    piece_local = np.arange(total_pieces) - first_piece[piece_curve]
    start = np.concatenate([[0], np.cumsum(steps)[:-1]])
    j = np.arange(int(steps.sum())) - np.repeat(start, steps)
    t = j / np.repeat(steps, steps)
    u = np.repeat(base[piece_curve] + piece_local, steps) + t
    u = np.sort(np.concatenate([u, base + k]))  # each curve's end, u = base + k
    curve_of = np.searchsorted(base, u, side="right") - 1

    def at(uu: np.ndarray, cc: np.ndarray) -> np.ndarray:
        local = np.minimum(np.floor(uu - base[cc]).astype(np.int64), k[cc] - 1)
        return _evaluate(coef_all, first_piece[cc] + local, uu - base[cc] - local)[0]

    pts = at(u, curve_of)
    for _ in range(_ROUNDS):
        same = curve_of[1:] == curve_of[:-1]
        mid = 0.5 * (u[:-1] + u[1:])[same]
        cm = curve_of[:-1][same]
        mp = at(mid, cm)
        a, b = pts[:-1][same], pts[1:][same]
        far = chord_gap(a, b, mp) > tol
        if not far.any():
            break
        if guard is not None:
            guard(u.size + int(far.sum()))
        order = np.argsort(np.concatenate([u, mid[far]]), kind="stable")
        u = np.concatenate([u, mid[far]])[order]
        pts = np.concatenate([pts, mp[far]])[order]
        curve_of = np.concatenate([curve_of, cm[far]])[order]
    ends = np.searchsorted(curve_of, np.arange(len(k) + 1))
    # each curve without its last sample (its end, the start again)
    out = [np.ascontiguousarray(pts[ends[i] : ends[i + 1] - 1]) for i in range(len(k))]
    if not params:
        return out
    local = u - base[curve_of]
    return [
        (out[i], _knot_parameter(local[ends[i] : ends[i + 1] - 1], _breaks(curves[i])))
        for i in range(len(k))
    ]


def _breaks(curve: tuple[np.ndarray, int, np.ndarray, np.ndarray | None]) -> np.ndarray:
    cp, p, kn, _ = curve
    return np.unique(np.asarray(kn, dtype=np.float64)[p : len(cp) + 1])


def points_within(
    evaluate: Callable[[np.ndarray], np.ndarray],
    second: Callable[[np.ndarray], np.ndarray],
    breaks: np.ndarray,
    tol: float,
    guard: Callable[[int], None] | None = None,
) -> np.ndarray:
    """(m, 3) points of a curve in space whose chords are all within ``tol`` of it.

    Each span between ``breaks`` (knots, where a NURBS may bend sharply) gets
    ``ceil(sqrt(1.5 max |C''| / (8 tol)))`` equal parameter steps, ``max |C''|`` looked at on
    a grid of the span (the interpolation bound of the module docstring, in 3-D).

    Parameters
    ----------
    evaluate : callable (m,) params -> (m, 3) points
    second : callable (m,) params -> (m, 3) second derivatives
    breaks : (s + 1,) float
        The spans' ends, increasing.
    tol : float
        > 0.
    guard : callable of the point count, optional
        Called before the points are made.
    """
    if not tol > 0:
        raise ValueError(f"the sampling tolerance must be positive, got {tol}")
    b = np.asarray(breaks, dtype=np.float64)
    spans = len(b) - 1
    g = np.linspace(0.0, 1.0, _GRID + 1)
    width = np.diff(b)
    t = (b[:-1, None] + g[None, :] * width[:, None]).reshape(-1)
    d2 = np.linalg.norm(np.asarray(second(t)), axis=-1).reshape(spans, _GRID + 1)
    steps = _steps(d2.max(axis=1) * width**2, tol)  # |C''| in the span's unit parameter
    total = int(steps.sum()) + 1
    if guard is not None:
        guard(total)
    first = np.concatenate([[0], np.cumsum(steps)[:-1]])
    span = np.repeat(np.arange(spans), steps)
    f = (np.arange(total - 1) - first[span]) / steps[span]
    u = np.append(b[span] + f * width[span], b[-1])
    return np.asarray(evaluate(u))
