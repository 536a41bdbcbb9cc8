"""``points.scatter``: points on a mesh or a surface, uniform by area or Poisson-disk
(:mod:`formgraph.kernels.mesh.scatter`)."""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import BudgetError, InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Mesh, Points, Surface
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.geometry.meshdist import fan_triangles
from formgraph.kernels.mesh import meshops
from formgraph.kernels.mesh import scatter as kscatter

GRID = 128  # a surface is drawn on by a GRID x GRID grid of its parameters, cells split in two


def _surface_triangles(surface: Surface) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A surface's GRID x GRID parameter grid: its points (n, 3), its (u, v) (n, 2) and the
    triangles (t, 3) of its cells (cell c = i * GRID + j is triangles 2c and 2c + 1)."""
    (u0, u1), (v0, v1) = surface.domain_u, surface.domain_v
    u, v = np.linspace(u0, u1, GRID + 1), np.linspace(v0, v1, GRID + 1)
    gu, gv = (a.reshape(-1) for a in np.meshgrid(u, v, indexing="ij"))
    xyz = np.asarray(surface.evaluate(gu, gv), dtype=np.float64).reshape(-1, 3)
    i, j = (a.reshape(-1) for a in np.meshgrid(np.arange(GRID), np.arange(GRID), indexing="ij"))
    a = i * (GRID + 1) + j
    b, c, d = a + GRID + 1, a + GRID + 2, a + 1
    tri = np.stack([np.stack([a, b, c], 1), np.stack([a, c, d], 1)], 1).reshape(-1, 3)
    return xyz, np.column_stack([gu, gv]), tri


@node("points.scatter", version=1)
def scatter(
    geometry: Mesh | Surface,
    count: Annotated[int | None, Range(min=0)] = None,
    spacing: Annotated[float | None, Range(min=0)] = None,
    seed: int = 0,
    *,
    ctx: Context,
) -> Points:
    """Points on a mesh or a surface: ``count`` uniform by area, or as many as fit
    ``spacing`` apart (Poisson disk).

    With ``count``, each point lands on a face with probability proportional to its area,
    uniformly within it. With ``spacing``, no two points are closer than it (in space) and
    the set is maximal within a factor of 2 (every point of the surface is within twice
    the spacing of one; about 98 % within the spacing): dart throwing on a hashed grid. The
    same seed gives the same points. Each point carries ``normal`` (its face's, or the
    surface's exact normal) and ``face`` (the index of its face; on a surface, of its cell
    of a 128 x 128 grid of the parameters, with ``u`` and ``v``); a mesh's point attributes
    are interpolated to it and its face attributes copied.

    Parameters
    ----------
    geometry : Mesh | Surface
        Where to scatter (polygons are fanned into triangles).
    count : int | None
        How many points (uniform); give this or ``spacing``.
    spacing : float | None
        The least distance between points (Poisson disk); give this or ``count``.
    seed : int
        The random stream.

    Example
    -------
    ``dots: {type: points.scatter, geometry: "@shade", spacing: 6, seed: 3}``
    """
    if (count is None) == (spacing is None):
        raise InputError(
            "count" if count is not None else "spacing",
            "give count (points uniform by area) or spacing (a Poisson disk), not "
            + ("both" if count is not None else "neither"),
        )
    if isinstance(geometry, Mesh):
        if geometry.n_faces == 0:
            raise InputError("geometry", "the mesh has no faces to scatter points on")
        v = np.asarray(geometry.vertices)
        tri, face_of = fan_triangles(geometry.face_indices, geometry.face_offsets)
    else:
        ctx.guard((GRID + 1) ** 2, "surface samples")
        v, uv, tri = _surface_triangles(geometry)
        face_of = np.repeat(np.arange(GRID * GRID), 2)
    area = float(kscatter.triangle_areas(v, tri).sum())
    if not area > 0:
        raise InputError("geometry", "the surface has no area to scatter points on")
    rng = np.random.default_rng(seed)
    if spacing is not None:
        if not spacing > 0:
            raise InputError("spacing", f"spacing must be > 0, got {spacing:g}")
        ctx.guard(kscatter.most_points(area, spacing), "points")
        darts = kscatter.DARTS * area / spacing**2
        if darts > ctx.budget:
            raise BudgetError(
                f"spacing {spacing:g} on an area of {area:.6g} needs {darts:,.0f} candidate "
                f"points, over the budget of {ctx.budget:,}: use a spacing of "
                f"{spacing * np.sqrt(darts / ctx.budget):.3g} or more (or raise the budget "
                "with --budget)"
            )
        lift = None
        if not isinstance(geometry, Mesh):

            def lift(t: np.ndarray, vw: np.ndarray) -> np.ndarray:
                here = carry.barycentric(tri[t], vw).apply(uv)
                return geometry.evaluate(here[:, 0], here[:, 1])

        p, t, vw = kscatter.poisson_disk(v, tri, spacing, rng, lift)
    else:
        ctx.guard(count, "points")
        p, t, vw = kscatter.uniform(v, tri, count, rng)
    face = face_of[t]
    data: dict[str, Any]
    if isinstance(geometry, Mesh):
        normals = meshops.face_normals(*geometry.arrays)[face]
        rule = carry.barycentric(tri[t], vw)
        data = {n: rule.apply(a) for n, a in geometry.point_data.items()}
        data.update({n: a[face] for n, a in geometry.face_data.items()})
    else:  # on the surface itself: its parameters there, evaluated exactly
        here = carry.barycentric(tri[t], vw).apply(uv)
        p = np.asarray(geometry.evaluate(here[:, 0], here[:, 1]), dtype=np.float64).reshape(-1, 3)
        normals = np.asarray(geometry.normals(here[:, 0], here[:, 1]), dtype=np.float64)
        normals = normals.reshape(-1, 3)
        length = np.linalg.norm(normals, axis=1, keepdims=True)
        normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
        data = {"u": here[:, 0], "v": here[:, 1]}
    data.update(normal=normals, face=face.astype(np.float64))
    return Points(p, data)
