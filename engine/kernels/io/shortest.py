"""Shortest round-trip decimal digits of doubles (the digits ``repr`` prints), vectorized.

The text exporters write coordinates as the shortest decimal that reads back to the same
double; :func:`shortest_decimal` finds those digits for a whole array at once, with no
Python loop per value (:mod:`formgraph.kernels.io.numfmt` lays them out as text).
"""

from __future__ import annotations

from fractions import Fraction
from functools import cache

import numpy as np

__all__ = ["POW10_INT", "check_finite", "shortest_decimal"]

POW10_INT = 10 ** np.arange(19, dtype=np.int64)


def check_finite(values: np.ndarray, what: str) -> None:
    """Refuse NaN and infinity with a sentence naming ``what``."""
    if not np.all(np.isfinite(values)):
        bad = values[~np.isfinite(values)][0]
        raise ValueError(f"{what} must be finite numbers to be written as text, got {bad}")


@cache
def _pow10_double_double() -> tuple[np.ndarray, np.ndarray]:
    """``10**k`` for k in [-300, 308] as unevaluated sums hi + lo of two doubles (exact to 2^-106).

    Index with ``k + 300``. Python's Fraction -> float conversion is correctly rounded.
    """
    ks = range(-300, 309)
    hi = np.empty(len(ks))
    lo = np.empty(len(ks))
    for i, k in enumerate(ks):
        exact = Fraction(10) ** k
        hi[i] = float(exact)
        lo[i] = float(exact - Fraction(hi[i]))
    return hi, lo


def _split(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Veltkamp/Dekker split of doubles into 26- and 27-bit halves (a = h + l exactly)."""
    c = a * 134217729.0  # 2**27 + 1
    h = c - (c - a)
    return h, a - h


def _two_prod(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Dekker's exact product: p + e == a * b exactly (T. J. Dekker, 1971)."""
    p = a * b
    ah, al = _split(a)
    bh, bl = _split(b)
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, e


def _scaled_17(a: np.ndarray, e10: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``a * 10**(16 - e10)`` as an integer part (int64) and a fraction in [0, 1).

    The product is carried in double-double arithmetic, so the integer part is exact and the
    fraction is good to ~1e-15: enough to round correctly to any number of digits.
    """
    hi, lo = _pow10_double_double()
    k = 16 - e10 + 300
    p, e = _two_prod(a, hi[k])
    q = e + a * lo[k]
    s = p + q
    t = q - (s - p)  # |p| >= |q|: fast two-sum
    # s >= 2**53 here, so it holds an integer exactly
    fl = np.floor(t)
    return s.astype(np.int64) + fl.astype(np.int64), t - fl


def shortest_decimal(
    x: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The shortest decimal that reads back as the same double, for every element of ``x``.

    The digits Python's ``repr(float)`` prints (shortest, and among the shortest the nearest),
    found with array arithmetic: the value is scaled to 17 digits in double-double arithmetic
    (Dekker's exact product), then a search over how many trailing digits can be dropped keeps
    the decimal inside the rounding interval of the double (half the gap to each neighbour) —
    the round-trip criterion of Steele & White, "How to print floating-point numbers
    accurately", PLDI 1990. Integers from 2**53 to 2**63 are done exactly in int64, where a
    decimal on the boundary reads back when the significand is even (round-half-even), as
    repr allows. Values beyond (above 2**63 or below 1e-280 in magnitude) go through numpy's
    own shortest formatting one by one.

    Parameters
    ----------
    x : (n,) float64
        Finite values.

    Returns
    -------
    negative : (n,) bool
        Sign bit (so -0.0 is negative, as repr prints it).
    mantissa : (n,) int64
        The digits as an integer, no trailing zeros (0 for zero).
    ndigits : (n,) int64
        Number of digits in ``mantissa`` (1 to 19).
    exp10 : (n,) int64
        Decimal exponent of the first digit: value = mantissa * 10**(exp10 - ndigits + 1).
    """
    x = np.asarray(x, dtype=np.float64).ravel()
    check_finite(x, "values")
    negative = np.signbit(x)
    a = np.abs(x)
    n = a.size
    mantissa = np.zeros(n, dtype=np.int64)
    ndigits = np.ones(n, dtype=np.int64)
    exp10 = np.zeros(n, dtype=np.int64)

    scaled = (a >= 1e-280) & (a < 2.0**53)
    zero = a == 0
    if np.all(scaled | zero):  # the usual case: no gathering and scattering
        m, d, e = _shortest_scaled(np.where(zero, 1.0, a))
        return negative, np.where(zero, 0, m), np.where(zero, 1, d), np.where(zero, 0, e)
    big = (a >= 2.0**53) & (a < 2.0**63)
    idx = np.flatnonzero(scaled)
    if idx.size:
        mantissa[idx], ndigits[idx], exp10[idx] = _shortest_scaled(a[idx])
    idx = np.flatnonzero(big)
    if idx.size:
        mantissa[idx], ndigits[idx], exp10[idx] = _shortest_big(a[idx])
    for i in np.flatnonzero((a != 0) & ~scaled & ~big):  # beyond the ranges above: rare
        digits, exponent = np.format_float_scientific(a[i], unique=True, trim="-").split("e")
        digits = digits.replace(".", "")
        mantissa[i], ndigits[i], exp10[i] = int(digits), len(digits), int(exponent)
    return negative, mantissa, ndigits, exp10


def _shortest_scaled(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`shortest_decimal` for 1e-280 <= a < 2**53 (positive)."""
    e10 = np.floor(np.log10(a)).astype(np.int64)
    vint, frac = _scaled_17(a, e10)
    # log10 may be one off next to a power of ten: settle the exponent so round(T) has 17 digits
    for _ in range(3):
        r17 = vint + (frac >= 0.5)
        low, high = r17 < 10**16, r17 >= 10**17
        fix = np.flatnonzero(low | high)
        if fix.size == 0:
            break
        e10[fix] += np.where(high[fix], 1, -1)
        vint[fix], frac[fix] = _scaled_17(a[fix], e10[fix])
    # half the gap to each neighbouring double in units of the scaled value, with a margin far
    # above the ~1e-15 error of the scaling so that an accepted decimal always reads back. A
    # decimal of at most 16 digits never sits exactly on the boundary below 2**53 (the midpoint
    # of two such doubles needs 17 digits), so no tie rule is needed here.
    hi, _ = _pow10_double_double()
    scale = hi[16 - e10 + 300] * (0.5 * (1.0 - 2.0**-40))
    bound_up = np.spacing(a) * scale
    bound_down = (a - np.nextafter(a, 0.0)) * scale
    mantissa, dropped = _drop_digits(vint, frac, bound_down, bound_up, None, np.full(a.size, 16))
    return _carry(mantissa, 17 - dropped, e10)


def _shortest_big(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`shortest_decimal` for integers 2**53 <= a < 2**63, exactly in int64."""
    vint = a.astype(np.int64)
    total = np.searchsorted(POW10_INT, vint, side="right")  # number of digits
    gap = np.spacing(a)
    bound_up = 0.5 * gap
    bound_down = 0.5 * (a - np.nextafter(a, 0.0))
    even = (vint // gap.astype(np.int64)) % 2 == 0
    frac = np.zeros(a.size)
    mantissa, dropped = _drop_digits(vint, frac, bound_down, bound_up, even, total - 1)
    return _carry(mantissa, total - dropped, total - 1)


def _carry(
    mantissa: np.ndarray, ndigits: np.ndarray, e10: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rounding up may carry into a new digit (9.99... -> 10): the value is then 10**(e10+1)."""
    carry = mantissa == POW10_INT[ndigits]
    return (
        np.where(carry, 1, mantissa),
        np.where(carry, 1, ndigits),
        e10 + carry,
    )


def _drop_digits(
    vint: np.ndarray,
    frac: np.ndarray,
    bound_down: np.ndarray,
    bound_up: np.ndarray,
    even: np.ndarray | None,
    max_drop: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Most trailing digits of ``vint + frac`` that can be dropped with rounding still reading back.

    A decimal below the value reads back when its distance is under ``bound_down`` (under or,
    with ``even``, equal), one above under ``bound_up``. Dropping more digits only moves the
    nearest candidate further away, so the answer is found by search: dropping 1 and then 2
    digits is tried first (most doubles need 16 or 17 digits), the rest by bisection over the
    values still undecided.

    Returns
    -------
    mantissa : (n,) int64
        The kept digits, rounded.
    dropped : (n,) int64
    """
    arrays = (vint, frac, bound_down, bound_up, even)

    def trial(j, v, f, bd, bu, ev):
        div = POW10_INT[j]
        q = v // div
        rem = v - q * div
        dist_down = rem + f  # distance to q * div
        dist_up = (div - rem).astype(np.float64) - f  # distance to (q + 1) * div
        ok_down = dist_down < bd
        ok_up = dist_up < bu
        if ev is not None:  # on the boundary, an even significand reads back (half-even)
            ok_down |= ev & (dist_down == bd)
            ok_up |= ev & (dist_up == bu)
        # the nearest wins; an exact tie goes to the even digit, as repr does
        up = ok_up & (~ok_down | (dist_up < dist_down) | ((dist_up == dist_down) & (q % 2 == 1)))
        return ok_down | ok_up, q, up

    n = vint.size
    # dropping nothing always reads back: round the 17 digits half to even
    half = (frac > 0.5) | ((frac == 0.5) & (vint % 2 == 1))
    mantissa = vint + half
    dropped = np.zeros(n, dtype=np.int64)
    idx = np.arange(n)
    sub = arrays
    for step in (1, 2):  # max_drop >= 15 always, so both steps are allowed
        ok, q, up = trial(step, *sub)
        idx = idx[ok]
        dropped[idx] = step
        mantissa[idx] = (q + up)[ok]
        sub = tuple(None if arr is None else arr[ok] for arr in sub)
    lo = np.full(idx.size, 2, dtype=np.int64)
    hi = max_drop[idx]
    if np.any(lo < hi):  # the rest (values with 15 digits or fewer) by bisection
        while True:
            active = lo < hi
            if not active.any():
                break
            mid = np.where(active, (lo + hi + 1) // 2, lo)
            ok, _, _ = trial(mid, *sub)
            lo = np.where(active & ok, mid, lo)
            hi = np.where(active & ~ok, mid - 1, hi)
        _, q, up = trial(lo, *sub)
        dropped[idx] = lo
        mantissa[idx] = q + up
    return mantissa, dropped
