"""``cam.profile``: the tool-centre paths that cut along a region's outlines, outside, inside
or on them, at step-down depths."""

from __future__ import annotations

import math
from enum import Enum
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve, NurbsCurve
from formgraph.kernels.cam import paths as kpaths
from formgraph.kernels.offset import OffsetTraceError, WorkLimit, offset_loops
from formgraph.nodes.cam import _common as _c

MAX_TABS = 10_000  # tabs a loop


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
    tabs: Annotated[int, Range(min=0, max=MAX_TABS)] = 0,
    tab_width: Annotated[float | None, Range(min=0)] = None,
    tab_height: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """Tool-centre paths along the outlines of a region, one pass per step down.

    The curves are one region by the even-odd rule (as ``curves.boolean`` reads them). Its
    offset by the tool's radius (outward for ``outside``, inward for ``inside``) is the
    offset kernel's (GEOS's buffer, as ``offset.marching_squares``); an outline that is a
    polygon or a chain of circular arcs and straight pieces (a circle, a rounded or sharp
    rectangle) gets its exact offset instead, a NURBS of the same kind whose corners are
    arcs of the tool's radius where the offset rounds them, so ``export.gcode`` writes
    its arcs as G2/G3. ``on`` runs on the outlines themselves (exact as they are).

    The paths are closed 3-D curves at z = -step_down, -2 step_down, ... down to -depth
    (one pass at -depth without ``step_down``): holes first, then outer loops (the part
    comes free last), each loop through all its depths. Loops run as the region's
    outlines: outer counter-clockwise and holes clockwise, so the part stays on the tool's
    left (climb milling with a clockwise spindle).

    Holding tabs (``tabs`` > 0): bridges of material ``tab_width`` wide (along the
    outline) and ``tab_height`` high, left at the bottom of the cut so the part stays in
    the stock until it is cut free by hand. Each outer loop (what frees a part; the slugs
    of holes are not held) gets ``tabs`` of them evenly spaced along it; every pass below
    the tabs' top (z = -depth + tab_height) is lifted over them: straight up, along at
    the tabs' top for the tab's width plus the tool's diameter, straight down. A lifted
    pass is a 3-D polyline within ``tolerance`` of the path (G1 moves); the passes above
    the tabs stay exact.

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
    tabs : int
        Holding tabs on each outer loop (0: none).
    tab_width : float
        Width of a tab along the outline. Default: the tool's diameter.
    tab_height : float
        Height of a tab above the bottom of the cut (less than the depth). Default: a
        third of the depth.

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
    loops_in_order = [flat[i] for i in order]
    if not tabs:
        return _c.at_depths(loops_in_order, zs, ctx)
    outer = [not holes[i] for i in order]
    return _tabbed(loops_in_order, outer, zs, tabs, tab_width, tab_height, depth, 2 * r, tol, ctx)


def _tabbed(
    loops: list[Curve],
    outer: list[bool],
    zs: np.ndarray,
    count: int,
    width: float | None,
    height: float | None,
    depth: float,
    diameter: float,
    tol: float,
    ctx: Context,
) -> list[Curve]:
    """Each loop through all its depths, an outer loop's passes below the tabs' top lifted
    over them (:func:`formgraph.kernels.cam.paths.over_tabs`)."""
    width = diameter if width is None else width
    height = depth / 3 if height is None else height
    if not (math.isfinite(width) and width > 0):
        raise InputError("tab_width", f"the tabs' width must be positive, got {width}")
    if not (math.isfinite(height) and 0 < height < depth):
        raise InputError(
            "tab_height",
            f"the tabs' height must be above 0 and below the depth ({depth:g}), got {height}",
        )
    top = -depth + height
    out: list[Curve] = []
    for i, loop in enumerate(loops):  # one step per loop: its passes, the low ones lifted
        flat = _c.at_depths([loop], zs, ctx)
        low = zs < top
        if not (low.any() and outer[i]):
            out += flat
            continue
        pts = _c.polyline_points(loop, tol, ctx)
        length = float(np.hypot(*np.diff(pts, axis=0).T).sum())
        try:
            spans = kpaths.tab_spans(length, count, width + diameter)
        except ValueError as exc:
            raise InputError("tabs", f"loop {i}: {exc}") from None
        ctx.guard(len(pts) * int(low.sum()), "tool-path points")
        for c, z, lifted in zip(flat, zs.tolist(), low.tolist(), strict=True):
            if lifted:
                out.append(NurbsCurve.polyline(kpaths.over_tabs(pts, spans, z, top), closed=True))
            else:
                out.append(c)
    return out


def _clockwise(loop: np.ndarray) -> bool:
    """Whether a loop turns clockwise (a hole of the offset region)."""
    x, y = loop[:, 0], loop[:, 1]
    return bool(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)) < 0)
