"""Mesh file writers as pure functions: arrays in, the file's bytes out.

STL (binary and ASCII), OBJ and PLY. Every writer builds its output with whole-array numpy
operations — binary records through structured dtypes, text through the bulk number
formatting of :mod:`formgraph.kernels.io.numfmt` — and never loops over faces or vertices in
Python. Writing the bytes to disk (atomically, inside the output directory) is the engine's
job, not these functions'.

Meshes come as ``vertices`` (n, 3) float64, ``face_indices`` (flat int) and ``face_offsets``
(n_faces + 1,): face ``k`` is ``face_indices[face_offsets[k]:face_offsets[k + 1]]``, with
any mix of face sizes.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from typing import Any

import numpy as np

from .meshdata import check_mesh, fan_triangles
from .numfmt import E9_WIDTH, float_words, format_e9, int_words, squeeze

__all__ = [
    "obj_bytes",
    "ply_binary",
    "stl_ascii",
    "stl_ascii_chunks",
    "stl_binary",
]


# --------------------------------------------------------------------------------------------
# STL

_BLOCK = 1 << 14
_STL_HEADER = b"formgraph binary STL".ljust(80, b"\0")  # must not start with "solid"
_STL_RECORD = np.dtype(
    [("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")]
)  # 50 bytes, packed


def _blocks(n: int, size: int = _BLOCK) -> list[slice]:
    """Consecutive slices covering ``range(n)``: big outputs are filled a cache-sized block at
    a time, so the temporaries of the arithmetic stay small."""
    return [slice(i, min(i + size, n)) for i in range(0, n, size)]


def stl_binary(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> memoryview:
    """Binary STL: an 80-byte header, the triangle count, then 50 bytes per triangle.

    Polygons are fan-triangulated; each facet's normal comes from its winding (counter-
    clockwise seen from outside), as the format asks. Coordinates are stored as float32
    (the format's only precision). The whole file is built in one buffer -- header, count
    and the packed records (`_STL_RECORD`) filled a block at a time -- and handed out as a
    read-only view of it, so the 50 bytes a triangle are never copied again before the
    write (a 1M-triangle file is 48 MiB).

    Parameters
    ----------
    vertices : (n, 3) float64
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int

    Returns
    -------
    memoryview
        ``84 + 50 * n_triangles`` bytes (read-only, bytes-like: it compares equal to the
        same ``bytes``, and files and sockets write it as it is).
    """
    v, tris = _stl_input(vertices, face_indices, face_offsets)
    v32 = v.astype(np.float32)
    n = len(tris)
    buffer = np.empty(84 + _STL_RECORD.itemsize * n, dtype=np.uint8)
    buffer[:80] = np.frombuffer(_STL_HEADER, dtype=np.uint8)
    buffer[80:84] = np.frombuffer(struct.pack("<I", n), dtype=np.uint8)
    records = buffer[84:].reshape(n, _STL_RECORD.itemsize)
    # Fields as opaque byte blobs: copying those into the packed (unaligned) records is far
    # faster than assigning float32 fields of the structured dtype.
    fields = _STL_RECORD.fields
    start = [fields[name][1] for name in ("normal", "vertices", "attribute")]
    normal = records[:, start[0] : start[1]].view(f"V{start[1] - start[0]}")[:, 0]
    corners = records[:, start[1] : start[2]].view(f"V{start[2] - start[1]}")[:, 0]
    records[:, start[2] :] = 0  # the attribute byte count
    columns = [np.ascontiguousarray(v32[:, k]) for k in range(3)]
    for s in _blocks(n):
        c = np.take(v32, tris[s], axis=0)  # (b, 3, 3) float32, the stored corners
        corners[s] = c.reshape(-1, 9).view(corners.dtype)[:, 0]
        normal[s] = _facet_normals(columns, tris[s]).view(normal.dtype)[:, 0]
    buffer.flags.writeable = False
    return memoryview(buffer)


def _facet_normals(columns: list[np.ndarray], tris: np.ndarray) -> np.ndarray:
    """Unit normals (t, 3) float32 of triangles over float32 vertex ``columns`` (x, y, z).

    Computed in double precision from the corners as the file stores them (float32), so
    binary and ASCII STL carry the same normals; (0, 0, 0) for zero-area triangles. The
    arithmetic runs on one contiguous array per coordinate, which vectorizes far better
    than (t, 3) rows.
    """
    a = [np.take(col, tris[:, 0]).astype(np.float64) for col in columns]
    e1 = [np.take(col, tris[:, 1]) - ak for col, ak in zip(columns, a, strict=True)]
    e2 = [np.take(col, tris[:, 2]) - ak for col, ak in zip(columns, a, strict=True)]
    nx = e1[1] * e2[2] - e1[2] * e2[1]
    ny = e1[2] * e2[0] - e1[0] * e2[2]
    nz = e1[0] * e2[1] - e1[1] * e2[0]
    length = np.sqrt(nx * nx + ny * ny + nz * nz)
    length[length == 0] = np.inf  # zero area: a zero normal
    out = np.empty((len(tris), 3), dtype=np.float32)
    out[:, 0], out[:, 1], out[:, 2] = nx / length, ny / length, nz / length
    return out


def stl_ascii(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    name: str = "formgraph",
) -> bytes:
    """ASCII STL in the classic ``facet normal ... endfacet`` layout, as one ``bytes``
    (the pieces of `stl_ascii_chunks` joined; write those to a file instead to keep the
    memory at a block's worth).

    Parameters
    ----------
    vertices : (n, 3) float64
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
    name : str
        The solid's name, written after ``solid`` and ``endsolid`` (ASCII, no line breaks).

    Returns
    -------
    bytes
    """
    return b"".join(stl_ascii_chunks(vertices, face_indices, face_offsets, name))


def stl_ascii_chunks(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    name: str = "formgraph",
) -> Iterator[bytes]:
    """ASCII STL in pieces: the ``solid`` line, blocks of facets, the ``endsolid`` line.

    Numbers are written in sign-mantissa-e-sign-exponent form with nine significant digits —
    exactly the float32 values a binary STL of the same mesh holds. Every facet is a
    fixed-width record: the constant words are laid down once in a block-sized template, each
    distinct vertex is formatted once and its 48 bytes of text copied (as one item) into every
    facet that uses it. One block of facets (``_BLOCK``, about 4 MiB of text) is built per
    piece, so a writer that passes the pieces on holds that and the vertices' text, not the
    whole file (1M triangles: 260 MiB of text). The input is checked before the first piece.

    Parameters
    ----------
    vertices : (n, 3) float64
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
    name : str
        The solid's name, written after ``solid`` and ``endsolid`` (ASCII, no line breaks).

    Returns
    -------
    iterator of bytes
    """
    if not name.isascii() or not name.isprintable():
        raise ValueError(f"the solid name must be printable ASCII, got {name!r}")
    v, tris = _stl_input(vertices, face_indices, face_offsets)
    return _stl_ascii_pieces(v, tris, name)


def _stl_ascii_pieces(v: np.ndarray, tris: np.ndarray, name: str) -> Iterator[bytes]:
    field = 3 * E9_WIDTH
    item = np.dtype(f"V{field}")
    vertex_text = (
        format_e9(v.ravel()).reshape(-1, field).view(item)[:, 0] if len(v) else np.empty(0, item)
    )
    words = [
        b"  facet normal",
        b"\n    outer loop\n      vertex",
        b"\n      vertex",
        b"\n      vertex",
        b"\n    endloop\n  endfacet\n",
    ]
    starts = np.cumsum([0] + [len(w) + field for w in words[:-1]])  # where each word begins
    width = int(starts[-1]) + len(words[-1])
    template = np.empty((min(len(tris), _BLOCK), width), dtype=np.uint8)
    for w, at in zip(words, starts, strict=True):
        template[:, at : at + len(w)] = np.frombuffer(w, dtype=np.uint8)
    fields = [int(at) + len(w) for w, at in zip(words[:-1], starts[:-1], strict=True)]
    v32 = v.astype(np.float32)
    columns = [np.ascontiguousarray(v32[:, k]) for k in range(3)]
    yield f"solid {name}\n".encode()
    for s in _blocks(len(tris), _BLOCK):
        t = tris[s]
        rec = template[: len(t)]
        normals = _facet_normals(columns, t)
        normal_text = format_e9(normals.ravel()).reshape(-1, field).view(item)[:, 0]
        rec[:, fields[0] : fields[0] + field].view(item)[:, 0] = normal_text
        for corner in range(3):
            at = fields[corner + 1]
            rec[:, at : at + field].view(item)[:, 0] = np.take(vertex_text, t[:, corner])
        yield rec.tobytes()
    yield f"endsolid {name}\n".encode()


def _stl_input(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    v, fi, fo = check_mesh(vertices, face_indices, face_offsets)
    if np.abs(v).max(initial=0.0) > np.finfo(np.float32).max:
        raise ValueError("STL stores 32-bit floats; vertex coordinates beyond 3.4e38 do not fit")
    return v, fan_triangles(fi, fo)


# --------------------------------------------------------------------------------------------
# OBJ


def obj_bytes(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    normals: np.ndarray | None = None,
) -> bytes:
    """Wavefront OBJ: ``v`` lines, optional ``vn`` lines, ``f`` lines with 1-based indices.

    Polygons are kept as they are (a quad stays one ``f`` line of four indices). Coordinates
    are written as Python's ``repr`` writes them — the shortest text that reads back to the
    same double — so the file holds the mesh exactly.

    Parameters
    ----------
    vertices : (n, 3) float64
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
    normals : (n, 3) float64, optional
        One normal per vertex; faces then read ``f a//a b//b c//c``.

    Returns
    -------
    bytes
    """
    v, fi, fo = check_mesh(vertices, face_indices, face_offsets)
    parts = [b"# formgraph\n"]
    parts.append(_vector_lines(b"v", v))
    if normals is not None:
        vn = np.asarray(normals, dtype=np.float64)
        if vn.shape != v.shape:
            raise ValueError(
                f"normals must be one per vertex, shape {v.shape}, got shape {vn.shape}"
            )
        parts.append(_vector_lines(b"vn", vn))
    parts.append(_face_lines(fi, fo, with_normals=normals is not None))
    return b"".join(parts)


def _word(text: bytes) -> np.uint64:
    return np.uint64(int.from_bytes(text, "little"))


def _vector_lines(prefix: bytes, xyz: np.ndarray) -> bytes:
    """``prefix x y z`` lines: per row a word with ``"\\n" + prefix`` and three numbers.

    Every line starts with the previous line's end; the first newline is dropped and one
    is added at the end.
    """
    if not len(xyz):
        return b""
    pieces = []
    for s in _blocks(len(xyz)):
        text = float_words(xyz[s].ravel(), lead=b" ").reshape(s.stop - s.start, -1)
        rows = np.empty((len(text), 1 + text.shape[1]), dtype=np.uint64)
        rows[:, 0] = _word(b"\n" + prefix)
        rows[:, 1:] = text
        pieces.append(squeeze(rows.view(np.uint8)))
    return b"".join(pieces)[1:] + b"\n"


def _face_lines(fi: np.ndarray, fo: np.ndarray, with_normals: bool) -> bytes:
    """``f`` lines for faces of any sizes, as rows of word tokens squeezed together.

    In a block of faces, row ``offsets[k] + k`` holds face k's ``"\\nf"`` and the rows after
    it its 1-based indices, ``" 12"`` or ``" 12//12"``: one scatter places them all, whatever
    the face sizes. The first newline is dropped and one is added at the end.
    """
    n_faces = fo.size - 1
    if n_faces == 0:
        return b""
    sizes = np.diff(fo)
    uniform = bool(np.all(sizes == sizes[0]))
    pieces = []
    for s in _blocks(n_faces):
        lo, hi = fo[s.start], fo[s.stop]
        if uniform and not with_normals:  # one face size: rows of "\nf" and k index words
            token = int_words(fi[lo:hi] + 1, lead=b" ")
            rows = np.empty((s.stop - s.start, 1 + token.size // (s.stop - s.start)), np.uint64)
            rows[:, 0] = _word(b"\nf")
            rows[:, 1:] = token.reshape(len(rows), -1)
            pieces.append(squeeze(rows.view(np.uint8)))
            continue
        offsets = fo[s.start : s.stop + 1] - lo
        n = s.stop - s.start
        token = int_words(fi[lo:hi] + 1, lead=b" ")
        if with_normals:
            slashes = np.full((hi - lo, 1), _word(b"//"))
            token = np.concatenate([token, slashes, int_words(fi[lo:hi] + 1)], axis=1)
        rows = np.zeros((hi - lo + n, token.shape[1]), dtype=np.uint64)
        rows[np.arange(hi - lo) + np.repeat(np.arange(1, n + 1), np.diff(offsets))] = token
        rows[offsets[:-1] + np.arange(n), 0] = _word(b"\nf")
        pieces.append(squeeze(rows.view(np.uint8)))
    return b"".join(pieces)[1:] + b"\n"


# --------------------------------------------------------------------------------------------
# PLY


def _ply_properties(data: Any, n: int) -> tuple[list[str], np.ndarray | None]:
    """Header lines and one packed record per element for a mapping of attributes.

    A ``color`` of 3 or 4 components (0..1) is written as ``uchar red green blue [alpha]``
    (what viewers and trimesh read as colours), a 3-component ``normal`` as ``nx ny nz``,
    any other attribute as ``double`` properties, ``name`` or ``name_0, name_1, ...``.
    """
    if not data:
        return [], None
    fields: list[tuple[str, str]] = []
    columns: list[np.ndarray] = []
    for name, a in data.items():
        a = np.asarray(a, dtype=np.float64).reshape(n, -1)
        k = a.shape[1]
        if name == "color" and k in (3, 4):
            names = ["red", "green", "blue", "alpha"][:k]
            rgb = np.rint(np.clip(a, 0.0, 1.0) * 255.0).astype(np.uint8)
            fields += [(c, "u1") for c in names]
            columns += [rgb[:, c] for c in range(k)]
            continue
        if name == "normal" and k == 3:
            names = ["nx", "ny", "nz"]
        else:
            names = [name] if k == 1 else [f"{name}_{c}" for c in range(k)]
        fields += [(c, "<f8") for c in names]
        columns += [a[:, c] for c in range(k)]
    record = np.dtype(fields)
    out = np.empty(n, dtype=record)
    for (c, _), col in zip(fields, columns, strict=True):
        out[c] = col
    ply_type = {"u1": "uchar", "<f8": "double"}
    return [f"property {ply_type[t]} {c}\n" for c, t in fields], out


def ply_binary(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    point_data: Any = None,
    face_data: Any = None,
) -> bytes:
    """Binary little-endian PLY: double x, y, z per vertex; faces as lists of int indices.

    Each face record is a count (``uchar``, or ``uint`` when some face has more than 255
    vertices) followed by that many ``int`` indices; polygons are kept as they are. The face
    records have different lengths, so they are laid out by computing every record's byte
    offset and placing counts and indices with one scatter each.

    Attributes (``point_data``, ``face_data``: name -> (n,) or (n, k) arrays) become
    properties of the vertex and face elements: a ``color`` in 0..1 as ``uchar red green
    blue`` (and ``alpha`` for 4 components), a ``normal`` as ``nx ny nz``, anything else as
    ``double`` (``name``, or ``name_0 ... name_{k-1}`` for a vector).

    Parameters
    ----------
    vertices : (n, 3) float64
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
    point_data, face_data : mapping name -> array, optional

    Returns
    -------
    bytes
    """
    v, fi, fo = check_mesh(vertices, face_indices, face_offsets)
    if len(v) >= 2**31:
        raise ValueError(f"PLY int indices hold at most 2**31 - 1 vertices, got {len(v)}")
    sizes = np.diff(fo)
    n_faces = sizes.size
    wide = bool(sizes.size and sizes.max() > 255)
    count_type, count_dtype = ("uint", np.dtype("<u4")) if wide else ("uchar", np.dtype("u1"))
    v_props, v_extra = _ply_properties(point_data, len(v))
    f_props, f_extra = _ply_properties(face_data, n_faces)
    header = (
        "ply\n"
        "format binary_little_endian 1.0\n"
        "comment formgraph\n"
        f"element vertex {len(v)}\n"
        "property double x\n"
        "property double y\n"
        "property double z\n" + "".join(v_props) + f"element face {n_faces}\n"
        f"property list {count_type} int vertex_indices\n" + "".join(f_props) + "end_header\n"
    ).encode()
    cw = count_dtype.itemsize
    ew = 0 if f_extra is None else f_extra.dtype.itemsize
    if n_faces and np.all(sizes == sizes[0]):  # one face size: a packed structured array
        parts = [("count", count_dtype), ("indices", "<i4", (int(sizes[0]),))]
        if f_extra is not None:
            parts.append(("extra", f"V{ew}"))
        record = np.dtype(parts)
        faces = np.empty(n_faces, dtype=record)
        faces["count"] = sizes[0]
        faces["indices"] = fi.reshape(n_faces, -1)
        if f_extra is not None:
            faces["extra"] = f_extra.view(f"V{ew}")
        face_bytes = faces.data
    else:
        face_of = np.repeat(np.arange(n_faces), sizes)
        starts = fo[:-1] * 4 + np.arange(n_faces) * (cw + ew)  # byte offset of each record
        buf = np.empty(fi.size * 4 + n_faces * (cw + ew), dtype=np.uint8)
        buf[starts[:, None] + np.arange(cw)] = (
            sizes.astype(count_dtype).view(np.uint8).reshape(-1, cw)
        )
        pos = np.arange(fi.size) * 4 + face_of * ew + (face_of + 1) * cw
        buf[pos[:, None] + np.arange(4)] = fi.astype("<i4").view(np.uint8).reshape(-1, 4)
        if f_extra is not None and n_faces:
            tail = starts + cw + 4 * sizes
            buf[tail[:, None] + np.arange(ew)] = f_extra.view(np.uint8).reshape(n_faces, ew)
        face_bytes = buf.data
    if v_extra is None:
        vertex_bytes = v.astype("<f8").data
    else:
        record = np.dtype([("xyz", "<f8", (3,)), ("extra", f"V{v_extra.dtype.itemsize}")])
        rows = np.empty(len(v), dtype=record)
        rows["xyz"] = v
        rows["extra"] = v_extra.view(f"V{v_extra.dtype.itemsize}")
        vertex_bytes = rows.data
    return b"".join([header, vertex_bytes, face_bytes])
