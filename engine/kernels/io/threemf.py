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
from collections.abc import Sequence
from xml.sax.saxutils import quoteattr

import numpy as np

from .numfmt import format_int, format_shortest, join_rows
from .textscan import parse_floats

__all__ = ["MAX_MODEL_BYTES", "UNITS", "read_3mf", "write_3mf"]

CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
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
_BLOCK = 1 << 16

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
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<model unit="{unit}" xml:lang="en-US" xmlns="{CORE}">\n<resources>\n'
    ]
    first_object = 1
    if colors is not None:
        bases = "".join(
            f'<base name={quoteattr(names[k])} displaycolor="{_hex(c)}"/>\n'
            for k, c in enumerate(colors)
        )
        parts.append(f'<basematerials id="1">\n{bases}</basematerials>\n')
        first_object = 2
    chunks: list[bytes] = ["".join(parts).encode()]
    for k, (v, tris) in enumerate(meshes):
        pid = f' pid="1" pindex="{k}"' if colors is not None else ""
        chunks.append(
            f'<object id="{first_object + k}" type="model" name={quoteattr(names[k])}{pid}>'
            "<mesh>\n<vertices>\n".encode()
        )
        chunks.extend(_vertex_rows(np.asarray(v, dtype=np.float64)))
        chunks.append(b"</vertices>\n<triangles>\n")
        chunks.extend(_triangle_rows(np.asarray(tris, dtype=np.int64).reshape(-1, 3)))
        chunks.append(b"</triangles>\n</mesh></object>\n")
    items = "".join(f'<item objectid="{first_object + k}"/>' for k in range(n))
    chunks.append(f"</resources>\n<build>{items}</build>\n</model>\n".encode())
    model = b"".join(chunks)
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=1) as z:
        for name, data in (
            ("[Content_Types].xml", _CONTENT_TYPES.encode()),
            ("_rels/.rels", _RELS.encode()),
            ("3D/3dmodel.model", model),
        ):
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data, compresslevel=1)
    return out.getvalue()


def _hex(c: Sequence[float]) -> str:
    rgba = np.clip(np.round(np.asarray(c, dtype=float) * 255), 0, 255).astype(int)
    return "#" + "".join(f"{x:02X}" for x in rgba)


def _vertex_rows(v: np.ndarray) -> list[bytes]:
    out = []
    for s in range(0, len(v), _BLOCK):
        b = v[s : s + _BLOCK]
        out.append(
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
    return out


def _triangle_rows(t: np.ndarray) -> list[bytes]:
    out = []
    for s in range(0, len(t), _BLOCK):
        b = t[s : s + _BLOCK]
        out.append(
            join_rows(
                [
                    b'<triangle v1="',
                    format_int(b[:, 0]),
                    b'" v2="',
                    format_int(b[:, 1]),
                    b'" v3="',
                    format_int(b[:, 2]),
                ],
                b'"/>\n',
            )
        )
    return out


# --------------------------------------------------------------------------------------------
# reading

_OBJECT = re.compile(rb"<(?:\w+:)?object\b([^>]*)>(.*?)</(?:\w+:)?object\s*>", re.S)
_ATTR = re.compile(rb'([\w:]+)\s*=\s*"([^"]*)"')
_ITEM = re.compile(rb"<(?:\w+:)?item\b([^>]*?)/?>")
_COMPONENT = re.compile(rb"<(?:\w+:)?component\b([^>]*?)/?>")
MAX_DEPTH = 32  # components within components


def read_3mf(
    data: bytes, max_bytes: int = MAX_MODEL_BYTES
) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """The meshes a 3MF package builds: ``(name, vertices (n, 3), triangles (t, 3))`` per
    build item, in millimetres, with the item's and its components' transforms applied.

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


def _model_meshes(model: bytes) -> list[tuple[str, np.ndarray, np.ndarray]]:
    head = re.search(rb"<(?:\w+:)?model\b([^>]*)>", model)
    if head is None:
        raise ValueError("the model part has no <model> element")
    unit = dict(_ATTR.findall(head.group(1))).get(b"unit", b"millimeter").decode()
    if unit not in UNITS:
        raise ValueError(f"unknown model unit {unit!r}")
    scale = UNITS[unit]
    objects: dict[bytes, tuple[str, object]] = {}
    for attrs, body in _OBJECT.findall(model):
        a = dict(_ATTR.findall(attrs))
        oid = a.get(b"id", b"")
        name = a.get(b"name", b"object " + oid).decode("utf-8", "replace")
        if re.search(rb"<(?:\w+:)?mesh\b", body):
            objects[oid] = (name, _mesh_of(body, oid))
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
        out.append((objects[oid][0], v * scale, t))
    return out


def _flatten(objects, oid: bytes, m: np.ndarray, depth: int) -> list:
    if depth > MAX_DEPTH:
        raise ValueError(f"components nest deeper than {MAX_DEPTH} levels (a cycle?)")
    if oid not in objects:
        raise ValueError(f"a component names object {oid.decode()!r}, which is not there")
    _, what = objects[oid]
    if isinstance(what, tuple):
        v, t = what
        return [(v @ m[:3] + m[3], t)]
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
