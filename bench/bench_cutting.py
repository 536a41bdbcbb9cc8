"""Cutting: region booleans against shapely, division, text outlines, the kerf offset.

Each row through its node on input made anew each call (the outlines built from the
arrays and moved a hair, in our time), the kernel beside:

* ``curves.union`` of two overlapping 10,000-vertex closed polylines (wiggly circles,
  their centres half a radius apart) -- sampling (a polyline is taken at its vertices),
  each ring's simplicity check, GEOS's overlay, the orientation of the result and the
  curves built from it -- against shapely's ``union`` of the two ``Polygon``s of the same
  vertices (GEOS alone, nothing checked or oriented), and the overlay alone on polygons
  made once (the floor under both); ``curves.boolean`` difference of the same pair;
* the union of two exact circles (``nurbs.circle``), the arcs it cuts rebuilt exact,
  against shapely's union of the same samples (which gives a polygon);
* ``curves.divide`` of a 10,000-vertex open polyline into 100,000 points at equal arc
  length (with tangents and parameters) against shapely's ``line_interpolate_point`` at
  the same distances, each on its own segment (:func:`shapely_divide`), and of a cubic
  NURBS of 100 control points into 10,000 points;
* ``curves.text`` of 1,000 characters (an English pangram repeated) at 10 mm: glyph
  outlines as exact NURBS, laid out with kerning, one curve per contour -- against
  matplotlib's ``TextPath`` of the same text and font (one path of Bezier codes, no
  curves). The font is parsed once, as in a graph's process;
* ``export.svg`` of those outlines (ours alone: the cost a curve);
* the offset of an offset (the nameplate's kerf): an 80 x 30 rectangle offset by 5 (a
  rounded plate), then that result offset by 0.1, against a fresh 90 x 40 rectangle
  offset by the same 0.1 (the same size and distance, from 4 vertices instead of the
  first offset's dense outline) and the first offset itself.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
from harness import through

import formgraph as fg
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


def _loops(*arrays: np.ndarray):
    """Params making closed polylines of ``arrays``, each moved a new hair every call."""
    return {
        f"c{i}": (lambda k, a=a: NurbsCurve.polyline(a * (1 + k * 1e-12), closed=True))
        for i, a in enumerate(arrays)
    }


def _shapely_op(op: str, a: np.ndarray, b: np.ndarray):
    def go():
        import shapely

        region = getattr(shapely, op)(shapely.Polygon(a), shapely.Polygon(b))
        return shapely.get_coordinates(shapely.get_rings(shapely.get_parts(region)))

    return go


def run(table) -> None:  # noqa: ANN001 - the harness's Table
    ctx = Context("bench", Path("."))
    a, b = wiggly(N, 0.0), wiggly(N, 0.5)
    ca, cb = NurbsCurve.polyline(a, closed=True), NurbsCurve.polyline(b, closed=True)

    def overlay_only():
        import shapely

        return shapely.union(pa, pb)

    import shapely

    pa, pb = shapely.Polygon(a), shapely.Polygon(b)
    note = "Polygons built from the arrays, rings' points out"
    table.compare(
        f"curves.union of two {N:,}-vertex outlines",
        api=through("curves.union", _loops(a, b), curves=["=c0", "=c1"]),
        kernel=lambda: cutting.union([ca, cb], ctx=ctx),
        references={
            "shapely": _shapely_op("union", a, b),
            "shapely (the overlay alone)": overlay_only,
        },
        notes={"shapely": note},
        rounds=7,
        note="the outlines made from the arrays each call, in our time",
    )
    table.compare(
        f"curves.boolean difference of two {N:,}-vertex outlines",
        api=through("curves.boolean", _loops(a, b), a=["=c0"], b=["=c1"], operation="difference"),
        kernel=lambda: cutting.boolean([ca], [cb], operation=cutting.Operation.difference, ctx=ctx),
        references={"shapely": _shapely_op("difference", a, b)},
        notes={"shapely": note},
        rounds=7,
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
    table.compare(
        "curves.union of two exact circles (cut arcs rebuilt exact)",
        api=_circles_graph(),
        kernel=lambda: cutting.union(circles, ctx=ctx),
        references={"shapely": _shapely_op("union", *samples)},
        notes={"shapely": f"the same {sum(map(len, samples)):,} samples, a polygon out"},
        rounds=7,
    )

    line_pts = wiggly(N, 0.0)
    line = NurbsCurve.polyline(line_pts)  # open: the loop without its closing edge
    ls = shapely.LineString(line_pts)
    at = np.linspace(0.0, ls.length, 100_000)
    table.compare(
        f"curves.divide of a {N:,}-vertex polyline into 100,000 points",
        api=through(
            "curves.divide",
            {"c": lambda k: NurbsCurve.polyline(line_pts * (1 + k * 1e-12))},
            curve="=c",
            count=100_000,
        ),
        kernel=lambda: curve_sample.divide(line, count=100_000, ctx=ctx),
        references={"shapely": lambda: shapely_divide(ls, at)},
        notes={
            "shapely": "points only; each distance on its own segment (one call on the line: 12 s)"
        },
        rounds=5,
    )
    rng = np.random.default_rng(1)
    cp = np.c_[np.cumsum(rng.normal(size=(100, 2)), axis=0), np.zeros(100)]
    from formgraph.kernels import nurbs

    knots = nurbs.clamped_uniform_knots(100, 3)
    cubic = NurbsCurve(cp, 3, knots)
    table.compare(
        "curves.divide of a 100-point cubic NURBS into 10,000 points",
        api=through(
            "curves.divide",
            {"c": lambda k: NurbsCurve(cp * (1 + k * 1e-12), 3, knots)},
            curve="=c",
            count=10_000,
        ),
        kernel=lambda: curve_sample.divide(cubic, count=10_000, ctx=ctx),
        rounds=5,
    )

    text = (PANGRAM * 23)[:1000]

    def matplotlib_text():
        from matplotlib.font_manager import FontProperties
        from matplotlib.textpath import TextPath

        return TextPath((0, 0), text, 10, FontProperties(family="DejaVu Sans"))

    sizes = itertools.count(1)
    g = fg.Graph()
    g.add_param("size", 10.0)
    g.add("t", "curves.text", text=text, size="=size")
    table.compare(
        "curves.text of 1,000 characters",
        api=lambda: g.evaluate("t", size=10.0 + next(sizes) * 1e-9),
        kernel=lambda: curve_text.text(text, ctx=ctx),
        references={"matplotlib TextPath": matplotlib_text},
        notes={"matplotlib TextPath": "one path of Bezier codes, no curves"},
        rounds=5,
        note="the font parsed once, as in a graph's process",
    )

    # export.svg of the same text: every glyph contour an exact cubic chain, all paths'
    # numbers formatted in one call (there is no reference writer of the same paths)
    import tempfile

    glyphs = curve_text.text(text, ctx=ctx)
    with tempfile.TemporaryDirectory() as out:
        names = itertools.count()
        eg = fg.Graph(out_dir=out)
        eg.add_param("name", "x")
        eg.add("t", "curves.text", text=text)
        eg.add("e", "export.svg", curves="@t", path="=name")
        eg.evaluate("t")
        stats = table.compare(
            f"export.svg of 1,000 characters ({len(glyphs):,} curves)",
            api=lambda: eg.evaluate("e", name=f"t{next(names)}.svg"),
            rounds=5,
            note="a new file name each call (the text's curves cached)",
        )
        table.rows[-1].note += f"; {stats['formgraph'].median / len(glyphs) * 1e6:.0f} us a curve"

    # the offset of an offset: the nameplate's kerf on its rounded plate
    from formgraph.nodes.offset import marching_squares as offset_nodes

    def rect(w: float, h: float) -> NurbsCurve:
        x, y = w / 2, h / 2
        return NurbsCurve.polyline([[-x, -y, 0], [x, -y, 0], [x, y, 0], [-x, y, 0]], closed=True)

    plate = rect(80, 30)
    rounded = offset_nodes.marching_squares([plate], 5.0, ctx=ctx)
    n = sum(len(c.control_points) for c in rounded)

    def offset(curves, d: float):
        steps = itertools.count(1)
        go = fg.Graph()
        go.add_param("d", d)
        params = {f"c{i}": c for i, c in enumerate(curves)}
        for name in params:
            go.add_param(name, type="Curve")
        go.add("o", "offset.marching_squares", curves=[f"={p}" for p in params], distance="=d")
        return lambda: go.evaluate("o", d=d * (1 + next(steps) * 1e-9), **params)

    table.compare(
        "offset of an offset: 80 x 30 rectangle by 5, then the result by 0.1",
        api=offset(rounded, 0.1),
        references={
            "a fresh 90 x 40 rectangle by the same 0.1": offset([rect(90, 40)], 0.1),
            "the first offset (the rectangle by 5)": offset([plate], 5.0),
        },
        rounds=7,
        note=f"through offset.marching_squares; its input {n:,} vertices",
    )


def _circles_graph():
    g = fg.Graph()
    g.add_param("r", 1.0)
    g.add("a", "nurbs.circle", radius="=r")
    g.add("b", "nurbs.circle", radius="=r", center=[1.0, 0.0, 0.0])
    g.add("u", "curves.union", curves=["@a", "@b"])
    steps = itertools.count(1)
    return lambda: g.evaluate("u", r=1.0 + next(steps) * 1e-12)
