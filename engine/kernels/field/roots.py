"""Vertices on the edges of a mesher's cells: a first guess from the samples along the
edge's grid line, then root-finding on the field itself.

The guess is Newton's method on the cubic through the (up to) four samples at -1, 0, 1, 2
along the edge; the field is sampled there, and a sample within :data:`ACCEPT` of a cell
of zero is the vertex (on a smooth field at mesher cells, nine in ten). Each step after
it moves to the inverse quadratic interpolant's root through the bracket's ends and the
new sample (Brent 1973), or to the regula falsi point (Illinois variant, Dowson &
Harrington 1971) where that root falls outside the bracket; a kink left after that is
bisected.

Edges are parametrized by ``t`` in [0, 1]; the field is reached through ``along(idx, t)``
(its values at parameters ``t`` on edges ``idx``), so a mesher can sample on its
lattice's lines rather than at points.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .lattice import checked

__all__ = ["ACCEPT", "END_GAP", "Brackets", "guess", "roots", "roots_on_segments"]

Fn = Callable[[np.ndarray], np.ndarray]
Along = Callable[[np.ndarray, np.ndarray], np.ndarray]
# a vertex stays this fraction of its edge off either end, so vertices never coincide, not
# even as the float32 coordinates of an STL (at 2,000 cells from the origin an ulp of
# float32 is 1e-4 of a cell)
END_GAP = 5e-4
ACCEPT = 5e-4  # a vertex is done once |f| there is surely below this (cells), see roots


def guess(fm, fa, fb, fq) -> np.ndarray:
    """First guesses of the roots on edges (0, 1) from the values at -1, 0, 1, 2 along
    them (``fm``, ``fq`` NaN where unknown): Newton's method on the cubic (or quadratic)
    through the known ones, from the linear guess; linear where neither is known. Kept
    :data:`END_GAP` off the ends."""
    c1 = fb - fa / 2 - fm / 3 - fq / 6  # the cubic through all four
    c2 = (fm + fb) / 2 - fa
    c3 = (fq - fm) / 6 + (fa - fb) / 2
    lack = np.flatnonzero(np.isnan(c1))  # fm or fq unknown: the quadratic or the line
    if len(lack):
        m, a, b, q = fm[lack], fa[lack], fb[lack], fq[lack]
        has_m, has_q = ~np.isnan(m), ~np.isnan(q)
        c1[lack] = np.where(has_m, (b - m) / 2, np.where(has_q, (-3 * a + 4 * b - q) / 2, b - a))
        c2[lack] = np.where(has_m, (b - 2 * a + m) / 2, np.where(has_q, (a - 2 * b + q) / 2, 0.0))
        c3[lack] = 0.0
    den = fa - fb
    lin = np.divide(fa, den, out=np.full(len(fa), 0.5), where=den != 0)
    t = lin.copy()
    c2x2, c3x3 = 2 * c2, 3 * c3
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(2):  # two Newton steps: a third changes 0.3 % of the vertices' cost
            p = c3 * t
            p += c2
            p *= t
            p += c1
            p *= t
            p += fa
            dp = c3x3 * t
            dp += c2x2
            dp *= t
            dp += c1
            p /= dp
            t -= p
            np.clip(t, 0.0, 1.0, out=t)
    bad = np.flatnonzero(~np.isfinite(t))
    t[bad] = lin[bad]
    return np.clip(t, END_GAP, 1 - END_GAP, out=t)


class Brackets:
    """Edges whose vertex is not found yet, gathered chunk by chunk (:meth:`first`) and
    then stepped all together (:func:`roots`), so the field is called on few, large
    arrays: their numbers (``idx``, the caller's), the next point to sample (``t``), the
    bracket ``[lo, hi]`` with the values there, and what the caller needs to sample them
    (``extra``)."""

    def __init__(self):
        self.parts: list[tuple[np.ndarray, ...]] = []
        self._arrays = None

    def first(self, idx, t, fc, fa, fb, cell: float, lipschitz: float, *extra) -> np.ndarray:
        """The first sample ``fc`` at ``t`` on edges ``idx`` with end values ``fa`` (t =
        0) and ``fb`` (t = 1), of opposite signs: the vertices' ``t`` where that sample
        decides them; the edges that need more are kept with the rows of ``extra`` (their
        entries in the returned ``t`` are provisional)."""
        n = len(t)
        done, nxt, lo, hi, flo, fhi = _step(t, fc, np.zeros(n), np.ones(n), fa, fb, cell, lipschitz)
        if not done.all():
            more = np.flatnonzero(~done)
            part = (idx, nxt, lo, hi, flo, fhi, *extra)
            self.parts.append(tuple(np.take(a, more, axis=0) for a in part))
            self._arrays = None
        return nxt

    def arrays(self) -> tuple[np.ndarray, ...]:
        """``(idx, t, lo, hi, flo, fhi, *extra)`` of every edge kept, concatenated."""
        if self._arrays is None:
            if not self.parts:
                return (np.zeros(0, np.int64), *(np.zeros(0) for _ in range(5)))
            self._arrays = tuple(np.concatenate(a) for a in zip(*self.parts, strict=True))
        return self._arrays


def _step(c, fc, a, b, f_a, f_b, cell: float, lipschitz: float):
    """One root step from the sample ``fc`` at ``c`` inside brackets ``[a, b]`` (values
    ``f_a``, ``f_b`` of opposite signs): whether the vertex is found (then it is the
    returned ``t``), the next point otherwise, and the shrunk brackets.

    A sample within ACCEPT of a cell of zero is the vertex. Otherwise the step is the
    inverse quadratic interpolant's root through the bracket's ends and the sample, or
    the regula falsi point where that falls outside the shrunk bracket. A step not
    sampled moves the point by ``|t' - c|`` of the edge: for an L-Lipschitz field its
    value is then at most ``|f(c)| + L cell |t' - c|``; where that bound is within ACCEPT
    of a cell the step is taken without sampling it (on a smooth field it lands far
    closer); the rest are sampled there.
    """
    accept = ACCEPT * cell
    done = np.abs(fc) <= accept
    t = c.copy()
    rest = np.flatnonzero(~done)
    if not len(rest):
        return done, t, a, b, f_a, f_b
    a, b, f_a, f_b = a.copy(), b.copy(), f_a.copy(), f_b.copy()
    cr, fr, ar, br, far, fbr = c[rest], fc[rest], a[rest], b[rest], f_a[rest], f_b[rest]
    with np.errstate(divide="ignore", invalid="ignore"):
        iqi = (
            ar * fbr * fr / ((far - fbr) * (far - fr))
            + br * far * fr / ((fbr - far) * (fbr - fr))
            + cr * far * fbr / ((fr - far) * (fr - fbr))
        )
    low = (fr < 0) == (far < 0)  # the sample replaces the end of its own sign
    ar, far = np.where(low, cr, ar), np.where(low, fr, far)
    br, fbr = np.where(low, br, cr), np.where(low, fbr, fr)
    a[rest], f_a[rest], b[rest], f_b[rest] = ar, far, br, fbr
    den = far - fbr
    rf = ar + np.divide(far, den, out=np.full(len(ar), 0.5), where=den != 0) * (br - ar)
    inside = np.isfinite(iqi) & (iqi > ar) & (iqi < br)
    step = np.clip(np.where(inside, iqi, rf), END_GAP, 1 - END_GAP)
    t[rest] = step
    done[rest] = np.abs(fr) + lipschitz * cell * np.abs(step - cr) <= accept
    return done, t, a, b, f_a, f_b


def roots(along: Along, brackets: Brackets, steps: int, cell: float, lipschitz: float = 1.0):
    """The vertices left in ``brackets`` after their first sample: ``(idx, t)``.

    ``along(i, t)`` samples the field at parameters ``t`` on edges ``i`` (rows of the
    brackets' :meth:`~Brackets.arrays`, whose ``extra`` say where the edges are). Up to
    ``steps - 1`` more steps (see :func:`_step`) sample and step; what is left after them
    (a kink of a sharp union on the edge converges only linearly) is bisected, which
    halves the bracket every step whatever the field's shape, to ``1e-4`` of a cell of
    zero.
    """
    idx, t, lo, hi, flo, fhi = brackets.arrays()[:6]
    tol = 1e-4 * cell
    live = np.arange(len(t))
    for _ in range(steps - 1):
        if not len(live):
            break
        c = t[live]
        fc = checked(along(live, c))
        done, nxt, a, b, f_a, f_b = _step(
            c, fc, lo[live], hi[live], flo[live], fhi[live], cell, lipschitz
        )
        lo[live], hi[live], flo[live], fhi[live] = a, b, f_a, f_b
        t[live] = nxt
        live = live[~done]
    for _ in range(16 if len(live) else 0):
        t[live] = np.clip((lo[live] + hi[live]) / 2.0, END_GAP, 1 - END_GAP)
        fp = checked(along(live, t[live]))
        low = (fp < 0) == (flo[live] < 0)
        lo[live[low]], flo[live[low]] = t[live[low]], fp[low]
        hi[live[~low]], fhi[live[~low]] = t[live[~low]], fp[~low]
        live = live[np.abs(fp) > tol]
        if not len(live):
            break
    return idx, t


def roots_on_segments(
    f: Fn, pa, pb, fa, fb, steps: int, cell: float, start=None, lipschitz: float = 1.0
) -> np.ndarray:
    """Points where ``f`` changes sign on segments ``pa -> pb`` (``fa``, ``fb`` of
    opposite signs: one < 0, the other >= 0), from first guesses ``start`` (linear if
    none) by :func:`roots`; each ends where ``|f| <= ACCEPT * cell`` for an L-Lipschitz
    ``f`` (``lipschitz``), ``END_GAP`` off the ends, so edges meeting at a corner on the
    surface give distinct vertices. ``steps = 0`` is linear interpolation."""
    d = pb - pa
    if start is None:
        den = fa - fb
        start = np.divide(fa, den, out=np.full(len(fa), 0.5), where=den != 0)
    t = np.clip(start, END_GAP, 1 - END_GAP)
    if steps:
        br = Brackets()
        fc = checked(f(pa + t[:, None] * d))
        t = br.first(np.arange(len(t)), t, fc, fa, fb, cell, lipschitz, pa, d)

        def along(i, s):
            p, dp = br.arrays()[6:]
            return f(p[i] + s[:, None] * dp[i])

        idx, tr = roots(along, br, steps, cell, lipschitz)
        t[idx] = tr
    return pa + t[:, None] * d
