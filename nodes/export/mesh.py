"""Export of meshes: STL, OBJ and PLY (:mod:`formgraph.kernels.io.exporters`), written by
``ctx.write`` as every export is. Each returns the written file's path.
"""

from __future__ import annotations

import numpy as np

from formgraph.core.registry import Context, node
from formgraph.core.types import OutputPath
from formgraph.geometry import Mesh
from formgraph.kernels.io import (
    fan_triangles,
    mesh_report,
    obj_bytes,
    ply_binary,
    stl_ascii_chunks,
    stl_binary,
)


@node("export.stl", version=1)
def stl(mesh: Mesh, path: OutputPath, ascii: bool = False, *, ctx: Context) -> str:
    """Write a mesh as STL (binary, or ASCII), for 3-D printing.

    Polygons are fan-triangulated, each facet's normal comes from its winding. A mesh that is
    not watertight, not consistently oriented, inside out or has zero-area triangles is
    still written, with a warning in the node's stats saying what a slicer will find.

    Parameters
    ----------
    mesh : Mesh
        The mesh to write.
    path : OutputPath
        File path relative to the output directory, e.g. ``parts/tube.stl``.
    ascii : bool
        Write the text layout (``facet normal ... endfacet``) instead of binary.
    """
    v, fi, fo = mesh.vertices, mesh.face_indices, mesh.face_offsets
    ctx.guard(int(np.sum(mesh.face_sizes - 2)), "triangles")
    for warning in mesh_report(v, fi, fo).warnings():
        ctx.warn(warning)
    # ASCII: written a block of facets at a time (the text is five times the binary)
    data = stl_ascii_chunks(v, fi, fo) if ascii else stl_binary(v, fi, fo)
    return str(ctx.write(path, data))


@node("export.obj", version=1)
def obj(mesh: Mesh, path: OutputPath, normals: bool = False, *, ctx: Context) -> str:
    """Write a mesh as Wavefront OBJ: polygons kept as they are, 1-based indices.

    Coordinates are written as the shortest text that reads back to the same double, so
    the file holds the mesh exactly.

    Parameters
    ----------
    mesh : Mesh
        The mesh to write.
    path : OutputPath
        File path relative to the output directory.
    normals : bool
        Also write one normal per vertex (``vn``; the area-weighted average of the normals
        of the faces around it) and reference them from the faces (``f 1//1 2//2 3//3``).
    """
    v, fi, fo = mesh.vertices, mesh.face_indices, mesh.face_offsets
    vn = _vertex_normals(v, fi, fo) if normals else None
    return str(ctx.write(path, obj_bytes(v, fi, fo, normals=vn)))


@node("export.ply", version=1)
def ply(mesh: Mesh, path: OutputPath, *, ctx: Context) -> str:
    """Write a mesh as binary little-endian PLY: double coordinates, polygon faces kept.

    Every point and face attribute is written: a ``color`` (3 or 4 components in 0..1) as
    ``uchar red green blue [alpha]``, which viewers show, a ``normal`` as ``nx ny nz``, any
    other as ``double`` properties (``name``, or ``name_0, name_1, ...`` for a vector).

    Parameters
    ----------
    mesh : Mesh
        The mesh to write.
    path : OutputPath
        File path relative to the output directory.
    """
    data = ply_binary(*mesh.arrays, mesh.point_data, mesh.face_data)
    return str(ctx.write(path, data))


def _vertex_normals(v: np.ndarray, fi: np.ndarray, fo: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals: the sum of the area vectors of the faces around each.

    A face's area vector is the sum of its fan triangles' cross products (Newell's normal,
    twice the area, exact for planar polygons); it is added to each of the face's vertices.
    """
    tris = fan_triangles(fi, fo)
    a = v[tris[:, 0]]
    cross = np.cross(v[tris[:, 1]] - a, v[tris[:, 2]] - a)
    face_of_tri = np.repeat(np.arange(fo.size - 1), np.diff(fo) - 2)
    area = np.zeros((fo.size - 1, 3))
    np.add.at(area, face_of_tri, cross)
    acc = np.zeros_like(v)
    np.add.at(acc, fi, area[np.repeat(np.arange(fo.size - 1), np.diff(fo))])
    length = np.linalg.norm(acc, axis=1)
    out = np.zeros_like(v)
    np.divide(acc, length[:, None], out=out, where=length[:, None] > 0)
    return out
