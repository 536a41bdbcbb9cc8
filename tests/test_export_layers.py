"""Layers and colours in export.svg, export.pdf and export.dxf: the layer follows the wire.

The SVG is parsed with ElementTree (and svgelements for the geometry), the PDF's objects
and content stream are read back by hand, the DXF with ezdxf.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
import zlib

import ezdxf
import numpy as np
import pytest

import formgraph as fg
from formgraph.core.types import Entries, entries_of, port_type
from formgraph.kernels.io.colors import CSS_COLORS, css_color

SVG = "{http://www.w3.org/2000/svg}"


def layered_graph(tmp_path, kind: str, **kwargs) -> fg.Graph:
    """Cut: an annulus of two loops from one wire (a boolean), and a hole; engrave: a circle."""
    g = fg.Graph(out_dir=tmp_path)
    g.add("outer", "curves.rectangle", size=[40, 20], radius=3)
    g.add("inner", "curves.rectangle", size=[30, 10], radius=1)
    g.add("frame", "curves.boolean", a=["@outer"], b=["@inner"], operation="difference")
    g.add("hole", "nurbs.circle", radius=2, center=[25, 0, 0])
    g.add("mark", "nurbs.circle", radius=1, center=[0, 0, 0])
    g.add("out", kind, curves=["@frame", "@hole", "@mark"], path="d.out", **kwargs)
    return g


def svg_groups(path) -> dict[str, tuple[str, int]]:
    root = ET.parse(path).getroot()
    return {
        g.get("id"): (g.get("stroke"), len(g.findall(f"{SVG}path")))
        for g in root.iter(f"{SVG}g")
        if g.get("id")
    }


def test_svg_layers_follow_the_wire_however_many_loops_it_holds(tmp_path):
    g = layered_graph(
        tmp_path, "export.svg", layers=["cut", "cut", "engrave"], colors=["red", "red", "#00F"]
    )
    assert len(g.evaluate("frame")) == 2  # one wire, two loops
    groups = svg_groups(g.evaluate("out"))
    assert groups == {"cut": ("#ff0000", 3), "engrave": ("#0000ff", 1)}


def test_svg_last_layer_takes_the_rest_and_default_colours(tmp_path):
    g = layered_graph(tmp_path, "export.svg", layers=["cut", "engrave"])
    groups = svg_groups(g.evaluate("out"))
    # the frame's two loops on cut; the hole and the mark (entries 1, 2) on engrave
    assert groups == {"cut": ("#ff0000", 2), "engrave": ("#0000ff", 2)}


def test_svg_without_layers_is_one_black_group(tmp_path):
    g = layered_graph(tmp_path, "export.svg")
    root = ET.parse(g.evaluate("out")).getroot()
    (group,) = root.findall(f"{SVG}g")
    assert group.get("stroke") == "#000000" and len(group.findall(f"{SVG}path")) == 4


def test_rounded_rectangle_is_drawn_exactly_as_arcs_and_lines(tmp_path):
    svgelements = pytest.importorskip("svgelements")
    g = fg.Graph(out_dir=tmp_path)
    g.add("plate", "curves.rectangle", size=[80, 30], radius=5)
    g.add("out", "export.svg", curves=["@plate"], path="p.svg")
    d = ET.parse(g.evaluate("out")).getroot().find(f"{SVG}g/{SVG}path").get("d")
    assert d.count("A") == 4 and d.count("L") == 4  # corner, side, corner, ...
    path = svgelements.Path(d)
    arcs = [s for s in path if isinstance(s, svgelements.Arc)]
    lines = [s for s in path if isinstance(s, svgelements.Line)]
    assert len(arcs) == 4 and len(lines) == 4
    np.testing.assert_allclose([float(a.rx) for a in arcs], 5, rtol=1e-12)
    # svgelements' own length of the outline: the closed form
    assert path.length() == pytest.approx(2 * (80 + 30) - 8 * 5 + 2 * np.pi * 5, rel=1e-6)


def pdf_objects(data: bytes) -> dict[int, bytes]:
    """Objects of a PDF by number, checked against the xref table's byte offsets."""
    start = int(re.search(rb"startxref\n(\d+)", data).group(1))
    rows = data[start:].split(b"\n")
    count = int(rows[1].split()[1])
    offsets = [int(r[:10]) for r in rows[3 : 2 + count]]
    objects = {}
    for i, off in enumerate(offsets, start=1):
        assert data[off:].startswith(f"{i} 0 obj".encode())
        objects[i] = data[off : data.index(b"endobj", off)]
    return objects


def test_pdf_layers_are_optional_content_groups_in_their_colours(tmp_path):
    g = layered_graph(tmp_path, "export.pdf", layers=["cut", "engrave"], colors=["red", "blue"])
    data = (tmp_path / g.evaluate("out")).read_bytes()
    assert data.startswith(b"%PDF-1.5")
    objects = pdf_objects(data)
    names = [
        re.search(rb"/Name \((\w+)\)", o).group(1) for o in objects.values() if b"/Type /OCG " in o
    ]
    assert names == [b"cut", b"engrave"]
    assert b"/OCProperties" in objects[1] and b"/Properties << /L0 6 0 R /L1 7 0 R" in objects[3]
    stream = objects[4]
    body = zlib.decompress(stream[stream.index(b"stream\n") + 7 : stream.rindex(b"\nendstream")])
    sections = re.findall(rb"/OC /(L\d) BDC\n([\d.]+ [\d.]+ [\d.]+) RG\n(.*?)EMC", body, re.S)
    assert [(s[0], s[1]) for s in sections] == [(b"L0", b"1 0 0"), (b"L1", b"0 0 1")]
    assert [s[2].count(b"S\n") for s in sections] == [2, 2]


def test_pdf_without_layers_is_unchanged_pdf_1_4(tmp_path):
    g = layered_graph(tmp_path, "export.pdf")
    data = (tmp_path / g.evaluate("out")).read_bytes()
    assert data.startswith(b"%PDF-1.4") and b"/OC" not in data
    assert len(pdf_objects(data)) == 5


def test_dxf_layers_follow_the_wire_with_css_true_colours(tmp_path):
    g = layered_graph(tmp_path, "export.dxf", layers=["cut", "engrave"], colors=["red", "#ff8000"])
    doc = ezdxf.readfile(tmp_path / g.evaluate("out"))
    layers = {layer.dxf.name: layer for layer in doc.layers}
    assert layers["cut"].rgb == (255, 0, 0) and layers["cut"].dxf.color == 1
    assert layers["engrave"].rgb == (255, 128, 0)
    assert 1 <= layers["engrave"].dxf.color <= 255
    entities = [e.dxf.layer for e in doc.modelspace()]
    assert entities.count("cut") == 2 and entities.count("engrave") == 2
    # ACI numbers still work, and one wire of two loops keeps both on its layer
    g2 = layered_graph(tmp_path, "export.dxf", layers=["cut", "engrave"], colors=[1, 5])
    doc2 = ezdxf.readfile(tmp_path / g2.evaluate("out"))
    assert {la.dxf.name: la.dxf.color for la in doc2.layers}["engrave"] == 5


def test_a_list_built_in_python_is_one_entry_per_item(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    a, b = fg.NurbsCurve.polyline([[0, 0], [1, 0], [1, 1]], closed=True), None
    b = fg.NurbsCurve.polyline([[2, 0], [3, 0], [3, 1]], closed=True)
    g.add("out", "export.svg", curves=[a, b], path="p.svg", layers=["x", "y"])
    assert svg_groups(g.evaluate("out")) == {"x": ("#ff0000", 1), "y": ("#0000ff", 1)}


@pytest.mark.parametrize(
    "kind, kwargs, match",
    [
        ("export.svg", {"layers": ["cut"], "colors": ["rde"]}, r"'colors'.*did you mean 'red'"),
        ("export.svg", {"layers": ["a b"]}, r"'layers'.*starts with a letter"),
        ("export.pdf", {"colors": ["red"]}, r"'colors'.*give layers too"),
        ("export.pdf", {"layers": ["a", "b"], "colors": ["red"]}, r"one colour per entry"),
        ("export.svg", {"layers": ["a", "a"], "colors": ["red", "blue"]}, r"two colours"),
        ("export.dxf", {"layers": ["a"], "colors": ["nocolour"]}, r"'colors'.*not a colour"),
    ],
)
def test_bad_layers_and_colours_are_located_errors(tmp_path, kind, kwargs, match):
    g = layered_graph(tmp_path, kind, **kwargs)
    with pytest.raises(fg.FormgraphError, match=match):
        g.evaluate("out")


def test_css_colour_table_is_the_standard_one():
    matplotlib_colors = pytest.importorskip("matplotlib.colors")
    assert CSS_COLORS == {k: v.lower() for k, v in matplotlib_colors.CSS4_COLORS.items()}
    assert css_color("#AbC") == "#aabbcc" and css_color(" RebeccaPurple ") == "#663399"


def test_entries_survive_coercion_and_default_to_one_per_item():
    t = port_type(list[fg.Curve])
    c = fg.NurbsCurve.polyline([[0, 0], [1, 0]])
    coerced = t.coerce(Entries([c, c, c], [0, 0, 1]))
    assert entries_of(coerced) == [0, 0, 1]
    assert entries_of([c, c]) == [0, 1]
    with pytest.raises(ValueError, match="2 items but 1 entry"):
        Entries([c, c], [0])


@pytest.mark.parametrize("kind, suffix", [("export.svg", "svg"), ("export.dxf", "dxf")])
def test_layers_read_back_with_read_curves(tmp_path, kind, suffix):
    g = fg.Graph(out_dir=tmp_path)
    g.add("outer", "curves.rectangle", size=[40, 20], radius=3)
    g.add("inner", "curves.rectangle", size=[30, 10], radius=1)
    g.add("frame", "curves.boolean", a=["@outer"], b=["@inner"], operation="difference")
    g.add("hole", "nurbs.circle", radius=2, center=[25, 0, 0])
    g.add("mark", "nurbs.circle", radius=1, center=[0, 0, 0])
    g.add(
        "out", kind, curves=["@frame", "@hole", "@mark"], path=f"d.{suffix}",
        layers=["cut", "engrave"], colors=["red", "blue"],
    )  # fmt: skip
    g.evaluate("out")
    r = fg.Graph(out_dir=tmp_path, inputs_dir=tmp_path)
    r.add("cut", "read.curves", path=f"d.{suffix}", layers=["cut"])
    r.add("engrave", "read.curves", path=f"d.{suffix}", layers=["engrave"])
    cut, engrave = r.evaluate("cut"), r.evaluate("engrave")
    assert len(cut) == 2 and len(engrave) == 2  # the frame's two loops; the hole and mark

    def area(curves):
        total = 0.0
        for c in curves:
            p = np.asarray(c.evaluate(np.linspace(*c.domain, 4001)))[:-1, :2]
            x, y = p[:, 0], p[:, 1]
            total += abs(0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
        return total

    assert area(engrave) == pytest.approx(np.pi * (4 + 1), rel=1e-5)
    outer = 40 * 20 - (4 - np.pi) * 9
    inner = 30 * 10 - (4 - np.pi) * 1
    assert area(cut) == pytest.approx(outer + inner, rel=1e-5)
