"""Cutting benchmark: region booleans against shapely, text outlines against matplotlib.

Cases:

* the union of two overlapping 10,000-vertex closed polylines (wiggly circles, their centres
  half a radius apart) through ``curves.union`` — sampling (a polyline is taken at its
  vertices), the validity checks, GEOS's overlay, the orientation of the result and the
  curves built from it — against shapely's ``union`` of the two ``Polygon``s of the same
  vertices (GEOS alone, nothing checked or oriented);
* ``curves.boolean`` difference of the same pair;
* ``curves.text`` of 1,000 characters (an English pangram repeated) at 10 mm: glyph
  outlines as exact NURBS, laid out with kerning, one curve per contour — against
  matplotlib's ``TextPath`` of the same text and font (which gives one path of Bezier
  codes, no curves). The font is parsed once, as in a graph's process.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from formgraph.core.registry import Context
from formgraph.geometry import NurbsCurve
from formgraph.nodes import cutting

N = 10_000
PANGRAM = "The quick brown fox jumps over the lazy dog. "


def wiggly(n: int, cx: float) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 1 + 0.1 * np.sin(20 * t) + 0.05 * np.sin(7 * t)
    return np.c_[cx + r * np.cos(t), r * np.sin(t)]


def run(table) -> None:  # noqa: ANN001 - the harness's Table
    ctx = Context("bench", Path("."))
    a, b = wiggly(N, 0.0), wiggly(N, 0.5)
    ca, cb = NurbsCurve.polyline(a, closed=True), NurbsCurve.polyline(b, closed=True)
    case = f"union of two {N:,}-vertex outlines"
    table.time(case, "formgraph", lambda: cutting.union([ca, cb], ctx=ctx), repeat=3)
    diff = f"difference of two {N:,}-vertex outlines"
    table.time(
        diff,
        "formgraph",
        lambda: cutting.boolean([ca], [cb], operation=cutting.Operation.difference, ctx=ctx),
        repeat=3,
    )
    try:
        import shapely

        def reference(op):  # the same polylines in, the outlines' points out
            def go():
                region = op(shapely.Polygon(a), shapely.Polygon(b))
                return shapely.get_coordinates(shapely.get_rings(shapely.get_parts(region)))

            return go

        note = "Polygons built from the arrays, rings' points out"
        table.time(case, "shapely", reference(shapely.union), repeat=3, note=note)
        table.time(diff, "shapely", reference(shapely.difference), repeat=3, note=note)
        pa, pb = shapely.Polygon(a), shapely.Polygon(b)
        table.time(case, "shapely (overlay only)", lambda: shapely.union(pa, pb), repeat=3)
    except ImportError:
        table.add(case, "shapely", None, "not installed (shapely)")

    text = (PANGRAM * 23)[:1000]
    case = "text of 1,000 characters"
    cutting.text(text, ctx=ctx)  # the font parsed once
    table.time(case, "formgraph", lambda: cutting.text(text, ctx=ctx), repeat=3)
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    prop = FontProperties(family="DejaVu Sans")
    table.time(case, "matplotlib TextPath", lambda: TextPath((0, 0), text, 10, prop), repeat=3)
