"""``curves.copy_to_points``: a curve copied onto every point, in one array operation."""

from __future__ import annotations

from formgraph.core.registry import Context, node
from formgraph.geometry import (
    Curve,
    NurbsCurve,
    Points,
)
from formgraph.kernels.geometry import instancing
from formgraph.nodes._instancing import Align, Rotate, Scale, frames, per_point
from formgraph.nodes.geometry.transform import transform_one


@node("curves.copy_to_points", version=1)
def curves_copy_to_points(
    curve: Curve,
    points: Points,
    scale: Scale = 1.0,
    rotate: Rotate = (0.0, 0.0, 0.0),
    align: Align = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """A copy of the curve on every point, as a list (NURBS copies stay exact).

    The copies are placed as by ``mesh.copy_to_points``: scale, rotate (degrees about x, y,
    z), turn +z along ``align``, move the origin to the point; each of the three may be a
    per-point expression (``scale: "=1 + 0.5 * noise(x, y)"``). A NURBS curve's control
    points for every copy are one array operation; weights are kept.

    Parameters
    ----------
    curve : Curve
        The curve to copy, modelled about its origin.
    points : Points
        Where the copies go.
    scale : float | list[float] | list[Vec3]
        One factor for all, one per point, or rows [sx, sy, sz].
    rotate : Vec3 | list[Vec3]
        Degrees about x, y, z: one for all, or one per point.
    align : Vec3 | list[Vec3] | None
        A direction for each copy's +z, one or one per point; None keeps the orientation.
    """
    n = len(points)
    per = per_point(points, scale=scale, rotate=rotate, align=align)
    linear = frames(n, per["scale"], per["rotate"], per["align"])
    offsets = points.xyz
    if isinstance(curve, NurbsCurve):
        coordinates = n * len(curve.control_points) * 3
        ctx.guard(coordinates, "coordinates", nbytes=8 * coordinates, port="points")
        cps = instancing.copy_points(curve.control_points, linear, offsets)
        w = curve.weights if curve.rational else None
        return [NurbsCurve(cp, curve.degree, curve.knots, w) for cp in cps]
    ctx.guard(n, "curves")
    return [transform_one(curve, linear[k], offsets[k]) for k in range(n)]
