"""Vertices on the edges of a mesher's cells: a first guess from the samples along the
edge's grid line, then root-finding on the field itself.

The guess is Newton's method on the cubic through the (up to) four samples at -1, 0, 1, 2
along the edge; each step after it samples the field and moves to the inverse quadratic
interpolant's root through the bracket's ends and the new sample (Brent 1973), or to the
regula falsi point (Illinois variant, Dowson & Harrington 1971) where that root falls
outside the bracket; a kink left after that is bisected.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["ACCEPT", "END_GAP", "guess", "roots"]

Fn = Callable[[np.ndarray], np.ndarray]
# a vertex stays this fraction of its edge off either end, so vertices never coincide, not
# even as the float32 coordinates of an STL (at 2,000 cells from the origin an ulp of
# float32 is 1e-4 of a cell)
END_GAP = 5e-4
ACCEPT = 5e-4  # a vertex is done once |f| there is surely below this (cells), see roots


def _check(values: np.ndarray) -> np.ndarray:
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if not np.isfinite(v).all():
        raise ValueError("the field is not finite at some points (NaN or infinity)")
    return v


def _eval(f: Fn, p: np.ndarray, chunk: int = 1 << 16) -> np.ndarray:
    if len(p) <= chunk:
        return _check(f(p))
    return np.concatenate([_check(f(p[i : i + chunk])) for i in range(0, len(p), chunk)])


def guess(fm, fa, fb, fq) -> np.ndarray:
    """First guesses of the roots on edges (0, 1) from the values at -1, 0, 1, 2 along
    them (``fm``, ``fq`` NaN where unknown): Newton's method on the cubic (or quadratic)
    through the known ones, from the linear guess; linear where neither is known."""
    has_m, has_q = ~np.isnan(fm), ~np.isnan(fq)
    both = has_m & has_q
    c1 = -fm / 3 - fa / 2 + fb - fq / 6  # the cubic through all four
    c2 = fm / 2 - fa + fb / 2
    c3 = -fm / 6 + fa / 2 - fb / 2 + fq / 6
    if not both.all():
        m, q = has_m & ~has_q, ~has_m & has_q
        c1 = np.where(both, c1, fb - fa)
        c2, c3 = np.where(both, c2, 0.0), np.where(both, c3, 0.0)
        c1 = np.where(m, (fb - fm) / 2, np.where(q, (-3 * fa + 4 * fb - fq) / 2, c1))
        c2 = np.where(m, (fb - 2 * fa + fm) / 2, np.where(q, (fa - 2 * fb + fq) / 2, c2))
    den = fa - fb
    lin = np.divide(fa, den, out=np.full(len(fa), 0.5), where=den != 0)
    t = lin
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(2):  # two Newton steps: a third changes 0.3 % of the vertices' cost
            p = fa + t * (c1 + t * (c2 + t * c3))
            dp = c1 + t * (2 * c2 + 3 * t * c3)
            t = np.clip(t - p / dp, 0.0, 1.0)
    return np.where(np.isfinite(t), t, lin)


def roots(
    f: Fn, pa, pb, fa, fb, steps: int, cell: float, guess=None, lipschitz: float = 1.0, first=None
) -> np.ndarray:
    """Points where ``f`` changes sign on segments ``pa -> pb``.

    ``fa`` and ``fb`` have opposite signs (one is < 0, the other >= 0). From ``guess``
    (the linear one if none), each step samples the field and moves to the inverse
    quadratic interpolant's root through the bracket's ends and the new sample (exact for
    a quadratic along the edge, Brent 1973), or to the regula falsi point of the shrunk
    bracket where that root falls outside it. A step is taken without sampling it where
    the Lipschitz bound already keeps ``|f|`` there below ``ACCEPT`` cells, so most
    vertices cost one sample and every one ends within that (an L-Lipschitz field). What
    is left after ``steps`` (a kink of a sharp union on the edge) is bisected. Points are
    kept ``END_GAP`` off the ends, so edges meeting at a corner on the surface give
    distinct vertices (and no triangle collapses to a point in a file of float32
    coordinates).
    """
    n = len(pa)
    lo_t, hi_t = np.zeros(n), np.ones(n)
    flo, fhi = fa.copy(), fb.copy()
    den = flo - fhi
    if guess is None:
        guess = np.divide(flo, den, out=np.full(n, 0.5), where=den != 0)
    t = np.clip(guess, END_GAP, 1 - END_GAP)
    tol = 1e-4 * cell
    idx = np.arange(n)
    d = pb - pa
    for k in range(steps):
        at = slice(None) if k == 0 else idx  # every vertex takes the first step
        c = t[at]
        if k == 0 and first is not None:  # the field on the edges' lines: ``first(t)``
            fc = _check(first(c))
        else:
            fc = _eval(f, pa[at] + c[:, None] * d[at])
        a, b, f_a, f_b = lo_t[at], hi_t[at], flo[at], fhi[at]
        with np.errstate(divide="ignore", invalid="ignore"):
            iqi = (
                a * f_b * fc / ((f_a - f_b) * (f_a - fc))
                + b * f_a * fc / ((f_b - f_a) * (f_b - fc))
                + c * f_a * f_b / ((fc - f_a) * (fc - f_b))
            )
        low = (fc < 0) == (f_a < 0)  # the sample replaces the end of its own sign
        a, f_a = np.where(low, c, a), np.where(low, fc, f_a)
        b, f_b = np.where(low, b, c), np.where(low, f_b, fc)
        lo_t[at], flo[at], hi_t[at], fhi[at] = a, f_a, b, f_b
        den = f_a - f_b
        rf = a + np.divide(f_a, den, out=np.full(len(a), 0.5), where=den != 0) * (b - a)
        inside = np.isfinite(iqi) & (iqi > a) & (iqi < b)
        conv = np.abs(fc) <= tol
        step = np.clip(np.where(inside, iqi, rf), END_GAP, 1 - END_GAP)
        # a step not sampled moves the point by |t' - c| of the edge: for an L-Lipschitz
        # field its value is then at most |f(c)| + L cell |t' - c|. Where that bound is
        # within ACCEPT of a cell, take the step (on a smooth field it lands far closer);
        # where only |f(c)| is, keep c; the rest sample again
        bound = np.abs(fc) + lipschitz * cell * np.abs(step - c)
        take = ~conv & (bound <= ACCEPT * cell)
        keep = ~conv & ~take & (np.abs(fc) <= ACCEPT * cell)
        t[at] = np.where(conv | keep, c, step)
        idx = idx[~(conv | take | keep)]
        if not len(idx):
            break
    # what is left (a kink of a sharp union on the edge converges only linearly):
    # bisection of the bracket, which halves it every step whatever the field's shape
    for _ in range(16 if steps else 0):
        if not len(idx):
            break
        t[idx] = np.clip((lo_t[idx] + hi_t[idx]) / 2.0, END_GAP, 1 - END_GAP)
        fp = _eval(f, pa[idx] + t[idx, None] * d[idx])
        low = (fp < 0) == (flo[idx] < 0)
        lo_t[idx[low]], flo[idx[low]] = t[idx[low]], fp[low]
        hi_t[idx[~low]], fhi[idx[~low]] = t[idx[~low]], fp[~low]
        idx = idx[np.abs(fp) > tol]
    return pa + t[:, None] * d
