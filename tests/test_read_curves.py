"""read.curves: SVG (against svgelements' own geometry) and DXF (against ezdxf's), exact."""

from __future__ import annotations

import io
import math
import time
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import svgelements as se

import formgraph as fg

HEAD = "formgraph: 1\nnodes:\n"


def _curves(folder: Path, name: str, data: bytes, layers=None, **load) -> list[fg.NurbsCurve]:
    (folder / name).write_bytes(data)
    extra = f", layers: {layers}" if layers is not None else ""
    (folder / "g.yaml").write_text(HEAD + f"  c: {{type: read.curves, path: {name}{extra}}}\n")
    return fg.load(folder / "g.yaml", **load).evaluate("c")


def _points(c: fg.NurbsCurve, n: int = 400) -> np.ndarray:
    return c.evaluate(np.linspace(c.knots[c.degree], c.knots[-c.degree - 1], n))


SVG = b"""<svg xmlns="http://www.w3.org/2000/svg"
  xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
  width="100mm" height="50mm" viewBox="0 0 200 100">
<g id="cut"><circle cx="50" cy="50" r="20"/><rect x="10" y="10" width="30" height="20" rx="5"/>
<polygon points="100,10 120,10 110,30"/></g>
<g inkscape:label="engrave" transform="translate(100,0) skewX(20)">
<path d="M0 0 L10 0 C 20 0 20 10 10 10 Q 5 15 0 10 A 5 3 30 0 1 0 0 Z"/></g>
</svg>"""


def test_svg_millimetres_from_width_and_viewbox_exact_circle(tmp_path):
    circle = _curves(tmp_path, "a.svg", SVG)[0]
    assert circle.degree == 2 and circle.rational
    p = _points(circle)
    # 20 user units of a 200-unit-wide, 100 mm document: 10 mm; y up from the bottom edge
    np.testing.assert_allclose(np.linalg.norm(p[:, :2] - [25, 25], axis=1), 10, atol=1e-12)


def test_svg_without_a_size_is_in_css_pixels(tmp_path):
    data = b'<svg xmlns="http://www.w3.org/2000/svg"><circle cx="0" cy="0" r="96"/></svg>'
    (c,) = _curves(tmp_path, "a.svg", data)
    np.testing.assert_allclose(np.linalg.norm(_points(c)[:, :2], axis=1), 25.4, atol=1e-12)


def test_svg_polygon_is_degree_one_and_closed(tmp_path):
    poly = _curves(tmp_path, "a.svg", SVG)[2]
    assert poly.degree == 1 and not poly.rational
    assert np.array_equal(poly.control_points[0], poly.control_points[-1])
    want = [[50, 45], [60, 45], [55, 35]]
    np.testing.assert_allclose(poly.control_points[:3, :2], want, rtol=1e-14)


def test_svg_path_pieces_match_svgelements_segment_by_segment(tmp_path):
    path = _curves(tmp_path, "a.svg", SVG)[3]
    assert path.degree == 3  # the cubic sets the degree; lines and arcs are raised to it
    doc = se.SVG.parse(io.BytesIO(SVG))
    shape = [e for e in doc.elements() if isinstance(e, se.Path)][0]
    mm = 100 / float(doc.width)
    segs = [s for s in shape if not isinstance(s, se.Move | se.Close)]
    # line, cubic, quadratic keep their parameter: piece k spans [k, k + 1]
    u = np.linspace(0, 1, 11)
    for k, seg in enumerate(segs[:3]):
        want = np.array([[seg.point(t).x, seg.point(t).y] for t in u]) * mm
        want[:, 1] = 50 - want[:, 1]
        np.testing.assert_allclose(path.evaluate(k + u)[:, :2], want, atol=1e-9)
    # the arc: every point, mapped back into the path's own coordinates, on the ellipse
    # svgelements finds there (centre to ~1e-8; its skewed, reified axes are not exact)
    local = se.SVG.parse(io.BytesIO(SVG), reify=False)
    shape = [e for e in local.elements() if isinstance(e, se.Path)][0]
    arc = [s for s in shape if isinstance(s, se.Arc)][0]
    m = shape.transform
    pts = path.evaluate(np.linspace(3, path.knots[-1], 200))[:, :2] / mm
    pts[:, 1] = 50 / mm - pts[:, 1]
    inv = np.linalg.inv([[m.a, m.c], [m.b, m.d]])
    uv = (pts - [m.e, m.f]) @ inv.T
    rot = float(arc.get_rotation())
    d = uv - [arc.center.x, arc.center.y]
    x = d @ [math.cos(rot), math.sin(rot)]
    y = d @ [-math.sin(rot), math.cos(rot)]
    np.testing.assert_allclose((x / arc.rx) ** 2 + (y / arc.ry) ** 2, 1, atol=1e-6)


def test_svg_layers_by_id_and_inkscape_label(tmp_path):
    assert len(_curves(tmp_path, "a.svg", SVG, layers="[cut]")) == 3
    assert len(_curves(tmp_path, "a.svg", SVG, layers="[engrave]")) == 1
    with pytest.warns(fg.FormgraphWarning, match="no curves on layer 'nope'"):
        assert _curves(tmp_path, "a.svg", SVG, layers="[nope]") == []


def test_svg_a_million_nested_groups_is_refused_quickly(tmp_path):
    data = b'<svg xmlns="http://www.w3.org/2000/svg">' + b"<g>" * 1_000_000 + b"</svg>"
    t0 = time.process_time()
    with pytest.raises(fg.NodeError, match="over the budget"):
        _curves(tmp_path, "bomb.svg", data)
    assert time.process_time() - t0 < 30  # CPU seconds: refused before parsing


def test_svg_deep_nesting_under_the_tag_budget_is_refused(tmp_path):
    data = b'<svg xmlns="http://www.w3.org/2000/svg">' + b"<g>" * 5000 + b"</g>" * 5000
    with pytest.raises(fg.NodeError, match="nest 5,001 deep"):
        _curves(tmp_path, "deep.svg", data + b"</svg>")


def test_svg_garbage_is_a_node_error(tmp_path):
    with pytest.raises(fg.NodeError, match="not an SVG"):
        _curves(tmp_path, "x.svg", b"<svg><g></svg")


# ---------------------------------------------------------------------------------- DXF


def _new():
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4  # millimetres (ezdxf's own default is metres)
    return doc


def _dxf(doc) -> bytes:
    buf = io.StringIO()
    doc.write(buf)
    return buf.getvalue().encode()


def test_dxf_bulges_are_exact_arcs(tmp_path):
    from ezdxf.math import bulge_to_arc

    doc = _new()
    pts = [(0, 0, 0), (20, 0, 0.5), (20, 20, 0), (0, 20, -1.5)]
    doc.modelspace().add_lwpolyline(pts, format="xyb", close=True)
    (c,) = _curves(tmp_path, "p.dxf", _dxf(doc))
    assert c.degree == 2 and c.rational
    assert np.allclose(c.control_points[0], c.control_points[-1])
    for (x0, y0, b), (x1, y1, _) in [(pts[1], pts[2]), (pts[3], pts[0])]:
        center, _, _, radius = bulge_to_arc((x0, y0), (x1, y1), b)
        p = _points(c, 2000)[:, :2]
        on = np.abs(np.linalg.norm(p - [center.x, center.y], axis=1) - radius) < 1e-9
        # the arc's points sit on ezdxf's circle to rounding; a sagitta point among them
        assert on.sum() > 200
        mid = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
        chord = np.array([x1 - x0, y1 - y0])
        sag = mid + abs(b) * np.hypot(*chord) / 2 * np.array([chord[1], -chord[0]]) / np.hypot(
            *chord
        ) * np.sign(b)
        assert np.min(np.linalg.norm(p - sag, axis=1)) < 0.05


def test_dxf_rational_spline_and_ellipse_match_ezdxf(tmp_path):
    doc = _new()
    msp = doc.modelspace()
    spline = msp.add_rational_spline(
        [(0, 0, 0), (1, 2, 0), (3, 2, 1), (4, 0, 0)], [1, 0.5, 2, 1], degree=3
    )
    ellipse = msp.add_ellipse((1, 2, 0), major_axis=(3, 1, 0), ratio=0.4, start_param=0.3,
                              end_param=5)  # fmt: skip
    s, e = _curves(tmp_path, "s.dxf", _dxf(doc))
    tool = spline.construction_tool()
    t = np.linspace(0, tool.max_t, 13)
    np.testing.assert_allclose(s.evaluate(t), [list(tool.point(x)) for x in t], atol=1e-12)
    assert s.knots.tolist() == list(tool.knots()) and s.degree == 3
    et = ellipse.construction_tool()
    p = _points(e) - [1, 2, 0]
    major = np.array(list(et.major_axis))
    minor = np.array(list(et.minor_axis))
    x = p @ major / np.dot(major, major)
    y = p @ minor / np.dot(minor, minor)
    np.testing.assert_allclose(x**2 + y**2, 1, atol=1e-12)
    np.testing.assert_allclose(_points(e)[0], list(et.start_point), atol=1e-12)
    np.testing.assert_allclose(_points(e)[-1], list(et.end_point), atol=1e-12)


def test_dxf_blocks_expand_with_layer_and_units(tmp_path):
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 5  # centimetres
    blk = doc.blocks.new("B")
    blk.add_circle((0, 0), 1)
    blk.add_line((0, 0), (1, 0), dxfattribs={"layer": "inner"})
    msp = doc.modelspace()
    msp.add_blockref("B", (10, 0), dxfattribs={"layer": "parts", "rotation": 90})
    msp.add_arc((0, 0), 3, 30, 300, dxfattribs={"layer": "cut"})
    curves = _curves(tmp_path, "b.dxf", _dxf(doc))
    assert len(curves) == 3
    circle, line, arc = curves
    np.testing.assert_allclose(np.linalg.norm(_points(circle) - [100, 0, 0], axis=1), 10)
    np.testing.assert_allclose(line.control_points, [[100, 0, 0], [100, 10, 0]], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(_points(arc), axis=1), 30)
    assert len(_curves(tmp_path, "b.dxf", _dxf(doc), layers="[parts]")) == 1  # layer 0 -> parts
    assert len(_curves(tmp_path, "b.dxf", _dxf(doc), layers="[inner, cut]")) == 2


def test_dxf_nested_block_bomb_is_refused_by_the_budget(tmp_path):
    doc = _new()
    doc.blocks.new("L0").add_line((0, 0), (1, 0))
    for level in range(1, 6):
        blk = doc.blocks.new(f"L{level}")
        for k in range(10):
            blk.add_blockref(f"L{level - 1}", (k, 0))
    doc.modelspace().add_blockref("L5", (0, 0))  # 100,000 lines
    t0 = time.process_time()
    with pytest.raises(fg.NodeError, match="over the budget"):
        _curves(tmp_path, "bomb.dxf", _dxf(doc), budget=3_000)
    assert time.process_time() - t0 < 30


def test_dxf_round_trips_our_own_export_exactly(tmp_path):
    (tmp_path / "w.yaml").write_text(
        HEAD + "  c: {type: curves.catmull_rom, points: [[0, 0], [10, 5], [20, -3], [30, 0]]}\n"
        "  x: {type: export.dxf, curves: ['@c'], path: c.dxf}\n"
    )
    g = fg.load(tmp_path / "w.yaml", out_dir=tmp_path)
    out = g.evaluate("x")
    (back,) = _curves(tmp_path, "c2.dxf", Path(out).read_bytes())
    want = g.evaluate("c")
    t = np.linspace(want.knots[want.degree], want.knots[-want.degree - 1], 50)
    u = np.linspace(back.knots[back.degree], back.knots[-back.degree - 1], 50)
    np.testing.assert_allclose(back.evaluate(u), want.evaluate(t), atol=1e-9)


def test_svg_layers_written_by_export_svg_are_read_back_by_name(tmp_path):
    (tmp_path / "w.yaml").write_text(
        HEAD + "  a: {type: nurbs.circle, radius: 5}\n"
        "  b: {type: curves.rectangle, size: [30, 20], radius: 3}\n"
        "  x: {type: export.svg, curves: ['@a', '@b'], layers: [cut, engrave], path: d.svg}\n"
    )
    g = fg.load(tmp_path / "w.yaml", out_dir=tmp_path)
    data = Path(g.evaluate("x")).read_bytes()
    (circle,) = _curves(tmp_path, "d.svg", data, layers="[cut]")
    (rect,) = _curves(tmp_path, "d.svg", data, layers="[engrave]")
    # the drawing is placed on its page: compare shapes about their centres
    cp = circle.control_points[:, :2]  # the control square of an exact circle: its centre
    centre = (cp.max(0) + cp.min(0)) / 2
    np.testing.assert_allclose(
        np.linalg.norm(_points(circle)[:, :2] - centre, axis=1), 5, atol=1e-12
    )
    r = rect.control_points[:, :2]
    np.testing.assert_allclose(r.max(0) - r.min(0), [30, 20], atol=1e-12)
    assert rect.degree == 2 and rect.rational  # the rounded corners came back as arcs


def test_svg_text_not_converted_to_paths_is_reported(tmp_path):
    data = (
        b'<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="10mm" viewBox="0 0 10 10">'
        b'<text x="1" y="5">Hi</text><circle cx="5" cy="5" r="2"/></svg>'
    )
    with pytest.warns(fg.FormgraphWarning, match=r"passed over what is not a curve \(1 text\)"):
        assert len(_curves(tmp_path, "t.svg", data)) == 1
