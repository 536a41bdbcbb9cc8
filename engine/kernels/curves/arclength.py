"""Arc length of a curve given by its derivative: the table, its inverse, even division.

Pure array functions for any curve whose derivative ``C'(t)`` can be evaluated vectorized
(NURBS, parametric); the length is integrated by Gauss-Legendre quadrature piecewise and
inverted through the polynomial that interpolates each piece's quadrature speeds, then
by safeguarded Newton steps on the curve itself. ``curves.divide`` and ``curves.resample`` divide a
curve at equal arc length through :func:`even_arc_parameters`; polylines, whose length is
exact from their chords, use :func:`formgraph.kernels.curves.polylines.resample_polyline`,
which places its points by :func:`even_lengths` too.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = [
    "arc_length_table",
    "parameters_at_lengths",
    "even_lengths",
    "even_arc_parameters",
]

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
    edges, cumulative, _ = _table(speed, breaks, pieces)
    return edges, cumulative


def _table(
    speed: Callable[[np.ndarray], np.ndarray], breaks: np.ndarray, pieces: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`arc_length_table` and the speeds it summed, ``(pieces, 8)``: one row a piece,
    at its Gauss nodes (what :func:`parameters_at_lengths` inverts without sampling again)."""
    b = np.unique(np.asarray(breaks, dtype=np.float64))
    f = np.linspace(0.0, 1.0, pieces + 1)[:-1]
    edges = np.append((b[:-1, None] + np.diff(b)[:, None] * f).ravel(), b[-1])
    lo, hi = edges[:-1], edges[1:]
    half = 0.5 * (hi - lo)
    tq = (lo + half)[:, None] + half[:, None] * _GAUSS_X
    at_nodes = speed(tq.ravel()).reshape(tq.shape)
    length = half * (at_nodes @ _GAUSS_W)
    return edges, np.concatenate([[0.0], np.cumsum(length)]), at_nodes


# The degree-7 polynomial through a piece's 8 Gauss-node speeds, as monomial coefficients on
# [-1, 1] (row i: the coefficient of x^i from the 8 values), and its integral from -1 as
# coefficients of x^1..x^8 plus the constant that makes it 0 at -1. Integrated over the whole
# piece it is exactly the Gauss sum: the inverse agrees with the table at every edge.
_TO_MONOMIAL = np.linalg.inv(np.vander(_GAUSS_X, 8, increasing=True))
_AT_MINUS_ONE = -((-1.0) ** np.arange(1, 9))


def _monomial(at_nodes: np.ndarray) -> np.ndarray:
    """The coefficients of x^0..x^7 on [-1, 1] of the polynomial through each row's 8
    Gauss-node speeds, ``(pieces, 8)``."""
    return at_nodes @ _TO_MONOMIAL.T


def _invert_interpolant(
    c: np.ndarray, half: np.ndarray, rest: np.ndarray, frac: np.ndarray
) -> np.ndarray:
    """Where, within its piece (as x in [-1, 1]), the interpolated speed (coefficients ``c``
    of :func:`_monomial`, one row a target) has covered ``rest`` of the length: Newton on
    ``half * P(x) = rest`` for the interpolant's integral P, from the linear guess ``frac``,
    kept inside the piece. Arrays of the targets only: no sample of the curve is taken."""
    integral = c / np.arange(1, 9)  # coefficients of x^1..x^8
    base = integral @ _AT_MINUS_ONE
    goal = np.divide(rest, half, out=np.zeros_like(rest), where=half > 0.0)
    x = 2.0 * frac - 1.0
    for _ in range(8):
        value = integral[:, 7].copy()  # Horner, x^8 .. x^1, and the speed x^7 .. x^0
        rate = c[:, 7].copy()
        for i in range(6, -1, -1):
            value = value * x + integral[:, i]
            rate = rate * x + c[:, i]
        value = value * x + base
        step = np.divide(value - goal, rate, out=np.zeros_like(x), where=rate > 1e-300)
        x = np.clip(x - step, -1.0, 1.0)
    return x


def _interpolant_exact(
    speed: Callable[[np.ndarray], np.ndarray],
    edges: np.ndarray,
    pieces: np.ndarray,
    c: np.ndarray,
    scale: np.ndarray,
) -> np.ndarray:
    """Per piece of ``pieces``: whether the degree-7 polynomial through its Gauss-node speeds
    (coefficients ``c`` of :func:`_monomial`, one row a piece) matches the true speed at
    both ends and at the middle within 1e-12 of ``scale`` (the piece's mean speed). The
    error of an interpolant at the Gauss nodes is f^(8)/8! times the nodes' polynomial,
    which is largest in magnitude at the ends of the piece; the middle catches a piece whose
    speed changes its character inside (three samples a piece, one call of ``speed``)."""
    lo, hi = edges[pieces], edges[pieces + 1]
    m = len(pieces)
    true = speed(np.concatenate([lo, 0.5 * (lo + hi), hi])).reshape(3, m)
    sign = (-1.0) ** np.arange(8)
    guessed = np.stack([c @ sign, c[:, 0], c.sum(axis=1)])
    return np.all(np.abs(guessed - true) <= 1e-12 * scale, axis=0) & (scale > 0.0)


def parameters_at_lengths(
    speed: Callable[[np.ndarray], np.ndarray],
    edges: np.ndarray,
    cumulative: np.ndarray,
    lengths: np.ndarray,
    iterations: int = 4,
    at_nodes: np.ndarray | None = None,
) -> np.ndarray:
    """Parameters where the arc length from ``edges[0]`` equals each of ``lengths``.

    Inverse of :func:`arc_length_table`: the piece holding each length is found by binary
    search, the parameter is guessed within it and refined by safeguarded Newton steps on
    s(t) - s = 0, s'(t) = |C'(t)| (each step integrates from the piece start by
    Gauss-Legendre and takes the speed at t, in one call of ``speed``; a step is kept inside
    its piece and skipped where the speed vanishes). A target whose step moved it less than
    1e-8 of its piece takes no more: Newton's error then squares to below rounding.

    The guess is linear within the piece, or, given ``at_nodes`` (the table's speeds at each
    piece's Gauss nodes, ``(pieces, 8)``), the exact inverse of the degree-7 polynomial
    through them (no sample of the curve). A piece where that polynomial matches the speed
    at the piece's two ends and its middle to 1e-12 (the ends are where a Gauss-node
    interpolant's error is largest) keeps the inverse as it is; the others take the Newton
    steps, from a guess close enough that one step usually finishes.

    Returns
    -------
    (m,) float
        Non-decreasing when ``lengths`` is.
    """
    s = np.asarray(lengths, dtype=np.float64)
    k = np.clip(np.searchsorted(cumulative, s, side="right") - 1, 0, len(edges) - 2)
    lo, hi = edges[k], edges[k + 1]
    piece = cumulative[k + 1] - cumulative[k]
    rest = s - cumulative[k]
    frac = np.clip(np.divide(rest, piece, out=np.zeros_like(s), where=piece > 0.0), 0.0, 1.0)
    if at_nodes is None:
        t = lo + (hi - lo) * frac
        active = np.arange(len(s))  # the targets still moving
    else:  # Newton only where the interpolant is not exact to rounding
        pieces, of_target = np.unique(k, return_inverse=True)
        c = _monomial(at_nodes[pieces])
        x = _invert_interpolant(c[of_target], 0.5 * (hi - lo), rest, frac)
        t = lo + 0.5 * (hi - lo) * (x + 1.0)
        scale = np.abs(at_nodes[pieces]).mean(axis=1)
        trusted = _interpolant_exact(speed, edges, pieces, c, scale)
        active = np.flatnonzero(~trusted[of_target])
    for _ in range(iterations):
        if active.size == 0:
            break
        ta, la, ha, n = t[active], lo[active], hi[active], active.size
        half = 0.5 * (ta - la)
        tq = (la + half)[:, None] + half[:, None] * _GAUSS_X
        both = speed(np.concatenate([tq.ravel(), ta]))
        s_t = cumulative[k[active]] + half * (both[: 8 * n].reshape(n, 8) @ _GAUSS_W)
        v = both[8 * n :]
        step = np.divide(s_t - s[active], v, out=np.zeros(n), where=v > 1e-300)
        t[active] = np.clip(ta - step, la, ha)
        active = active[np.abs(step) > 1e-8 * (ha - la)]
    return t


def even_lengths(length: float, count: int, closed: bool) -> np.ndarray:
    """``count`` arc lengths dividing ``length`` evenly: an open curve gets both ends, a
    closed one its start and no repeat of it (the last gap closes the loop).

    Returns
    -------
    (count,) float
    """
    if closed:
        return np.arange(count) * (length / count)
    return np.linspace(0.0, length, count)


def even_arc_parameters(
    derivative: Callable[[np.ndarray], np.ndarray],
    breaks: np.ndarray,
    divisions: Callable[[float], int],
    closed: bool,
    pieces: int = 16,
) -> np.ndarray:
    """Parameters of points at equal arc length along a curve.

    The length is tabulated by :func:`arc_length_table`, ``divisions`` says how many points
    that length gets, the lengths are placed by :func:`even_lengths` and inverted by
    :func:`parameters_at_lengths`.

    Parameters
    ----------
    derivative : callable, (m,) float -> (m, 3) float
        C'(t), vectorized.
    breaks : (k,) float
        Increasing parameters where the speed may have a kink (knot spans), the domain's
        ends first and last.
    divisions : callable, float -> int
        The number of points for the curve's length, asked once the length is known and
        before anything of that size is made: the caller rounds a spacing, checks the
        count and charges its budget there (and raises as it sees fit).
    closed : bool
        Closed: the first point at the start, none at the end (see :func:`even_lengths`).
    pieces : int
        Quadrature pieces per interval between breaks.

    Returns
    -------
    (divisions(length),) float
        Non-decreasing parameters; the first is ``breaks[0]``.

    Example
    -------
    A quarter of an ellipse of semi-axes 2 and 1, cut in three equal lengths:

    >>> def d(t):
    ...     return np.c_[-2 * np.sin(t), np.cos(t), 0 * t]
    >>> t = even_arc_parameters(d, [0, np.pi / 2], lambda length: 4, closed=False)
    >>> t.round(4).tolist()
    [0.0, 0.682, 1.1585, 1.5708]
    """

    def speed(t: np.ndarray) -> np.ndarray:
        return np.linalg.norm(derivative(t), axis=-1)

    edges, cumulative, at_nodes = _table(speed, breaks, pieces)
    length = float(cumulative[-1])
    lengths = even_lengths(length, divisions(length), closed)
    return parameters_at_lengths(speed, edges, cumulative, lengths, at_nodes=at_nodes)
