"""Which reader a file's name calls: the one table behind the ``read.*`` nodes and
``--set part=FILE``.

Each function takes a file's name (for its extension) and bytes and returns plain arrays;
building geometry values from them is the caller's job.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import PurePath

import numpy as np

from .dxf_read import MAX_ENTITIES, read_dxf
from .gltf import read_gltf
from .mesh_read import read_obj, read_off, read_stl, triangles_flat
from .ply_read import point_data, read_ply
from .points_read import read_ply_points, read_text_points
from .svg_read import MAX_ELEMENTS, read_svg
from .threemf_read import MAX_ELEMENTS as MAX_PLACED
from .threemf_read import read_3mf

__all__ = [
    "CURVE_FORMATS",
    "MESH_FORMATS",
    "POINT_FORMATS",
    "extension",
    "in_words",
    "mesh_arrays",
    "mesh_data",
    "vertex_attributes",
]


def _merged(parts: list[tuple]) -> tuple:
    """One mesh of several placed ones; a ``color`` when every part has one."""
    if not parts:
        raise ValueError("the file places no triangle mesh")
    shift = np.cumsum([0] + [len(p[1]) for p in parts[:-1]])
    v = np.concatenate([p[1] for p in parts])
    t = np.concatenate([p[2] + s for p, s in zip(parts, shift, strict=True)]).astype(np.int64)
    colors = [p[3] if len(p) > 3 else None for p in parts]
    attributes = {}
    if all(c is not None for c in colors) and len({c.shape[1] for c in colors}) == 1:
        attributes["color"] = np.concatenate(colors)
    return v, t.ravel(), np.arange(0, t.size + 1, 3, dtype=np.int64), attributes


def _threemf(data: bytes, budget: int) -> tuple:
    got = read_3mf(data, max_elements=budget)
    if not got.items:
        raise ValueError("the file places no triangle mesh (its build has no items)")
    attributes = {"color": got.colors} if got.colors is not None else {}
    return (*triangles_flat(got.vertices, got.triangles), attributes)


def _plain(reader):
    return lambda data, budget: (*reader(data), {})


MESH_FORMATS = {  # (data, element budget) -> (vertices, face_indices, face_offsets, attributes)
    ".stl": _plain(read_stl),
    ".obj": _plain(read_obj),
    ".ply": lambda data, budget: (*read_ply(data), point_data(data)),
    ".off": _plain(read_off),
    ".3mf": _threemf,
    ".glb": lambda data, budget: _merged(read_gltf(data, max_elements=budget)),
    ".gltf": lambda data, budget: _merged(read_gltf(data, max_elements=budget)),
}


CURVE_FORMATS = {  # (data, element budget) -> (curves with a .curve and a .layer, skipped)
    ".svg": lambda data, budget: read_svg(data, min(MAX_ELEMENTS, budget)),
    ".dxf": lambda data, budget: read_dxf(data, min(MAX_ENTITIES, budget)),
}


POINT_FORMATS = {
    ".csv": lambda data: read_text_points(data, comma=True),
    ".txt": lambda data: read_text_points(data, comma=False),
    ".xyz": lambda data: read_text_points(data, comma=False),
    ".ply": read_ply_points,
}


def extension(name: str, formats: dict) -> str:
    """The lower-case extension of ``name``, which must be one of ``formats``."""
    ext = PurePath(name).suffix.lower()
    if ext not in formats:
        raise ValueError(
            f"{name!r}: unknown format {ext or '(no extension)'!r}; read are {', '.join(formats)}"
        )
    return ext


def mesh_data(
    name: str, data: bytes, budget: int = MAX_PLACED
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """``(vertices, face_indices, face_offsets, point attributes)`` of the mesh file
    ``name`` holding ``data`` (attributes: a PLY's extra vertex properties, a glTF's
    ``COLOR_0`` or a 3MF colour group as ``color``). ``budget`` bounds what a 3MF build or a
    glTF scene places (instances times their triangles), counted before it is expanded.

    Raises
    ------
    ValueError
        An unknown extension, or what the format's reader finds wrong.
    """
    return MESH_FORMATS[extension(name, MESH_FORMATS)](data, budget)


def mesh_arrays(name: str, data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(vertices, face_indices, face_offsets)`` of a mesh file, attributes dropped."""
    return mesh_data(name, data)[:3]


def vertex_attributes(name: str, data: bytes) -> dict[str, np.ndarray]:
    """The per-vertex attributes a point file carries (a PLY's extra vertex properties);
    none for the text formats."""
    return point_data(data) if extension(name, POINT_FORMATS) == ".ply" else {}


_WHY = {  # what an exception a parser did not raise on purpose means of the file
    KeyError: "a field it needs is missing",
    IndexError: "it ends before the data it announces (truncated?)",
    TypeError: "a value has the wrong type for its field",
    OverflowError: "a number is too large",
    struct.error: "a binary field is shorter than its format says (truncated?)",
    zlib.error: "a compressed block is corrupt",
}


def in_words(exc: BaseException) -> str:
    """A reader's error as a sentence about the file: its own message when it raised one on
    purpose (a ValueError with a reason), else what that kind of failure means, with the
    detail, never a bare exception name (#33 item 13)."""
    message = str(exc.args[0] if isinstance(exc, KeyError) and exc.args else exc).strip()
    if type(exc) is ValueError or (isinstance(exc, ValueError) and message):
        return message or "it is malformed (the reader gave no reason)"
    why = next((w for kind, w in _WHY.items() if isinstance(exc, kind)), "it is malformed")
    return f"{why} ({message[:100]})" if message else why
