"""Polygon meshes: boxes and explicit faces, Catmull-Clark and Doo-Sabin subdivision,
triangulation, merging and transforms.

Each node is a thin adapter over :mod:`formgraph.kernels.mesh.meshops` and
:mod:`formgraph.kernels.mesh.subdivision`; subdivision refuses, before allocating, a level
whose face count (known in closed form) would pass the element budget.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Faces, Vec3
from formgraph.geometry import Mesh, Points
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import (
    HalfEdges,
    MeshTopologyError,
    WorkLimitError,
    meshops,
    subdivision,
)


def _arrays(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return mesh.vertices, mesh.face_indices, mesh.face_offsets


def _halfedges(mesh: Mesh, port: str = "mesh") -> HalfEdges:
    try:
        return mesh.halfedges
    except MeshTopologyError as exc:
        raise InputError(port, str(exc)) from None


def _guard_counts(ctx: Context, counts: list[tuple[int, int, int]]) -> None:
    if counts:
        n_vertices, _, n_faces = counts[-1]
        ctx.guard(n_faces, "faces")
        ctx.guard(n_vertices, "vertices")


@node("mesh.from_faces", version=1)
def from_faces(vertices: Points, faces: Faces) -> Mesh:
    """A polygon mesh from vertices and faces (lists of vertex indices), checked.

    Faces may mix sizes (triangles, quads, n-gons) and list their vertices
    counter-clockwise seen from outside. The mesh must be an oriented manifold, possibly
    with boundary: every index names a vertex, a face has at least 3 distinct vertices, an
    edge belongs to at most two faces, and neighbouring faces run their shared edge in
    opposite directions.

    Parameters
    ----------
    vertices : Points
        The vertex positions; [x, y] gets z = 0. Their point attributes become the mesh's.
    faces : list[list[int]]
        One list of 0-based vertex indices per face.

    Example
    -------
    ``quad: {type: mesh.from_faces, vertices: [[0, 0], [1, 0], [1, 1], [0, 1]],
    faces: [[0, 1, 2, 3]]}``
    """
    try:
        fi, fo = meshops.faces_from_lists(faces)
        v, fi, fo = meshops.validate_faces(vertices.xyz, fi, fo)
    except ValueError as exc:
        raise InputError("faces", str(exc)) from None
    return Mesh(v, fi, fo, vertices.point_data)  # the points' attributes on the vertices


@node("mesh.box", version=1)
def box(size: float | Vec3 = (1.0, 1.0, 1.0), center: Vec3 = (0.0, 0.0, 0.0)) -> Mesh:
    """An axis-aligned box of six outward quads.

    Parameters
    ----------
    size : float | Vec3
        Edge lengths [sx, sy, sz], or one number for a cube; each > 0.
    center : Vec3
        Centre of the box.
    """
    try:
        return Mesh(*meshops.box(size, center))
    except ValueError as exc:
        raise InputError("size", str(exc)) from None


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
    he = _halfedges(mesh)
    _guard_counts(
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
    he = _halfedges(mesh)
    _guard_counts(ctx, subdivision.doo_sabin_counts(he, levels))
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
        v, fi, fo = meshops.triangulate(*_arrays(mesh), max_tests=ctx.budget)
        parents = np.repeat(np.arange(mesh.n_faces), mesh.face_sizes - 2)
        return Mesh(v, fi, fo, **carry.carried(mesh, carry.SAME, carry.copy(parents)))
    except WorkLimitError as exc:
        ctx.guard(exc.work, "triangle-corner tests of ear clipping")
        raise


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
    v, fi, fo = meshops.merge([_arrays(m) for m in meshes])
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
