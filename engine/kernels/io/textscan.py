"""Vectorized scanning of line-based text formats (OBJ, OFF, ASCII PLY, XYZ, CSV).

A file is a ``uint8`` array; lines, tokens and integers are found with whole-array numpy
operations, never a Python loop per line. Floats go through ``np.fromstring`` (the C
library's correctly rounded ``strtod``), so a coordinate written as its shortest round-trip
text reads back as the same double.
"""

from __future__ import annotations

import re
import warnings

import numpy as np

__all__ = [
    "Lines",
    "TokenError",
    "ints_at",
    "line_numbers",
    "parse_floats",
    "parse_ints",
    "token_starts",
]

# what C's strtod (np.fromstring) reads as one number: Python's float() also takes "1_000"
_C_NUMBER = re.compile(
    rb"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|nan|inf(?:inity)?)", re.I
)


class TokenError(ValueError):
    """A token that is not what the format wants; ``offset`` is where it starts in the
    scanned text, so a reader can name its line."""

    def __init__(self, message: str, offset: int):
        super().__init__(message)
        self.offset = offset


_SPACE = np.zeros(256, dtype=bool)
_SPACE[[9, 10, 11, 12, 13, 32]] = True
_DIGIT = np.zeros(256, dtype=bool)
_DIGIT[48:58] = True


class Lines:
    """The lines of a text as start/end byte offsets (``\\n`` ends a line, ``\\r`` is space).

    Parameters
    ----------
    buf : (n,) uint8
    """

    def __init__(self, buf: np.ndarray):
        self.buf = buf
        nl = np.flatnonzero(buf == 10)
        self.starts = np.concatenate([[0], nl + 1]).astype(np.int64)
        self.ends = np.concatenate([nl, [buf.size]]).astype(np.int64)  # exclusive, no '\n'
        if self.starts[-1] >= buf.size:  # the text ends with a newline: no empty last line
            self.starts, self.ends = self.starts[:-1], self.ends[:-1]

    def __len__(self) -> int:
        return int(self.starts.size)

    def keyword(self, word: bytes) -> np.ndarray:
        """Which lines start with ``word`` followed by whitespace (or the line's end)."""
        ok = self.ends - self.starts >= len(word)
        for k, ch in enumerate(word):
            at = np.minimum(self.starts + k, self.buf.size - 1)
            ok &= self.buf[at] == ch
        after = np.minimum(self.starts + len(word), self.buf.size - 1)
        ok &= (self.starts + len(word) >= self.ends) | _SPACE[self.buf[after]]
        return ok

    def text(self, which: np.ndarray, skip: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """The bytes of the chosen lines joined by newlines, the first ``skip`` bytes of each
        blanked, and each chosen line's start in that text."""
        which = np.asarray(which, dtype=bool)
        # every line with its newline covers the buffer exactly: repeat the choice per byte
        spans = np.diff(np.concatenate([self.starts, [self.buf.size]]))
        out = self.buf[np.repeat(which, spans)]
        lengths = spans[which]
        if which.size and which[-1] and (out.size == 0 or out[-1] != 10):
            out = np.concatenate([out, np.array([10], np.uint8)])  # the last line's newline
            lengths = lengths.copy()
            lengths[-1] += 1
        new_starts = (np.cumsum(lengths) - lengths).astype(np.int64)
        if skip:
            # out is a fresh array (boolean indexing copies): blank the prefixes in place
            out[(new_starts[:, None] + np.arange(skip)).ravel()] = 32
        return out, new_starts


def token_starts(buf: np.ndarray) -> np.ndarray:
    """Byte offsets of the tokens (runs of non-space bytes) of ``buf``."""
    space = _SPACE[buf]
    begin = ~space
    begin[1:] &= space[:-1]
    return np.flatnonzero(begin)


def line_numbers(line_starts: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The index of the line each byte offset falls in."""
    return np.searchsorted(line_starts, offsets, side="right") - 1


def parse_floats(buf: np.ndarray, expected: int) -> np.ndarray:
    """Exactly ``expected`` whitespace-separated floats from ``buf``.

    Raises
    ------
    TokenError
        When a token is not a number or the count differs (a ValueError with the offset).
    """
    if expected == 0:
        return np.zeros(0)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # older numpy: a warning
            values = np.fromstring(buf.tobytes(), sep=" ")
    except ValueError:  # numpy >= 2.3: unmatched data is an error
        values = np.zeros(0)
    if values.size != expected:
        message, offset = _first_bad(buf, expected)
        raise TokenError(message, offset)
    return values


def parse_ints(buf: np.ndarray, expected: int) -> np.ndarray:
    """Exactly ``expected`` whitespace-separated decimal integers from ``buf`` (int64; one
    past the int64 range saturates, which a caller's range check then refuses).

    Raises
    ------
    TokenError
        When a token is not a whole number (``3.5``, ``1e3``) or the count differs.
    """
    if expected == 0:
        return np.zeros(0, np.int64)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            values = np.fromstring(buf.tobytes(), dtype=np.int64, sep=" ")
    except ValueError:
        values = np.zeros(0, np.int64)
    if values.size != expected:
        for m in re.finditer(rb"\S+", bytes(buf)):
            if re.fullmatch(rb"[+-]?[0-9]+", m.group()) is None:
                word = m.group()[:20].decode("latin-1")
                raise TokenError(f"{word!r} is not a whole number", m.start())
        raise TokenError(f"expected {expected:,} whole numbers, found {values.size:,}", 0)
    return values


def _first_bad(buf: np.ndarray, expected: int) -> tuple[str, int]:
    """Why the text is not ``expected`` numbers, and where (the error path: token by token
    is fine)."""
    text = bytes(buf)
    words = list(re.finditer(rb"\S+", text))
    for m in words:
        if _C_NUMBER.fullmatch(m.group()) is None:
            return f"{m.group()[:20].decode('latin-1')!r} is not a number", m.start()
    return f"expected {expected:,} numbers, found {len(words):,}", 0


def ints_at(buf: np.ndarray, starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The decimal integers that begin at byte offsets ``starts`` (an optional ``-``, then
    digits up to the first non-digit), and the offset just past each.

    Raises
    ------
    TokenError
        When a start holds no digit or a number has more than 18 digits (a ValueError with
        the offset).
    """
    starts = np.asarray(starts, dtype=np.int64)
    if starts.size == 0:
        return np.zeros(0, np.int64), starts
    n = buf.size
    negative = buf[starts] == 45
    at = starts + negative
    value = np.zeros(starts.size, np.int64)
    length = np.zeros(starts.size, np.int64)
    alive = np.ones(starts.size, dtype=bool)
    for _ in range(19):  # digit by digit, all numbers at once; a run ends at its first non-digit
        inside = at < n
        b = buf[np.minimum(at, n - 1)]
        alive &= inside & _DIGIT[b]
        if not alive.any():
            break
        value = np.where(alive, value * 10 + (b.astype(np.int64) - 48), value)
        length += alive
        at += alive
    if alive.any():
        raise TokenError("an index has more than 18 digits", int(starts[np.argmax(alive)]))
    if length.min() < 1:
        k = int(starts[np.argmin(length)])
        word = bytes(buf[k : k + 20]).split()
        shown = (word[0] if word else b"").decode("latin-1")
        raise TokenError(f"{shown!r} is not an index (a whole number)", k)
    return np.where(negative, -value, value), at
