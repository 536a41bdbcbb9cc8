"""Cutting benchmark: region booleans against shapely, text outlines against matplotlib.

Cases:

* the union of two overlapping 10,000-vertex closed polylines (wiggly circles, their centres
  half a radius apart) through ``curves.union`` — sampling (a polyline is taken at its
  vertices), each ring's simplicity check (the even-odd rule), GEOS's overlay, the
  orientation of the result and the curves built from it — against shapely's ``union`` of
  the two ``Polygon``s of the same vertices (GEOS alone, nothing checked or oriented), and
  the overlay alone on polygons made once (the floor under both);
* ``curves.boolean`` difference of the same pair;
* the union of two exact circles, the arcs it cuts rebuilt exact, against shapely's union
  of the same samples (which gives a polygon);
* ``curves.divide`` of a 10,000-vertex open polyline into 100,000 points at equal arc
  length (with tangents and parameters) against shapely's ``line_interpolate_point`` at the
  same distances, each on its own segment (:func:`shapely_divide`), and of a cubic NURBS of
  100 control points into 10,000 points;
* ``curves.text`` of 1,000 characters (an English pangram repeated) at 10 mm: glyph
  outlines as exact NURBS, laid out with kerning, one curve per contour — against
  matplotlib's ``TextPath`` of the same text and font (which gives one path of Bezier
  codes, no curves). The font is parsed once, as in a graph's process;
* ``export.svg`` of those outlines (ours alone: the cost a curve);
* the offset of an offset (the nameplate's kerf): an 80 x 30 rectangle offset by 5 (a
  rounded plate), then that result offset by 0.1, against the first offset and against a
  fresh 90 x 40 rectangle offset by the same 0.1 (the same size and distance, from 4
  vertices instead of the first offset's dense outline).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from formgraph.core.registry import Context
from formgraph.geometry import NurbsCurve
from formgraph.nodes.curves import regions as cutting
from formgraph.nodes.curves import sample as curve_sample
from formgraph.nodes.curves import text as curve_text

N = 10_000
PANGRAM = "The quick brown fox jumps over the lazy dog. "


def wiggly(n: int, cx: float) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 1 + 0.1 * np.sin(20 * t) + 0.05 * np.sin(7 * t)
    return np.c_[cx + r * np.cos(t), r * np.sin(t)]


def shapely_divide(line, at: np.ndarray) -> np.ndarray:  # noqa: ANN001 - a LineString
    """The points at distances ``at`` along ``line`` by shapely, as an (m, 2) array.

    GEOS's interpolate walks the line from its start for every distance, so one call on the
    whole 10,000-vertex line costs O(vertices) a point (12 s for 100,000 points). Here
    shapely measures the line's segments, numpy finds each distance's segment, and one
    ``line_interpolate_point`` call interpolates every point on its own two-point segment:
    O(1) a point, the same points (to 1e-13), the fair use of its array API.
    """
    import shapely

    xy = shapely.get_coordinates(line)
    segments = shapely.linestrings(np.stack([xy[:-1], xy[1:]], axis=1))
    start = np.concatenate([[0.0], np.cumsum(shapely.length(segments))])
    i = np.clip(np.searchsorted(start, at, side="right") - 1, 0, len(segments) - 1)
    return shapely.get_coordinates(shapely.line_interpolate_point(segments[i], at - start[i]))


def run(table) -> None:  # noqa: ANN001 - the harness's Table
    ctx = Context("bench", Path("."))
    a, b = wiggly(N, 0.0), wiggly(N, 0.5)
    ca, cb = NurbsCurve.polyline(a, closed=True), NurbsCurve.polyline(b, closed=True)
    case = f"union of two {N:,}-vertex outlines"
    diff = f"difference of two {N:,}-vertex outlines"

    def ours_difference():
        return cutting.boolean([ca], [cb], operation=cutting.Operation.difference, ctx=ctx)

    try:
        import shapely
    except ImportError:
        table.time(case, "formgraph", lambda: cutting.union([ca, cb], ctx=ctx), repeat=3)
        table.time(diff, "formgraph", ours_difference, repeat=3)
        table.add(case, "shapely", None, "not installed (shapely)")
    else:

        def reference(op):  # the same polylines in, the outlines' points out
            def go():
                region = op(shapely.Polygon(a), shapely.Polygon(b))
                return shapely.get_coordinates(shapely.get_rings(shapely.get_parts(region)))

            return go

        note = "Polygons built from the arrays, rings' points out"
        pa, pb = shapely.Polygon(a), shapely.Polygon(b)
        table.time_together(  # alternating rounds: a burst of load falls on both
            case,
            [
                ("formgraph", lambda: cutting.union([ca, cb], ctx=ctx), ""),
                ("shapely", reference(shapely.union), note),
                ("shapely (overlay only)", lambda: shapely.union(pa, pb), ""),
            ],
        )
        table.time_together(
            diff,
            [
                ("formgraph", ours_difference, ""),
                ("shapely", reference(shapely.difference), note),
            ],
        )

    # two exact circles: sampled to the tolerance, united, and the cut arcs rebuilt exact
    # (the crossings by Newton on both circles) -- against shapely on the same samples
    from formgraph.kernels import nurbs as knurbs
    from formgraph.kernels.curves import sampling as ksampling

    circles = [NurbsCurve(*knurbs.circle(1.0)), NurbsCurve(*knurbs.circle(1.0, (1.0, 0, 0)))]
    samples = [
        ksampling.sample_nurbs(c.control_points, 2, c.knots, c.weights, 2e-5, closed=True)
        for c in circles
    ]
    case = "union of two circles (cut arcs rebuilt exact)"
    try:
        import shapely
    except ImportError:
        table.time(case, "formgraph", lambda: cutting.union(circles, ctx=ctx), repeat=3)
    else:

        def on_samples():
            region = shapely.union(shapely.Polygon(samples[0]), shapely.Polygon(samples[1]))
            return shapely.get_coordinates(shapely.get_rings(shapely.get_parts(region)))

        table.time_together(
            case,
            [
                ("formgraph", lambda: cutting.union(circles, ctx=ctx), ""),
                (
                    "shapely",
                    on_samples,
                    f"the same {sum(map(len, samples)):,} samples, a polygon out",
                ),
            ],
        )

    line = NurbsCurve.polyline(wiggly(N, 0.0))  # open: the loop without its closing edge
    case = f"divide a {N:,}-vertex polyline into 100,000 points"
    divide = lambda: curve_sample.divide(line, count=100_000, ctx=ctx)  # noqa: E731
    table.time(case, "formgraph", divide, repeat=3)
    try:
        import shapely

        ls = shapely.LineString(wiggly(N, 0.0))
        at = np.linspace(0.0, ls.length, 100_000)
        note = "points only; each distance on its own segment (one call on the line: 12 s)"
        table.time(case, "shapely", lambda: shapely_divide(ls, at), repeat=3, note=note)
    except ImportError:
        table.add(case, "shapely", None, "not installed (shapely)")
    rng = np.random.default_rng(1)
    cp = np.c_[np.cumsum(rng.normal(size=(100, 2)), axis=0), np.zeros(100)]
    from formgraph.kernels import nurbs

    cubic = NurbsCurve(cp, 3, nurbs.clamped_uniform_knots(100, 3))
    table.time(
        "divide a 100-point cubic NURBS into 10,000 points",
        "formgraph",
        lambda: curve_sample.divide(cubic, count=10_000, ctx=ctx),
        repeat=3,
    )

    text = (PANGRAM * 23)[:1000]
    case = "text of 1,000 characters"
    curve_text.text(text, ctx=ctx)  # the font parsed once
    table.time(case, "formgraph", lambda: curve_text.text(text, ctx=ctx), repeat=3)
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    prop = FontProperties(family="DejaVu Sans")
    table.time(case, "matplotlib TextPath", lambda: TextPath((0, 0), text, 10, prop), repeat=3)

    # export.svg of the same text: every glyph contour an exact cubic chain, all paths'
    # numbers formatted in one call (there is no reference writer of the same paths)
    import tempfile

    from formgraph.nodes.export import drawing as export

    glyphs = curve_text.text(text, ctx=ctx)
    with tempfile.TemporaryDirectory() as out:
        wctx = Context("bench", Path(out))
        seconds = table.time(
            f"export.svg of 1,000 characters ({len(glyphs):,} curves)",
            "formgraph",
            lambda: export.svg(glyphs, "text.svg", ctx=wctx),
            repeat=3,
        )
    if seconds is not None:
        table.rows[-1].note = f"{seconds / len(glyphs) * 1e6:.0f} us a curve"

    # the offset of an offset: the nameplate's kerf on its rounded plate
    from formgraph.nodes.offset import marching_squares as offset_nodes

    def rect(w: float, h: float) -> NurbsCurve:
        x, y = w / 2, h / 2
        return NurbsCurve.polyline([[-x, -y, 0], [x, -y, 0], [x, y, 0], [-x, y, 0]], closed=True)

    plate = rect(80, 30)
    rounded = offset_nodes.marching_squares([plate], 5.0, ctx=ctx)
    case = "offset of an offset: 80 x 30 rectangle by 5, then the result by 0.1"
    table.time(
        case,
        "formgraph, the first offset (by 5)",
        lambda: offset_nodes.marching_squares([plate], 5.0, ctx=ctx),
        repeat=5,
    )
    fresh = rect(90, 40)
    first = table.time(
        case,
        "formgraph, a fresh 90 x 40 rectangle by 0.1",
        lambda: offset_nodes.marching_squares([fresh], 0.1, ctx=ctx),
        repeat=5,
    )
    again = table.time(
        case,
        "formgraph, the offset of the offset (by 0.1)",
        lambda: offset_nodes.marching_squares(rounded, 0.1, ctx=ctx),
        repeat=5,
    )
    if first and again:
        n = sum(len(c.control_points) for c in rounded)
        table.rows[-1].note = (
            f"{again / first:.2f}x the fresh outline of its size and distance; "
            f"its input {n:,} vertices"
        )
