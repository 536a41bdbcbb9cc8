"""``mesh.copy_to_points``: a mesh copied onto every point in one array operation
(:mod:`formgraph.kernels.geometry.instancing`), mirrored copies turned outward again.
"""

from __future__ import annotations

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.geometry import (
    Mesh,
    Points,
)
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.geometry import instancing
from formgraph.kernels.mesh import meshops
from formgraph.nodes._instancing import Align, Rotate, Scale, frames, per_point


@node("mesh.copy_to_points", version=1)
def mesh_copy_to_points(
    mesh: Mesh,
    points: Points,
    scale: Scale = 1.0,
    rotate: Rotate = (0.0, 0.0, 0.0),
    align: Align = None,
    *,
    ctx: Context,
) -> Mesh:
    """A copy of the mesh on every point, all copies in one mesh (one array operation).

    Copy k is the mesh scaled, rotated (degrees about x, y, z), turned so its +z points
    along ``align[k]`` (the minimal rotation, Rodrigues' formula), then moved to point k.
    The mesh's origin lands on the point. Copies follow the points' order; a mirroring
    scale reverses that copy's faces.

    ``scale``, ``rotate`` and ``align`` may be expressions evaluated per point, over the
    point's ``x y z``, ``i``, ``count``, its attributes and the params:
    ``scale: "=0.5 + rand(i)"``, ``rotate: [0, 0, "=360 * rand(i, 1)"]``, ``align: "=normal"``.
    Attributes: each copy keeps the part's (a ``normal`` turned with the copy), the point's
    attributes go onto its copy's vertices, and a ``copy`` point attribute holds each
    vertex's copy index.

    Parameters
    ----------
    mesh : Mesh
        The part to copy, modelled about its origin.
    points : Points
        Where the copies go.
    scale : float | list[float] | list[Vec3]
        One factor for all copies, one factor per point, or rows [sx, sy, sz] (one row
        for all, e.g. [[1, 1, 2]], or one per point).
    rotate : Vec3 | list[Vec3]
        Degrees about x, y, z: one [rx, ry, rz] for all, or one per point.
    align : Vec3 | list[Vec3] | None
        A direction for each copy's +z (e.g. surface normals), one or one per point; None
        keeps the orientation.

    Example
    -------
    ``windows: {type: mesh.copy_to_points, mesh: "@frame", points: "@grid.points",
    align: "@grid.normals"}``
    """
    n = len(points)
    ctx.guard(n * mesh.n_faces, "faces")
    ctx.guard(n * mesh.n_vertices * 3, "coordinates", nbytes=n * mesh.nbytes, port="points")
    per = per_point(points, scale=scale, rotate=rotate, align=align)
    linear = frames(n, per["scale"], per["rotate"], per["align"])
    mirrored = np.linalg.det(linear) < 0
    rev = meshops.reverse_faces(mesh.face_indices, mesh.face_offsets) if mirrored.any() else None
    v, fi, fo = instancing.copy_mesh(
        mesh.vertices, mesh.face_indices, mesh.face_offsets, linear, points.xyz, rev
    )
    if not np.isfinite(v).all():
        raise InputError("points", "the copies' coordinates overflow (not finite)")
    # the part's attributes on every copy (a normal turned with it), the point's
    # attributes on its copy's vertices, and ``copy``: the index of each vertex's copy
    m, f = mesh.n_vertices, mesh.n_faces
    which_v = np.repeat(np.arange(n), m)
    tile_v = carry.copy(np.tile(np.arange(m), n))
    point_data = carry.turn(carry.carried(mesh, point=tile_v)["point_data"], linear, which_v)
    point_data.update(carry.carried(points, point=carry.copy(which_v))["point_data"])
    point_data["copy"] = which_v.astype(np.float64)
    tile_f = carry.copy(np.tile(np.arange(f), n))
    face_data = carry.turn(
        carry.carried(mesh, face=tile_f)["face_data"], linear, np.repeat(np.arange(n), f)
    )
    return Mesh.trusted(v, fi, fo, point_data, face_data)
