"""Adaptive quadrature breaks: split the intervals of a partition until 8-point
Gauss-Legendre on each agrees with its two halves, so a length is good to ``rtol``."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["refine_breaks"]


def refine_breaks(
    speed: Callable[[np.ndarray], np.ndarray],
    breaks: np.ndarray,
    rtol: float = 1e-12,
    max_intervals: int = 1 << 16,
) -> np.ndarray:
    """Breaks on which Gauss-Legendre integrates ``speed`` to ``rtol`` of the total.

    Every round integrates each undecided interval whole and as two halves (8 points each,
    all intervals in one vectorized call); an interval is kept when the two agree to its
    share of the tolerance, ``rtol * total * width / domain``, else it is split. Rounds stop
    when all are kept or ``max_intervals`` would be passed (then the finest partition so far).

    Parameters
    ----------
    speed : callable, (m,) float -> (m,) float
        The integrand, ``|C'(t)|`` for a length.
    breaks : (k,) float
        Increasing parameters, the domain's ends first and last.

    Returns
    -------
    (k',) float
        The refined, increasing breaks (a superset of ``breaks``).
    """
    breaks = np.asarray(breaks, dtype=np.float64)
    span = breaks[-1] - breaks[0]
    done = [breaks]
    lo, hi = breaks[:-1], breaks[1:]
    total = None
    while lo.size:
        mid = 0.5 * (lo + hi)
        edges = np.column_stack([lo, mid, hi]).ravel()
        whole = _pieces(speed, np.column_stack([lo, hi]))
        halves = _pieces(speed, edges.reshape(-1, 3)[:, [0, 1, 1, 2]].reshape(-1, 2))
        halves = halves.reshape(-1, 2).sum(axis=1)
        if total is None:
            total = float(halves.sum())
        share = rtol * max(abs(total), 1e-300) * (hi - lo) / span
        split = np.abs(halves - whole) > share
        done.append(mid[split])
        if not split.any() or sum(d.size for d in done) * 2 > max_intervals:
            break
        lo = np.concatenate([lo[split], mid[split]])
        hi = np.concatenate([mid[split], hi[split]])
    return np.unique(np.concatenate(done))


def _pieces(speed: Callable[[np.ndarray], np.ndarray], intervals: np.ndarray) -> np.ndarray:
    """The Gauss-Legendre integral of ``speed`` over each (start, end) row."""
    x, w = np.polynomial.legendre.leggauss(8)
    a, b = intervals[:, :1], intervals[:, 1:]
    t = 0.5 * (a + b) + 0.5 * (b - a) * x
    values = np.asarray(speed(t.ravel()), dtype=np.float64).reshape(t.shape)
    return (values * (0.5 * (b - a)) * w).sum(axis=1)
