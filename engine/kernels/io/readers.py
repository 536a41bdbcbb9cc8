"""Which reader a file's name calls: the one table behind the ``read.*`` nodes and
``--set part=FILE``.

Each function takes a file's name (for its extension) and bytes and returns plain arrays;
building geometry values from them is the caller's job.
"""

from __future__ import annotations

from pathlib import PurePath

import numpy as np

from .dxf_read import MAX_ENTITIES, read_dxf
from .gltf import read_gltf
from .mesh_read import read_obj, read_off, read_stl
from .ply_read import read_ply
from .points_read import read_ply_points, read_text_points
from .svg_read import MAX_ELEMENTS, read_svg
from .threemf import read_3mf

__all__ = ["CURVE_FORMATS", "MESH_FORMATS", "POINT_FORMATS", "extension", "mesh_arrays"]


def _merged(parts: list[tuple[str, np.ndarray, np.ndarray]]) -> tuple[np.ndarray, ...]:
    if not parts:
        raise ValueError("the file places no triangle mesh")
    shift = np.cumsum([0] + [len(p[1]) for p in parts[:-1]])
    v = np.concatenate([p[1] for p in parts])
    t = np.concatenate([p[2] + s for p, s in zip(parts, shift, strict=True)]).astype(np.int64)
    return v, t.ravel(), np.arange(0, t.size + 1, 3, dtype=np.int64)


MESH_FORMATS = {
    ".stl": read_stl,
    ".obj": read_obj,
    ".ply": read_ply,
    ".off": read_off,
    ".3mf": lambda data: _merged(read_3mf(data)),
    ".glb": lambda data: _merged(read_gltf(data)),
    ".gltf": lambda data: _merged(read_gltf(data)),
}


CURVE_FORMATS = {  # (data, element budget) -> (curves with a .curve and a .layer, skipped)
    ".svg": lambda data, budget: (read_svg(data, min(MAX_ELEMENTS, budget)), {}),
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


def mesh_arrays(name: str, data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(vertices, face_indices, face_offsets)`` of the mesh file ``name`` holding ``data``.

    Raises
    ------
    ValueError
        An unknown extension, or what the format's reader finds wrong.
    """
    return MESH_FORMATS[extension(name, MESH_FORMATS)](data)
