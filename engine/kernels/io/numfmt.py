"""Numbers to ASCII text in bulk, with numpy: the text exporters (STL, OBJ, SVG, PDF) stand on it.

Formatting millions of floats one ``repr`` at a time costs about half a microsecond each;
here every number is turned into digits with integer array arithmetic
(:mod:`formgraph.kernels.io.shortest` finds the shortest round-trip digits) and its characters
are packed eight to a 64-bit word and moved with shifts and masks, so a mesh of a million
triangles formats in a fraction of a second.

Every formatter returns a *canvas*: a ``(n, width)`` uint8 array holding one number per row,
padded with NUL bytes (0) that :func:`join_rows` squeezes out when it assembles the text.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction
from functools import cache

import numpy as np

from .shortest import POW10_INT, check_finite, shortest_decimal

PAD = 0  # filler byte in canvases, removed when the text is assembled

# arrays are formatted in blocks of this many values so the temporaries stay in cache
_BLOCK = 1 << 15


# --------------------------------------------------------------------------------------------
# text from digits, eight characters at a time
#
# A number's text is held in uint64 words (the first character in the lowest byte of the first
# word), so moving characters is shifting words: a handful of whole-array integer operations
# instead of per-character shuffles. Unused bytes stay 0 (PAD). numpy defines shifts of 64
# bits or more to give 0, which the shifts and masks below rely on.

_U = np.uint64
_ZEROS8 = _U(0x3030303030303030)  # "00000000"
_DOTS8 = _U(0x2E2E2E2E2E2E2E2E)  # "........"
_MASKS = np.array([(1 << (8 * k)) - 1 for k in range(9)], dtype=_U)  # the low k bytes
REPR_WIDTH = 24  # bytes: the longest repr of a double, "-1.2345678901234567e-308", fits


def _swar8(v: np.ndarray) -> np.ndarray:
    """Integers below 10**8 as eight ASCII digits packed in a uint64, leading zeros included.

    SIMD-within-a-register conversion: split into two 4-digit lanes, each into two 2-digit
    lanes, each into two digits, with multiply-shift divisions exact on these ranges
    (x // 10**4 == (x * 3518437209) >> 45 for x < 2**32, x // 100 == (x * 5243) >> 19 for
    x < 10**4, x // 10 == (x * 103) >> 10 for x < 100) — no integer division at all.
    """
    v = v.astype(_U)
    hi = (v * _U(3518437209)) >> _U(45)
    x = hi | ((v - hi * _U(10000)) << _U(32))
    q = ((x * _U(5243)) >> _U(19)) & _U(0x0000007F0000007F)
    z = q | ((x - q * _U(100)) << _U(16))
    t = ((z * _U(103)) >> _U(10)) & _U(0x000F000F000F000F)
    return (t | ((z - t * _U(10)) << _U(8))) + _ZEROS8


def _low_bytes(k: np.ndarray, word: int) -> np.ndarray:
    """Mask of the bytes of word ``word`` that lie below byte ``k`` of the string."""
    return _MASKS[np.clip(k - 8 * word, 0, 8)]


def _shift_up(words: list[np.ndarray], nbytes: np.ndarray | int) -> list[np.ndarray]:
    """Move the string ``nbytes`` (0 to 8) bytes further on; bytes pushed past the end are lost."""
    bits = (np.asarray(nbytes) * 8).astype(_U)
    back = _U(64) - bits
    out = [words[0] << bits]
    for i in range(1, len(words)):
        out.append((words[i] << bits) | (words[i - 1] >> back))
    return out


def _place(text: np.ndarray | np.uint64, pos: np.ndarray, word: int) -> np.ndarray:
    """Word ``word`` of a string holding the (up to 8-byte) ``text`` at byte ``pos``, else 0."""
    off = pos - 8 * word
    bits = (np.abs(off) * 8).astype(_U)
    return np.where(off >= 0, text << bits, text >> bits)


def _lead_word(lead: bytes) -> np.uint64:
    if len(lead) > 8:
        raise ValueError(f"a lead of at most 8 bytes fits a word, got {lead!r}")
    return _U(int.from_bytes(lead, "little"))


@cache
def _prefix_masks(nwords: int) -> np.ndarray:
    """(nwords, 8 * nwords + 2) uint64: column k masks the first k bytes of the string."""
    k = np.arange(8 * nwords + 2)
    kb = np.clip(k[None, :] - 8 * np.arange(nwords)[:, None], 0, 8)
    return _MASKS[kb]


def _shift_rows(w: np.ndarray, nbytes: np.ndarray | int) -> np.ndarray:
    """:func:`_shift_up` for a string held as rows of a (nwords, n) array."""
    bits = (np.asarray(nbytes) * 8).astype(_U)
    out = w << bits
    out[1:] |= w[:-1] >> (_U(64) - bits)
    return out


def _number_words(
    negative: np.ndarray,
    mantissa: np.ndarray,
    ndigits: np.ndarray,
    exp10: np.ndarray,
    positional: np.ndarray,
    point_zero: bool,
    lead: bytes,
    nwords: int,
) -> np.ndarray:
    """Text of ``(-1)**negative * mantissa * 10**(exp10 - ndigits + 1)`` as (n, nwords) words.

    ``lead`` first (a separator), then the sign where negative, then the number: positional
    where ``positional`` (``12.5``, ``0.001``; integers as ``3.0`` with ``point_zero`` else
    ``3``), else scientific as repr writes it (``1.5e+16``, ``1e-05``). At most 7 zeros may
    follow the point, and the whole must fit ``nwords`` words. The words of all values are
    rows of one (nwords, n) array, so every step is one operation over all of them.
    """
    n = mantissa.size
    left = mantissa * POW10_INT[17 - ndigits]  # the 17 digits, left-aligned
    d0 = left // 10**16
    rest = left - d0 * 10**16
    h = _swar8(rest // 10**8)
    l = _swar8(rest % 10**8)
    v = np.empty((nwords, n), dtype=_U)
    v[0] = (d0.astype(_U) + _U(ord("0"))) | (h << _U(8))
    v[1] = (h >> _U(56)) | (l << _U(8))
    v[2] = (l >> _U(56)) | (_ZEROS8 << _U(8))
    v[3:] = _ZEROS8
    # "0.001" is the digits after z = 3 zeros, "0001", with the point after the first
    small = positional & (exp10 < 0)
    if small.any():
        z = np.where(small, -exp10, 0)
        v = _shift_rows(v, z)
        v[0] |= _ZEROS8 & _MASKS[z]
    else:
        z = 0
    integer = positional & (exp10 >= ndigits - 1)
    last = np.where(positional, np.maximum(exp10, 0), 0)  # the digit before the point
    has_point = np.where(positional, point_zero | ~integer, ndigits > 1)
    length = np.where(
        positional,
        np.where(integer & ~has_point, exp10 + 1, np.maximum(ndigits + z, last + 2)),
        ndigits,
    )
    # insert the point: the digits after it move one byte on; after & ~before is its byte
    masks = _prefix_masks(nwords)
    point = np.where(has_point, last + 1, 8 * nwords)
    before = np.take(masks, point, axis=1)
    after = np.take(masks, point + 1, axis=1)
    body = (v & before) | (_shift_rows(v, 1) & ~after) | (_DOTS8 & after & ~before)
    text_len = length + has_point
    body &= np.take(masks, text_len, axis=1)
    # the lead, then a sign slot ("-" or padding, which the squeeze removes)
    front = len(lead) + 1
    out = _shift_rows(body, front)
    out[0] |= np.where(negative, _U(ord("-")) << _U(8 * len(lead)), _U(0)) | _lead_word(lead)
    # scientific: "e", sign, (hundreds), tens, units right after the mantissa
    sci = np.flatnonzero(~positional)
    if sci.size:
        e = exp10[sci]
        eabs = np.abs(e)
        units = ((eabs % 10).astype(_U) + _U(ord("0"))) << _U(8)
        tens = ((eabs // 10) % 10).astype(_U) + _U(ord("0"))
        hund = (eabs // 100).astype(_U) + _U(ord("0"))
        digits_e = np.where(eabs >= 100, hund | ((tens | units) << _U(8)), tens | units)
        sign_e = np.where(e < 0, _U(ord("-")), _U(ord("+")))
        exp = _U(ord("e")) | (sign_e << _U(8)) | (digits_e << _U(16))
        at = front + text_len[sci]
        for i in range(nwords):
            out[i, sci] |= _place(exp, at, i)
    return out.T


def float_words(x: np.ndarray, *, decimals: int | None = None, lead: bytes = b"") -> np.ndarray:
    """Text of every value, ``lead`` first, as rows of uint64 words (NUL-padded).

    With ``decimals=None`` the text is Python's ``repr(float(value))``: the shortest that
    reads back to the same double (:func:`shortest_decimal`), positional for exponents -4..15
    (``0.0001``, ``12.5``, ``3.0``), scientific otherwise (``1e-05``, ``1.5e+16``). With
    ``decimals=d`` (0 to 7) the value is rounded to ``d`` places and written positionally
    without trailing zeros (``1.5``, ``3``, ``0``; never ``-0``, never an exponent).

    Parameters
    ----------
    x : (n,) float64
        Finite values; below 1e15 in magnitude with ``decimals``.
    decimals : int, optional
    lead : bytes
        Up to 2 bytes put before each number (e.g. a space separator).

    Returns
    -------
    (n, w) uint64
        ``w`` is 3 or, when ``lead`` and some value has a three-digit exponent, 4.
    """
    x = np.asarray(x, dtype=np.float64).ravel()
    check_finite(x, "values")
    if len(lead) > 2:
        raise ValueError(f"lead must be at most 2 bytes, got {lead!r}")
    if decimals is not None:
        if not 0 <= decimals <= 7:
            raise ValueError(f"decimals must be between 0 and 7, got {decimals}")
        if x.size and np.abs(x).max() >= 1e15:
            raise ValueError(
                "values must be below 1e15 in magnitude to be written positionally, got "
                f"{np.abs(x).max():g}"
            )
        x = np.round(x, decimals) + 0.0  # + 0.0 turns -0.0 into 0.0
    a = np.abs(x)
    extreme = bool(np.any((a >= 1e100) | ((a < 1e-99) & (a > 0))))
    # the sign slot, up to 23 characters of number, and the lead must fit: a three-digit
    # exponent with 17 digits is 23, anything else at most 22
    nwords = 4 if (len(lead) + 1 + (23 if extreme else 22)) > 24 else 3
    out = np.empty((x.size, nwords), dtype=_U)
    for start in range(0, x.size, _BLOCK):  # blocks keep temporaries in cache
        neg, m, nd, e = shortest_decimal(x[start : start + _BLOCK])
        positional = (e >= -4) & (e <= 15) if decimals is None else np.ones(e.size, dtype=bool)
        out[start : start + _BLOCK] = _number_words(
            neg, m, nd, e, positional, decimals is None, lead, nwords
        )
    return out


def format_shortest(x: np.ndarray) -> np.ndarray:
    """Each value as Python's ``repr(float(value))`` prints it, in bulk: ``float(text) == value``.

    Parameters
    ----------
    x : (n,) float64
        Finite values.

    Returns
    -------
    (n, 24) uint8
        Canvas, NUL-padded.

    Example
    -------
    >>> join_rows([format_shortest(np.array([0.1, -2.0, 1e-7]))], b"\\n")
    b'0.1\\n-2.0\\n1e-07\\n'
    """
    return float_words(x).view(np.uint8)


def format_fixed(x: np.ndarray, decimals: int = 6) -> np.ndarray:
    """Each value rounded to ``decimals`` places, positional, no trailing zeros.

    ``1.5``, ``-0.25``, ``3``, ``0`` — never ``-0`` and never an exponent, so the text is a
    valid number in SVG path data and in a PDF content stream alike.

    Parameters
    ----------
    x : (n,) float64
        Finite values below 1e15 in magnitude.
    decimals : int
        Places after the point, 0 to 7.

    Returns
    -------
    (n, 24) uint8
        Canvas, NUL-padded.
    """
    return float_words(x, decimals=decimals).view(np.uint8)


def int_words(v: np.ndarray, lead: bytes = b"") -> np.ndarray:
    """Non-negative integers as right-aligned decimal text after ``lead``, in uint64 words.

    Parameters
    ----------
    v : (n,) int
        Values from 0 to 10**15 - 1.
    lead : bytes
        Up to 1 byte (a separator) at the start of each row.

    Returns
    -------
    (n, 1) uint64 when every value has at most ``8 - len(lead)`` digits, else (n, 2).
    """
    v = np.asarray(v, dtype=np.int64).ravel()
    if len(lead) > 1:
        raise ValueError(f"lead must be at most 1 byte, got {lead!r}")
    if v.size and (v.min() < 0 or v.max() >= 10**15):
        raise ValueError(f"integers from 0 to 10**15 - 1 expected, got {v.min()} .. {v.max()}")
    ndig = np.maximum(np.searchsorted(POW10_INT, v, side="right"), 1)
    if not v.size or v.max() < 10 ** (8 - len(lead)):
        words = [_swar8(v) & ~_low_bytes(8 - ndig, 0)]
    else:
        blank = 16 - ndig
        words = [
            _swar8(v // 10**8) & ~_low_bytes(blank, 0),
            _swar8(v % 10**8) & ~_low_bytes(blank, 1),
        ]
    words[0] = words[0] | _lead_word(lead)
    return np.stack(words, axis=1)


def format_int(v: np.ndarray) -> np.ndarray:
    """Non-negative integers in decimal, right-aligned in a NUL-padded canvas.

    Parameters
    ----------
    v : (n,) int
        Values from 0 to 10**15 - 1.

    Returns
    -------
    (n, 8) uint8 when every value is below 10**8, else (n, 16).
    """
    return int_words(v).view(np.uint8)


E9_WIDTH = 16  # " -1.23456789e+00"


@cache
def _pow10_float() -> np.ndarray:
    """Correctly rounded ``10.0**k`` for k in [-60, 60], index ``k + 60``."""
    return np.array([float(Fraction(10) ** k) for k in range(-60, 61)])


def format_e9(x: np.ndarray) -> np.ndarray:
    """Single-precision values in fixed-width e-format with 9 significant digits.

    ``' -1.23456789e+00'``: a leading space, the sign or a space, nine digits, a two-digit
    exponent — 16 bytes per value, no padding to remove. Nine digits carry every float32
    exactly (a reader that parses into float32 gets the same bits back). The digits come
    from one scaling in double precision: its ~1e-16 error can move the ninth digit only when
    the value lies within 1e-7 of a rounding tie, and the result still reads back to the same
    float32. Formats the STL ``facet normal`` and ``vertex`` lines (the ASCII STL layout asks
    for sign-mantissa-'e'-sign-exponent numbers).

    Parameters
    ----------
    x : (n,) float32 or float64
        Finite values; rounded to float32 first.

    Returns
    -------
    (n, 16) uint8
    """
    x = np.asarray(x).ravel()
    if x.dtype != np.float32:
        with np.errstate(over="ignore"):
            x32 = x.astype(np.float32)
        check_finite(x32, "values (as 32-bit floats)")
        x = x32
    else:
        check_finite(x, "values")
    out = np.empty((x.size, 2), dtype=_U)
    for start in range(0, x.size, _BLOCK):  # blocks keep temporaries in cache
        out[start : start + _BLOCK] = _e9_block(x[start : start + _BLOCK])
    return out.view(np.uint8)


def _e9_block(x: np.ndarray) -> np.ndarray:
    a = np.abs(x).astype(np.float64)
    neg = np.signbit(x)
    nonzero = a != 0
    with np.errstate(divide="ignore"):
        e = np.floor(np.log10(np.where(nonzero, a, 1.0))).astype(np.int64)
    pw = _pow10_float()
    m = np.rint(a * pw[8 - e + 60]).astype(np.int64)
    for _ in range(2):  # log10 may be one off next to a power of ten
        fix = (m >= 10**9) | ((m < 10**8) & nonzero)
        if not fix.any():
            break
        e = np.where(fix, e + np.where(m >= 10**9, 1, -1), e)
        m = np.where(fix, np.rint(a * pw[8 - e + 60]).astype(np.int64), m)
    m = np.where(nonzero, m, 0)
    e = np.where(nonzero, e, 0)
    d0 = m // 10**8
    digits = _swar8(m - d0 * 10**8)
    eabs = np.abs(e).astype(_U)
    c = {ch: _U(ord(ch)) for ch in " -.e+0"}
    out = np.empty((x.size, 2), dtype=_U)
    out[:, 0] = (
        c[" "]
        | (np.where(neg, c["-"], c[" "]) << _U(8))
        | ((d0.astype(_U) + c["0"]) << _U(16))
        | (c["."] << _U(24))
        | (digits << _U(32))
    )
    out[:, 1] = (
        (digits >> _U(32))
        | (c["e"] << _U(32))
        | (np.where(e < 0, c["-"], c["+"]) << _U(40))
        | ((eabs // _U(10) + c["0"]) << _U(48))
        | ((eabs % _U(10) + c["0"]) << _U(56))
    )
    return out


# --------------------------------------------------------------------------------------------
# assembling text


def join_rows(parts: Sequence[bytes | np.ndarray], end: bytes = b"") -> bytes:
    """Rows of text: each row is the concatenation of ``parts``, then ``end``; NULs dropped.

    Parameters
    ----------
    parts : sequence of bytes or (n, w) uint8
        Constant text shared by every row, or a canvas with one row per line.
    end : bytes
        Appended to every row (e.g. ``b"\\n"``).

    Returns
    -------
    bytes
    """
    parts = list(parts) + ([end] if end else [])
    rows = {p.shape[0] for p in parts if isinstance(p, np.ndarray)}
    if len(rows) != 1:
        raise ValueError(f"join_rows needs canvases with one common row count, got {sorted(rows)}")
    (n,) = rows
    widths = [p.shape[1] if isinstance(p, np.ndarray) else len(p) for p in parts]
    canvas = np.empty((n, sum(widths)), dtype=np.uint8)
    col = 0
    for p, w in zip(parts, widths, strict=True):
        canvas[:, col : col + w] = p if isinstance(p, np.ndarray) else np.frombuffer(p, np.uint8)
        col += w
    return squeeze(canvas)


def squeeze(canvas: np.ndarray) -> bytes:
    """The bytes of a canvas in row order with the NUL padding removed."""
    flat = canvas.reshape(-1)
    return np.compress(flat != PAD, flat).tobytes()
