"""Thick and offset meshes: ``mesh.solidify`` (a shell given a wall, planar rims kept on their
plane; :mod:`formgraph.kernels.mesh.solidify`) and ``mesh.offset`` (``field.from_mesh`` ->
``field.offset`` -> ``field.mesh`` in one node: the 3-D twin of ``offset.marching_squares``).
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Expression, Variables
from formgraph.geometry import Field, Mesh
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import solidify as ks
from formgraph.nodes.field.mesh import mesh_of
from formgraph.nodes.mesh._common import (
    mesh_arrays,
    topology,
    within_floats,
)


@node("mesh.offset", version=3)
def mesh_offset(
    mesh: Mesh,
    distance: float,
    cell: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Mesh:
    """A closed mesh grown (or shrunk, ``distance`` < 0) by ``distance``: a 3-D offset.

    The mesh's signed distance field (``field.from_mesh``: exact distance, winding-number
    sign) less ``distance``, meshed adaptively (``field.mesh``): robust for any closed
    input, self-intersecting or not; convex edges come out rounded (a Minkowski sum with a
    ball), concave ones sharp up to the cell. Point attributes are interpolated at each new
    vertex's closest point of the input (the foot of its offset), face attributes come from
    the input face nearest each new face's centroid.

    Parameters
    ----------
    mesh : Mesh
        A closed (or nearly closed) outward mesh.
    distance : float
        Offset distance (positive grows).
    cell : float | None
        The finest cell; none: 1/100 of the grown box's largest side.
    """
    if mesh.n_faces == 0:
        raise InputError("mesh", "the mesh has no faces")
    if not np.isfinite(distance) or distance == 0:
        raise InputError("distance", f"distance must be finite and not 0, got {distance:g}")
    size = float((mesh.bounds[1] - mesh.bounds[0]).max())
    if distance < 0 and -distance * 2 >= size:
        ctx.warn(f"an inward offset of {-distance:g} may remove the whole mesh")
    f = Field.offset(Field.from_mesh(mesh), float(distance))
    out = mesh_of(f, cell, None, ctx, port="mesh")
    # attributes from the input's closest point (the offset's foot), faces' from the nearest
    faces = (out.face_indices, out.face_offsets)
    return Mesh(out.vertices, *faces, **carry.onto(mesh, out.vertices, faces, max_tests=ctx.budget))


@node("mesh.solidify", version=3)
def solidify(
    mesh: Mesh,
    thickness: Annotated[float, Range(min=0)],
    offset: Annotated[float, Range(min=-1, max=1)] = 0.0,
    thickness_map: Annotated[Expression | None, Variables("x", "y", "z", "thickness")] = None,
    planar_rims: bool = True,
    *,
    ctx: Context,
) -> Mesh:
    """Thicken a surface into a closed shell: two offset copies joined along the rims.

    Vertices move along angle-weighted normals (Thuermer & Wuethrich 1998); every boundary
    edge gets a quad joining the two sides. An oriented manifold surface, open or closed,
    gives a watertight, outward shell; a closed one gives a hollow solid. The wall stays
    clean while the thickness is below the surface's smallest radius of curvature.

    Parameters
    ----------
    mesh : Mesh
        An oriented manifold surface.
    thickness : float
        Wall thickness, > 0 (an expression like "=wall" reads the graph's params).
    offset : float
        Where the wall sits: -1 behind the surface (inside), 0 centred, 1 in front.
    thickness_map : Expression | None
        A wall that varies: the thickness at each vertex as an expression in its position
        x, y, z and ``thickness``, e.g. "thickness * (1 + z / 5)". Each value must be > 0.
    planar_rims : bool
        Keep every planar boundary loop in its own plane: its vertices move along their
        normals projected into the plane (the wall's thickness kept), so a shade whose
        bottom rim lies on z = 0 still stands on z = 0. Where the whole surface lies on
        one side of such a plane (a bed, or a top), no vertex of the wall passes it: the
        rings next to the rim, whose normals point through the plane on a flaring wall,
        slide along the wall away from it, so the wall ends in the plane without folding
        back. Loops that are not planar, or whose surface lies nearly in the loop's plane
        (within 30 degrees), move along their normals.
    """
    if thickness <= 0:
        raise InputError("thickness", f"thickness must be > 0, got {thickness:g}")
    ctx.guard(3 * mesh.face_indices.size, "face corners")
    t: float | np.ndarray = thickness
    if thickness_map is not None:
        v = mesh.vertices
        t = np.broadcast_to(
            np.asarray(thickness_map(x=v[:, 0], y=v[:, 1], z=v[:, 2], thickness=thickness), float),
            (mesh.n_vertices,),
        )
        bad = np.flatnonzero(~(np.isfinite(t) & (t > 0)))
        if bad.size:
            i = int(bad[0])
            raise InputError(
                "thickness_map",
                f"{getattr(thickness_map, 'text', 'the expression')!r} gives {t[i]:g} at vertex "
                f"{i} ({', '.join(f'{c:.6g}' for c in v[i])}); a thickness must be > 0",
            )
    try:
        arrays = topology("mesh", ks.solidify, *mesh_arrays(mesh), t, offset, planar_rims)
    except ValueError as exc:
        raise InputError("mesh", str(exc)) from None
    port, what = (
        ("thickness_map", f"the thickness map's values (up to {float(np.max(t)):g})")
        if thickness_map is not None
        else ("thickness", f"thickness {thickness:g}")
    )
    v, fi, fo = within_floats(arrays, port, f"{what} with offset {offset:g}")
    # front and back copies of every vertex and face, a rim quad per boundary edge
    he = mesh.halfedges
    points = carry.copy(np.tile(np.arange(mesh.n_vertices), 2))
    rims = he.face[he.boundary_halfedges]
    faces = carry.copy(np.concatenate([np.arange(mesh.n_faces)] * 2 + [rims]))
    return Mesh(v, fi, fo, **carry.carried(mesh, points, faces))
