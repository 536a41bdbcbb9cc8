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
    marks: list[Curve]


@node("layout.nest", version=2)
def nest(
    curves: list[Curve],
    sheet: list[float],
    spacing: Annotated[float, Range(min=0)] = 0.0,
    rotations: Annotated[int, Range(min=1, max=360)] = 4,
    seed: int = 0,
    effort: Annotated[int, Range(min=1, max=MAX_EFFORT)] = 10,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    marks: list[Curve] | None = None,
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
    (the sheets' rectangles) and ``marks`` (the ``marks`` moved with their parts).

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
    marks : list[Curve]
        Curves that ride on the parts without being cut (labels from ``curves.text``,
        engraving, bend lines): each goes with the part that holds most of its points,
        moved and turned as that part is; they do not take part in the nesting. A mark on
        no part is an error naming it.

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
    if spacing > math.hypot(w, h):
        ctx.warn(
            f"the spacing {spacing:g} is more than the sheet's diagonal "
            f"({math.hypot(w, h):.6g}): every part gets a sheet of its own"
        )
    loops, outline, hole = _o.region_loops(curves, ctx)
    starts = np.flatnonzero(~hole)
    bounds = np.r_[starts, len(loops)]
    parts = [loops[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
    groups = [outline[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
    ctx.guard(len(parts) * rotations * effort, "part placements")
    marks = [marks] if isinstance(marks, Curve) else list(marks or [])
    owner = _owners(marks, parts)
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
    moves = []
    for i, group in enumerate(groups):  # one step per part: its curves moved as a whole
        c, s = math.cos(result.angle[i]), math.sin(result.angle[i])
        linear = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        shift = result.offset[i] + (result.sheet[i] * w * (1 + SHEET_GAP), 0.0)
        offset = np.array([shift[0], shift[1], 0.0])
        moves.append((linear, offset))
        placed += [transform_one(g, linear, offset) for g in group]
    moved = [transform_one(m, *moves[k]) for m, k in zip(marks, owner, strict=True)]
    corners = np.array([[0, 0, 0], [w, 0, 0], [w, h, 0], [0, h, 0]], dtype=np.float64)
    outlines: list[Curve] = [
        NurbsCurve.polyline(corners + [k * w * (1 + SHEET_GAP), 0, 0], closed=True)
        for k in range(result.sheets)
    ]
    return Nested(placed, result.sheets, result.utilisation, outlines, moved)


def _owners(marks: list[Curve], parts: list[list[np.ndarray]]) -> list[int]:
    """The part each mark rides on: the one that holds most of its points (33 along it,
    ends and holes counted as the region does), found for all points at once through
    GEOS's STR tree."""
    if not marks:
        return []
    samples = []
    for j, m in enumerate(marks):  # one step per mark: its points
        if not isinstance(m, Curve):
            raise InputError("marks", f"mark {j} is a {type(m).__name__}, not a curve")
        pts = np.asarray(m.sample(33), dtype=np.float64)[:, :2]
        if not np.isfinite(pts).all():
            raise InputError("marks", f"mark {j} has points that are not finite")
        samples.append(pts)
    pts = np.concatenate(samples)
    which = np.repeat(np.arange(len(marks)), [len(p) for p in samples])
    polys = np.array([shapely.Polygon(r[0], list(r[1:])) for r in parts], dtype=object)
    hit_pt, hit_part = shapely.STRtree(polys).query(shapely.points(pts), predicate="intersects")
    counts = np.zeros((len(marks), len(parts)), dtype=np.int64)
    np.add.at(counts, (which[hit_pt], hit_part), 1)
    lost = np.flatnonzero(counts.max(axis=1) == 0)
    if len(lost):
        j = int(lost[0])
        x, y = samples[j][0]
        raise InputError(
            "marks",
            f"mark {j} (from ({x:.6g}, {y:.6g})) lies on no part: a mark rides on the part "
            f"it is drawn on ({len(lost)} mark(s) on none)",
        )
    return counts.argmax(axis=1).tolist()
