"""glTF 2.0: binary ``.glb`` written, ``.glb`` and ``.gltf`` (embedded buffers) read.

Writing: one node and one mesh per input mesh, each a triangle primitive with ``POSITION``
(float32, with the min/max the format requires), ``NORMAL`` (area-weighted vertex normals)
and ``uint32`` indices, all in one binary chunk (glTF 2.0 specification, sections 3.6-3.7 and
4.4). glTF's unit is the metre: model units are scaled by ``scale`` (1/1000 from millimetres).

Reading: every mesh the default scene's node tree places (every mesh at the origin when the
file has no scene), with each node's transform (``matrix`` or translation, rotation, scale)
composed down the tree. Accessors are viewed in place with their strides after their extents
are checked against their buffer views and buffers; a node tree deeper than
:data:`MAX_DEPTH` or visiting more than :data:`MAX_VISITS` nodes (a cycle or a tree shared
many times over) is refused.
"""

from __future__ import annotations

import base64
import json
import struct
from collections.abc import Sequence

import numpy as np

__all__ = ["MAX_DEPTH", "MAX_VISITS", "read_gltf", "vertex_normals", "write_glb"]

MAX_DEPTH = 64
MAX_VISITS = 100_000
MAX_JSON = 64 << 20
_COMPONENT = {5120: "i1", 5121: "u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def vertex_normals(v: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Unit vertex normals: the sum of the (area-weighted) normals of the triangles around
    each vertex, in float32 (what glTF stores); a vertex on no triangle gets +z."""
    p = np.asarray(v, dtype=np.float32)
    a = p[tris[:, 1]] - p[tris[:, 0]]
    b = p[tris[:, 2]] - p[tris[:, 0]]
    n = np.empty_like(a)
    n[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    n[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    n[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    corners = tris.ravel()
    acc = np.empty((len(p), 3), dtype=np.float64)
    for c in range(3):  # each corner of each triangle adds its triangle's normal
        acc[:, c] = np.bincount(corners, weights=np.repeat(n[:, c], 3), minlength=len(p))
    length = np.sqrt(np.einsum("ij,ij->i", acc, acc))
    out = np.zeros((len(p), 3), dtype=np.float32)
    out[:, 2] = 1.0
    ok = length > 0
    out[ok] = acc[ok] / length[ok, None]
    return out


def write_glb(
    meshes: Sequence[tuple[np.ndarray, np.ndarray]],
    *,
    names: Sequence[str] | None = None,
    scale: float = 1e-3,
    colors: Sequence[np.ndarray | None] | None = None,
) -> bytes:
    """A binary glTF 2.0 file of triangle meshes.

    Parameters
    ----------
    meshes : sequence of (vertices (n, 3) float, triangles (t, 3) int)
    names : sequence of str, optional
    colors : sequence of (n, 3) or (n, 4) float in 0..1 or None, optional
        Vertex colours per mesh, written as ``COLOR_0`` (float RGB or RGBA, linear as
        glTF defines it).
    scale : float
        Metres per model unit (glTF's unit is the metre; 1e-3 for millimetres).
    colors : sequence of (n, 3) or (n, 4) float in 0..1, or None, optional
        Each mesh's vertex colours, written as ``COLOR_0`` (float32, linear as glTF reads
        them; clipped to 0..1).

    Returns
    -------
    bytes
    """
    names = list(names) if names is not None else [f"mesh {k + 1}" for k in range(len(meshes))]
    blobs: list[bytes] = []
    views, accessors, gmeshes, nodes = [], [], [], []
    offset = 0

    def add(array: np.ndarray, target: int, component: int, kind: str, bounds: bool) -> int:
        nonlocal offset
        data = np.ascontiguousarray(array).tobytes()
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data), "target": target})
        acc = {
            "bufferView": len(views) - 1,
            "componentType": component,
            "count": int(array.shape[0]) if kind != "SCALAR" else int(array.size),
            "type": kind,
        }
        if bounds and array.size:
            acc["min"] = [float(x) for x in array.min(axis=0)]
            acc["max"] = [float(x) for x in array.max(axis=0)]
        accessors.append(acc)
        pad = (-len(data)) % 4
        blobs.append(data + b"\0" * pad)
        offset += len(data) + pad
        return len(accessors) - 1

    for k, (v, tris) in enumerate(meshes):
        v = np.asarray(v, dtype=np.float64)
        tris = np.asarray(tris, dtype=np.int64).reshape(-1, 3)
        if len(v) >= 2**32 - 1:
            raise ValueError("glTF uint32 indices hold fewer than 2**32 - 1 vertices")
        position = add((v * scale).astype("<f4"), 34962, 5126, "VEC3", True)
        normal = add(vertex_normals(v, tris).astype("<f4"), 34962, 5126, "VEC3", False)
        indices = add(tris.astype("<u4").ravel(), 34963, 5125, "SCALAR", False)
        attributes = {"POSITION": position, "NORMAL": normal}
        c = None if colors is None else colors[k]
        if c is not None:
            c = np.clip(np.asarray(c, dtype=np.float64).reshape(len(v), -1), 0.0, 1.0)
            if c.shape[1] not in (3, 4):
                raise ValueError(f"vertex colours need 3 or 4 components, got {c.shape[1]}")
            kind = "VEC3" if c.shape[1] == 3 else "VEC4"
            attributes["COLOR_0"] = add(c.astype("<f4"), 34962, 5126, kind, False)
        gmeshes.append(
            {
                "name": names[k],
                "primitives": [
                    {
                        "attributes": attributes,
                        "indices": indices,
                        "mode": 4,
                    }
                ],
            }
        )
        nodes.append({"mesh": k, "name": names[k]})
    doc = {
        "asset": {"version": "2.0", "generator": "formgraph"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": gmeshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": offset}],
    }
    if not meshes:
        for key in ("meshes", "accessors", "bufferViews", "buffers", "nodes"):
            doc.pop(key)
        doc["scenes"] = [{}]
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * ((-len(text)) % 4)
    binary = b"".join(blobs)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text
    if binary:
        chunks += struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


# --------------------------------------------------------------------------------------------
# reading


def read_gltf(
    data: bytes, *, scale: float = 1e3, max_elements: int = 50_000_000
) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """The triangle meshes a glTF 2.0 file (``.glb``, or ``.gltf`` JSON with embedded
    ``data:`` buffers) places: ``(name, vertices (n, 3), triangles (t, 3), colours (n, 3|4)
    or None)`` per mesh instance (``COLOR_0``, normalized integers read as 0..1), transforms
    applied, coordinates times ``scale`` (1000: metres to millimetres).

    Raises
    ------
    ValueError
        For a malformed container, external or compressed buffers, accessors that run past
        their buffers, bad or non-integer indices, a node tree that is too deep or too
        large, or a scene placing more than ``max_elements`` vertices or triangles (counted
        from the accessors before a copy is made).
    """
    doc, binary = _container(data)
    if doc.get("extensionsRequired"):
        raise ValueError(
            f"the file requires the extensions {', '.join(map(str, doc['extensionsRequired']))}"
            ", which are not read (compressed meshes?)"
        )
    buffers = [_buffer(b, k, binary) for k, b in enumerate(_list(doc, "buffers"))]
    meshes = _list(doc, "meshes")
    nodes = _list(doc, "nodes")
    scenes = _list(doc, "scenes")
    placed: list[tuple[int, np.ndarray]] = []
    if scenes:
        scene = scenes[_int(doc.get("scene", 0), len(scenes), "scene")]
        roots = scene.get("nodes", []) if isinstance(scene, dict) else []
        stack = [(_int(n, len(nodes), "node"), np.eye(4), 0) for n in reversed(roots)]
        visits = 0
        while stack:
            n, parent, depth = stack.pop()
            visits += 1
            if depth > MAX_DEPTH or visits > MAX_VISITS:
                raise ValueError(
                    f"the node tree is deeper than {MAX_DEPTH} or visits more than "
                    f"{MAX_VISITS:,} nodes (a cycle?)"
                )
            node = nodes[n] if isinstance(nodes[n], dict) else {}
            m = parent @ _node_matrix(node)
            if "mesh" in node:
                placed.append((_int(node["mesh"], len(meshes), "mesh"), m))
            for c in reversed(node.get("children", [])):
                stack.append((_int(c, len(nodes), "node"), m, depth + 1))
    else:
        placed = [(k, np.eye(4)) for k in range(len(meshes))]
    _budgeted(doc, meshes, placed, max_elements)
    out = []
    for k, m in placed:
        mesh = meshes[k] if isinstance(meshes[k], dict) else {}
        verts, tris, colors, base = [], [], [], 0
        for prim in mesh.get("primitives", []):
            if prim.get("mode", 4) != 4:
                continue  # points and lines are not surfaces
            attrs = prim.get("attributes", {})
            if "POSITION" not in attrs:
                continue
            p = _accessor(doc, buffers, attrs["POSITION"]).astype(np.float64).reshape(-1, 3)
            if "indices" in prim:
                t = _accessor(doc, buffers, prim["indices"])
                if t.dtype.kind != "u":  # glTF 2.0, 3.7.2.1: UNSIGNED_BYTE, SHORT or INT
                    raise ValueError(
                        f"mesh {k}: its indices are {t.dtype.name} (accessor "
                        f"{prim['indices']}); glTF indices are unsigned integers"
                    )
                t = t.astype(np.int64).ravel()
            else:
                t = np.arange(len(p), dtype=np.int64)
            if t.size % 3:
                raise ValueError(f"mesh {k}: {t.size} indices are not whole triangles")
            if t.size and (t.min() < 0 or t.max() >= len(p)):
                raise ValueError(f"mesh {k}: an index refers to a vertex that does not exist")
            verts.append(p @ m[:3, :3].T + m[:3, 3])
            tris.append(t.reshape(-1, 3) + base)
            color = None
            if "COLOR_0" in attrs:
                color = _accessor(doc, buffers, attrs["COLOR_0"]).astype(np.float64)
                if color.shape != (len(p), color.shape[1]) or color.shape[1] not in (3, 4):
                    raise ValueError(f"mesh {k}: COLOR_0 does not hold a colour a vertex")
            colors.append(color)
            base += len(p)
        if verts:
            name = str(mesh.get("name", f"mesh {k}"))
            c = np.concatenate(colors) if all(x is not None for x in colors) else None
            out.append((name, np.concatenate(verts) * scale, np.concatenate(tris), c))
    return out


def _budgeted(doc: dict, meshes: list, placed: list, max_elements: int) -> None:
    """Refuse a scene that places more than ``max_elements`` vertices or triangles, from the
    accessors' counts, before any copy is made (a big mesh placed by many nodes)."""
    accessors = doc.get("accessors", [])
    size: dict[int, tuple[int, int]] = {}
    vertices = triangles = 0
    for k, _ in placed:
        if k not in size:
            nv = nt = 0
            mesh = meshes[k] if isinstance(meshes[k], dict) else {}
            for prim in mesh.get("primitives", []):
                attrs = prim.get("attributes", {}) if isinstance(prim, dict) else {}
                count = _count(accessors, attrs.get("POSITION"))
                nv += count
                nt += (_count(accessors, prim.get("indices")) if "indices" in prim else count) // 3
            size[k] = (nv, nt)
        vertices, triangles = vertices + size[k][0], triangles + size[k][1]
    for count, what in ((vertices, "vertices"), (triangles, "triangles")):
        if count > max_elements:
            raise ValueError(
                f"the scene places {count:,} {what} ({len(placed):,} mesh instances), over the "
                f"budget of {max_elements:,}: refused before expanding"
            )


def _count(accessors: list, index) -> int:
    a = accessors[index] if isinstance(index, int) and 0 <= index < len(accessors) else None
    count = a.get("count", 0) if isinstance(a, dict) else 0
    return count if isinstance(count, int) and count > 0 else 0


def _container(data: bytes) -> tuple[dict, bytes | None]:
    if data[:4] == b"glTF":
        if len(data) < 20:
            raise ValueError("the GLB file is shorter than its header")
        _, version, length = struct.unpack_from("<4sII", data)
        if version != 2:
            raise ValueError(f"GLB version {version}; only glTF 2.0 is read")
        if length > len(data):
            raise ValueError(f"the header claims {length:,} bytes but the file is {len(data):,}")
        at, doc, binary = 12, None, None
        while at + 8 <= length:
            size, kind = struct.unpack_from("<II", data, at)
            if at + 8 + size > length:
                raise ValueError("a GLB chunk runs past the end of the file: truncated")
            body = data[at + 8 : at + 8 + size]
            if kind == 0x4E4F534A and doc is None:
                doc = _json(body)
            elif kind == 0x004E4942 and binary is None:
                binary = body
            at += 8 + size + ((-size) % 4 if at + 8 + size < length else 0)
        if doc is None:
            raise ValueError("the GLB file has no JSON chunk")
        return doc, binary
    return _json(data), None


def _json(text: bytes) -> dict:
    if len(text) > MAX_JSON:
        raise ValueError(f"the glTF JSON is over {MAX_JSON >> 20} MiB")
    try:
        doc = json.loads(text.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise ValueError(f"not glTF (its JSON does not parse: {str(exc)[:80]})") from None
    if not isinstance(doc, dict) or str(doc.get("asset", {}).get("version", ""))[:1] != "2":
        raise ValueError("not a glTF 2.0 document (asset.version)")
    return doc


def _list(doc: dict, key: str) -> list:
    value = doc.get(key, [])
    if not isinstance(value, list):
        raise ValueError(f"glTF '{key}' must be a list")
    return value


def _int(value, n: int, what: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value < n:
        raise ValueError(f"a glTF {what} index {value!r} is out of range ({n} {what}s)")
    return value


def _buffer(b: dict, k: int, binary: bytes | None) -> bytes:
    uri = b.get("uri") if isinstance(b, dict) else None
    if uri is None:
        if binary is None:
            raise ValueError(f"buffer {k} refers to a binary chunk the file does not have")
        out = binary
    elif isinstance(uri, str) and uri.startswith("data:") and ";base64," in uri[:200]:
        try:
            out = base64.b64decode(uri.split(",", 1)[1], validate=True)
        except ValueError:
            raise ValueError(f"buffer {k}: its data URI is not base64") from None
    else:
        raise ValueError(
            f"buffer {k} is an external file ({str(uri)[:60]!r}); pack the model as .glb"
        )
    length = b.get("byteLength", len(out))
    if not isinstance(length, int) or length > len(out):
        raise ValueError(f"buffer {k} claims {length} bytes but holds {len(out):,}")
    return out


def _accessor(doc: dict, buffers: list[bytes], index) -> np.ndarray:
    accessors = _list(doc, "accessors")
    a = accessors[_int(index, len(accessors), "accessor")]
    if "sparse" in a:
        raise ValueError("sparse accessors are not read")
    dtype = np.dtype(_COMPONENT.get(a.get("componentType"), "V"))
    if dtype.kind == "V" or a.get("type") not in _WIDTH:
        raise ValueError(f"accessor {index} has an unknown component or element type")
    width, count = _WIDTH[a["type"]], a.get("count", 0)
    if not isinstance(count, int) or count < 0:
        raise ValueError(f"accessor {index} has a bad count")
    if "bufferView" not in a:
        return np.zeros((count, width), dtype)
    views = _list(doc, "bufferViews")
    view = views[_int(a["bufferView"], len(views), "bufferView")]
    buf = buffers[_int(view.get("buffer", 0), len(buffers), "buffer")]
    start = int(view.get("byteOffset", 0)) + int(a.get("byteOffset", 0))
    length = int(view.get("byteLength", 0))
    element = dtype.itemsize * width
    stride = int(view.get("byteStride", element) or element)
    end = start + (stride * (count - 1) + element if count else 0)
    if (
        stride < element
        or start < int(view.get("byteOffset", 0))
        or end > int(view.get("byteOffset", 0)) + length
        or end > len(buf)
    ):
        raise ValueError(f"accessor {index} runs past its buffer view or buffer")
    raw = np.frombuffer(buf, np.uint8)
    out = np.lib.stride_tricks.as_strided(
        raw[start:].view(np.uint8), shape=(count, element), strides=(stride, 1)
    )
    values = np.ascontiguousarray(out).view(dtype).reshape(count, width)
    if a.get("normalized") and dtype.kind in "iu":
        values = values.astype(np.float64) / np.iinfo(dtype).max
    return values


def _node_matrix(node: dict) -> np.ndarray:
    if "matrix" in node:
        m = np.asarray(node["matrix"], dtype=float)
        if m.shape != (16,) or not np.all(np.isfinite(m)):
            raise ValueError("a node matrix needs 16 finite numbers")
        return m.reshape(4, 4).T  # column-major
    t = np.asarray(node.get("translation", [0, 0, 0]), dtype=float)
    q = np.asarray(node.get("rotation", [0, 0, 0, 1]), dtype=float)
    s = np.asarray(node.get("scale", [1, 1, 1]), dtype=float)
    if (
        t.shape != (3,)
        or q.shape != (4,)
        or s.shape != (3,)
        or not np.all(np.isfinite(np.concatenate([t, q, s])))
    ):
        raise ValueError("a node's translation, rotation or scale is malformed")
    x, y, z, w = q / (np.linalg.norm(q) or 1.0)
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    m = np.eye(4)
    m[:3, :3] = r * s
    m[:3, 3] = t
    return m
