"""Export nodes: files read back, atomic and idempotent writes, paths kept inside out_dir."""

from __future__ import annotations

import io
import os
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import formgraph as fg
from formgraph.geometry import Mesh, NurbsCurve

S = np.sqrt(0.5)
CIRCLE = NurbsCurve(
    np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]]) * 4.0
    + [2, 1],
    2,
    [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
    [1, S, 1, S, 1, S, 1, S, 1],
)


def graph(tmp_path, **params) -> fg.Graph:
    g = fg.Graph(out_dir=tmp_path / "out")
    for name, kind in params.items():
        g.add_param(name, type=kind)
    return g


def files(folder) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def test_mesh_files_read_back(tmp_path):
    import meshio
    import trimesh

    g = graph(tmp_path)
    g.add("box", "mesh.box", size=[2, 1, 3])
    g.add("stl", "export.stl", mesh="@box", path="parts/box.stl")
    g.add("stla", "export.stl", mesh="@box", path="parts/box_ascii.stl", ascii=True)
    g.add("obj", "export.obj", mesh="@box", path="box.obj")
    g.add("objn", "export.obj", mesh="@box", path="box_n.obj", normals=True)
    g.add("ply", "export.ply", mesh="@box", path="box.ply")
    out = g.evaluate(["stl", "stla", "obj", "objn", "ply"])
    root = tmp_path / "out"
    assert out["stl"] == str(root / "parts" / "box.stl")
    assert files(root) == [
        "box.obj", "box.ply", "box_n.obj", "parts/box.stl", "parts/box_ascii.stl"
    ]  # fmt: skip
    for name in ("stl", "stla"):
        t = trimesh.load(out[name])
        assert len(t.faces) == 12 and t.is_watertight and t.volume == pytest.approx(6.0)
        assert np.allclose(t.bounds, [[-1, -0.5, -1.5], [1, 0.5, 1.5]])
        assert g.stats[name].warnings == []
    m = meshio.read(out["obj"])
    assert [(c.type, len(c.data)) for c in m.cells] == [("quad", 6)]
    normals = trimesh.load(out["objn"], process=False).vertex_normals
    # each corner: the sum of its three faces' area vectors, (3, 6, 2) for a 2 x 1 x 3 box
    assert np.allclose(np.abs(normals), np.array([3, 6, 2]) / 7)
    t = trimesh.load(out["ply"], process=False)
    assert t.volume == pytest.approx(6.0) and len(t.vertices) == 8


def test_stl_warns_about_holes_and_flips(tmp_path):
    g = graph(tmp_path, m="Mesh")
    g.add("stl", "export.stl", mesh="=m", path="open.stl")
    box = fg.Graph()
    box.add("b", "mesh.box")
    b = box.evaluate("b")
    open_box = Mesh(b.vertices, b.faces[1:])
    g.evaluate("stl", m=open_box)
    assert any("not watertight: 4 boundary edges" in w for w in g.stats["stl"].warnings)
    flipped = Mesh(b.vertices, [f[::-1] for f in b.faces])
    g.evaluate("stl", m=flipped)
    assert any("inside out" in w for w in g.stats["stl"].warnings)


def _svg(path) -> tuple[ET.Element, list[str]]:
    root = ET.parse(path).getroot()
    return root, [p.get("d") for p in root.iter("{http://www.w3.org/2000/svg}path")]


def _numbers(d: str) -> np.ndarray:
    return np.array([float(x) for x in re.findall(r"-?[\d.]+(?:e[-+]?\d+)?", d)])


def test_svg_curves_exact_where_they_can_be(tmp_path):
    g = graph(tmp_path, circle="Curve", quad="Curve")
    g.add("pts", "points.circle", count=6, radius=10)
    g.add("cr", "curves.catmull_rom", points="@pts", closed=True)
    g.add("wave", "curves.parametric", x="t", y="sin(t)", t=[0, 6])
    g.add("svg", "export.svg", curves=["@cr", "=circle", "=quad", "@wave"], path="d.svg")
    quad = NurbsCurve([[0, 0], [2, 4], [4, 0], [6, 3]], 2, [0, 0, 0, 0.5, 1, 1, 1])
    path = g.evaluate("svg", circle=CIRCLE, quad=quad)
    root, (cr, circle, qd, wave) = _svg(path)
    assert root.get("width").endswith("mm")
    # Catmull-Rom: six cubic Beziers through the six points, closed
    assert cr.startswith("M ") and " C " in cr and cr.endswith("Z")
    knots = _numbers(cr).reshape(-1, 2)[::3] * [1, -1]
    a = np.arange(7) * np.pi / 3
    assert np.allclose(knots, 10 * np.column_stack([np.cos(a), np.sin(a)]), atol=1e-6)
    # the rational circle: four exact arc commands of radius 4
    assert circle.count("A") == 1 and len(_numbers(circle)) == 2 + 4 * 7
    assert np.allclose(_numbers(circle)[2:].reshape(4, 7)[:, :2], 4.0)
    # the quadratic B-spline: raised to cubic Beziers that trace the same curve
    c = _numbers(qd).reshape(-1, 2) * [1, -1]
    segs = np.stack([c[0:-1:3], c[1::3], c[2::3], c[3::3]], axis=1)
    t = np.linspace(0, 1, 11)[:, None, None]
    bez = ((1 - t) ** 3 * segs[:, 0] + 3 * (1 - t) ** 2 * t * segs[:, 1]
           + 3 * (1 - t) * t**2 * segs[:, 2] + t**3 * segs[:, 3])  # fmt: skip
    ts = np.concatenate([np.linspace(0, 0.5, 11), np.linspace(0.5, 1, 11)])
    assert np.allclose(np.concatenate(bez.transpose(1, 0, 2)), quad.evaluate(ts)[:, :2], atol=2e-6)
    # the parametric curve: a polyline on the curve
    w = _numbers(wave).reshape(-1, 2) * [1, -1]
    assert len(w) == 1024 and np.allclose(w[:, 1], np.sin(w[:, 0]), atol=1e-5)


def test_pdf_page_fits_the_drawing(tmp_path):
    g = graph(tmp_path, circle="Curve")
    g.add("pdf", "export.pdf", curves=["=circle"], path="c.pdf", margin=2)
    data = open(g.evaluate("pdf", circle=CIRCLE), "rb").read()
    side = (8 + 4) * 72 / 25.4
    box = re.search(rb"/MediaBox \[0 0 ([\d.]+) ([\d.]+)\]", data).groups()
    assert [float(x) for x in box] == pytest.approx([side, side], abs=1e-4)
    start = int(re.search(rb"startxref\n(\d+)", data).group(1))
    assert data[start:].startswith(b"xref")


def test_dxf_keeps_the_circle_exact(tmp_path):
    import ezdxf

    g = graph(tmp_path, circle="Curve")
    g.add("pl", "curves.polyline", points=[[0, 0], [5, 0], [5, 5]], closed=True)
    g.add("box", "mesh.box")
    g.add("dxf", "export.dxf", curves=["=circle", "@pl"], mesh="@box", path="cad/d.dxf")
    doc = ezdxf.readfile(g.evaluate("dxf", circle=CIRCLE))
    auditor = doc.audit()
    assert not auditor.has_errors and not auditor.has_fixes
    msp = doc.modelspace()
    assert [e.dxftype() for e in msp] == ["SPLINE", "LWPOLYLINE", "MESH"]
    spline = msp.query("SPLINE")[0]
    pts = np.array(list(spline.construction_tool().points(np.linspace(0, 1, 1001))))
    assert np.abs(np.linalg.norm(pts - [2, 1, 0], axis=1) - 4).max() < 1e-9
    lw = msp.query("LWPOLYLINE")[0]
    assert lw.closed and len(lw) == 3
    g.add("empty", "export.dxf", path="nothing.dxf")
    with pytest.raises(fg.NodeError, match="needs curves or a mesh"):
        g.evaluate("empty", circle=CIRCLE)


def _box_graph(tmp_path, size=(1, 1, 1)) -> fg.Graph:
    g = graph(tmp_path)
    g.add("box", "mesh.box", size=list(size))
    g.add("stl", "export.stl", mesh="@box", path="sub/box.stl")
    return g


def test_rerun_leaves_an_identical_file_untouched(tmp_path):
    target = tmp_path / "out" / "sub" / "box.stl"
    _box_graph(tmp_path).evaluate("stl")
    before = target.stat().st_mtime_ns
    os.utime(target, ns=(before - 10**9, before - 10**9))  # make any rewrite visible
    stamp = target.stat().st_mtime_ns
    _box_graph(tmp_path).evaluate("stl")  # a fresh graph, no cache: same bytes again
    assert target.stat().st_mtime_ns == stamp
    _box_graph(tmp_path, size=(2, 1, 1)).evaluate("stl")
    assert target.stat().st_mtime_ns != stamp
    assert files(tmp_path / "out") == ["sub/box.stl"]  # no temp files left


def test_a_failing_write_leaves_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "out" / "sub" / "box.stl"
    _box_graph(tmp_path).evaluate("stl")
    old = target.read_bytes()
    folder = target.parent
    if os.geteuid() == 0:  # root writes into read-only folders: make the rename fail instead
        import formgraph.core.safety

        def refuse(*args, **kwargs):
            raise PermissionError(13, "Permission denied", str(target))

        monkeypatch.setattr(formgraph.core.safety.os, "replace", refuse)
    else:
        folder.chmod(0o555)
    try:
        with pytest.raises(fg.NodeError, match="export.stl"):
            _box_graph(tmp_path, size=(3, 1, 1)).evaluate("stl")
    finally:
        folder.chmod(0o755)
    assert target.read_bytes() == old
    assert files(tmp_path / "out") == ["sub/box.stl"]


@pytest.mark.parametrize("path", ["../escape.stl", "/tmp/escape.stl", "a/../../escape.stl"])
def test_paths_leaving_the_output_directory_are_refused(tmp_path, path):
    g = graph(tmp_path)
    g.add("box", "mesh.box")
    g.add("stl", "export.stl", mesh="@box", path=path)
    with pytest.raises(fg.GraphError, match="output"):
        g.evaluate("stl")
    assert not (tmp_path / "escape.stl").exists()


def test_a_symlink_out_is_refused(tmp_path):
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "link").symlink_to(outside)
    g = graph(tmp_path)
    g.add("box", "mesh.box")
    g.add("stl", "export.stl", mesh="@box", path="link/box.stl")
    with pytest.raises(fg.GraphError, match="outside the output directory"):
        g.evaluate("stl")
    assert list(outside.iterdir()) == []


def test_stl_ascii_and_binary_agree(tmp_path):
    from stl import mesh as stl_mesh

    g = graph(tmp_path)
    g.add("box", "mesh.box", size=[1, 2, 3])
    g.add("cc", "mesh.catmull_clark", mesh="@box", levels=2)
    g.add("b", "export.stl", mesh="@cc", path="b.stl")
    g.add("a", "export.stl", mesh="@cc", path="a.stl", ascii=True)
    out = g.evaluate(["a", "b"])
    a = stl_mesh.Mesh.from_file(out["a"], calculate_normals=False)
    b = stl_mesh.Mesh.from_file(out["b"], calculate_normals=False)
    assert len(a.vectors) == 2 * 96 and np.array_equal(a.vectors, b.vectors)
    assert io.BytesIO(open(out["a"], "rb").read()).read(6) == b"solid "


def test_nurbs_circles_and_arcs_become_svg_arcs_and_dxf_splines(tmp_path):
    import ezdxf

    g = graph(tmp_path)
    g.add("c", "nurbs.circle", radius=5, center=[1, 2, 0])
    g.add("a", "nurbs.arc", radius=3, start=30, end=200)
    g.add("tilted", "nurbs.circle", radius=2, normal=[1, 0, 1])  # an ellipse seen from +z
    g.add("svg", "export.svg", curves=["@c", "@a", "@tilted"], path="arcs.svg")
    g.add("dxf", "export.dxf", curves=["@c", "@a"], path="arcs.dxf")
    out = g.evaluate(["svg", "dxf"])
    _, (circle, arc, tilted) = _svg(out["svg"])
    assert circle.endswith("Z") and " A " in circle
    args = _numbers(circle)[2:].reshape(-1, 7)
    assert np.allclose(args[:, :2], 5) and np.allclose(args[-1, 5:], [6, -2])
    args = _numbers(arc)[2:].reshape(-1, 7)
    assert np.allclose(args[:, :2], 3) and np.all(args[:, 4] == 0)  # CCW: y flipped on the page
    end = np.radians(200)
    assert np.allclose(args[-1, 5:], [3 * np.cos(end), -3 * np.sin(end)], atol=1e-6)
    assert " L " in tilted and " A " not in tilted  # not a circle in the drawing: a polyline
    doc = ezdxf.readfile(out["dxf"])
    assert not doc.audit().has_errors
    for spline, (centre, r) in zip(
        doc.modelspace().query("SPLINE"), [([1, 2, 0], 5), ([0, 0, 0], 3)], strict=True
    ):
        pts = np.array(list(spline.construction_tool().points(np.linspace(0, 1, 501))))
        assert np.abs(np.linalg.norm(pts - centre, axis=1) - r).max() < 1e-9


def test_curves_in_bezier_form_are_read_off_their_control_points():
    # glyph outlines and rounded rectangles are in Bezier form already: the drawing path
    # takes their pieces without knot insertion, the same pieces as A5.6 gives
    import formgraph as fg
    from formgraph.kernels import nurbs as kn
    from formgraph.nodes.export.drawing import _bezier_form

    g = fg.Graph()
    g.add("t", "curves.text", text="gS8")
    g.add("r", "curves.rectangle", size=[8, 3], radius=1)
    rect = g.evaluate("r")
    cubic = fg.NurbsCurve(
        np.random.default_rng(3).normal(size=(7, 3)), 3, kn.clamped_uniform_knots(7, 3)
    )
    for c in [*g.evaluate("t"), rect]:
        cp = np.asarray(c.control_points)
        ours = _bezier_form(cp, c.degree, np.asarray(c.knots))
        ref, _ = kn.decompose_bezier(cp, c.degree, c.knots, None)
        np.testing.assert_array_equal(ours, ref)
        assert c.closed == fg.Curve.closed.fget(c)  # the clamped shortcut agrees
    assert _bezier_form(np.asarray(cubic.control_points), 3, np.asarray(cubic.knots)) is None
    assert cubic.closed is False and fg.Curve.closed.fget(cubic) is False
