"""``attr.curvature``: mean and Gaussian curvature per point of a mesh
(:mod:`formgraph.kernels.mesh.curvature`)."""

from __future__ import annotations

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.geometry import Mesh
from formgraph.kernels.geometry.meshdist import fan_triangles
from formgraph.kernels.mesh import curvature as kcurv
from formgraph.kernels.mesh.solidify import vertex_normals

MEAN, GAUSSIAN = "mean_curvature", "gaussian_curvature"


@node("attr.curvature", version=1)
def curvature(mesh: Mesh, *, ctx: Context) -> Mesh:
    """The mesh with point attributes ``mean_curvature`` and ``gaussian_curvature``.

    Per unit area, by Meyer, Desbrun, Schroeder & Barr (2003): the mean curvature from the
    cotangent Laplacian over each vertex's mixed Voronoi area, signed along the vertex
    normal (1/r on a sphere whose faces look out, -1/r looking in); the Gaussian curvature
    from the angle defect ``2 pi - sum of angles`` over the same area (1/r^2 on a sphere,
    0 on a plane or a cylinder; its sum times the areas is ``2 pi`` times the Euler
    characteristic). Polygons are fanned into triangles. Points on an open boundary get 0
    (a warning counts them): a curvature needs the surface all round.

    Parameters
    ----------
    mesh : Mesh
        The surface.

    Example
    -------
    ``bent: {type: attr.curvature, mesh: "@shell"}`` then
    ``colour: {type: attr.set, geometry: "@bent", name: c, value: "=abs(mean_curvature)"}``
    """
    if mesh.n_faces == 0:
        raise InputError("mesh", "the mesh has no faces: curvature needs a surface")
    ctx.guard(mesh.n_vertices, "points")
    tri, _ = fan_triangles(mesh.face_indices, mesh.face_offsets)
    normals = vertex_normals(*mesh.arrays)
    mean, gauss, boundary = kcurv.curvatures(mesh.vertices, tri, normals)
    if boundary.any():
        ctx.warn(
            f"mesh: {int(boundary.sum())} points lie on an open or non-manifold edge: their "
            "curvature is set to 0"
        )
    data = mesh.point_data.with_(MEAN, mean).with_(GAUSSIAN, gauss)
    return mesh.with_data(data, mesh.face_data)
