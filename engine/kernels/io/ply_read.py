"""PLY reading: ASCII and binary (little- and big-endian), vertices and polygon faces.

The header is parsed into elements and properties; a binary element whose properties are
all scalars is one structured ``np.frombuffer``. A face element (a list property) is read
with one structured view when every face has the size of the first (checked on the count
column), else its records are walked. Counts the header claims are checked against the
file's size before anything is allocated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .textscan import Lines, line_numbers, parse_floats, token_starts

__all__ = ["PlyElement", "point_data", "read_ply", "read_ply_vertices"]

_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip
MAX_HEADER = 1 << 16


@dataclass
class PlyElement:
    name: str
    count: int
    properties: list[tuple[str, str, str | None]]  # (name, type, list count type or None)


def _header(data: bytes) -> tuple[str, list[PlyElement], int]:
    if not data.startswith(b"ply"):
        raise ValueError("a PLY file starts with 'ply'")
    end = data.find(b"end_header", 0, MAX_HEADER)
    if end < 0:
        raise ValueError(f"no 'end_header' in the first {MAX_HEADER:,} bytes")
    body = data.index(b"\n", end) + 1 if b"\n" in data[end : end + 64] else len(data)
    fmt = None
    elements: list[PlyElement] = []
    for raw in data[:end].decode("latin-1").splitlines()[1:]:
        words = raw.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format" and len(words) >= 2:
            fmt = words[1]
        elif words[0] == "element" and len(words) == 3:
            try:
                count = int(words[2])
            except ValueError:
                raise ValueError(f"element {words[1]!r} has the count {words[2]!r}") from None
            if count < 0:
                raise ValueError(f"element {words[1]!r} has a negative count")
            elements.append(PlyElement(words[1], count, []))
        elif words[0] == "property" and elements:
            if len(words) == 5 and words[1] == "list":
                if words[2] not in _TYPES or words[3] not in _TYPES:
                    raise ValueError(f"unknown PLY type in {raw.strip()!r}")
                elements[-1].properties.append((words[4], words[3], words[2]))
            elif len(words) == 3 and words[1] in _TYPES:
                elements[-1].properties.append((words[2], words[1], None))
            else:
                raise ValueError(f"cannot read the header line {raw.strip()[:60]!r}")
        else:
            raise ValueError(f"cannot read the header line {raw.strip()[:60]!r}")
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise ValueError(f"unknown PLY format {fmt!r}")
    return fmt, elements, body


def read_ply(data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A PLY file's ``vertex`` (x, y, z) and ``face`` (``vertex_indices`` or
    ``vertex_index``) elements as a polygon mesh; other elements and properties are read
    past and dropped.

    Raises
    ------
    ValueError
        For a header it cannot read, counts the file cannot hold, or bad indices.
    """
    columns, faces = _read(data, want_faces=True)
    v = np.column_stack([columns[c] for c in "xyz"]).astype(np.float64)
    if faces is None:
        return v, np.zeros(0, np.int64), np.zeros(1, np.int64)
    fi, fo = faces
    if fi.size and (fi.min() < 0 or fi.max() >= len(v)):
        raise ValueError(f"a face refers to a vertex that does not exist ({len(v):,} vertices)")
    if fo.size > 1 and np.diff(fo).min() < 3:
        raise ValueError("a face has fewer than 3 vertices")
    return v, fi, fo


def read_ply_vertices(data: bytes) -> dict[str, np.ndarray]:
    """Every scalar property of a PLY file's ``vertex`` element, by name (faces skipped)."""
    columns, _ = _read(data, want_faces=False)
    return columns


def point_data(data: bytes) -> dict[str, np.ndarray]:
    """The vertex attributes of a PLY file, named as formgraph writes them
    (:func:`formgraph.kernels.io.exporters.ply_binary`): ``red green blue [alpha]`` as a
    ``color`` in 0..1 (integers divided by their type's maximum), ``nx ny nz`` as a
    ``normal``, ``name_0 .. name_k`` as one (n, k) ``name``, any other scalar as itself."""
    fmt, elements, _ = _header(data)
    vertex = next(e for e in elements if e.name == "vertex")
    types = {p[0]: p[1] for p in vertex.properties if p[2] is None}
    columns = read_ply_vertices(data)
    out: dict[str, np.ndarray] = {}
    used = {"x", "y", "z"}
    rgb = [c for c in ("red", "green", "blue", "alpha") if c in columns]
    if {"red", "green", "blue"} <= set(rgb):
        kind = np.dtype(_TYPES[types["red"]])
        scale = float(np.iinfo(kind).max) if kind.kind in "iu" else 1.0
        out["color"] = np.column_stack([columns[c] for c in rgb]) / scale
        used |= set(rgb)
    if {"nx", "ny", "nz"} <= set(columns):
        out["normal"] = np.column_stack([columns[c] for c in ("nx", "ny", "nz")])
        used |= {"nx", "ny", "nz"}
    vectors: dict[str, list[tuple[int, str]]] = {}
    for name in columns:
        base, _, index = name.rpartition("_")
        if name not in used and base and index.isdigit():
            vectors.setdefault(base, []).append((int(index), name))
    for base, parts in vectors.items():
        parts.sort()
        if [k for k, _ in parts] == list(range(len(parts))) and base not in columns:
            out[base] = np.column_stack([columns[n] for _, n in parts])
            used |= {n for _, n in parts}
    for name, values in columns.items():
        if name not in used:
            out[name] = values
    return out


def _read(data: bytes, want_faces: bool):
    fmt, elements, at = _header(data)
    names = [e.name for e in elements]
    if "vertex" not in names:
        raise ValueError("the PLY file has no 'vertex' element")
    vertex = elements[names.index("vertex")]
    if not all(p in [q[0] for q in vertex.properties] for p in "xyz"):
        raise ValueError("the PLY vertex element has no x, y and z properties")
    if fmt == "ascii":
        return _read_ascii(data[at:], elements, want_faces)
    order = "<" if fmt == "binary_little_endian" else ">"
    columns: dict[str, np.ndarray] = {}
    faces = None
    for e in elements:
        lists = [p for p in e.properties if p[2] is not None]
        if not lists:
            dt = np.dtype([(p[0], order + _TYPES[p[1]]) for p in e.properties])
            if at + dt.itemsize * e.count > len(data):
                raise ValueError(_short(e, dt.itemsize * e.count, len(data) - at))
            if e.name == "vertex":
                rec = np.frombuffer(data, dtype=dt, count=e.count, offset=at)
                columns = {p[0]: rec[p[0]].astype(np.float64) for p in e.properties}
            at += dt.itemsize * e.count
            continue
        parsed, at = _binary_lists(data, at, e, order)
        if e.name == "face" and want_faces:
            faces = parsed
        if e.name == "vertex":
            raise ValueError("the PLY vertex element has a list property")
    return columns, faces


def _short(e: PlyElement, need: int, have: int) -> str:
    return (
        f"the header claims {e.count:,} {e.name} records ({need:,} bytes) but {max(have, 0):,} "
        f"bytes follow: truncated"
    )


def _binary_lists(data: bytes, at: int, e: PlyElement, order: str):
    """A binary element holding a list property: (indices, offsets) of its first list."""
    props = e.properties
    index_list = next(
        (p for p in props if p[0] in ("vertex_indices", "vertex_index")),
        next(p for p in props if p[2] is not None),
    )
    if e.count == 0:
        return (np.zeros(0, np.int64), np.zeros(1, np.int64)), at
    if e.count > len(data) - at:  # every record takes a byte at least
        raise ValueError(_short(e, e.count, len(data) - at))
    # the layout of one record whose lists all hold `k` items, k from the first record
    fields = []
    offset = at
    for name, typ, count_type in props:
        if count_type is None:
            fields.append((name, order + _TYPES[typ], None))
            offset += np.dtype(_TYPES[typ]).itemsize
        else:
            if offset + np.dtype(_TYPES[count_type]).itemsize > len(data):
                raise ValueError(_short(e, offset - at + 1, len(data) - at))
            k = int(np.frombuffer(data, order + _TYPES[count_type], 1, offset)[0])
            fields.append((name + "#", order + _TYPES[count_type], None))
            fields.append((name, order + _TYPES[typ], k))
            offset += np.dtype(_TYPES[count_type]).itemsize + k * np.dtype(_TYPES[typ]).itemsize
    dt = np.dtype([(n, t) if k is None else (n, t, (k,)) for n, t, k in fields])
    size = dt.itemsize * e.count
    if at + size <= len(data):
        rec = np.frombuffer(data, dtype=dt, count=e.count, offset=at)
        uniform = all(np.all(rec[n + "#"] == k) for n, _, k in fields if k is not None)
        if uniform:
            k = dict((n, kk) for n, _, kk in fields)[index_list[0]]
            fi = rec[index_list[0]].reshape(-1).astype(np.int64)
            return (fi, np.arange(0, fi.size + 1, max(k, 1), dtype=np.int64)), at + size
    return _walk(data, at, e, order, index_list[0])


def _walk(data: bytes, at: int, e: PlyElement, order: str, wanted: str):
    """Records of different lengths: walked one by one (a file of mixed face sizes)."""
    view = memoryview(data)
    out: list[np.ndarray] = []
    sizes = np.empty(e.count, np.int64)
    steps = [
        (name, np.dtype(order + _TYPES[typ]), None if ct is None else np.dtype(order + _TYPES[ct]))
        for name, typ, ct in e.properties
    ]
    for r in range(e.count):
        for name, dt, ct in steps:
            if ct is None:
                at += dt.itemsize
                continue
            if at + ct.itemsize > len(data):
                raise ValueError(_short(e, at + 1, len(data)))
            k = int(np.frombuffer(view, ct, 1, at)[0])
            at += ct.itemsize
            if at + k * dt.itemsize > len(data):
                raise ValueError(_short(e, at + k * dt.itemsize, len(data)))
            if name == wanted:
                out.append(np.frombuffer(view, dt, k, at))
                sizes[r] = k
            at += k * dt.itemsize
    if at > len(data):
        raise ValueError(_short(e, at, len(data)))
    fi = np.concatenate(out).astype(np.int64) if out else np.zeros(0, np.int64)
    return (fi, np.concatenate([[0], np.cumsum(sizes)])), at


def _read_ascii(body: bytes, elements: list[PlyElement], want_faces: bool):
    buf = np.frombuffer(body, dtype=np.uint8)
    lines = Lines(buf)
    blank = np.zeros(len(lines), bool)
    content = np.flatnonzero(~blank & (lines.ends > lines.starts))
    need = sum(e.count for e in elements)
    if need > content.size:
        raise ValueError(
            f"the header claims {need:,} records but {content.size:,} lines follow: truncated"
        )
    columns: dict[str, np.ndarray] = {}
    faces = None
    row = 0
    for e in elements:
        pick = np.zeros(len(lines), dtype=bool)
        pick[content[row : row + e.count]] = True
        row += e.count
        if e.name not in ("vertex", "face") or (e.name == "face" and not want_faces):
            continue
        text, starts = lines.text(pick)
        tokens = token_starts(text)
        per_line = np.bincount(line_numbers(starts, tokens), minlength=e.count)
        values = parse_floats(text, int(per_line.sum()))
        first = np.concatenate([[0], np.cumsum(per_line)[:-1]]).astype(np.int64)
        if e.name == "vertex":
            if per_line.size and per_line.min() < len(e.properties):
                raise ValueError("a vertex line has fewer numbers than the header's properties")
            columns = {p[0]: values[first + j] for j, p in enumerate(e.properties) if p[2] is None}
            continue
        if e.properties[0][2] is None:
            raise ValueError("ASCII faces are read when the list comes first on each line")
        k = values[first] if e.count else np.zeros(0)
        whole = np.isfinite(k) & (k == np.round(k)) & (k >= 0)
        if not whole.all():
            f = int(np.argmax(~whole))
            raise ValueError(f"face {f}: its vertex count {k[f]:g} is not a whole number")
        k = k.astype(np.int64)
        if np.any(k + 1 > per_line):
            raise ValueError("a face line holds fewer indices than its count says")
        take = np.repeat(first + 1, k) + (np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k))
        idx = values[take]
        whole = np.isfinite(idx) & (idx == np.round(idx))  # '2.5' is not vertex 2
        if not whole.all():
            t = int(np.argmax(~whole))
            f = int(np.searchsorted(np.cumsum(k), t, side="right"))
            raise ValueError(f"face {f}: its vertex index {idx[t]:g} is not a whole number")
        faces = (idx.astype(np.int64), np.concatenate([[0], np.cumsum(k)]))
    return columns, faces
