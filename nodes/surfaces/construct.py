"""Surfaces from points and expressions: quad grids, parametric and bicubic surfaces."""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import Expression, Variables
from formgraph.geometry import Mesh, NurbsSurface, ParametricSurface, Points
from formgraph.kernels import curves as kc
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import grid_faces


def _rows(points: list[Points], closed_u: bool, closed_v: bool) -> np.ndarray:
    """Rows of points as an (nu, nv, 3) grid, checked rectangular and large enough."""
    sizes = [len(r) for r in points]
    if not sizes:
        raise InputError(
            "points",
            "a grid needs rows of points (a list of rows, each a list of points), got none",
        )
    for i, n in enumerate(sizes):
        if n != sizes[0]:
            raise InputError(
                "points",
                f"every row needs the same number of points: row 0 has {sizes[0]}, row {i} has {n}",
            )
    for n, closed, what in ((len(sizes), closed_u, "rows"), (sizes[0], closed_v, "points a row")):
        need = 3 if closed else 2
        if n < need:
            side = "closed" if closed else "open"
            raise InputError(
                "points",
                f"an {side} grid needs at least {need} {what}, got {n} (the input is "
                f"{len(sizes)} row(s) of {sizes[0]} point(s); a grid is a list of rows, "
                "each a list of points)",
            )
    return np.stack([r.xyz for r in points])


@node("surfaces.grid", version=1)
def grid(
    points: list[Points],
    closed_u: bool = False,
    closed_v: bool = False,
    *,
    ctx: Context,
) -> Mesh:
    """A quad mesh joining rows of points: row i, point j is vertex i * row_length + j.

    Faces run counter-clockwise when rows advance along +x and points within a row along
    +y. Closing u joins the last row to the first; closing v joins each row's last point
    to its first (a tube, or with both, a torus). The rows' point attributes are carried;
    ``u`` (the row, 0 to 1) and ``v`` (along the row, 0 to 1) are added.

    Parameters
    ----------
    points : list[Points]
        The rows, all with the same number of points (at least 2 rows of 2).
    closed_u : bool
        Join the last row back to the first.
    closed_v : bool
        Join the last point of each row back to its first.
    """
    g = _rows(points, closed_u, closed_v)
    nu, nv = g.shape[:2]
    ctx.guard((nu if closed_u else nu - 1) * (nv if closed_v else nv - 1), "faces")
    fi, fo = grid_faces(nu, nv, closed_u, closed_v)
    # the rows' attributes, and where each vertex sits in the grid: u by row, v along it
    data, dropped = carry.concat([p.point_data for p in points], [len(p) for p in points])
    for name in dropped:
        ctx.warn(f"attribute {name!r} has different shapes on the rows; it was dropped")
    gu, gv = np.meshgrid(
        np.arange(nu) / (nu if closed_u else max(nu - 1, 1)),
        np.arange(nv) / (nv if closed_v else max(nv - 1, 1)),
        indexing="ij",
    )
    data.update(u=gu.reshape(-1), v=gv.reshape(-1))
    return Mesh(g.reshape(-1, 3), fi, fo, data)


@node("surfaces.parametric", version=1)
def parametric(
    x: Annotated[Expression, Variables("u", "v")],
    y: Annotated[Expression, Variables("u", "v")],
    z: Annotated[Expression, Variables("u", "v")],
    u: list[float] = (0.0, 1.0),  # type: ignore[assignment]
    v: list[float] = (0.0, 1.0),  # type: ignore[assignment]
) -> ParametricSurface:
    """A surface from expressions in u and v (and the graph params), exact at every (u, v).

    The expressions are evaluated whenever the surface is; nurbs.tessellate turns it into
    a mesh. The node checks a 33 x 33 grid of parameters when it runs: a NaN or infinity
    is an error naming the expression and the (u, v) where it happened.

    Parameters
    ----------
    x, y, z : Expression
        Coordinates as expressions in u and v, e.g. "(2 + cos(v)) * cos(u)".
    u : list[float]
        [start, end] of u, start < end.
    v : list[float]
        [start, end] of v, start < end.

    Example
    -------
    ``enneper: {type: surfaces.parametric, x: "u - u**3/3 + u*v**2",
    y: "v - v**3/3 + v*u**2", z: "u**2 - v**2", u: [-2, 2], v: [-2, 2]}``
    """
    for name, r in (("u", u), ("v", v)):
        if len(r) != 2 or not r[0] < r[1]:
            raise InputError(name, f"{name} must be [start, end] with start < end, got {list(r)}")
    fx, fy, fz = x, y, z
    surface = ParametricSurface(fx, fy, fz, (float(u[0]), float(u[1])), (float(v[0]), float(v[1])))
    probe = np.linspace(0.0, 1.0, 33)
    surface.evaluate_grid(u[0] + (u[1] - u[0]) * probe, v[0] + (v[1] - v[0]) * probe)
    return surface


@node("surfaces.bicubic", version=1)
def bicubic(
    points: list[Points],
    closed_u: bool = False,
    closed_v: bool = False,
    tension: float = 0.0,
    *,
    ctx: Context,
) -> NurbsSurface:
    """A bicubic NURBS surface through every point: Catmull-Rom in both directions, exact.

    The uniform Catmull-Rom conversion is linear in the points, so it is applied along the
    rows and then along the columns (a tensor product): the surface passes through every
    point, is C1 everywhere (across the seams too when closed) and each row and column of
    points lies on a Catmull-Rom curve of the surface. Open sides pass through their end
    rows, with end tangents along the first and last chords.

    Parameters
    ----------
    points : list[Points]
        The rows, all with the same number of points (at least 2 rows of 2).
    closed_u : bool
        Join the last row back to the first, smoothly.
    closed_v : bool
        Join each row's last point back to its first, smoothly.
    tension : float
        As curves.catmull_rom: 0 is Catmull-Rom, 1 makes flat bilinear-looking patches.
    """
    g = _rows(points, closed_u, closed_v)
    nu, nv = g.shape[:2]
    ctx.guard((3 * nu + 1) * (3 * nv + 1), "control points")
    try:
        cps, du, dv, ku, kv, w = kc.catmull_rom_surface(g, closed_u, closed_v, tension)
    except ValueError as exc:
        raise InputError("points", str(exc)) from None
    return NurbsSurface(cps, du, dv, ku, kv, w)
