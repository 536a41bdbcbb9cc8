"""B-spline basis functions, knot spans and input validation, vectorized over parameters.

Conventions shared by every ``nurbs_*`` module:

- A curve is ``(control_points (n, 3), degree p, knots (n + p + 1,), weights (n,) | None)``.
  ``weights=None`` means non-rational (all ones). The domain is ``[knots[p], knots[n]]``;
  knots need not be clamped (a periodic curve uses unclamped uniform knots).
- A surface is ``(control_points (nu, nv, 3), degree_u, degree_v, knots_u, knots_v,
  weights (nu, nv) | None)``; u runs along the first axis.
- Parameters outside the domain are evaluated on the first or last polynomial piece
  (polynomial extrapolation), never wrapped.

References: L. Piegl and W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997 (cited as
"A2.1" etc. for its algorithms).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "basis_function_derivatives",
    "basis_functions",
    "blossom_basis",
    "domain_spans",
    "find_spans",
    "validate_curve",
    "validate_surface",
]


def domain_spans(degree: int, knots: np.ndarray) -> tuple[int, int]:
    """First and last usable span index of a knot vector (non-empty spans in the domain).

    Parameters
    ----------
    degree : int
    knots : (n + degree + 1,) float

    Returns
    -------
    first, last : int
        ``knots[first] < knots[first + 1]`` and ``knots[last] < knots[last + 1]``; every
        parameter of the domain ``[knots[p], knots[n]]`` lies in a span between them.
    """
    knots = np.asarray(knots, dtype=np.float64)
    n = len(knots) - degree - 1
    first = int(np.searchsorted(knots, knots[degree], side="right")) - 1
    last = int(np.searchsorted(knots, knots[n], side="left")) - 1
    return first, last


def find_spans(degree: int, knots: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Knot span index of every parameter: ``knots[i] <= t < knots[i + 1]`` (A2.1).

    Vectorized with a binary search (``searchsorted``). The end of the domain belongs to
    the last non-empty span, and parameters outside the domain to the first or last span.

    Parameters
    ----------
    degree : int
        Degree p.
    knots : (n + p + 1,) float
        Non-decreasing knot vector.
    t : (m,) float
        Parameters.

    Returns
    -------
    spans : (m,) int64
        Span indices in ``[p, n - 1]``.

    Example
    -------
    >>> find_spans(2, np.array([0, 0, 0, 1, 2, 2, 2.0]), np.array([0.0, 0.5, 1.0, 2.0]))
    array([2, 2, 3, 3])
    """
    knots = np.asarray(knots, dtype=np.float64)
    first, last = domain_spans(degree, knots)
    spans = np.searchsorted(knots, t, side="right") - 1
    return np.clip(spans, first, last).astype(np.int64, copy=False)


#: Parameters are processed in blocks of this size so that the dozens of temporaries of
#: the triangular scheme stay in the CPU cache (about 3x faster than whole arrays at 10^5).
CHUNK = 4096


def _span_table(degree: int, knots: np.ndarray) -> tuple[np.ndarray, int]:
    """Per-span constants of A2.2, one column per non-empty span of the domain.

    Rows: ``knots[s+1-j]`` (j = 1..p), ``knots[s+j]`` (j = 1..p), then the reciprocals
    ``1 / (knots[s+r+1] - knots[s+1-j+r])`` of A2.2's denominators for j = 1..p,
    r = 0..j-1 (they depend on the span only). Rows are contiguous so that a block of
    parameters picks its columns with one ``np.take(..., axis=1)``.

    Returns
    -------
    table : (2p + p(p+1)/2, n_spans) float
    first : int
        Span index of column 0.
    """
    p = degree
    first, last = domain_spans(p, knots)
    s = np.arange(first, last + 1)
    rows = [knots[s + 1 - j] for j in range(1, p + 1)]
    rows += [knots[s + j] for j in range(1, p + 1)]
    with np.errstate(divide="ignore"):  # empty spans (repeated knots) are never looked up
        for j in range(1, p + 1):
            for r in range(j):
                rows.append(1.0 / (knots[s + r + 1] - knots[s + 1 - j + r]))
    return np.ascontiguousarray(np.array(rows).reshape(len(rows), len(s))), first


def basis_workspace(degree: int, size: int) -> np.ndarray:
    """Scratch memory for :func:`_basis_from_table` on blocks of up to ``size`` parameters."""
    return np.empty((3 * degree + 3, size))


def _basis_from_table(
    degree: int, k: np.ndarray, t: np.ndarray, work: np.ndarray | None = None
) -> np.ndarray:
    """A2.2 on a block: ``k`` holds the block's columns of :func:`_span_table`.

    The loops run over the degree only; each step is one array operation over the block,
    written in place into ``work`` (from :func:`basis_workspace`; allocated if None), as
    A2.2 itself works in place. Returns the basis functions as a ``(p + 1, m)`` view into
    ``work``: use it before the next block overwrites it.
    """
    p = degree
    m = t.shape[0]
    if work is None:
        work = basis_workspace(p, m)
    w = work[:, :m]
    N = w[: p + 1]
    if p == 0:
        N[0] = 1.0
        return N
    left = w[p + 1 : 2 * p + 1]  # left[j - 1] = t - knots[s + 1 - j]
    right = w[2 * p + 1 : 3 * p + 1]  # right[j - 1] = knots[s + j] - t
    temp, saved = w[3 * p + 1], w[3 * p + 2]
    np.subtract(t, k[:p], out=left)
    np.subtract(k[p : 2 * p], t, out=right)
    inv = 2 * p
    # level 1 (N_0 = 1)
    np.multiply(right[0], k[inv], out=N[0])
    np.multiply(left[0], k[inv], out=N[1])
    inv += 1
    for j in range(2, p + 1):
        for r in range(j):
            np.multiply(N[r], k[inv], out=temp)
            inv += 1
            if r == 0:
                np.multiply(right[0], temp, out=N[0])
            else:
                np.multiply(right[r], temp, out=N[r])
                N[r] += saved
            np.multiply(left[j - r - 1], temp, out=saved)
        N[j] = saved
    return N


def _basis_rows(
    degree: int, knots: np.ndarray, spans: np.ndarray, t: np.ndarray
) -> list[np.ndarray]:
    """A2.2 for all parameters; returns ``p + 1`` arrays of shape (m,)."""
    p = degree
    t = np.asarray(t, dtype=np.float64)
    if p == 0:
        return [np.ones_like(t)]
    table, first = _span_table(p, knots)
    out = np.empty((p + 1, t.shape[0]))
    work = basis_workspace(p, min(CHUNK, t.shape[0]))
    for s0 in range(0, t.shape[0], CHUNK):
        sl = slice(s0, s0 + CHUNK)
        k = np.take(table, spans[sl] - first, axis=1)
        out[:, sl] = _basis_from_table(p, k, t[sl], work)
    return list(out)


def basis_functions(degree: int, knots: np.ndarray, spans: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The p + 1 non-zero B-spline basis functions at every parameter (A2.2).

    Parameters
    ----------
    degree : int
    knots : (n + p + 1,) float
    spans : (m,) int
        From :func:`find_spans`.
    t : (m,) float

    Returns
    -------
    N : (m, p + 1) float
        ``N[i, r]`` is the basis function of control point ``spans[i] - p + r`` at ``t[i]``;
        each row sums to 1.
    """
    knots = np.asarray(knots, dtype=np.float64)
    spans = np.asarray(spans, dtype=np.int64)
    return np.stack(_basis_rows(degree, knots, spans, t), axis=-1)


def basis_function_derivatives(
    degree: int, knots: np.ndarray, spans: np.ndarray, t: np.ndarray, order: int
) -> np.ndarray:
    """Basis functions and their derivatives up to ``order`` at every parameter (A2.3).

    Parameters
    ----------
    degree : int
    knots : (n + p + 1,) float
    spans : (m,) int
    t : (m,) float
    order : int
        Highest derivative; derivatives above the degree are zero.

    Returns
    -------
    ders : (order + 1, m, p + 1) float
        ``ders[k, i, r]`` is the k-th derivative of the basis function of control point
        ``spans[i] - p + r`` at ``t[i]``.
    """
    p = degree
    knots = np.asarray(knots, dtype=np.float64)
    spans = np.asarray(spans, dtype=np.int64)
    t = np.asarray(t, dtype=np.float64)
    m = t.shape[0]
    if order < 0:
        raise ValueError(f"derivative order must be >= 0, got {order}")
    ders = np.zeros((order + 1, m, p + 1))
    # ndu[j][r]: basis functions (upper triangle, j >= r ... stored at [r][j]) and knot
    # differences (lower triangle), exactly as in A2.3, each entry an (m,) array
    ndu = [[None] * (p + 1) for _ in range(p + 1)]
    ndu[0][0] = np.ones(m)
    left = [None] * (p + 1)
    right = [None] * (p + 1)
    for j in range(1, p + 1):
        left[j] = t - knots[spans + 1 - j]
        right[j] = knots[spans + j] - t
        saved = np.zeros(m)
        for r in range(j):
            ndu[j][r] = right[r + 1] + left[j - r]
            temp = ndu[r][j - 1] / ndu[j][r]
            ndu[r][j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j][j] = saved
    for j in range(p + 1):
        ders[0, :, j] = ndu[j][p]
    top = min(order, p)
    for r in range(p + 1):
        s1, s2 = 0, 1
        a = [[None] * (p + 1) for _ in range(2)]
        a[0][0] = np.ones(m)
        for k in range(1, top + 1):
            d = np.zeros(m)
            rk, pk = r - k, p - k
            if r >= k:
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk]
                d = a[s2][0] * ndu[rk][pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j]
                d = d + a[s2][j] * ndu[rk + j][pk]
            if r <= pk:
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r]
                d = d + a[s2][k] * ndu[r][pk]
            ders[k, :, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, top + 1):
        ders[k] *= factor
        factor *= p - k
    return ders


def blossom_basis(
    degree: int, knots: np.ndarray, spans: np.ndarray, args: np.ndarray
) -> np.ndarray:
    """The basis functions' blossoms: A2.2 with a different argument at each level.

    Level j of the triangular scheme uses ``args[:, j - 1]``; with all p arguments equal to
    t this is :func:`basis_functions`. Because the blossom is symmetric, the order of the
    arguments does not matter. Row i gives the blossom of the polynomial piece on span
    ``spans[i]`` as a combination of control points ``spans[i] - p .. spans[i]``.

    This one scheme gives knot refinement (the discrete B-splines of the Oslo algorithm,
    Cohen, Lyche and Riesenfeld 1980), Bezier extraction and degree elevation (Ramshaw's
    blossoming principle; The NURBS Book section 5.5).

    Parameters
    ----------
    degree : int
    knots : (n + p + 1,) float
    spans : (m,) int
    args : (m, p) float

    Returns
    -------
    alpha : (m, p + 1) float
    """
    p = degree
    knots = np.asarray(knots, dtype=np.float64)
    spans = np.asarray(spans, dtype=np.int64)
    args = np.asarray(args, dtype=np.float64)
    m = spans.shape[0]
    N = [np.ones(m)]
    for j in range(1, p + 1):
        x = args[:, j - 1]
        saved = np.zeros(m)
        new = []
        for r in range(j):
            hi = knots[spans + r + 1]
            lo = knots[spans + 1 - j + r]
            temp = N[r] / (hi - lo)
            new.append(saved + (hi - x) * temp)
            saved = (x - lo) * temp
        new.append(saved)
        N = new
    return np.stack(N, axis=-1)


# ------------------------------------------------------------------------------ validation


def _check_degree_and_knots(degree: int, knots: np.ndarray, n: int, what: str) -> None:
    if isinstance(degree, bool) or int(degree) != degree:
        raise ValueError(f"{what}degree must be an integer, got {degree!r}")
    if degree < 1:
        raise ValueError(f"{what}degree must be at least 1, got {degree}")
    if n < degree + 1:
        raise ValueError(
            f"{what}degree {degree} needs at least {degree + 1} control points, got {n}"
        )
    knots = np.asarray(knots)
    if knots.ndim != 1:
        raise ValueError(f"{what}knots must be a flat list of numbers, got shape {knots.shape}")
    if len(knots) != n + degree + 1:
        raise ValueError(
            f"{what}knots: {n} control points of degree {degree} need {n + degree + 1} knots "
            f"(control points + degree + 1), got {len(knots)}"
        )
    if not np.all(np.isfinite(knots)):
        raise ValueError(f"{what}knots must be finite numbers, got {knots.tolist()}")
    dk = np.diff(knots)
    if np.any(dk < 0):
        i = int(np.argmax(dk < 0))
        raise ValueError(
            f"{what}knots must be non-decreasing, but knot {i + 1} ({knots[i + 1]:g}) is less "
            f"than knot {i} ({knots[i]:g})"
        )
    if not knots[degree] < knots[n]:
        raise ValueError(
            f"{what}knots give an empty domain: knots[{degree}] = {knots[degree]:g} and "
            f"knots[{n}] = {knots[n]:g} must differ"
        )
    # multiplicities as run lengths of the (now known sorted) knots: no second sort
    starts = np.concatenate([[0], np.flatnonzero(dk != 0) + 1])
    counts = np.diff(np.append(starts, len(knots)))
    values = knots[starts]
    if np.any(counts > degree + 1):
        i = int(np.argmax(counts > degree + 1))
        raise ValueError(
            f"{what}knot {values[i]:g} repeats {counts[i]} times; a knot may repeat at most "
            f"degree + 1 = {degree + 1} times"
        )


def _check_weights(weights: np.ndarray | None, shape: tuple[int, ...], what: str) -> None:
    if weights is None:
        return
    w = np.asarray(weights)
    if w.shape != shape:
        raise ValueError(
            f"{what}weights must have one value per control point, shape {shape}, got shape "
            f"{w.shape}"
        )
    if not np.all(np.isfinite(w)):
        raise ValueError(f"{what}weights must be finite numbers")
    if np.any(w <= 0):
        raise ValueError(f"{what}weights must be positive, got {float(w.min()):g}")


def validate_curve(
    control_points: np.ndarray, degree: int, knots: np.ndarray, weights: np.ndarray | None
) -> None:
    """Raise ``ValueError`` with a sentence if the arrays are not a valid NURBS curve.

    Checks: control points an (n, 3) finite array; degree an integer >= 1 with at least
    degree + 1 control points; ``n + degree + 1`` finite, non-decreasing knots with a
    non-empty domain and no knot repeated more than degree + 1 times; weights (n,),
    finite and positive (or None).
    """
    cp = np.asarray(control_points)
    if cp.ndim != 2 or cp.shape[1] != 3:
        raise ValueError(f"control points must be an (n, 3) array of points, got shape {cp.shape}")
    if not np.all(np.isfinite(cp)):
        raise ValueError("control points must be finite numbers")
    _check_degree_and_knots(degree, knots, cp.shape[0], "")
    _check_weights(weights, (cp.shape[0],), "")


def validate_surface(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
) -> None:
    """Raise ``ValueError`` with a sentence if the arrays are not a valid NURBS surface.

    The same checks as :func:`validate_curve` in each direction (u along the first axis of
    the ``(nu, nv, 3)`` control net), and weights of shape ``(nu, nv)``.
    """
    cp = np.asarray(control_points)
    if cp.ndim != 3 or cp.shape[2] != 3:
        raise ValueError(
            f"surface control points must be an (nu, nv, 3) array, got shape {cp.shape}"
        )
    if not np.all(np.isfinite(cp)):
        raise ValueError("surface control points must be finite numbers")
    _check_degree_and_knots(degree_u, knots_u, cp.shape[0], "u: ")
    _check_degree_and_knots(degree_v, knots_v, cp.shape[1], "v: ")
    _check_weights(weights, cp.shape[:2], "")
