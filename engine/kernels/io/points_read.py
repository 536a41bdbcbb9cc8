"""Point files: CSV and whitespace text (``.txt``, ``.xyz``) as (n, 3) arrays, vectorized.

One point a line, ``x, y[, z]`` first (z = 0 when missing; further columns such as colours
or normals are passed over). A first line that is not all numbers is a header: when it
names columns ``x``, ``y`` (and ``z``), those columns are the point, in whatever order.
Blank lines and ``#`` comments are skipped.
"""

from __future__ import annotations

import re

import numpy as np

from .ply_read import read_ply_vertices
from .textscan import Lines, line_numbers, parse_floats, token_starts

__all__ = ["MAX_COLUMNS", "MAX_LINE", "read_ply_points", "read_text_points"]

MAX_LINE = 1 << 20  # characters on one line
MAX_COLUMNS = 10_000  # values on one line


def read_text_points(data: bytes, *, comma: bool) -> np.ndarray:
    """The points of a CSV (``comma``) or whitespace-separated text file, (n, 3).

    Raises
    ------
    ValueError
        A line with fewer than two numbers, lines of different widths, a non-number, a NUL
        byte (not text), or a line over :data:`MAX_LINE` characters or :data:`MAX_COLUMNS`
        values.
    """
    if b"\0" in data:
        at = data.index(b"\0")
        line = data.count(b"\n", 0, at) + 1
        raise ValueError(
            f"it holds a NUL byte (at byte {at:,}, line {line}): not a "
            "text file of points (a binary file with a text extension?)"
        )
    text = re.sub(rb"#[^\n]*", b"", data)
    if comma:
        text = text.replace(b";", b",").replace(b",", b" ")
    buf = np.frombuffer(text, dtype=np.uint8)
    lines = Lines(buf)
    longest = int(np.max(lines.ends - lines.starts, initial=0))
    if longest > MAX_LINE:  # refused before its tokens are counted (memory, and time)
        k = int(np.argmax(lines.ends - lines.starts))
        raise ValueError(
            f"line {k + 1} is {longest:,} characters long, over {MAX_LINE:,}: a point file's "
            "lines hold x, y, z and a few more values"
        )
    tokens = token_starts(buf)
    per_line = np.bincount(line_numbers(lines.starts, tokens), minlength=len(lines))
    rows = np.flatnonzero(per_line > 0)
    if rows.size == 0:
        return np.zeros((0, 3))
    if per_line.max() > MAX_COLUMNS:
        k = int(np.argmax(per_line))
        raise ValueError(
            f"line {k + 1} has {int(per_line[k]):,} values, over {MAX_COLUMNS:,}: a point "
            "file's lines hold x, y, z and a few more values"
        )
    columns = (0, 1, 2)
    first = bytes(buf[lines.starts[rows[0]] : lines.ends[rows[0]]]).split()
    if not _numbers(first):  # a header
        names = [w.decode("latin-1").strip("\"'").lower() for w in first]
        if "x" in names and "y" in names:
            columns = (names.index("x"), names.index("y"), names.index("z") if "z" in names else -1)
        rows = rows[1:]
    if rows.size == 0:
        return np.zeros((0, 3))
    width = per_line[rows]
    if width.min() != width.max():
        k = int(np.argmax(width != width[0]))
        raise ValueError(
            f"line {rows[k] + 1} has {width[k]} values but line {rows[0] + 1} has {width[0]}"
        )
    w = int(width[0])
    need = max(c for c in columns if c >= 0) + 1 if columns != (0, 1, 2) else 2
    if w < need:
        raise ValueError(f"a point needs {need} columns, the lines have {w}")
    pick = np.zeros(len(lines), dtype=bool)
    pick[rows] = True
    body, _ = lines.text(pick)
    values = parse_floats(body, rows.size * w).reshape(-1, w)
    if columns == (0, 1, 2):
        columns = (0, 1, 2 if w >= 3 else -1)
    out = np.zeros((rows.size, 3))
    for k, c in enumerate(columns):
        if c >= 0:
            out[:, k] = values[:, c]
    if not np.all(np.isfinite(out)):
        raise ValueError("a coordinate is not finite")
    return out


def _numbers(words: list[bytes]) -> bool:
    try:
        [float(w) for w in words]
    except ValueError:
        return False
    return True


def read_ply_points(data: bytes) -> np.ndarray:
    """The x, y, z of a PLY file's vertices (faces, if any, skipped), (n, 3)."""
    cols = read_ply_vertices(data)
    return np.column_stack([cols["x"], cols["y"], cols["z"]]).astype(np.float64)
