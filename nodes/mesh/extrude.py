"""Solids from outlines: ``mesh.extrude`` and ``mesh.revolve`` of a region of closed curves
(:mod:`formgraph.kernels.mesh.extrude`).

The region is read as ``curves.boolean`` reads it, by the even-odd rule, in one place
(:func:`formgraph.nodes._outlines.region_rings`): nested curves make holes, exact curves are
sampled within ``tolerance``.
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve, Mesh
from formgraph.kernels.mesh import extrude as ke
from formgraph.nodes import _outlines as _o


def _finite(port: str, value: float) -> float:
    if not math.isfinite(value):
        raise InputError(port, f"{port} must be a finite number, got {value}")
    return float(value)


def _scale(scale: float | list[float]) -> tuple[float, float]:
    values = [scale] if isinstance(scale, (int, float)) else list(scale)
    if len(values) not in (1, 2):
        raise InputError("scale", f"scale is one number or [sx, sy], got {len(values)} numbers")
    sx, sy = (_finite("scale", float(x)) for x in (values * 2)[:2])
    if sx < 0 or sy < 0:
        raise InputError(
            "scale",
            f"scale {_o_fmt(sx, sy)} is negative: the top would pass through the axis and "
            "the sides would cross each other (a self-intersecting solid); use a scale >= 0",
        )
    if (sx == 0) != (sy == 0):
        raise InputError(
            "scale",
            f"scale {_o_fmt(sx, sy)} flattens the top into a line: the solid would end in a "
            "knife edge of no area; give both 0 for a cone to a point, or both > 0",
        )
    return sx, sy


def _o_fmt(sx: float, sy: float) -> str:
    return f"{sx:g}" if sx == sy else f"[{sx:g}, {sy:g}]"


@node("mesh.extrude", version=1)
def extrude(
    curves: list[Curve],
    height: float,
    twist: float = 0.0,
    scale: float | list[float] = 1.0,
    center: bool = False,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    slices: Annotated[int | None, Range(min=1)] = None,
    *,
    ctx: Context,
) -> Mesh:
    """The region of closed curves in the XY plane extruded along +z into a closed solid.

    OpenSCAD's ``linear_extrude``, Grasshopper's Extrude with caps. The curves are read as
    one region by the even-odd rule, holes included, as ``curves.boolean`` reads them (z
    is dropped); the solid is closed, outward and consistently wound: its caps are the
    region triangulated on the ring points (no point added), its sides one quad per ring
    edge. While it rises the region turns by ``twist`` degrees (counter-clockwise seen
    from +z, about the z axis; OpenSCAD turns the other way) and scales linearly to
    ``scale`` at the top (after the turn). Exact curves are sampled so that every chord is
    within ``tolerance`` of its curve; with a twist the solid is cut into slices so that
    each point's helix is followed to the same tolerance (at most 45 degrees a slice), and
    with a twist or unequal scales long edges get points along them, so that the sides'
    triangles stay within the tolerance of the exact twisted surface.

    Parameters
    ----------
    curves : list[Curve]
        Closed curves in the XY plane bounding the region (nested ones are holes).
    height : float
        The height of the solid, > 0.
    twist : float
        Degrees turned from bottom to top, counter-clockwise seen from +z.
    scale : float | list[float]
        The top's scale, one number or [sx, sy]; 0 ends the solid in a point (a cone).
    center : bool
        Put the solid from -height/2 to height/2 instead of from 0 to height.
    tolerance : float
        Largest distance between a curve and its chords (and between a twisted point's
        helix and the side's edges). Default: 1e-5 of the size of the region.
    slices : int
        Levels from bottom to top; default: one without a twist, else as the tolerance
        asks. More than 45 degrees of twist a slice is refused (the sides would cut across
        the solid).

    Example
    -------
    ``plate: {type: mesh.extrude, curves: "@outline", height: 3}``
    """
    height = _finite("height", height)
    if not height > 0:
        raise InputError("height", f"height must be > 0, got {height:g}")
    twist = _finite("twist", twist)
    sx, sy = _scale(scale)
    xy, offsets, hole, tol = _o.region_rings(curves, tolerance, ctx)
    reach = float(np.sqrt((xy * xy).sum(axis=1).max())) * max(1.0, sx, sy)
    if slices is None:
        slices = ke.twist_slices(twist, reach, tol)
    elif abs(twist) / slices > ke.MAX_TWIST_STEP:
        raise InputError(
            "slices",
            f"a twist of {twist:g} degrees in {slices} slice(s) turns "
            f"{abs(twist) / slices:.3g} degrees a slice, past {ke.MAX_TWIST_STEP:g}: the side "
            f"triangles would cut across the solid (it would intersect itself); use at least "
            f"{math.ceil(abs(twist) / ke.MAX_TWIST_STEP)} slices, or leave slices unset",
        )
    # the sides between slices follow the exact twisted (or unequally scaled) solid to
    # the tolerance: points along the long edges (counted against the budget first)
    sx_sy = (sx, sy)
    step = (abs(sx - sy) / 2 + max(1.0, sx, sy) * abs(math.radians(twist))) / slices
    if step > 0:
        edges = np.hypot(*(np.roll(xy, -1, axis=0) - xy).T)  # (a ring's last: a bound)
        added = float(np.sum(np.ceil(step * edges / (4.0 * tol))))
        ctx.guard((slices + 1) * added, "vertices")
        xy, offsets = ke.refine_edges(xy, offsets, twist, sx_sy, slices, tol)
    n = len(xy)
    ctx.guard((slices + 1) * n, "vertices")
    ctx.guard(2 * slices * n + 2 * n, "faces")
    bottom = -height / 2 if center else 0.0
    # (Mesh.trusted: the kernel's faces index its vertices by construction)
    return Mesh.trusted(*ke.extrude(xy, offsets, hole, height, twist, (sx, sy), slices, bottom))


@node("mesh.revolve", version=1)
def revolve(
    curves: list[Curve],
    angle: Annotated[float, Range(min=0, max=360)] = 360.0,
    segments: Annotated[int | None, Range(min=1)] = None,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Mesh:
    """The region of closed curves at x >= 0 turned about the z axis into a closed solid.

    OpenSCAD's ``rotate_extrude``, Grasshopper's Revolution of a region. The curves are read
    as one region by the even-odd rule (holes included) in the XY plane at x >= 0, turned
    up into the XZ plane (y becomes z) and revolved counter-clockwise seen from +z, from the
    XZ plane by ``angle`` degrees. A whole turn closes on itself; a part is capped by the
    region at both ends. Points on the axis (x = 0) stay one vertex (a pole, no sliver
    faces). The solid is closed, outward and consistently wound.

    Parameters
    ----------
    curves : list[Curve]
        Closed curves in the XY plane at x >= 0 bounding the profile region.
    angle : float
        Degrees of the turn, in (0, 360].
    segments : int
        Steps around; default: as the tolerance asks for the point farthest from the
        axis (at most 12 degrees a step, at least 3 for a whole turn).
    tolerance : float
        Largest distance between a curve and its chords, and between a point's circle
        and the edges around it. Default: 1e-5 of the size of the region.

    Example
    -------
    ``ring: {type: mesh.revolve, curves: "@profile", angle: 270}``
    """
    angle = _finite("angle", angle)
    if not 0 < angle <= 360:
        raise InputError("angle", f"angle must be in (0, 360] degrees, got {angle:g}")
    xy, offsets, hole, tol = _o.region_rings(curves, tolerance, ctx)
    size = float(max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1]), np.abs(xy).max()))
    near = np.abs(xy[:, 0]) <= 1e-9 * size  # on the axis, up to rounding: made exactly so
    if near.any():
        xy = xy.copy()
        xy[near, 0] = 0.0
    lowest = float(xy[:, 0].min())
    if lowest < 0:
        raise InputError(
            "curves",
            f"the region reaches x = {lowest:g}: a revolution about the z axis takes a "
            "region at x >= 0 (one that crosses the axis would sweep through itself); move "
            "it to x >= 0 or cut it at the axis with curves.boolean",
        )
    reach = float(xy[:, 0].max())
    if segments is None:
        segments = ke.turn_segments(angle, reach, tol)
    elif angle >= 360 and segments < 3:
        raise InputError("segments", f"a whole turn needs at least 3 segments, got {segments}")
    n = len(xy)
    ctx.guard((segments + 1) * n, "vertices")
    ctx.guard(segments * n + 2 * n, "faces")
    return Mesh.trusted(*ke.revolve(xy, offsets, hole, angle, segments))
