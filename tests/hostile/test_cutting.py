"""Hostile inputs to the cutting nodes and the layered drawings: budgets before work,
names that would inject markup into SVG or PDF, fonts that are not fonts, degenerate
regions."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg
from formgraph.geometry import NurbsCurve
from formgraph.kernels import nurbs
from formgraph.kernels.curves import text as ktext


def test_sampling_to_a_tiny_tolerance_is_budgeted_before_it_runs():
    g = fg.Graph(budget=100_000)
    g.add("c", "nurbs.circle", radius=1000)
    g.add("u", "curves.union", curves=["@c"], tolerance=1e-7)  # about 7 million samples
    with pytest.raises(fg.BudgetError, match="curve samples"):
        g.evaluate("u")


def test_a_million_characters_are_refused_before_layout():
    g = fg.Graph(budget=1_000_000)
    g.add("t", "curves.text", text="x" * 1_000_000)
    with pytest.raises(fg.BudgetError, match="glyph control points"):
        g.evaluate("t")


@pytest.mark.parametrize(
    "name", ['a"><script>alert(1)</script>', "cut) >> /JavaScript (x", "1st", "", "a b"]
)
@pytest.mark.parametrize("kind", ["export.svg", "export.pdf"])
def test_layer_names_cannot_inject_markup(tmp_path, kind, name):
    g = fg.Graph(out_dir=tmp_path)
    g.add("c", "nurbs.circle")
    g.add("out", kind, curves=["@c"], layers=[name], path="x.out")
    with pytest.raises(fg.NodeError, match="input 'layers'"):
        g.evaluate("out")
    assert not (tmp_path / "x.out").exists()


@pytest.mark.parametrize("color", ["url(#x)", "#12345", "red; stroke-width: 9", "#ggg", "java"])
def test_colours_are_css_colours_only(tmp_path, color):
    g = fg.Graph(out_dir=tmp_path)
    g.add("c", "nurbs.circle")
    g.add("out", "export.svg", curves=["@c"], layers=["cut"], colors=[color], path="x.svg")
    with pytest.raises(fg.NodeError, match="input 'colors'.*not a colour"):
        g.evaluate("out")


@pytest.mark.parametrize("font", ["../../../etc/passwd", "/usr/share/fonts/x.ttf", "DejaVu"])
def test_font_names_are_bundled_names_not_paths(font):
    g = fg.Graph()
    g.add("t", "curves.text", text="a", font=font)
    with pytest.raises(fg.NodeError, match="input 'font'.*no bundled font"):
        g.evaluate("t")


@pytest.mark.parametrize("data", [b"", b"not a font at all", b"\x00\x01\x00\x00" + b"\x00" * 40])
def test_bytes_that_are_not_a_font_are_a_value_error(data):
    with pytest.raises(ValueError, match="cannot read the font|neither TrueType"):
        ktext.load_font(data)


def test_degenerate_regions():
    flat = NurbsCurve.polyline([[0, 0], [1, 0], [2, 0]], closed=True)  # zero area
    g = fg.Graph()
    g.add("u", "curves.union", curves=[flat])
    with pytest.warns(fg.FormgraphWarning, match="no area"):
        assert g.evaluate("u") == []
    # a curve that returns on itself (a figure eight) is read by the even-odd rule
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    eight = NurbsCurve.polyline(np.c_[np.sin(2 * t), np.sin(t)], closed=True)
    g.add("e", "curves.union", curves=[eight])
    loops = g.evaluate("e")
    assert len(loops) == 2 and all(c.closed for c in loops)
    # the same circle twice in one list: nothing is left (even-odd), no exception
    c = NurbsCurve(*nurbs.circle(1.0))
    g.add("x", "curves.boolean", a=[c, c], b=[])
    with pytest.warns(fg.FormgraphWarning, match="no area"):
        assert g.evaluate("x") == []


def test_a_billion_sided_polygon_is_refused_before_it_is_built():
    g = fg.Graph(budget=1_000_000)
    g.add("p", "curves.polygon", sides=10**9, radius=1)
    with pytest.raises(fg.BudgetError, match="polygon corners"):
        g.evaluate("p")


def test_a_rectangle_too_large_for_doubles_is_a_located_error():
    g = fg.Graph()
    g.add("r", "curves.rectangle", size=[1e308, 1e308], radius=1e307)
    with pytest.raises(fg.NodeError, match=r"input 'size'.*too large"):
        g.evaluate("r")


def test_curves_out_of_the_xy_plane_are_projected_with_a_warning():
    tilted = NurbsCurve.polyline([[0, 0, 0], [1, 0, 1], [1, 1, 2], [0, 1, 1]], closed=True)
    g = fg.Graph()
    g.add("u", "curves.union", curves=[tilted])
    with pytest.warns(fg.FormgraphWarning, match=r"curves: curve\(s\) 0 are not parallel"):
        (loop,) = g.evaluate("u")
    assert np.allclose(np.asarray(loop.control_points)[:, 2], 0)


@pytest.mark.parametrize("node,port", [("curves.union", "curves"), ("curves.boolean", "b")])
def test_a_polyline_of_one_point_is_refused_where_its_region_is_made(node, port):
    # a closed polyline that stays on one point of the XY plane (its repeats are not
    # dropped before GEOS, which calls such a ring simple): located, not an empty result
    point = NurbsCurve(np.tile([2.0, 2.0, 0.0], (5, 1)), 1, [0, 0, 1, 2, 3, 4, 4])
    there_and_back = NurbsCurve.polyline([[0, 0], [3, 1], [3, 1], [0, 0]])
    square = NurbsCurve.polyline([[0, 0], [1, 0], [1, 1], [0, 1]], closed=True)
    for bad in (point, there_and_back):
        g = fg.Graph()
        inputs = {"curves": [square, bad]} if port == "curves" else {"a": [square], "b": [bad]}
        g.add("r", node, **inputs)
        index = 1 if port == "curves" else 0
        with pytest.raises(fg.NodeError, match=rf"input '{port}'.*curve {index} encloses no area"):
            g.evaluate("r")
