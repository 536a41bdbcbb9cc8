"""``layout.nest``: the parts of a drawing put on sheets, each moved and turned rigidly as a
whole (:mod:`formgraph.kernels.layout.nest`), its exact curves kept exact.

The parts are read as every region node reads closed curves (:mod:`formgraph.nodes._outlines`:
the even-odd region, an outer loop and the holes inside it per part), and each part's
curves are moved with :func:`formgraph.nodes.geometry.transform.transform_one`, the map
``geometry.transform`` applies: NURBS through their control points, so circles stay
rational circles and SVG and DXF write them as arcs.
"""

from __future__ import annotations

import math
from typing import Annotated, NamedTuple

import numpy as np
import shapely

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve, NurbsCurve
from formgraph.kernels.layout import nest as knest
from formgraph.nodes import _outlines as _o
from formgraph.nodes.geometry.transform import transform_one

MAX_EFFORT = 10_000  # evaluations: each is a whole bottom-left fill
SHEET_GAP = 0.1  # sheet k sits k (width + 10 % of it) along x


class Nested(NamedTuple):
    curves: list[Curve]
    sheets: int
    utilisation: float
    outlines: list[Curve]


@node("layout.nest", version=1)
def nest(
    curves: list[Curve],
    sheet: list[float],
    spacing: Annotated[float, Range(min=0)] = 0.0,
    rotations: Annotated[int, Range(min=1, max=360)] = 4,
    seed: int = 0,
    effort: Annotated[int, Range(min=1, max=MAX_EFFORT)] = 10,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Nested:
    """Nest parts on sheets: no overlap, ``spacing`` apart, parts inside others' holes.

    The curves are one region by the even-odd rule (as ``curves.boolean`` reads them);
    each of its parts (an outer loop and the holes inside it) is moved and turned as a
    whole, so arcs and splines stay exact. Parts are placed by bottom-left fill over
    no-fit polygons (Minkowski sums, Burke et al. 2006), the order searched by a genetic
    algorithm (SVGnest's method) for ``effort`` evaluations; the same input, seed and
    effort give the same layout.

    Outputs: ``curves`` (the parts placed; sheet k shifted k times the sheet's width plus
    10 % along x), ``sheets``, ``utilisation`` (the parts' area over the sheet area used:
    every sheet but the last whole, the last up to its rightmost part) and ``outlines``
    (the sheets' rectangles).

    Parameters
    ----------
    curves : list[Curve]
        Closed curves in the XY plane: the parts, holes inside them.
    sheet : list[float]
        [width, height] of a sheet; its corner is at the origin.
    spacing : float
        Smallest distance between two parts (the kerf plus the web between them).
    rotations : int
        Equal turns allowed: 1 none, 2 half turns, 4 quarter turns.
    seed : int
        Seed of the search.
    effort : int
        Layouts tried (each a whole bottom-left fill); 1 places the parts by decreasing
        area once.
    tolerance : float
        Outlines are simplified within this for the nesting (the spacing grows by it, so
        parts never come closer). Default: 1e-4 of the sheet's diagonal.

    Example
    -------
    ``sheet: {type: layout.nest, curves: "@parts", sheet: [600, 400], spacing: 2}``
    """
    if isinstance(curves, Curve):
        curves = [curves]
    if not curves:
        raise InputError("curves", "give the parts' closed curves, got none")
    if len(sheet) != 2 or not all(math.isfinite(v) and v > 0 for v in sheet):
        raise InputError("sheet", f"the sheet is [width, height], both positive, got {sheet}")
    w, h = float(sheet[0]), float(sheet[1])
    if not math.isfinite(spacing):
        raise InputError("spacing", f"the spacing must be finite, got {spacing}")
    loops, outline, hole = _o.region_loops(curves, ctx)
    starts = np.flatnonzero(~hole)
    bounds = np.r_[starts, len(loops)]
    parts = [loops[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
    groups = [outline[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
    ctx.guard(len(parts) * rotations * effort, "part placements")
    try:
        result = knest.nest(parts, (w, h), spacing, rotations, seed, effort, tolerance)
    except knest.PartTooLarge as exc:
        centre = np.mean(shapely.bounds(shapely.Polygon(parts[exc.part][0])).reshape(2, 2), 0)
        raise InputError(
            "curves",
            f"{exc} (the part around ({centre[0]:.6g}, {centre[1]:.6g}) of the input); "
            "use a larger sheet, allow turns, or split the part",
        ) from None
    except ValueError as exc:
        port = "tolerance" if str(exc).startswith("the tolerance") else "sheet"
        raise InputError(port, str(exc)) from None
    placed: list[Curve] = []
    for i, group in enumerate(groups):  # one step per part: its curves moved as a whole
        c, s = math.cos(result.angle[i]), math.sin(result.angle[i])
        linear = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        shift = result.offset[i] + (result.sheet[i] * w * (1 + SHEET_GAP), 0.0)
        offset = np.array([shift[0], shift[1], 0.0])
        placed += [transform_one(g, linear, offset) for g in group]
    corners = np.array([[0, 0, 0], [w, 0, 0], [w, h, 0], [0, h, 0]], dtype=np.float64)
    outlines: list[Curve] = [
        NurbsCurve.polyline(corners + [k * w * (1 + SHEET_GAP), 0, 0], closed=True)
        for k in range(result.sheets)
    ]
    return Nested(placed, result.sheets, result.utilisation, outlines)
