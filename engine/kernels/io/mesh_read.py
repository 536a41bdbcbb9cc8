"""Mesh file readers as pure functions: the file's bytes in, flat polygon arrays out.

STL (binary and ASCII), Wavefront OBJ (polygons kept, negative indices), OFF and PLY
(ASCII, binary little- and big-endian). Each returns ``(vertices (n, 3) float64,
face_indices (m,) int64, face_offsets (n_faces + 1,) int64)`` and raises ``ValueError``
with a sentence for a file that is truncated, inconsistent or not of its format. Counts a
header claims are checked against the bytes there are before anything is allocated, so a
lying header costs nothing.
"""

from __future__ import annotations

import re

import numpy as np

from ..buffers import fill_frozen, frozen_arange
from .textscan import Lines, TokenError, ints_at, line_numbers, parse_floats, token_starts

__all__ = [
    "read_obj",
    "read_off",
    "read_stl",
    "soup_faces",
    "stl_binary_vertices",
    "triangles_flat",
]

_SPACE = np.zeros(256, dtype=bool)
_SPACE[[9, 10, 11, 12, 13, 32]] = True
_STL_RECORD = np.dtype(
    [("normal", "<f4", (3,)), ("v", "<f4", (9,)), ("attr", "<u2")], align=False
)  # 50 bytes


def triangles_flat(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, ...]:
    """``(vertices, face_indices, face_offsets)`` of a triangle array (t, 3)."""
    tris = np.ascontiguousarray(triangles, dtype=np.int64)
    return vertices, tris.ravel(), np.arange(0, tris.size + 1, 3, dtype=np.int64)


def read_stl(data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An STL file, binary or ASCII, as a triangle soup (three vertices per facet).

    Binary is recognized by its size matching the header's triangle count (84 + 50 n
    bytes), whatever the header's text says (many binary files start with ``solid``). The
    facet normals are not read: a facet's winding is its orientation.

    Raises
    ------
    ValueError
        For a size that matches neither layout, a count that does not fit the file, or an
        ASCII file whose numbers do not come in facets of three vertices.
    """
    size = len(data)
    vertices = stl_binary_vertices(data)
    if vertices is not None:
        return (vertices, *soup_faces(len(vertices) // 3))
    count = int.from_bytes(data[80:84], "little") if size >= 84 else 0
    head = data[:512].lstrip()
    if head[:5].lower() == b"solid" and re.search(rb"\bfacet\b|\bendsolid\b", data[:4096]):
        return _stl_ascii(data)
    if size < 84:
        raise ValueError(f"the file is {size} bytes: too short for an STL (binary needs 84)")
    raise ValueError(
        f"the header claims {count:,} triangles ({84 + 50 * count:,} bytes) but the file is "
        f"{size:,} bytes: truncated, padded or not an STL"
    )


def stl_binary_vertices(data: bytes) -> np.ndarray | None:
    """The vertices of a binary STL, three per facet: ``(3 n, 3)`` float64, frozen, cast
    from the records' float32 in one pass straight into their immutable buffer (and checked
    finite block by block while each block is in cache); None when ``data`` is not laid out
    as a binary STL (84 + 50 n bytes, n the header's count).

    Raises
    ------
    ValueError
        For a coordinate that is not finite, naming its facet.
    """
    if len(data) < 84:
        return None
    count = int.from_bytes(data[80:84], "little")
    if 84 + 50 * count != len(data):
        return None
    corners = np.frombuffer(data, dtype=_STL_RECORD, count=count, offset=84)["v"]  # (n, 9)
    return fill_frozen((3 * count, 3), np.float64, lambda out: _cast(out, corners))


def _cast(out: np.ndarray, corners: np.ndarray, block: int = 1 << 12) -> None:
    rows = out.reshape(corners.shape)
    for start in range(0, len(rows), block):
        part = rows[start : start + block]
        np.copyto(part, corners[start : start + block])
        with np.errstate(all="ignore"):  # a sum is finite only if every term is
            if np.isfinite(np.add.reduce(part, axis=None)):
                continue
        bad = ~np.isfinite(part).all(axis=1)
        if bad.any():
            facet = start + int(np.argmax(bad))
            raise ValueError(f"facet {facet} has a vertex coordinate that is not a number")


def soup_faces(count: int) -> tuple[np.ndarray, np.ndarray]:
    """``(face_indices, face_offsets)`` of ``count`` triangles on their own three vertices
    each (0, 1, 2, 3, 4, 5, ...), frozen, made in place (no array copied to freeze it)."""
    return frozen_arange(3 * count, 1), frozen_arange(count + 1, 3)


def _stl_ascii(data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    if b"\0" in data:  # text holds no NUL: binary bytes after a 'solid' header, not facets
        at = data.index(b"\0")
        raise ValueError(
            f"it starts like an ASCII STL ('solid') but holds a NUL byte at byte {at:,}: "
            "binary data, not text (a binary STL whose size does not match its triangle "
            "count?)"
        )
    buf = np.frombuffer(data, dtype=np.uint8)
    lines = Lines(buf)
    vertex = lines.keyword(b"vertex") | _indented(lines, b"vertex")
    n = int(vertex.sum())
    facets = data.count(b"facet normal") or data.count(b"facet")  # 'endfacet' has no space
    if n % 3 or (facets and 3 * data.count(b"endloop") != n):
        raise ValueError(
            f"the ASCII STL has {n:,} vertex lines, not three per facet: truncated or garbled"
        )
    if n == 0:  # an empty solid is 'solid' and 'endsolid' alone, not junk between them
        first = _first_token(lines)
        blank = first >= lines.ends
        named = _indented(lines, b"solid") | _indented(lines, b"endsolid")
        other = int((~blank & ~named).sum())
        if other:
            raise ValueError(
                f"it starts like an ASCII STL ('solid') but none of its lines is a facet's "
                f"vertex, and {other:,} are not STL at all: binary data or another format"
            )
    text, _ = _stripped(lines, vertex, b"vertex")
    v = parse_floats(text, 3 * n).reshape(-1, 3)
    return triangles_flat(v, np.arange(n).reshape(-1, 3))


def _indented(lines: Lines, word: bytes) -> np.ndarray:
    """Lines whose first token (after leading whitespace) is ``word``."""
    buf = lines.buf
    first = _first_token(lines)
    ok = first + len(word) <= lines.ends
    for k, ch in enumerate(word):
        ok &= buf[np.minimum(first + k, buf.size - 1)] == ch
    return ok


def _first_token(lines: Lines) -> np.ndarray:
    buf = lines.buf
    space = (buf == 32) | (buf == 9)
    nonspace = np.flatnonzero(~space)
    if nonspace.size == 0:
        return lines.ends.copy()
    at = np.searchsorted(nonspace, lines.starts)
    return np.where(at < nonspace.size, nonspace[np.minimum(at, nonspace.size - 1)], lines.ends)


def _stripped(lines: Lines, which: np.ndarray, word: bytes) -> tuple[np.ndarray, np.ndarray]:
    """The chosen lines' text with their leading ``word`` (and indentation) blanked."""
    first = _first_token(lines)[which]
    text, starts = lines.text(which)
    text = text.copy()
    lead = first - lines.starts[which] + len(word)
    width = int(lead.max()) if lead.size else 0
    cols = np.arange(width)
    mask = cols[None, :] < lead[:, None]
    text[(starts[:, None] + cols[None, :])[mask]] = 32
    return text, starts


# --------------------------------------------------------------------------------------------
# OBJ


def read_obj(data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A Wavefront OBJ file's ``v`` and ``f`` lines: polygons kept, every group and object
    in one mesh, texture and normal references dropped.

    Face indices are 1-based or negative (relative to the vertices read so far), as the
    format says. A ``v`` line may carry more than three numbers (a weight or a colour):
    the first three are the point.

    Raises
    ------
    ValueError
        For a number that is not one, a face of fewer than three vertices or an index out
        of range, naming the line.
    """
    buf = np.frombuffer(data, dtype=np.uint8)
    lines = Lines(buf)
    is_v, is_f = lines.keyword(b"v"), lines.keyword(b"f")
    if not is_v.any() and not is_f.any() and bytes(data).strip() and not _any_obj_line(lines):
        raise ValueError("no OBJ statement (v, f, o, g, # ...) on any line: not an OBJ file")
    v = _rows(lines, is_v, b"v", 3, "vertex")
    finite = np.isfinite(v).all(axis=1)
    if not finite.all():
        k = int(np.argmin(finite))
        bad = v[k][~np.isfinite(v[k])][0]
        line = np.flatnonzero(is_v)[k] + 1
        raise ValueError(f"line {line}: a vertex coordinate is {bad}, not a finite number")
    text, starts = lines.text(is_f, skip=1)
    tokens = token_starts(text)
    line_of = line_numbers(starts, tokens)
    sizes = np.bincount(line_of, minlength=starts.size)
    f_lines = np.flatnonzero(is_f)
    if sizes.size and sizes.min() < 3:
        k = int(np.argmin(sizes))
        raise ValueError(f"line {f_lines[k] + 1}: a face needs at least 3 vertices")
    try:
        idx, after = ints_at(text, tokens)  # a token 'v/vt/vn' starts with its vertex index
    except TokenError as exc:
        line = f_lines[line_numbers(starts, np.array([exc.offset]))[0]] + 1
        raise ValueError(f"line {line}: a face's vertex: {exc}") from None
    # the index ends the token or meets its '/': '3.5' or '3x' is not index 3
    end = text[np.minimum(after, text.size - 1)]
    bad = (after < text.size) & ~(_SPACE[end] | (end == ord("/")))
    if bad.any():
        k = int(np.argmax(bad))
        word = bytes(text[tokens[k] : tokens[k] + 20]).split()[0].decode("latin-1")
        raise ValueError(
            f"line {f_lines[line_of[k]] + 1}: a face's vertex {word!r} is not an index (a "
            "whole number, then /texture/normal)"
        )
    before = np.cumsum(is_v)[f_lines] if f_lines.size else np.zeros(0, np.int64)
    idx = np.where(idx < 0, idx + np.repeat(before, sizes), idx - 1)
    bad = (idx < 0) | (idx >= len(v))
    if bad.any():
        k = int(np.argmax(bad))
        raise ValueError(
            f"line {f_lines[line_of[k]] + 1}: a face refers to a vertex that does not exist "
            f"({len(v):,} vertices)"
        )
    return v, idx, np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)


_OBJ_WORDS = (b"#", b"v", b"vt", b"vn", b"vp", b"f", b"l", b"p", b"o", b"g", b"s", b"usemtl",
              b"mtllib", b"cstype", b"deg", b"curv", b"parm", b"end")  # fmt: skip


def _any_obj_line(lines: Lines) -> bool:
    """Whether any line starts with an OBJ statement (a file of none is not OBJ)."""
    return any(lines.keyword(w).any() for w in _OBJ_WORDS) or bool(
        (lines.buf[np.minimum(lines.starts, lines.buf.size - 1)] == ord("#")).any()
    )


def _rows(lines: Lines, which: np.ndarray, word: bytes, width: int, what: str) -> np.ndarray:
    """The first ``width`` numbers of each chosen line (which must have at least that many)."""
    text, starts = lines.text(which, skip=len(word))
    tokens = token_starts(text)
    counts = np.bincount(line_numbers(starts, tokens), minlength=starts.size)
    chosen = np.flatnonzero(which)
    if counts.size and counts.min() < width:
        k = int(np.argmin(counts))
        raise ValueError(f"line {chosen[k] + 1}: a {what} needs {width} numbers")
    try:
        values = parse_floats(text, int(counts.sum()))
    except TokenError as exc:
        line = chosen[line_numbers(starts, np.array([exc.offset]))[0]] + 1
        raise ValueError(f"line {line}: {exc}") from None
    if np.all(counts == width):
        return values.reshape(-1, width)
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return values[first[:, None] + np.arange(width)]


# --------------------------------------------------------------------------------------------
# OFF


def read_off(data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An OFF file: ``OFF``, then ``nv nf ne``, ``nv`` points and ``nf`` faces ``k i1 .. ik``
    (any colour after a face's indices is ignored); ``#`` comments anywhere. A ``4OFF``'s
    vertices are homogeneous, ``x y z w`` (Geomview's OFF format): the point is their
    quotient by ``w``; an ``nOFF`` (N dimensions) is refused.

    Raises
    ------
    ValueError
        For a missing keyword, counts that the file cannot hold, or a bad face.
    """
    text = re.sub(rb"#[^\n]*", b"", data)
    buf = np.frombuffer(text, dtype=np.uint8)
    lines = Lines(buf)
    blank = _first_token(lines) >= lines.ends
    content = np.flatnonzero(~blank)
    if content.size == 0:
        raise ValueError("the file is empty")
    head = bytes(buf[lines.starts[content[0]] : lines.ends[content[0]]]).split()
    if not head or not head[0].endswith(b"OFF"):
        raise ValueError("an OFF file starts with the keyword OFF")
    prefix = head[0][:-3]  # Geomview's [ST][C][N][4][n]OFF
    if b"n" in prefix:
        raise ValueError(
            f"{head[0].decode('latin-1')!r}: an OFF of vertices in N dimensions is not read"
        )
    homogeneous = b"4" in prefix  # x y z w: the point is (x, y, z) / w
    counts = head[1:]
    rest = content[1:]
    if len(counts) < 2:  # the counts on their own line
        if rest.size == 0:
            raise ValueError("the OFF header has no vertex and face counts")
        counts = bytes(buf[lines.starts[rest[0]] : lines.ends[rest[0]]]).split()
        rest = rest[1:]
    try:
        nv, nf = int(counts[0]), int(counts[1])
    except (ValueError, IndexError):
        raise ValueError("the OFF counts line must hold whole numbers: nv nf ne") from None
    if nv < 0 or nf < 0 or nv + nf > rest.size:
        raise ValueError(
            f"the header claims {nv:,} vertices and {nf:,} faces but the file has "
            f"{rest.size:,} lines after it: truncated"
        )
    pick = np.zeros(len(lines), dtype=bool)
    pick[rest[:nv]] = True
    v = _rows(lines, pick, b"", 4 if homogeneous else 3, "vertex")
    if homogeneous:
        w = v[:, 3]
        if not np.all(np.isfinite(w) & (w != 0)):
            k = int(np.argmax(~(np.isfinite(w) & (w != 0))))
            raise ValueError(
                f"vertex {k}: its homogeneous w is {w[k]:g} (4OFF: the point is x/w, y/w, z/w)"
            )
        v = v[:, :3] / w[:, None]
    pick[:] = False
    pick[rest[nv : nv + nf]] = True
    ftext, starts = lines.text(pick)
    tokens = token_starts(ftext)
    line_of = line_numbers(starts, tokens)
    per_line = np.bincount(line_of, minlength=nf)
    values, after = ints_at(ftext, tokens)  # every token of a face line is an integer...
    first = np.concatenate([[0], np.cumsum(per_line)[:-1]]).astype(np.int64)
    k = values[first] if nf else np.zeros(0, np.int64)
    if nf and (k.min() < 3 or np.any(k + 1 > per_line)):
        bad = int(np.argmax((k < 3) | (k + 1 > per_line)))
        raise ValueError(f"face {bad}: a face needs a count of at least 3, then that many indices")
    take = np.repeat(first + 1, k) + (np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k))
    # ...read to its first non-digit: the count and the indices must end there ('2.5' is
    # not index 2); what follows them, a colour, may be any number
    used = np.concatenate([first, take]) if nf else np.zeros(0, np.int64)
    end = ftext[np.minimum(after[used], max(ftext.size - 1, 0))]
    bad = (after[used] < ftext.size) & ~_SPACE[end]
    if bad.any():
        t = int(used[np.argmax(bad)])
        word = bytes(ftext[tokens[t] : tokens[t] + 20]).split()[0].decode("latin-1")
        raise ValueError(
            f"face {int(line_of[t])}: {word!r} is not a whole number (a face is its vertex "
            "count, then that many vertex indices)"
        )
    idx = values[take]
    if idx.size and (idx.min() < 0 or idx.max() >= nv):
        raise ValueError(f"a face refers to a vertex that does not exist ({nv:,} vertices)")
    return v, idx, np.concatenate([[0], np.cumsum(k)]).astype(np.int64)
