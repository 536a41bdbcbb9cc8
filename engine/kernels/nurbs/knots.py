"""Knot operations on NURBS curves: insertion, refinement, degree elevation, Bezier
decomposition, reparametrization and the compatibility step used by lofting.

Every operation keeps the curve's shape exactly (up to rounding). Rational curves are
processed in homogeneous coordinates. Apart from A5.1, the operations are written with
one tool, the blossom of the basis functions (:func:`~.nurbs_basis.blossom_basis`): a
control point of the same curve on a new knot vector is the curve's blossom at that knot
vector's p consecutive interior knots (de Boor's dual functionals). This is the Oslo
algorithm for refinement and Ramshaw's blossoming principle for elevation and Bezier
extraction, and it vectorizes over all new control points at once.

References: L. Piegl and W. Tiller, *The NURBS Book*, 2nd ed. (A5.1, A5.4, A5.6, A5.9);
E. Cohen, T. Lyche and R. Riesenfeld, "Discrete B-splines and subdivision techniques in
computer-aided geometric design", CGIP 14 (1980); L. Ramshaw, "Blossoms are polar forms",
CAGD 6 (1989).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .basis import blossom_basis, domain_spans, find_spans, validate_curve, validate_surface
from .curve import homogeneous, project

__all__ = [
    "clamp",
    "decompose_bezier",
    "decompose_bezier_batch",
    "decompose_bezier_surface",
    "elevate_degree",
    "insert_knot",
    "insert_knot_surface",
    "is_clamped",
    "make_compatible",
    "refine_knots",
    "reparametrize",
    "respace",
]

Curve = tuple[np.ndarray, int, np.ndarray, "np.ndarray | None"]


def _flat(pw: np.ndarray) -> tuple[np.ndarray, tuple[int, ...]]:
    return pw.reshape(pw.shape[0], -1), pw.shape[1:]


def respace(degree: int, knots: np.ndarray, pw: np.ndarray, new_knots: np.ndarray) -> np.ndarray:
    """Control points of the same spline on another knot vector of the same degree.

    Row i is the blossom of the polynomial piece under the start of new basis function
    i's support, at ``new_knots[i+1 .. i+p]`` (dual functionals; the Oslo algorithm when
    ``new_knots`` refines ``knots``). Exact whenever the new knot vector's spline space
    contains the curve on the new domain, which must lie inside the old one: refinement,
    clamping an unclamped vector, or restricting to a sub-domain.

    Parameters
    ----------
    degree : int
    knots : (n + p + 1,) float
    pw : (n, ...) float
        Control points (homogeneous for a rational curve); trailing axes are carried
        along, so a surface's control net is respaced along its first axis.
    new_knots : (n' + p + 1,) float

    Returns
    -------
    (n', ...) float
    """
    p = degree
    knots = np.asarray(knots, dtype=np.float64)
    tau = np.asarray(new_knots, dtype=np.float64)
    flat, tail = _flat(np.asarray(pw, dtype=np.float64))
    n_new = len(tau) - p - 1
    a = knots[p]
    lo = np.maximum(tau[:n_new], a)
    mu = find_spans(p, knots, lo)
    args = (
        np.lib.stride_tricks.sliding_window_view(tau[1:], p)[:n_new] if p else np.empty((n_new, 0))
    )
    alpha = blossom_basis(p, knots, mu, args)
    idx = mu[:, None] - p + np.arange(p + 1)
    out = np.einsum("ir,ird->id", alpha, flat[idx])
    return out.reshape((n_new,) + tail)


def is_clamped(degree: int, knots: np.ndarray) -> bool:
    """True when the first and last ``degree + 1`` knots are equal (the curve's ends are
    its end control points)."""
    k = np.asarray(knots)
    p = degree
    return bool(np.all(k[: p + 1] == k[0]) and np.all(k[-p - 1 :] == k[-1]))


def clamp(
    control_points: np.ndarray, degree: int, knots: np.ndarray, weights: np.ndarray | None
) -> Curve:
    """The same curve on a clamped knot vector over the same domain (no-op if clamped).

    The knots inside the domain are kept; the ``p`` knots outside each end are replaced by
    the domain's ends (:func:`respace`).

    Returns
    -------
    (control_points, degree, knots, weights)
    """
    p = degree
    knots = np.asarray(knots, dtype=np.float64)
    if is_clamped(p, knots):
        return np.array(control_points, dtype=np.float64), p, knots.copy(), _copy(weights)
    n = len(knots) - p - 1
    a, b = knots[p], knots[n]
    inner = knots[(knots > a) & (knots < b)]
    tau = np.concatenate([[a] * (p + 1), inner, [b] * (p + 1)])
    pw = respace(p, knots, homogeneous(control_points, weights), tau)
    cp, w = project(pw, weights is not None)
    return cp, p, tau, w


def _copy(w: np.ndarray | None) -> np.ndarray | None:
    return None if w is None else np.array(w, dtype=np.float64)


def _multiplicity(knots: np.ndarray, t: float) -> int:
    return int(np.count_nonzero(knots == t))


def _snap(knots: np.ndarray, t: np.ndarray, scale: float) -> np.ndarray:
    """Parameters within 1e-12 of the domain size from an existing knot become that knot."""
    i = np.clip(np.searchsorted(knots, t), 1, len(knots) - 1)
    near = np.where(np.abs(knots[i - 1] - t) <= np.abs(knots[i] - t), knots[i - 1], knots[i])
    return np.where(np.abs(near - t) <= 1e-12 * scale, near, t)


def _check_in_domain(t: np.ndarray, a: float, b: float, what: str) -> None:
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{what} must be finite numbers")
    out = (t < a) | (t > b)
    if np.any(out):
        raise ValueError(
            f"{what} {float(t[out][0]):g} is outside the curve's domain [{a:g}, {b:g}]"
        )


def insert_knot(
    control_points: np.ndarray,
    degree: int,
    knots: np.ndarray,
    weights: np.ndarray | None,
    t: float,
    times: int = 1,
) -> Curve:
    """Insert the knot ``t`` ``times`` times without changing the curve (Boehm, A5.1).

    The knot's multiplicity may not exceed the degree (a multiplicity of p already puts
    a control point on the curve at t; more would only split it).

    Parameters
    ----------
    control_points : (n, 3) float
    degree : int
    knots : (n + p + 1,) float
    weights : (n,) float or None
    t : float
        In the domain ``[knots[p], knots[n]]``.
    times : int
        How many times to insert it (>= 0).

    Returns
    -------
    control_points : (n + times, 3), degree, knots (n + p + 1 + times,), weights or None
        New arrays; the inputs are not modified.

    Raises
    ------
    ValueError
        If t is outside the domain or the multiplicity would exceed the degree.
    """
    validate_curve(control_points, degree, knots, weights)
    U = np.asarray(knots, dtype=np.float64)
    Qw, UQ = _insert_rows(degree, U, homogeneous(control_points, weights), t, times)
    cp, w = project(Qw, weights is not None)
    return cp, degree, UQ, w


def _insert_rows(
    p: int, U: np.ndarray, Pw: np.ndarray, t: float, times: int
) -> tuple[np.ndarray, np.ndarray]:
    """Boehm's insertion (A5.1) on rows of control points ``Pw`` (n, ...): each row a
    control point, trailing axes carried along (A5.3 for a surface's net)."""
    n = len(U) - p - 1
    if isinstance(times, bool) or int(times) != times or times < 0:
        raise ValueError(f"times must be a whole number >= 0, got {times!r}")
    times = int(times)
    a, b = U[p], U[n]
    tv = np.asarray([t], dtype=np.float64)
    _check_in_domain(tv, a, b, "knot")
    t = float(_snap(U, tv, b - a)[0])
    s = _multiplicity(U, t)
    if s + times > p:
        raise ValueError(
            f"knot {t:g} has multiplicity {s}; inserting it {times} more time(s) would exceed "
            f"the degree {p}"
        )
    Pw = np.asarray(Pw, dtype=np.float64)
    if times == 0:
        return Pw.copy(), U.copy()
    r = times
    k = int(np.searchsorted(U, t, side="right")) - 1
    Qw = np.empty((n + r,) + Pw.shape[1:])
    Qw[: k - p + 1] = Pw[: k - p + 1]
    Qw[k - s + r :] = Pw[k - s :]
    Rw = Pw[k - p : k - s + 1].copy()
    tail = (1,) * (Pw.ndim - 1)
    L = k - p
    for j in range(1, r + 1):  # loops over the inserted copies and the degree only
        L = k - p + j
        i = np.arange(p - j - s + 1)
        alpha = ((t - U[L + i]) / (U[i + k + 1] - U[L + i])).reshape((-1,) + tail)
        Rw[: len(i)] = alpha * Rw[1 : len(i) + 1] + (1.0 - alpha) * Rw[: len(i)]
        Qw[L] = Rw[0]
        Qw[k + r - j - s] = Rw[p - j - s]
    Qw[L + 1 : k - s] = Rw[1 : k - s - L]
    UQ = np.concatenate([U[: k + 1], np.full(r, t), U[k + 1 :]])
    return Qw, UQ


def insert_knot_surface(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
    t: float,
    times: int = 1,
    direction: str = "u",
) -> tuple[np.ndarray, int, int, np.ndarray, np.ndarray, np.ndarray | None]:
    """Insert a knot in u or in v without changing the surface (A5.3).

    Inserting ``t`` in u is Boehm's curve insertion applied to every column of the net
    (the control points with the same v index) at once: the same coefficients for all,
    one more row of control points per insertion. In v, to every row.

    Parameters
    ----------
    control_points : (nu, nv, 3) float
    degree_u, degree_v : int
    knots_u : (nu + degree_u + 1,) float
    knots_v : (nv + degree_v + 1,) float
    weights : (nu, nv) float or None
    t : float
        In the domain of the chosen direction.
    times : int
        How many times (the multiplicity may not exceed that direction's degree).
    direction : {"u", "v"}

    Returns
    -------
    surface tuple with (nu + times, nv) or (nu, nv + times) control points; new arrays.
    """
    validate_surface(control_points, degree_u, degree_v, knots_u, knots_v, weights)
    if direction not in ("u", "v"):
        raise ValueError(f"direction must be 'u' or 'v', got {direction!r}")
    pw = homogeneous(control_points, weights)
    if direction == "u":
        U = np.asarray(knots_u, dtype=np.float64)
        qw, knots = _insert_rows(degree_u, U, pw, t, times)
        ku, kv = knots, np.array(knots_v, dtype=np.float64)
    else:
        U = np.asarray(knots_v, dtype=np.float64)
        qw, knots = _insert_rows(degree_v, U, np.swapaxes(pw, 0, 1), t, times)
        qw = np.swapaxes(qw, 0, 1)
        ku, kv = np.array(knots_u, dtype=np.float64), knots
    cp, w = project(np.ascontiguousarray(qw), weights is not None)
    return cp, degree_u, degree_v, ku, kv, w


def refine_knots(
    control_points: np.ndarray,
    degree: int,
    knots: np.ndarray,
    weights: np.ndarray | None,
    new_knots: np.ndarray,
) -> Curve:
    """Insert many knots at once without changing the curve (knot refinement).

    The result is the one of The NURBS Book's A5.4, computed row by row with the Oslo
    algorithm (:func:`respace`), vectorized over all new control points.

    Parameters
    ----------
    control_points : (n, 3) float
    degree : int
    knots : (n + p + 1,) float
    weights : (n,) float or None
    new_knots : (r,) float
        Knots to insert (any order, repeats allowed), each in the domain; no knot may end
        up with a multiplicity above the degree.

    Returns
    -------
    control_points : (n + r, 3), degree, knots (n + p + 1 + r,), weights or None
    """
    validate_curve(control_points, degree, knots, weights)
    p = degree
    U = np.asarray(knots, dtype=np.float64)
    n = len(U) - p - 1
    X = np.sort(np.asarray(new_knots, dtype=np.float64).reshape(-1))
    if X.size == 0:
        return np.array(control_points, dtype=np.float64), p, U.copy(), _copy(weights)
    a, b = U[p], U[n]
    _check_in_domain(X, a, b, "knot")
    X = _snap(U, X, b - a)
    values, counts = np.unique(X, return_counts=True)
    existing = np.array([_multiplicity(U, v) for v in values])
    over = existing + counts > p
    if np.any(over):
        i = int(np.argmax(over))
        raise ValueError(
            f"knot {values[i]:g} has multiplicity {existing[i]}; inserting it {counts[i]} more "
            f"time(s) would exceed the degree {p}"
        )
    tau = np.sort(np.concatenate([U, X]))
    pw = respace(p, U, homogeneous(control_points, weights), tau)
    cp, w = project(pw, weights is not None)
    return cp, p, tau, w


def elevate_degree(
    control_points: np.ndarray,
    degree: int,
    knots: np.ndarray,
    weights: np.ndarray | None,
    times: int = 1,
) -> Curve:
    """Raise the degree by ``times`` in one step, without changing the curve.

    Every distinct knot's multiplicity grows by ``times``, so the continuity is kept (the
    result of A5.9, generalized there to any ``t``). As in A5.9 the curve is split into its
    Bezier pieces (:func:`decompose_bezier`), each piece is raised from degree p to
    q = p + t at once with the coefficients ``C(p, j) C(t, i - j) / C(q, i)`` (Eq. 5.36),
    and the surplus knots are then removed all together: the new control points are the
    dual functionals (blossoms, :func:`respace`) of the degree-q piecewise Bezier curve on
    the target knot vector, which holds the curve exactly. The cost is one pass over the
    new control points (O(n q^2)), whatever ``t``. An unclamped (periodic) curve is
    clamped first (same shape and domain).

    Returns
    -------
    control_points (n', 3), degree + times, knots, weights or None
    """
    validate_curve(control_points, degree, knots, weights)
    if isinstance(times, bool) or int(times) != times or times < 0:
        raise ValueError(f"times must be a whole number >= 0, got {times!r}")
    t = int(times)
    cp, p, U, w = clamp(control_points, degree, knots, weights)
    if t == 0:
        return cp, p, U, w
    q = p + t
    seg, spans = _bezier_pieces(p, U, homogeneous(cp, w))  # (S, p + 1, d)
    j = np.arange(p + 1)
    i = np.arange(q + 1)[:, None]
    coef = np.where(
        (i - j >= 0) & (i - j <= t),
        _binom(p, j) * _binom(t, np.clip(i - j, 0, t)) / _binom(q, i),
        0.0,
    )
    raised = np.einsum("ij,sjd->sid", coef, seg)  # (S, q + 1, d)
    chain = np.concatenate([raised[:1, 0], raised[:, 1:].reshape(-1, raised.shape[2])])
    breaks = np.concatenate([U[spans], U[spans[-1] + 1 : spans[-1] + 2]])
    reps = np.full(len(breaks), q)
    reps[[0, -1]] = q + 1
    bezier_knots = np.repeat(breaks, reps)
    values, counts = np.unique(U, return_counts=True)
    tau = np.repeat(values, counts + t)
    pw = _blossoms_on_widest_span(q, bezier_knots, breaks, chain, tau)
    cp, w = project(pw, weights is not None)
    return cp, q, tau, w


def _blossoms_on_widest_span(
    q: int, bezier_knots: np.ndarray, breaks: np.ndarray, chain: np.ndarray, tau: np.ndarray
) -> np.ndarray:
    """Control points on ``tau`` of a piecewise Bezier curve of degree q (knots at
    ``breaks``, each interior one q times): row i is the blossom at ``tau[i+1 .. i+q]`` of
    the piece on the widest span under new basis function i. Any span under it gives the
    same value in exact arithmetic; the widest extrapolates least, so rounding grows least
    (a knot removal, unlike an insertion, is not a convex combination)."""
    n_new = len(tau) - q - 1
    width = np.diff(breaks)
    first = np.searchsorted(breaks, tau[:n_new], side="right") - 1
    last = np.searchsorted(breaks, tau[q + 1 : q + 1 + n_new], side="left") - 1
    first = np.clip(first, 0, len(width) - 1)
    last = np.clip(np.maximum(last, first), 0, len(width) - 1)
    best = first.copy()
    for step in range(1, int((last - first).max(initial=0)) + 1):  # at most q + 1 spans
        cand = np.minimum(first + step, last)
        best = np.where(width[cand] > width[best], cand, best)
    # span index of piece `best` in the Bezier knot vector: q + 1 + q * best - 1
    mu = q * best + q
    args = np.lib.stride_tricks.sliding_window_view(tau[1:], q)[:n_new]
    alpha = blossom_basis(q, bezier_knots, mu, args)
    idx = mu[:, None] - q + np.arange(q + 1)
    flat = chain.reshape(len(chain), -1)
    return np.einsum("ir,ird->id", alpha, flat[idx]).reshape((n_new,) + chain.shape[1:])


def _binom(n: int, k: np.ndarray) -> np.ndarray:
    """Binomial coefficients C(n, k) as floats (exact for the degrees used here)."""
    k = np.asarray(k)
    return np.array([math.comb(n, int(x)) for x in k.ravel()], dtype=np.float64).reshape(k.shape)


def _bezier_pieces(p: int, U: np.ndarray, pw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bezier control points (S, p + 1, d) of every non-empty span of the domain, and the
    spans; Bezier point k of the piece on [a, b] is its blossom at (a^(p-k), b^k)."""
    first, last = domain_spans(p, U)
    spans = np.arange(first, last + 1)
    spans = spans[U[spans + 1] > U[spans]]
    return _pieces_at(p, U, pw, spans), spans


def _pieces_at(p: int, U: np.ndarray, pw: np.ndarray, spans: np.ndarray) -> np.ndarray:
    """The Bezier control points (S, p + 1, d) of the pieces on knot spans ``spans``."""
    a, b = U[spans], U[spans + 1]
    kk = np.arange(p + 1)
    # argument j of Bezier point k is b when j < k, else a
    args = np.where(
        np.arange(p)[None, None, :] < kk[None, :, None], b[:, None, None], a[:, None, None]
    )  # (segments, p+1, p)
    mu = np.repeat(spans, p + 1)
    alpha = blossom_basis(p, U, mu, args.reshape(-1, p))
    idx = mu[:, None] - p + kk
    return np.einsum("ir,ird->id", alpha, pw[idx]).reshape(len(spans), p + 1, -1)


def decompose_bezier(
    control_points: np.ndarray,
    degree: int,
    knots: np.ndarray,
    weights: np.ndarray | None,
    validate: bool = True,
    projected: bool = True,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Split the curve into its Bezier pieces, one per non-empty knot span (A5.6).

    Bezier point k of the piece on ``[a, b]`` is the blossom of that piece at
    ``(a, .., a, b, .., b)`` (p - k times a, k times b): the result of inserting every
    knot up to multiplicity p, computed for all pieces at once. Works for unclamped
    curves too (only the domain's pieces). ``validate=False`` skips the check of the
    arrays, for callers that hand over a curve checked when it was made (a NurbsCurve's);
    ``projected=False`` gives the pieces in homogeneous coordinates ``(w x, w y, w z, w)``
    (a rational curve's; a non-rational one's are its points) and None.

    Returns
    -------
    segments : (k, p + 1, 3) float
    segment_weights : (k, p + 1) float, or None for a non-rational curve
    """
    if validate:
        validate_curve(control_points, degree, knots, weights)
    U = np.asarray(knots, dtype=np.float64)
    seg, _ = _bezier_pieces(degree, U, homogeneous(control_points, weights))
    if not projected:
        return seg, None
    cp, w = project(seg, weights is not None)
    return cp, w


def decompose_bezier_batch(curves: Sequence[Curve]) -> tuple[np.ndarray, np.ndarray]:
    """:func:`decompose_bezier` of many curves of one degree at once, in homogeneous
    coordinates ``(w x, w y, w z, w)`` (w = 1 for a non-rational curve).

    The blossoms of a span use only the knots and control points around it, so the curves'
    knot vectors are laid end to end as they are (not shifted: each piece comes out bit for
    bit as it would alone) and each curve's control points padded with ``p + 1`` rows, so
    that control point j of every curve sits at the index its knots do; one pass of the
    blossoms then makes every piece of every curve. The curves are not checked (callers
    hand over curves checked when they were made).

    Returns
    -------
    pieces : (k, p + 1, 4) float
        The pieces of every curve, curve after curve.
    counts : (c,) int64
        How many pieces each curve has.
    """
    if not curves:
        return np.zeros((0, 1, 4)), np.zeros(0, np.int64)
    p = int(curves[0][1])
    pws, knots, spans = [], [], []
    at = 0
    for cp, degree, kn, w in curves:  # one step per curve: its arrays are laid end to end
        if int(degree) != p:
            raise ValueError(f"a batch is of one degree, got {degree} and {p}")
        cp = np.asarray(cp, dtype=np.float64)
        n = len(cp)
        hom = homogeneous(cp, np.ones(n) if w is None else w)
        pws += [hom, np.zeros((p + 1, 4))]
        U = np.asarray(kn, dtype=np.float64)
        knots.append(U)
        local = np.arange(p, n)
        spans.append(local[U[local + 1] > U[local]] + at)
        at += n + p + 1
    seg = _pieces_at(p, np.concatenate(knots), np.concatenate(pws), np.concatenate(spans))
    counts = np.array([len(x) for x in spans], dtype=np.int64)
    plain = np.repeat([c[3] is None for c in curves], counts)
    seg[plain, :, 3] = 1.0  # a non-rational curve's weights stay exactly 1 (not a sum)
    return seg, counts


def decompose_bezier_surface(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Split a surface into its Bezier patches, one per pair of non-empty knot spans.

    A tensor product decomposes one direction at a time: :func:`decompose_bezier`'s
    blossoms along u with every column of control points carried along (each column a
    curve in u), then along v on the result (A5.7 done as two passes of A5.6).

    Returns
    -------
    patches : (k, p + 1, q + 1, 3) float
        Patch (i, j) of the spans is ``k = i * (spans in v) + j``.
    patch_weights : (k, p + 1, q + 1) float, or None for a non-rational surface
    """
    validate_surface(control_points, degree_u, degree_v, knots_u, knots_v, weights)
    p, q = int(degree_u), int(degree_v)
    pw = homogeneous(control_points, weights)  # (nu, nv, d)
    nu, nv, d = pw.shape
    a, _ = _bezier_pieces(p, np.asarray(knots_u, np.float64), pw.reshape(nu, nv * d))
    su = a.shape[0]  # (su, p + 1, nv * d): every column's u pieces
    cols = a.reshape(su * (p + 1), nv, d).transpose(1, 0, 2).reshape(nv, -1)
    b, _ = _bezier_pieces(q, np.asarray(knots_v, np.float64), cols)
    sv = b.shape[0]  # (sv, q + 1, su * (p + 1) * d)
    patches = b.reshape(sv, q + 1, su, p + 1, d).transpose(2, 0, 3, 1, 4)
    return project(patches.reshape(su * sv, p + 1, q + 1, d), weights is not None)


def reparametrize(knots: np.ndarray, t0: float, t1: float, degree: int | None = None) -> np.ndarray:
    """Map a knot vector affinely so that the domain becomes ``[t0, t1]``.

    Parameters
    ----------
    knots : (k,) float
    t0, t1 : float
        New domain, ``t0 < t1``.
    degree : int, optional
        With the degree, the domain ``[knots[p], knots[-p-1]]`` is mapped (right for
        unclamped knots); without it the first and last knots are (right when clamped).

    Returns
    -------
    (k,) float
    """
    k = np.asarray(knots, dtype=np.float64)
    if not (np.isfinite(t0) and np.isfinite(t1) and t0 < t1):
        raise ValueError(f"the new domain must have t0 < t1, got [{t0:g}, {t1:g}]")
    a, b = (k[0], k[-1]) if degree is None else (k[degree], k[len(k) - degree - 1])
    if not a < b:
        raise ValueError(f"cannot reparametrize an empty domain [{a:g}, {b:g}]")
    out = t0 + (k - a) * ((t1 - t0) / (b - a))
    out[k == a] = t0  # the domain's ends exactly, whatever the rounding
    out[k == b] = t1
    return out


def _merge_knots(vectors: Sequence[np.ndarray], tol: float = 1e-10) -> list[np.ndarray]:
    """Snap nearly equal knots of several vectors on [0, 1] to one value, per vector."""
    allk = np.unique(np.concatenate(vectors))
    if allk.size == 0:
        return list(vectors)
    starts = np.concatenate([[True], np.diff(allk) > tol])
    reps = allk[starts][np.cumsum(starts) - 1]
    return [reps[np.searchsorted(allk, v)] for v in vectors]


def make_compatible(curves: Sequence[Curve]) -> list[Curve]:
    """Give several curves one degree and one knot vector, each keeping its shape.

    Each curve is clamped, reparametrized to [0, 1], elevated to the highest degree
    among them, and refined to the union of all knot vectors (each value with the highest
    multiplicity it has in any of them; knots closer than 1e-10 are merged). If any curve
    is rational, all get weights. This is the first step of skinning (The NURBS Book
    section 10.3).

    Parameters
    ----------
    curves : sequence of (control_points, degree, knots, weights)

    Returns
    -------
    list of (control_points (n, 3), degree, knots (n + degree + 1,), weights (n,) or None)
        All with the same n, degree and knots.
    """
    curves = list(curves)
    if not curves:
        raise ValueError("make_compatible needs at least one curve, got none")
    rational = any(c[3] is not None for c in curves)
    q = max(int(c[1]) for c in curves)
    work = []
    for cp, p, U, w in curves:
        validate_curve(cp, p, U, w)
        cp, p, U, w = clamp(cp, p, U, w)
        U = reparametrize(U, 0.0, 1.0)
        if rational and w is None:
            w = np.ones(len(cp))
        cp, p, U, w = elevate_degree(cp, p, U, w, q - p)
        work.append((cp, U, w))
    snapped = _merge_knots([U for _, U, _ in work])
    values = np.unique(np.concatenate(snapped))
    mult = np.zeros(len(values), dtype=np.int64)
    for U in snapped:
        v, c = np.unique(U, return_counts=True)
        i = np.searchsorted(values, v)
        mult[i] = np.maximum(mult[i], c)
    target = np.repeat(values, mult)
    out = []
    for (cp, _, w), U in zip(work, snapped, strict=True):
        pw = respace(q, U, homogeneous(cp, w), target)
        cpn, wn = project(pw, w is not None)
        out.append((cpn, q, target.copy(), wn))
    return out
