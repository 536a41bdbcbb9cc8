"""The points of any geometry, for the operations that take point sets (the hulls): points
as they are, a mesh's vertices, curves sampled so that every chord is within a tolerance
(:func:`formgraph.kernels.curves.sampling.points_within`), polylines at their vertices.
Point attributes come along (0 where an input has none)."""

from __future__ import annotations

from typing import Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context
from formgraph.geometry import Curve, Mesh, NurbsCurve, Points
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.curves import sampling as ksampling

__all__ = ["points_of"]

_TOLERANCE = 1e-5  # default chord tolerance, relative to the size of everything given


def _rough(g: Any) -> np.ndarray:
    """Points whose box is about the geometry's (control points of a NURBS)."""
    if isinstance(g, Points):
        return g.xyz
    if isinstance(g, Mesh):
        return g.vertices
    if isinstance(g, NurbsCurve):
        return g.control_points
    return np.asarray(g.sample(65))


def points_of(
    geometry: Any, tolerance: float | None, ctx: Context, port: str = "geometry"
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Every point of the geometry (a list all together) and their point attributes.

    Raises
    ------
    InputError
        On ``port``: a type that has no point set here (a surface: tessellate it), or
        non-finite or no points; on ``tolerance``: not positive.
    """
    items = geometry if isinstance(geometry, list) else [geometry]
    for g in items:
        if not isinstance(g, (Points, Mesh, Curve)):
            raise InputError(
                port,
                f"takes points, curves and meshes, got a {type(g).__name__} (tessellate a "
                "surface with nurbs.tessellate, mesh a field with field.mesh)",
            )
    if tolerance is not None and not tolerance > 0:
        raise InputError("tolerance", f"the tolerance must be positive, got {tolerance}")
    rough = [_rough(g) for g in items]
    every = np.concatenate(rough) if rough else np.zeros((0, 3))
    if len(every) == 0:
        raise InputError(port, "there are no points to take the hull of")
    size = float(np.ptp(every, axis=0).max())
    tol = tolerance if tolerance is not None else _TOLERANCE * (size if size > 0 else 1.0)
    total = 0

    def guard(n: int) -> None:
        ctx.guard(total + n, "points")

    pts: list[np.ndarray] = []
    maps: list[Any] = []
    for g in items:  # one step per input; each one's points are vectorized
        if isinstance(g, Points):
            p, data = g.xyz, g.point_data
        elif isinstance(g, Mesh):
            p, data = g.vertices, g.point_data
        elif isinstance(g, NurbsCurve) and g.degree == 1:
            p, data = g.control_points, {}
        else:
            if isinstance(g, NurbsCurve):
                breaks = np.unique(g.knots[g.degree : len(g.control_points) + 1])
            else:
                breaks = np.linspace(*g.domain, 65)
            p = InputError.call(
                port,
                ksampling.points_within,
                g.evaluate,
                lambda t, g=g: g.derivative(t, 2),
                breaks,
                tol,
                guard,
            )
            data = {}
        guard(len(p))
        total += len(p)
        pts.append(np.asarray(p, dtype=np.float64))
        maps.append(data)
    xyz = np.concatenate(pts)
    if not np.isfinite(xyz).all():
        raise InputError(port, "the points are not all finite numbers")
    data, dropped = carry.concat(maps, [len(p) for p in pts])
    for name in dropped:
        ctx.warn(f"attribute {name!r} has different shapes on the inputs; it was dropped")
    return xyz, data
