"""3MF (3D Manufacturing Format) packages: written and read as pure functions on bytes.

A 3MF file is a zip (Open Packaging Conventions) holding ``[Content_Types].xml``,
``_rels/.rels`` (pointing at the model part) and the model, ``3D/3dmodel.model``: XML with
one ``<object>`` per mesh (vertices and triangles), optional base materials for colours, and
a ``<build>`` with one ``<item>`` per object (3MF Core Specification 1.3, chapters 3-4).

The model's text is built in bulk (numbers through :mod:`formgraph.kernels.io.numfmt`, rows
assembled with one ``join_rows`` per block). Reading is :mod:`.threemf_read`.
"""

from __future__ import annotations

import io
import zipfile
from collections.abc import Sequence
from xml.sax.saxutils import quoteattr

import numpy as np

from .numfmt import format_int, format_shortest, join_rows

__all__ = ["UNITS", "write_3mf"]

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
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<model unit="{unit}" xml:lang="en-US" xmlns="{CORE}" xmlns:m="{MATERIAL}">\n'
        "<resources>\n"
    ]
    next_id = 1
    # a base material only for a mesh its object points at: one with vertex colours uses
    # its colour group instead (an unreferenced material is what strict consumers flag)
    plain = [k for k in range(n) if vertex_colors[k] is None] if colors is not None else []
    if plain:
        bases = "".join(
            f'<base name={quoteattr(names[k])} displaycolor="{_hex(colors[k])}"/>\n' for k in plain
        )
        parts.append(f'<basematerials id="1">\n{bases}</basematerials>\n')
        next_id = 2
    base_index = {k: j for j, k in enumerate(plain)}
    chunks: list[bytes] = ["".join(parts).encode()]
    object_ids = []
    for k, (v, tris) in enumerate(meshes):
        v = np.asarray(v, dtype=np.float64)
        group = None
        if (
            vertex_colors[k] is not None
        ):  # the materials extension's colour group, a colour a vertex
            group = next_id
            next_id += 1
            chunks.append(f'<m:colorgroup id="{group}">\n'.encode())
            chunks.extend(_color_rows(np.asarray(vertex_colors[k], dtype=np.float64)))
            chunks.append(b"</m:colorgroup>\n")
        if group is not None:
            pid = f' pid="{group}" pindex="0"'
        elif k in base_index:
            pid = f' pid="1" pindex="{base_index[k]}"'
        else:
            pid = ""
        object_ids.append(next_id)
        chunks.append(
            f'<object id="{next_id}" type="model" name={quoteattr(names[k])}{pid}>'
            "<mesh>\n<vertices>\n".encode()
        )
        next_id += 1
        chunks.extend(_vertex_rows(v))
        chunks.append(b"</vertices>\n<triangles>\n")
        chunks.extend(_triangle_rows(np.asarray(tris, dtype=np.int64).reshape(-1, 3), group))
        chunks.append(b"</triangles>\n</mesh></object>\n")
    items = "".join(f'<item objectid="{i}"/>' for i in object_ids)
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


def _triangle_rows(t: np.ndarray, group: int | None = None) -> list[bytes]:
    out = []
    for s in range(0, len(t), _BLOCK):
        b = t[s : s + _BLOCK]
        cols = [format_int(b[:, c]) for c in range(3)]
        parts = [b'<triangle v1="', cols[0], b'" v2="', cols[1], b'" v3="', cols[2]]
        if group is not None:  # the corners' colours are the vertices' own, by index
            parts += [f'" pid="{group}" p1="'.encode(), cols[0], b'" p2="', cols[1], b'" p3="',
                      cols[2]]  # fmt: skip
        out.append(join_rows(parts, b'"/>\n'))
    return out


def _color_rows(c: np.ndarray) -> list[bytes]:
    """``<m:color color="#RRGGBBAA"/>`` rows, hex digits laid out as one canvas."""
    c = np.clip(np.round(c.reshape(len(c), -1) * 255), 0, 255).astype(np.uint8)
    if c.shape[1] not in (3, 4):
        raise ValueError(f"vertex colours need 3 or 4 components, got {c.shape[1]}")
    if c.shape[1] == 3:
        c = np.column_stack([c, np.full(len(c), 255, np.uint8)])
    digits = np.frombuffer(b"0123456789ABCDEF", np.uint8)
    hexes = np.stack([digits[c >> 4], digits[c & 15]], axis=2).reshape(len(c), 8)
    return [join_rows([b'<m:color color="#', hexes], b'"/>\n')] if len(c) else []
