"""``cam.pocket``: the tool-centre paths that clear a region by contour-parallel passes, at
step-down depths (:mod:`formgraph.kernels.cam.paths`)."""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve
from formgraph.kernels.cam import paths as kpaths
from formgraph.kernels.offset import OffsetTraceError, WorkLimit
from formgraph.nodes.cam import _common as _c


@node("cam.pocket", version=1)
def pocket(
    curves: list[Curve],
    tool_diameter: float,
    stepover: Annotated[float, Range(min=0, max=1)] = 0.4,
    depth: float = 1.0,
    step_down: Annotated[float | None, Range(min=0)] = None,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """Tool-centre paths that clear a region (holes are islands left standing).

    The curves are one region by the even-odd rule. The passes are its offsets inward by
    the tool's radius r (along the wall, never cutting it), then r + s, r + 2 s, ... with
    s = ``stepover`` times the diameter, until nothing is left (contour-parallel pocketing,
    Held 1991), each an offset of the region itself by the offset kernel. No material is
    left standing between passes: with a stepover up to 0.5 the passes are close enough
    everywhere; above it the ridges between passes are found (GEOS) and the passes halfway
    between are added where they cut them. The wall pass of an outline made of arcs and
    straight pieces, or of a polygon, is its exact offset (G2/G3 in G-code; its inside
    corners arcs of the tool's radius).

    Inside corners keep a fillet of radius r. Material the tool cannot reach beyond that
    (a gap narrower than the tool: a piece wider than two thirds of r) is named in a
    warning, with where it stays. Paths go innermost first at each depth, depths in turn;
    each is a closed 3-D curve at its z.

    Parameters
    ----------
    curves : list[Curve]
        Closed curves in the XY plane: the pocket, islands inside it.
    tool_diameter : float
        The cutter's diameter.
    stepover : float
        Distance between passes, as a share of the diameter (0 < stepover <= 1).
    depth : float
        How deep the pocket goes (positive: the paths reach z = -depth).
    step_down : float
        Depth of each pass. Default: one pass at the full depth.
    tolerance : float
        Accuracy of the offsets. Default: 1e-4 of the drawing's size.

    Example
    -------
    ``clear: {type: cam.pocket, curves: "@recess", tool_diameter: 6, depth: 4}``
    """
    r = _c.tool_radius(tool_diameter)
    if not 0 < stepover <= 1:
        raise InputError(
            "stepover", f"the stepover is a share of the diameter in (0, 1], got {stepover}"
        )
    zs = _c.pass_depths(depth, step_down)
    loops, outline, _, default = _c.region(curves, ctx)
    tol = _c.accuracy(tolerance, default)

    def guard(levels: int) -> None:
        ctx.guard(levels * len(zs), "pocket passes")

    try:
        levels = kpaths.pocket_levels(loops, r, stepover * 2 * r, tol, guard)
    except (OffsetTraceError, WorkLimit) as exc:
        raise InputError("curves", str(exc)) from None
    left = kpaths.leftovers(loops, levels, r)
    if not levels:
        ctx.warn(
            f"the tool (diameter {tool_diameter:g}) fits nowhere in the pocket: nothing is "
            "cut, all the material stays"
        )
        return []
    if left:
        where = "; ".join(
            f"around ({x:.4g}, {y:.4g}), {w:.3g} wide, area {a:.4g}" for x, y, a, w in left[:5]
        )
        more = f" and {len(left) - 5} more" if len(left) > 5 else ""
        ctx.warn(
            f"the tool (diameter {tool_diameter:g}) is wider than the pocket's narrowest "
            f"gaps: material stays in {len(left)} place(s): {where}{more}"
        )
    flat = _c.exact_loops(levels[0], outline, -r, tol)
    rest = [_c.exact_loops(lv, [], 0.0, tol) for lv in levels[1:]]
    inner_first = [c for lv in reversed(rest) for c in lv] + flat
    ctx.guard(len(inner_first) * len(zs), "tool-path passes")
    out: list[Curve] = []
    for z in zs.tolist():  # one step per depth: every path at it, innermost first
        out += _c.at_depths(inner_first, np.array([z]), ctx)
    return out
