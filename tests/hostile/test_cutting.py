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
