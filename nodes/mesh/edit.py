"""Meshes edited whole: triangulation, merging and affine transforms, attributes carried."""

from __future__ import annotations

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import Vec3
from formgraph.geometry import Mesh
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import (
    WorkLimitError,
    meshops,
)
from formgraph.nodes.mesh._common import mesh_arrays


@node("mesh.triangulate", version=1)
def triangulate(mesh: Mesh, *, ctx: Context) -> Mesh:
    """Split every face into triangles, keeping orientation and face order.

    Convex faces become fans from their first corner; concave ones are ear-clipped in
    their own plane (Newell normal), in O(k^2) at worst for a face of k corners (a
    10,000-corner star takes well under a second). The clipping's triangle-corner tests
    count against the element budget.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh.
    """
    try:
        v, fi, fo = meshops.triangulate(*mesh_arrays(mesh), max_tests=ctx.budget)
    except WorkLimitError as exc:
        ctx.guard(exc.work, "triangle-corner tests of ear clipping")
        raise

    def parents() -> carry.Carry:  # made only for a mesh with face attributes
        return carry.copy(np.repeat(np.arange(mesh.n_faces), mesh.face_sizes - 2))

    # the input's vertices and corners, regrouped: valid by construction, not checked again
    return Mesh.trusted(v, fi, fo, **carry.carried(mesh, carry.SAME, parents))


@node("mesh.merge", version=1)
def merge(meshes: list[Mesh], *, ctx: Context) -> Mesh:
    """Several meshes as one (vertices appended in order; nothing is welded).

    Parameters
    ----------
    meshes : list[Mesh]
        The meshes, in order.
    """
    ctx.guard(sum(m.n_faces for m in meshes), "faces")
    return merged(meshes, ctx)


def merged(meshes: list[Mesh], ctx: Context) -> Mesh:
    """The meshes laid end to end, with their attributes (0 where one lacks an attribute
    the others have; an attribute whose shape differs between them is dropped, warned)."""
    v, fi, fo = meshops.merge([mesh_arrays(m) for m in meshes])
    point_data, p_bad = carry.concat([m.point_data for m in meshes], [m.n_vertices for m in meshes])
    face_data, f_bad = carry.concat([m.face_data for m in meshes], [m.n_faces for m in meshes])
    for name in p_bad + f_bad:
        ctx.warn(f"attribute {name!r} has different shapes on the meshes; it was dropped")
    return Mesh(v, fi, fo, point_data, face_data)


@node("mesh.transform", version=1)
def transform(
    mesh: Mesh,
    translate: Vec3 = (0.0, 0.0, 0.0),
    rotate: Vec3 = (0.0, 0.0, 0.0),
    scale: float | Vec3 = 1.0,
) -> Mesh:
    """Scale, then rotate (degrees about x, then y, then z), then translate a mesh.

    A mirroring scale (an odd number of negative factors) also reverses the faces, so
    they keep facing outward.

    Parameters
    ----------
    mesh : Mesh
        The mesh to move.
    translate : Vec3
        Offset added last.
    rotate : Vec3
        Angles in degrees about the fixed x, y and z axes, applied in that order.
    scale : float | Vec3
        One factor, or [sx, sy, sz]; none may be 0.
    """
    try:
        v = meshops.transform(mesh.vertices, translate, rotate, scale)
    except ValueError as exc:
        raise InputError("scale", str(exc)) from None
    fi = mesh.face_indices
    if np.prod(np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))) < 0:
        fi = meshops.reverse_faces(fi, mesh.face_offsets)
    linear = meshops.transform(np.eye(3), 0.0, rotate, scale).T  # the map's linear part
    return Mesh(
        v,
        fi,
        mesh.face_offsets,
        carry.turn(mesh.point_data, linear),
        carry.turn(mesh.face_data, linear),
    )
