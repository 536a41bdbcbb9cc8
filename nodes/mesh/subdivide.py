"""Subdivision: Catmull-Clark (with creases) and Doo-Sabin, after the original papers
(:mod:`formgraph.kernels.mesh.subdivision`). A level whose face count, known in closed form,
would pass the element budget is refused before anything is allocated.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Mesh
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import (
    HalfEdges,
    meshops,
    subdivision,
)
from formgraph.nodes.mesh._common import (
    guard_counts,
    halfedges,
)


def _creases(mesh: Mesh, he: HalfEdges, crease_angle: float | None) -> np.ndarray | None:
    if crease_angle is None:
        return None
    angles = meshops.dihedral_angles(mesh.vertices, he)
    return he.edge_vertices[angles > crease_angle]


@node("mesh.catmull_clark", version=2)
def catmull_clark(
    mesh: Mesh,
    levels: Annotated[int, Range(min=0)] = 1,
    crease_angle: Annotated[float | None, Range(min=0, max=180)] = None,
    sharpness: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Mesh:
    """Catmull-Clark subdivision: any polygons in, quads out, smooth in the limit.

    Catmull & Clark 1978: face points are centroids, edge points average the two ends and
    the two face points, a vertex of valence n moves to (Q + 2R + (n - 3) S) / n. Open
    boundaries follow the cubic B-spline curve rule (edge midpoints; boundary vertices
    1/8, 6/8, 1/8) and corners in a single face stay put. Each level turns a face of k
    corners into k quads.

    Parameters
    ----------
    mesh : Mesh
        An oriented manifold polygon mesh, possibly open.
    levels : int
        Number of subdivision steps; each multiplies the face count by about 4.
    crease_angle : float | None
        Keep as sharp creases the edges whose two faces meet at more than this angle
        (degrees between their normals; 0 creases every bent edge). None: all smooth.
    sharpness : float | None
        How many levels the creases stay sharp (semi-sharp creases, DeRose et al. 1998;
        fractions blend). None: sharp on every level.
    """
    he = halfedges(mesh)
    guard_counts(
        ctx,
        subdivision.catmull_clark_counts(
            he.n_vertices, he.n_edges, he.n_faces, he.n_halfedges, levels
        ),
    )
    creases = _creases(mesh, he, crease_angle)
    if creases is None and sharpness is not None:
        ctx.warn("sharpness has no effect without crease_angle")
    # point attributes ride along as extra columns: the same stencils as the points
    stacked = carry.columns(mesh.vertices, mesh.point_data)
    v, fi, fo = subdivision.catmull_clark(
        stacked,
        mesh.face_indices,
        mesh.face_offsets,
        levels,
        creases=creases,
        sharpness=None if creases is None else sharpness,
        halfedges=he,
    )
    v, point_data = carry.split_columns(v, mesh.point_data)
    faces = carry.copy(subdivision.catmull_clark_face_parents(mesh.face_offsets, levels))
    face_data = carry.carried(mesh, face=faces)["face_data"]
    return Mesh.trusted(v, fi, fo, point_data, face_data)  # all quads of valid indices


@node("mesh.doo_sabin", version=2)
def doo_sabin(mesh: Mesh, levels: Annotated[int, Range(min=0)] = 1, *, ctx: Context) -> Mesh:
    """Doo-Sabin subdivision: corner cutting that converges to a biquadratic-like surface.

    Doo & Sabin 1978: every corner of a k-sided face gets a new point weighted
    a0 = 1/4 + 5/(4k), ai = (3 + 2 cos(2 pi i/k)) / (4k); the new mesh has a face per face,
    per edge and per vertex. On an open boundary each edge gets the Chaikin points at 1/4
    and 3/4 (the boundary converges to a quadratic B-spline curve) and corners in a single
    face stay put.

    Parameters
    ----------
    mesh : Mesh
        An oriented manifold polygon mesh, possibly open.
    levels : int
        Number of subdivision steps.
    """
    he = halfedges(mesh)
    guard_counts(ctx, subdivision.doo_sabin_counts(he, levels))
    # point attributes ride along as extra columns (the same stencils as the points), face
    # attributes as the face values (v2: the sums in another order, the last bits differ)
    stacked = carry.columns(mesh.vertices, mesh.point_data)
    faces = carry.columns(np.zeros((mesh.n_faces, 3)), mesh.face_data) if mesh.face_data else None
    v, fi, fo, *fv = subdivision.doo_sabin(
        stacked, mesh.face_indices, mesh.face_offsets, levels, face_values=faces, halfedges=he
    )
    v, point_data = carry.split_columns(v, mesh.point_data)
    face_data = carry.split_columns(fv[0], mesh.face_data)[1] if fv else {}
    return Mesh(v, fi, fo, point_data, face_data)
