"""``cam.profile``: the tool-centre paths that cut along a region's outlines, outside, inside
or on them, at step-down depths."""

from __future__ import annotations

from enum import Enum
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve
from formgraph.kernels.offset import OffsetTraceError, WorkLimit, offset_loops
from formgraph.nodes.cam import _common as _c


class Side(str, Enum):
    """Where the tool's centre runs relative to the outline."""

    outside = "outside"  # the region keeps its size: the tool runs a radius outside it
    inside = "inside"  # a radius inside it (the region is the scrap, e.g. a cut-out)
    on = "on"  # on the outline itself (engraving, or a laser's thin cut)


@node("cam.profile", version=1)
def profile(
    curves: list[Curve],
    tool_diameter: float,
    side: Side = Side.outside,
    depth: float = 1.0,
    step_down: Annotated[float | None, Range(min=0)] = None,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """Tool-centre paths along the outlines of a region, one pass per step down.

    The curves are one region by the even-odd rule (as ``curves.boolean`` reads them). Its
    offset by the tool's radius (outward for ``outside``, inward for ``inside``) is the
    offset kernel's (GEOS's buffer, as ``offset.marching_squares``); an outline that is a
    chain of circular arcs and straight pieces (a circle, a rounded rectangle) gets its
    exact offset instead, a NURBS of the same kind, so ``export.gcode`` writes its arcs
    as G2/G3. ``on`` runs on the outlines themselves (exact as they are).

    The paths are closed 3-D curves at z = -step_down, -2 step_down, ... down to -depth
    (one pass at -depth without ``step_down``): holes first, then outer loops (the part
    comes free last), each loop through all its depths. Loops run as the region's
    outlines: outer counter-clockwise and holes clockwise, so the part stays on the tool's
    left (climb milling with a clockwise spindle).

    Parameters
    ----------
    curves : list[Curve]
        Closed curves in the XY plane bounding the part.
    tool_diameter : float
        The cutter's diameter.
    side : Side
        outside, inside or on the outline.
    depth : float
        How deep the cut goes (positive: the paths reach z = -depth).
    step_down : float
        Depth of each pass. Default: one pass at the full depth.
    tolerance : float
        Accuracy of the offset (the chords of its round corners). Default: 1e-4 of the
        drawing's size.

    Example
    -------
    ``cut: {type: cam.profile, curves: "@part", tool_diameter: 6, depth: 12, step_down: 3}``
    """
    r = _c.tool_radius(tool_diameter)
    zs = _c.pass_depths(depth, step_down)
    loops, outline, hole, default = _c.region(curves, ctx)
    tol = _c.accuracy(tolerance, default)
    if side == Side.on:
        flat = list(outline)
        holes = hole
    else:
        d = r if side == Side.outside else -r
        try:
            got = offset_loops(loops, [True] * len(loops), d, tolerance=tol).loops
        except (OffsetTraceError, WorkLimit) as exc:
            raise InputError("curves", str(exc)) from None
        if not got:
            ctx.warn(
                f"the tool (diameter {tool_diameter:g}) fits nowhere inside the outline: no path"
            )
            return []
        got = [np.asarray(lp)[:, :2] for lp in got]
        flat = _c.exact_loops(got, outline, d, tol)
        holes = np.array([_clockwise(lp) for lp in got], dtype=bool)
    order = [i for i in range(len(flat)) if holes[i]] + [
        i for i in range(len(flat)) if not holes[i]
    ]
    return _c.at_depths([flat[i] for i in order], zs, ctx)


def _clockwise(loop: np.ndarray) -> bool:
    """Whether a loop turns clockwise (a hole of the offset region)."""
    x, y = loop[:, 0], loop[:, 1]
    return bool(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)) < 0)
