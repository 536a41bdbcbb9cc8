"""``layout.nest``: parts placed without overlap, at the spacing, on their sheets, moved
rigidly, exact curves kept exact, parts in holes; checked with shapely and ezdxf."""

from __future__ import annotations

import re
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely
from fabrication_parts import benchmark_parts, part

import formgraph as fg

UTILISATION_FLOOR = 0.55  # the benchmark set (40 parts) on 600 x 400 gives 0.567 (effort 10)


def _nest(curves, **kw):
    g = fg.Graph()
    g.add("n", "layout.nest", curves=curves, **kw)
    return g, g.evaluate("n")


def _parts(curves):
    """The placed parts as shapely polygons: the even-odd region (the symmetric difference
    of every loop's polygon) of their fine samples, split into its pieces."""
    polys = [shapely.Polygon(np.asarray(c.sample(400))[:-1, :2]) for c in curves]
    region = polys[0]
    for p in polys[1:]:
        region = shapely.symmetric_difference(region, p)
    return shapely.get_parts(region)


def _ccw(r):
    x, y = r[:, 0], r[:, 1]
    return np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)) > 0


def _sheets(n, width):
    return [shapely.box(k * width * 1.1, 0, k * width * 1.1 + width, 400) for k in range(n)]


def test_mixed_parts_never_overlap_keep_the_spacing_and_stay_on_their_sheets():
    curves = benchmark_parts(24)
    _, out = _nest(curves, sheet=[600, 400], spacing=3, effort=3)
    placed = _parts(out.curves)
    assert len(placed) == 24
    polys = np.array(placed)
    d = shapely.distance(polys[:, None], polys[None, :])
    np.fill_diagonal(d, np.inf)
    assert d.min() >= 3 - 1e-6
    sheets = _sheets(out.sheets, 600)
    assert all(any(s.contains(p) for s in sheets) for p in placed)
    assert [np.asarray(o.control_points)[0, 0] for o in out.outlines] == pytest.approx(
        [660.0 * k for k in range(out.sheets)]
    )


def test_parts_are_moved_rigidly_areas_and_lengths_kept():
    curves = benchmark_parts(8)
    _, out = _nest(curves, sheet=[600, 400], spacing=2)
    assert len(out.curves) == len(curves)
    for a, b in zip(curves, out.curves, strict=True):
        pa, pb = np.asarray(a.sample(300)), np.asarray(b.sample(300))
        # the same samples at the same parameters, rotated and moved: all distances kept
        da = np.linalg.norm(pa[:, None] - pa[None], axis=-1)
        db = np.linalg.norm(pb[:, None] - pb[None], axis=-1)
        assert np.abs(da - db).max() < 1e-9 * da.max()
        assert np.allclose(pb[:, 2], 0)


def test_a_disc_that_fits_only_in_the_ring_goes_into_its_hole():
    ring = part("ring", 0.0)
    disc = part("small disc", 200.0)  # radius 10, the hole 22
    _, out = _nest(ring + disc, sheet=[72, 72], spacing=1, rotations=1)
    assert out.sheets == 1
    outer, hole, placed_disc = (np.asarray(c.sample(200))[:, :2] for c in out.curves)
    c_hole, c_disc = hole.mean(axis=0), placed_disc.mean(axis=0)
    assert np.linalg.norm(c_disc - c_hole) <= 22 - 10 - 1 + 1e-6


def test_a_circle_stays_an_exact_circle_written_as_an_arc(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("disc", "nurbs.circle", radius=20, center=[500, 300, 0])
    g.add("plate", "curves.rectangle", size=[80, 30], radius=0, center=[0, 0, 0])
    g.add("n", "layout.nest", curves=["@disc", "@plate"], sheet=[200, 100], spacing=2)
    g.add("svg", "export.svg", curves="@n.curves", path="n.svg")
    g.add("dxf", "export.dxf", curves="@n.curves", path="n.dxf")
    out = g.evaluate("n")
    circle = next(c for c in out.curves if c.rational)
    t = np.linspace(0, 1, 101)
    p = np.asarray(circle.evaluate(t))[:, :2]
    centre = 0.5 * (p.max(axis=0) + p.min(axis=0))
    assert np.linalg.norm(p - centre, axis=1) == pytest.approx(20.0, abs=1e-9)
    g.evaluate_all()
    svg = (tmp_path / "n.svg").read_text()
    assert re.search(r"A ?20[ ,]20", svg)  # the circle drawn as arcs of radius 20
    doc = ezdxf.readfile(tmp_path / "n.dxf")
    splines = [e for e in doc.modelspace() if e.dxftype() == "SPLINE"]
    (spline,) = splines
    assert (
        spline.dxf.degree == 2
        and max(spline.weights) == 1
        and min(spline.weights) == pytest.approx(2**-0.5)
    )
    ctrl = np.asarray(spline.control_points)[:, :2]
    assert np.linalg.norm(ctrl[::2] - centre, axis=1) == pytest.approx(20.0, abs=1e-9)


def test_utilisation_of_the_benchmark_set_does_not_fall():
    _, out = _nest(benchmark_parts(40), sheet=[600, 400], spacing=2, effort=10)
    assert out.utilisation >= UTILISATION_FLOOR
    area = sum(p.area for p in _parts(out.curves))
    used = (out.sheets - 1) * 600 * 400 + 400 * (
        max(np.asarray(c.sample(100))[:, 0].max() for c in out.curves) - 660 * (out.sheets - 1)
    )
    assert out.utilisation == pytest.approx(area / used, rel=2e-3)


def test_the_same_seed_gives_the_same_layout_and_a_new_seed_may_not():
    curves = benchmark_parts(10)
    _, a = _nest(curves, sheet=[300, 200], seed=1, effort=4)
    _, b = _nest(curves, sheet=[300, 200], seed=1, effort=4)
    for x, y in zip(a.curves, b.curves, strict=True):
        assert np.array_equal(x.control_points, y.control_points)


def test_errors_name_the_part_and_the_port():
    with pytest.raises(fg.NodeError, match=r"part 1 \(.*does not fit on the 50 x 50 sheet"):
        _nest(part("square", 0) + part("slot", 200), sheet=[50, 50])
    open_curve = fg.NurbsCurve.polyline([[0, 0, 0], [10, 0, 0], [10, 10, 0]])
    with pytest.raises(fg.NodeError, match=r"curves.*curve 0 is open"):
        _nest([open_curve], sheet=[50, 50])
    with pytest.raises(fg.NodeError, match=r"sheet.*\[width, height\]"):
        _nest(part("disc", 0), sheet=[50, -1])


def test_marks_ride_rigidly_on_the_parts_they_lie_on():
    g = fg.Graph()
    g.add("a", "curves.rectangle", size=[60, 30])
    g.add("b", "curves.rectangle", size=[40, 40], radius=5, center=[100, 0, 0])
    g.add("ta", "curves.text", text="A", size=10, align="center", position=[0, -3, 0])
    g.add("tb", "curves.text", text="B", size=10, align="center", position=[100, -3, 0])
    g.add("n", "layout.nest", curves=["@a", "@b"], marks=["@tb", "@ta"], sheet=[100, 50])
    nested = g.evaluate("n")
    parts = {
        round(shapely.Polygon(np.asarray(c.sample(400))[:-1, :2]).area): c for c in nested.curves
    }
    before = {"A": (g.evaluate("a"), g.evaluate("ta")), "B": (g.evaluate("b"), g.evaluate("tb"))}
    marks = iter(nested.marks)
    for name in ("B", "A"):  # in the order given: B's two loops, then A's two
        outline, glyphs = before[name]
        placed = parts[round(shapely.Polygon(np.asarray(outline.sample(400))[:-1, :2]).area)]
        ring = shapely.Polygon(np.asarray(placed.sample(400))[:-1, :2])
        ref = shapely.Polygon(np.asarray(outline.sample(400))[:-1, :2])
        for glyph in glyphs:
            moved = next(marks)
            p0 = np.asarray(glyph.sample(200))[:, :2]
            p1 = np.asarray(moved.sample(200))[:, :2]
            # on the placed part, each point as far from its outline as before: rigid
            assert shapely.contains_xy(ring, p1[:, 0], p1[:, 1]).all()
            d0 = shapely.distance(shapely.points(p0), ref.exterior)
            d1 = shapely.distance(shapely.points(p1), ring.exterior)
            assert d1 == pytest.approx(d0, abs=1e-6)
            # and the glyph's own shape is kept (pairwise distances)
            assert np.linalg.norm(p1[0] - p1[100]) == pytest.approx(np.linalg.norm(p0[0] - p0[100]))
    assert next(marks, None) is None


def test_contour_sheets_numbers_each_layer_on_its_engrave_layer(tmp_path):
    g = fg.load(
        Path(__file__).resolve().parents[1] / "graphs/contour_sheets.yaml", out_dir=tmp_path
    )
    doc = ezdxf.readfile(g.evaluate("dxf"))
    by_layer: dict[str, list] = {}
    for e in doc.modelspace():
        by_layer.setdefault(e.dxf.layer, []).append(e)
    assert len(by_layer["cut"]) == 6  # six layers, one outline each
    assert len(by_layer["engrave"]) == 8  # the digits 1-6, the 4 and the 6 with a counter
    nested = g.evaluate("nested")
    layers = [shapely.Polygon(np.asarray(c.sample(800))[:-1, :2]) for c in nested.curves]
    for mark in nested.marks:  # every number lies on exactly one layer
        p = np.asarray(mark.sample(100))[:, :2]
        on = [shapely.contains_xy(poly, p[:, 0], p[:, 1]).all() for poly in layers]
        assert sum(on) == 1
    svg = open(g.evaluate("svg")).read()
    for layer in ("sheet", "cut", "engrave"):  # Inkscape's layers, one per kind of line
        assert f'id="{layer}" inkscape:groupmode="layer"' in svg
    engrave = svg.split('id="engrave"')[1].split("</g>")[0]
    assert engrave.count("<path") == 8
