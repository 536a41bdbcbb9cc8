"""3MF (3D Manufacturing Format) packages: written and read as pure functions on bytes.

A 3MF file is a zip (Open Packaging Conventions) holding ``[Content_Types].xml``,
``_rels/.rels`` (pointing at the model part) and the model, ``3D/3dmodel.model``: XML with
one ``<object>`` per mesh (vertices and triangles), optional base materials for colours, and
a ``<build>`` with one ``<item>`` per object (3MF Core Specification 1.3, chapters 3-4).

The model's text is built in bulk (numbers through :mod:`formgraph.kernels.io.numfmt`, rows
assembled with one ``join_rows`` per block), and read back with regular expressions over the
whole vertex and triangle blocks, never one element at a time. Reading budgets the package:
the uncompressed size each member claims is capped, and the model is read through a bounded
stream, so a zip bomb (or a member that lies about its size) stops at the cap.
"""

from __future__ import annotations

import io
import re
import zipfile
from collections.abc import Iterator, Sequence
from xml.sax.saxutils import quoteattr

import numpy as np

from .numfmt import format_int, format_shortest, join_rows
from .textscan import parse_floats

__all__ = ["MAX_MODEL_BYTES", "UNITS", "read_3mf", "write_3mf"]

CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
MATERIAL = "http://schemas.microsoft.com/3dmanufacturing/material/2015/02"
MODEL_REL = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"
UNITS = {  # the unit's length in millimetres
    "micron": 1e-3,
    "millimeter": 1.0,
    "centimeter": 10.0,
    "inch": 25.4,
    "foot": 304.8,
    "meter": 1000.0,
}
MAX_MODEL_BYTES = 1 << 31  # the uncompressed model part a reader accepts
_BLOCK = 1 << 14

_CONTENT_TYPES = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    '<Default Extension="rels" '
    'ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
    '<Default Extension="model" '
    'ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    "</Types>\n"
)
_RELS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    f'<Relationship Target="/3D/3dmodel.model" Id="rel0" Type="{MODEL_REL}"/>'
    "</Relationships>\n"
)


def write_3mf(
    meshes: Sequence[tuple[np.ndarray, np.ndarray]],
    *,
    names: Sequence[str] | None = None,
    colors: Sequence[tuple[float, float, float, float]] | None = None,
    unit: str = "millimeter",
    vertex_colors: Sequence[np.ndarray | None] | None = None,
) -> bytes:
    """A 3MF package of triangle meshes: one object and one build item per mesh.

    Parameters
    ----------
    meshes : sequence of (vertices (n, 3) float, triangles (t, 3) int)
    names : sequence of str, optional
        Each object's ``name``.
    colors : sequence of (r, g, b, a) in 0..1, optional
        Each object's colour, as a base material's ``displaycolor``.
    unit : str
        One of :data:`UNITS`; the coordinates are written as they are, in that unit.
    vertex_colors : sequence of (n, 3) or (n, 4) float in 0..1, or None, optional
        Each mesh's vertex colours, as a colour group of the 3MF Materials and Properties
        extension (one ``<m:color>`` per vertex, each triangle's ``p1 p2 p3`` its corners');
        they take precedence over ``colors`` for that mesh.

    Returns
    -------
    bytes
        The zip, deflated, its members in a fixed order with fixed times (the same meshes
        give the same bytes).
    """
    if unit not in UNITS:
        raise ValueError(f"unknown unit {unit!r}; one of {', '.join(UNITS)}")
    n = len(meshes)
    names = list(names) if names is not None else [f"mesh {k + 1}" for k in range(n)]
    vertex_colors = list(vertex_colors) if vertex_colors is not None else [None] * n
    for c in vertex_colors:  # refused before anything is written
        width = np.asarray(c).reshape(len(c), -1).shape[1] if c is not None else 3
        if width not in (3, 4):
            raise ValueError(f"vertex colours need 3 or 4 components, got {width}")
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=1) as z:
        for name, data in (
            ("[Content_Types].xml", _CONTENT_TYPES.encode()),
            ("_rels/.rels", _RELS.encode()),
        ):
            z.writestr(_member_info(name), data, compresslevel=1)
        # the model is deflated as it is formatted, a block of rows at a time: the text of
        # a million triangles (80 MB) never exists whole, only its compressed bytes do
        size = sum(_MAX_ROW * (len(v) + len(t)) for v, t in meshes)
        with z.open(_member_info("3D/3dmodel.model"), "w", force_zip64=size > 1 << 30) as f:
            for piece in _model(meshes, names, colors, unit, vertex_colors):
                f.write(piece)
    return out.getvalue()  # (BytesIO hands over its buffer: no copy)


_MAX_ROW = 160  # bytes a vertex or triangle row can take, colour indices included


def _member_info(name: str) -> zipfile.ZipInfo:
    """A member with a fixed time (the same meshes give the same bytes), deflated."""
    info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_DEFLATED
    # the level ZipFile.open(info, "w") deflates at: writestr takes it as an argument,
    # open only from the ZipInfo (``compress_level`` from Python 3.13, before it private)
    for attr in ("compress_level", "_compresslevel"):
        if hasattr(info, attr):
            setattr(info, attr, 1)
    return info


def _model(
    meshes: Sequence[tuple[np.ndarray, np.ndarray]],
    names: list[str],
    colors: Sequence[tuple[float, float, float, float]] | None,
    unit: str,
    vertex_colors: list[np.ndarray | None],
) -> Iterator[bytes]:
    """The model part's text, in pieces of at most a block of rows."""
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<model unit="{unit}" xml:lang="en-US" xmlns="{CORE}" xmlns:m="{MATERIAL}">\n'
        "<resources>\n"
    ]
    next_id = 1
    if colors is not None:
        bases = "".join(
            f'<base name={quoteattr(names[k])} displaycolor="{_hex(c)}"/>\n'
            for k, c in enumerate(colors)
        )
        parts.append(f'<basematerials id="1">\n{bases}</basematerials>\n')
        next_id = 2
    yield "".join(parts).encode()
    object_ids = []
    for k, (v, tris) in enumerate(meshes):
        v = np.asarray(v, dtype=np.float64)
        group = None
        if vertex_colors[k] is not None:  # the materials extension's colour group
            group = next_id
            next_id += 1
            yield f'<m:colorgroup id="{group}">\n'.encode()
            yield from _color_rows(np.asarray(vertex_colors[k], dtype=np.float64))
            yield b"</m:colorgroup>\n"
        if group is not None:
            pid = f' pid="{group}" pindex="0"'
        elif colors is not None:
            pid = f' pid="1" pindex="{k}"'
        else:
            pid = ""
        object_ids.append(next_id)
        yield (
            f'<object id="{next_id}" type="model" name={quoteattr(names[k])}{pid}>'
            "<mesh>\n<vertices>\n".encode()
        )
        next_id += 1
        yield from _vertex_rows(v)
        yield b"</vertices>\n<triangles>\n"
        yield from _triangle_rows(np.asarray(tris).reshape(-1, 3), group)
        yield b"</triangles>\n</mesh></object>\n"
    items = "".join(f'<item objectid="{i}"/>' for i in object_ids)
    yield f"</resources>\n<build>{items}</build>\n</model>\n".encode()


def _hex(c: Sequence[float]) -> str:
    rgba = np.clip(np.round(np.asarray(c, dtype=float) * 255), 0, 255).astype(int)
    return "#" + "".join(f"{x:02X}" for x in rgba)


def _vertex_rows(v: np.ndarray) -> Iterator[bytes]:
    for s in range(0, len(v), _BLOCK):
        b = v[s : s + _BLOCK]
        yield (
            join_rows(
                [
                    b'<vertex x="',
                    format_shortest(b[:, 0]),
                    b'" y="',
                    format_shortest(b[:, 1]),
                    b'" z="',
                    format_shortest(b[:, 2]),
                ],
                b'"/>\n',
            )
        )


def _triangle_rows(t: np.ndarray, group: int | None = None) -> Iterator[bytes]:
    for s in range(0, len(t), _BLOCK):
        b = t[s : s + _BLOCK].astype(np.int64, copy=False)
        cols = [format_int(b[:, c]) for c in range(3)]
        parts = [b'<triangle v1="', cols[0], b'" v2="', cols[1], b'" v3="', cols[2]]
        if group is not None:  # the corners' colours are the vertices' own, by index
            parts += [f'" pid="{group}" p1="'.encode(), cols[0], b'" p2="', cols[1], b'" p3="',
                      cols[2]]  # fmt: skip
        yield join_rows(parts, b'"/>\n')


def _color_rows(c: np.ndarray) -> Iterator[bytes]:
    """``<m:color color="#RRGGBBAA"/>`` rows, hex digits laid out as one canvas a block."""
    digits = np.frombuffer(b"0123456789ABCDEF", np.uint8)
    c = c.reshape(len(c), -1)
    for s in range(0, len(c), _BLOCK):
        b = np.clip(np.round(c[s : s + _BLOCK] * 255), 0, 255).astype(np.uint8)
        if b.shape[1] == 3:
            b = np.column_stack([b, np.full(len(b), 255, np.uint8)])
        hexes = np.stack([digits[b >> 4], digits[b & 15]], axis=2).reshape(len(b), 8)
        yield join_rows([b'<m:color color="#', hexes], b'"/>\n')


# --------------------------------------------------------------------------------------------
# reading

_OBJECT = re.compile(rb"<(?:\w+:)?object\b([^>]*)>(.*?)</(?:\w+:)?object\s*>", re.S)
_ATTR = re.compile(rb'([\w:]+)\s*=\s*"([^"]*)"')
_ITEM = re.compile(rb"<(?:\w+:)?item\b([^>]*?)/?>")
_COMPONENT = re.compile(rb"<(?:\w+:)?component\b([^>]*?)/?>")
MAX_DEPTH = 32  # components within components


def read_3mf(data: bytes, max_bytes: int = MAX_MODEL_BYTES) -> list[tuple]:
    """The meshes a 3MF package builds: ``(name, vertices (n, 3), triangles (t, 3), colours
    (n, 4) or None)`` per build item, in millimetres, with the item's and its components'
    transforms applied; colours from a Materials-extension colour group the object and its
    triangles' corners point into.

    Raises
    ------
    ValueError
        Not a zip, no model part, a member over ``max_bytes`` uncompressed (a zip bomb),
        a DTD (3MF has none; entity expansion is refused outright), or malformed meshes.
    """
    try:
        z = zipfile.ZipFile(io.BytesIO(data))
    except (zipfile.BadZipFile, OSError, ValueError) as exc:
        raise ValueError(f"not a 3MF package (a zip): {exc}") from None
    with z:
        members = {i.filename.lstrip("/"): i for i in z.infolist()}
        total = sum(i.file_size for i in members.values())
        if total > max_bytes:
            raise ValueError(
                f"the package's members claim {total:,} bytes uncompressed, over the budget of "
                f"{max_bytes:,}: refused (a zip bomb?)"
            )
        name = "3D/3dmodel.model"
        if "_rels/.rels" in members:
            rels = _member(z, members["_rels/.rels"], 1 << 20)
            for attrs in re.findall(rb"<Relationship\b([^>]*)>", rels):
                a = dict(_ATTR.findall(attrs))
                if a.get(b"Type", b"").decode() == MODEL_REL:
                    name = a.get(b"Target", b"").decode().lstrip("/")
        if name not in members:
            raise ValueError(f"the package has no model part {name!r}")
        model = _member(z, members[name], max_bytes)
    if re.search(rb"<!DOCTYPE|<!ENTITY", model[: 1 << 16]):
        raise ValueError("the model has a DTD; 3MF has none (refused)")
    return _model_meshes(model)


def _member(z: zipfile.ZipFile, info: zipfile.ZipInfo, cap: int) -> bytes:
    """A member's bytes, never more than ``cap`` whatever its header says."""
    try:
        with z.open(info) as fh:
            out = fh.read(cap + 1)
    except (zipfile.BadZipFile, OSError, EOFError, ValueError, NotImplementedError) as exc:
        raise ValueError(f"cannot unpack {info.filename!r}: {exc}") from None
    if len(out) > cap:
        raise ValueError(f"{info.filename!r} unpacks to more than {cap:,} bytes: refused")
    return out


def _model_meshes(model: bytes) -> list[tuple]:
    head = re.search(rb"<(?:\w+:)?model\b([^>]*)>", model)
    if head is None:
        raise ValueError("the model part has no <model> element")
    unit = dict(_ATTR.findall(head.group(1))).get(b"unit", b"millimeter").decode()
    if unit not in UNITS:
        raise ValueError(f"unknown model unit {unit!r}")
    scale = UNITS[unit]
    groups = _color_groups(model)
    objects: dict[bytes, tuple[str, object]] = {}
    for attrs, body in _OBJECT.findall(model):
        a = dict(_ATTR.findall(attrs))
        oid = a.get(b"id", b"")
        name = a.get(b"name", b"object " + oid).decode("utf-8", "replace")
        if re.search(rb"<(?:\w+:)?mesh\b", body):
            v, t = _mesh_of(body, oid)
            objects[oid] = (name, (v, t, _vertex_colors(body, a, groups, len(v), t)))
        else:
            comps = [dict(_ATTR.findall(c)) for c in _COMPONENT.findall(body)]
            objects[oid] = (name, [(c.get(b"objectid", b""), c.get(b"transform")) for c in comps])
    build = re.search(rb"<(?:\w+:)?build\b[^>]*>(.*?)</(?:\w+:)?build\s*>", model, re.S)
    items = [dict(_ATTR.findall(i)) for i in _ITEM.findall(build.group(1))] if build else []
    out = []
    for item in items:
        oid = item.get(b"objectid", b"")
        if oid not in objects:
            raise ValueError(f"a build item names object {oid.decode()!r}, which is not there")
        pieces = _flatten(objects, oid, _transform(item.get(b"transform")), 0)
        v = np.concatenate([p[0] for p in pieces]) if pieces else np.zeros((0, 3))
        shift = np.cumsum([0] + [len(p[0]) for p in pieces[:-1]])
        t = (
            np.concatenate([p[1] + s for p, s in zip(pieces, shift, strict=True)])
            if pieces
            else np.zeros((0, 3), np.int64)
        )
        colors = [p[2] for p in pieces]
        c = np.concatenate(colors) if pieces and all(x is not None for x in colors) else None
        out.append((objects[oid][0], v * scale, t, c))
    return out


_GROUP = re.compile(rb"<(?:\w+:)?colorgroup\b([^>]*)>(.*?)</(?:\w+:)?colorgroup\s*>", re.S)


def _color_groups(model: bytes) -> dict[bytes, np.ndarray]:
    """The Materials extension's colour groups: id -> (k, 4) RGBA in 0..1."""
    out = {}
    for attrs, body in _GROUP.findall(model):
        gid = dict(_ATTR.findall(attrs)).get(b"id", b"")
        hexes = re.findall(rb'\bcolor\s*=\s*"#([0-9A-Fa-f]{6}(?:[0-9A-Fa-f]{2})?)"', body)
        if len(hexes) != len(re.findall(rb"<(?:\w+:)?color\b", body)):
            raise ValueError(
                f"colour group {gid.decode()!r} holds a colour that is not #RRGGBB[AA]"
            )
        rows = [h + b"FF" if len(h) == 6 else h for h in hexes]
        raw = np.frombuffer(bytes.fromhex(b"".join(rows).decode()), np.uint8)
        out[gid] = raw.reshape(-1, 4) / 255.0
    return out


def _vertex_colors(body: bytes, attrs: dict, groups: dict, n: int, t: np.ndarray):
    """A colour a vertex from a colour group the triangles' corners point into (p1 p2 p3,
    or the object's default pindex), or None when the object has no colour group."""
    pid = attrs.get(b"pid")
    if pid not in groups or not t.size:
        return None
    colors = groups[pid]
    ts = re.search(rb"<(?:\w+:)?triangles\b[^>]*>(.*?)</(?:\w+:)?triangles\s*>", body, re.S)
    block = ts.group(1) if ts else b""
    corners = [re.findall(rb"\b" + k + rb'\s*=\s*"(\d+)"', block) for k in (b"p1", b"p2", b"p3")]
    out = np.zeros((n, 4))
    default = int(attrs.get(b"pindex", b"0") or 0)
    if not 0 <= default < len(colors):
        raise ValueError(f"an object's pindex {default} is outside its colour group")
    out[:] = colors[default]
    if all(len(c) == len(t) for c in corners):  # every corner names its colour
        idx = np.array(corners, dtype=np.int64).T
        if idx.size and idx.max() >= len(colors):
            raise ValueError("a triangle's colour index is outside its colour group")
        out[t.ravel()] = colors[idx.ravel()]
    return out


def _flatten(objects, oid: bytes, m: np.ndarray, depth: int) -> list:
    if depth > MAX_DEPTH:
        raise ValueError(f"components nest deeper than {MAX_DEPTH} levels (a cycle?)")
    if oid not in objects:
        raise ValueError(f"a component names object {oid.decode()!r}, which is not there")
    _, what = objects[oid]
    if isinstance(what, tuple):
        v, t, c = what
        return [(v @ m[:3] + m[3], t, c)]
    out = []
    for child, transform in what:
        c = _transform(transform)
        full = np.vstack([c[:3] @ m[:3], c[3] @ m[:3] + m[3]])
        out.extend(_flatten(objects, child, full, depth + 1))
    return out


def _transform(text: bytes | None) -> np.ndarray:
    """A 3MF transform ``m00 m01 m02 m10 ... m32`` as a (4, 3) matrix: p' = p @ M[:3] + M[3]."""
    if text is None:
        return np.vstack([np.eye(3), np.zeros(3)])
    values = np.array(text.split(), dtype=float) if text.strip() else np.zeros(0)
    if values.size != 12 or not np.all(np.isfinite(values)):
        raise ValueError(f"a transform needs 12 finite numbers, got {text[:60]!r}")
    return values.reshape(4, 3)


def _mesh_of(body: bytes, oid: bytes) -> tuple[np.ndarray, np.ndarray]:
    vs = re.search(rb"<(?:\w+:)?vertices\b[^>]*>(.*?)</(?:\w+:)?vertices\s*>", body, re.S)
    ts = re.search(rb"<(?:\w+:)?triangles\b[^>]*>(.*?)</(?:\w+:)?triangles\s*>", body, re.S)
    v = _columns(vs.group(1) if vs else b"", b"vertex", (b"x", b"y", b"z"), float, oid)
    t = _columns(ts.group(1) if ts else b"", b"triangle", (b"v1", b"v2", b"v3"), int, oid)
    t = t.astype(np.int64)
    if t.size and (t.min() < 0 or t.max() >= len(v)):
        raise ValueError(
            f"object {oid.decode()!r}: a triangle refers to a vertex that does not exist "
            f"({len(v):,} vertices)"
        )
    return v, t


def _columns(block: bytes, tag: bytes, names: tuple[bytes, ...], kind: type, oid: bytes):
    count = len(re.findall(rb"<(?:\w+:)?" + tag + rb"\b", block))
    cols = []
    for name in names:
        found = re.findall(rb"\b" + name + rb'\s*=\s*"([^"]*)"', block)
        if len(found) != count:
            raise ValueError(
                f"object {oid.decode()!r}: {count:,} <{tag.decode()}> elements but "
                f"{len(found):,} {name.decode()} attributes"
            )
        try:
            values = parse_floats(np.frombuffer(b" ".join(found), np.uint8), count)
        except ValueError as exc:
            raise ValueError(f"object {oid.decode()!r}: a {name.decode()} {exc}") from None
        if not np.all(np.isfinite(values)):
            raise ValueError(f"object {oid.decode()!r}: a {name.decode()} is not a finite number")
        if kind is int and np.any(values != np.round(values)):
            raise ValueError(f"object {oid.decode()!r}: a {name.decode()} is not an index")
        cols.append(values)
    return np.column_stack(cols) if cols else np.zeros((0, len(names)))
