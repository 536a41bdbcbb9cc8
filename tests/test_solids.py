"""Solid nodes (nodes/mesh/), curves.measure, Mesh measures, poles, run --strict."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from tools import admesh, cli

import formgraph as fg
from formgraph.core.errors import BudgetError
from formgraph.kernels.io import mesh_report

ROOT = Path(__file__).resolve().parents[1]


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n"), g.stats["n"].warnings


def tm(mesh: fg.Mesh) -> trimesh.Trimesh:
    from formgraph.kernels.mesh.meshops import triangulate

    v, fi, _ = triangulate(mesh.vertices, mesh.face_indices, mesh.face_offsets)
    return trimesh.Trimesh(v, fi.reshape(-1, 3), process=False)


def is_solid(mesh: fg.Mesh) -> bool:
    t = tm(mesh)
    return mesh.is_watertight and t.is_watertight and t.is_winding_consistent and t.volume > 0


# ------------------------------------------------------------------------------ primitives


@pytest.mark.parametrize(
    "node_type,inputs",
    [
        ("mesh.cylinder", {"radius": 1, "height": 2}),
        ("mesh.sphere", {"radius": 1.5, "center": [1, 2, 3]}),
        ("mesh.torus", {"major": 2, "minor": 0.5}),
    ],
)
def test_closed_primitives_are_solid(node_type, inputs):
    m, _ = run(node_type, **inputs)
    assert is_solid(m) and m.euler_characteristic == (0 if node_type == "mesh.torus" else 2)
    assert m.volume == pytest.approx(tm(m).volume, rel=1e-12)


def test_cylinder_without_caps_and_plane_are_open():
    tube, _ = run("mesh.cylinder", radius=1, height=2, segments=12, caps=False)
    assert not tube.is_watertight and tube.n_faces == 12
    sheet, _ = run("mesh.plane", size=[2, 3], divisions=[4, 6])
    assert sheet.n_faces == 24 and sheet.area == pytest.approx(6.0)
    np.testing.assert_allclose(sheet.bounds, [[-1, -1.5, 0], [1, 1.5, 0]])


def test_primitive_errors_name_the_input():
    with pytest.raises(fg.GraphError, match=r"input 'radius'.*must be >= 0"):
        run("mesh.sphere", radius=-1)
    with pytest.raises(fg.NodeError, match=r"input 'minor'.*must be smaller than major"):
        run("mesh.torus", major=1, minor=2)
    with pytest.raises(fg.NodeError, match=r"input 'size'.*size takes \[width, depth\]"):
        run("mesh.plane", size=[1, 2, 3])


# ---------------------------------------------------------------------------------- repair


def test_weld_orient_cap_make_a_soup_of_an_open_tube_solid(tmp_path):
    tube, _ = run("mesh.cylinder", radius=1, height=3, segments=24, caps=False)
    tris, _ = run("mesh.triangulate", mesh=tube)
    v = tris.vertices[tris.face_indices]  # an STL-like soup, every other face flipped
    fi = np.arange(v.shape[0]).reshape(-1, 3)
    fi[::2] = fi[::2, ::-1]
    soup = fg.Mesh(v, fi.reshape(-1), np.arange(0, fi.size + 1, 3))
    g = fg.Graph(out_dir=tmp_path)
    g.add("w", "mesh.weld", mesh=soup)
    g.add("o", "mesh.orient", mesh="@w")
    g.add("c", "mesh.cap", mesh="@o")
    g.add("m", "mesh.measure", mesh="@c")
    g.add("f", "export.stl", mesh="@c", path="tube.stl")
    out = g.evaluate(["c", "m", "f"])
    assert is_solid(out["c"])
    assert out["m"].watertight and out["m"].faces == out["c"].n_faces
    assert out["m"].volume == pytest.approx(24 / 2 * np.sin(2 * np.pi / 24) * 3, rel=1e-12)
    np.testing.assert_allclose(out["m"].size, [2, 2 * np.sin(np.pi * 6 / 12), 3], atol=1e-12)
    assert g.stats["f"].warnings == []
    if shutil.which("admesh"):
        a = admesh(Path(out["f"]))
        assert a["open"] == 0 and a["Number of parts"] == 1 and a["Volume"] > 0
        for name in ("Edges fixed", "Facets reversed", "Backwards edges", "Facets added"):
            assert a[name] == 0, name


def test_orient_turns_an_inward_grid_outward():
    # rows built bottom-up: every face points inward
    g = fg.Graph()
    g.add("t", "mesh.torus", major=2, minor=0.5, segments_u=16, segments_v=8)
    g.add("inside_out", "mesh.flip", mesh="@t")
    g.add("o", "mesh.orient", mesh="@inside_out")
    out = g.evaluate(["inside_out", "o"])
    assert out["inside_out"].volume < 0 < out["o"].volume
    assert is_solid(out["o"])


def test_weld_warns_about_collapsed_faces():
    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1e-9, 0, 0], [0, 0, 1]]
    m = fg.Mesh(v, [[0, 1, 2], [0, 3, 4]])
    out, warnings = run("mesh.weld", mesh=m, tolerance=1e-6)
    assert out.n_faces == 1 and out.n_vertices == 3  # vertex 4 is no longer used
    assert warnings == ["1 faces collapsed and were dropped"]


def test_cap_asks_for_orient_on_misoriented_input():
    m = fg.Mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3][::-1]])
    with pytest.raises(fg.NodeError, match=r"input 'mesh'.*inconsistent orientation.*mesh.orient"):
        run("mesh.cap", mesh=m)


def test_solidify_node_thickness_from_a_param():
    g = fg.Graph()
    g.add_param("wall", 0.2)
    g.add("p", "mesh.plane", size=[2, 2], divisions=[3, 3])
    g.add("s", "mesh.solidify", mesh="@p", thickness="=wall", offset=1)
    s = g.evaluate("s")
    assert is_solid(s) and s.volume == pytest.approx(0.8, rel=1e-12)
    with pytest.raises(fg.GraphError, match=r"input 'offset'.*must be <= 1"):
        run("mesh.solidify", mesh=s, thickness=0.1, offset=2)


# -------------------------------------------------------------------------------- booleans


def test_boolean_node_and_union(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("a", "mesh.box", size=2)
    g.add("b", "mesh.sphere", radius=1.2, segments=48)
    g.add("d", "mesh.boolean", a="@a", b="@b", operation="difference")
    g.add("i", "mesh.boolean", a="@a", b="@b", operation="intersection")
    g.add("u", "mesh.union", meshes=["@a", "@b"])
    g.add("f", "export.stl", mesh="@d", path="d.stl")
    out = g.evaluate(["d", "i", "u", "f"])
    for k in "diu":
        assert is_solid(out[k]), k
    vb = g.evaluate("b").volume
    assert out["d"].volume + out["i"].volume == pytest.approx(8.0, rel=1e-9)
    assert out["u"].volume == pytest.approx(8.0 + vb - out["i"].volume, rel=1e-9)
    if shutil.which("admesh"):
        a = admesh(Path(out["f"]))
        assert a["open"] == 0 and a["Edges fixed"] == 0 and a["Facets reversed"] == 0
        assert a["Volume"] == pytest.approx(out["d"].volume, rel=1e-5)


def test_boolean_refuses_an_open_mesh_with_a_sentence():
    g = fg.Graph()
    g.add("a", "mesh.cylinder", radius=1, height=1, segments=8, caps=False)
    g.add("b", "mesh.box")
    g.add("d", "mesh.boolean", a="@b", b="@a", operation="difference")
    with pytest.raises(
        fg.NodeError,
        match=r"node 'd', input 'b' \(mesh.boolean\): the mesh is not a closed solid: it has 16 "
        r"open edges \(e.g. edge \d+-\d+ at \(.*\)\); mesh.weld joins duplicate vertices, "
        r"mesh.cap closes open loops",
    ):
        g.evaluate("d")


def test_empty_intersection_warns():
    g = fg.Graph()
    g.add("a", "mesh.box")
    g.add("b", "mesh.box", center=[5, 0, 0])
    g.add("i", "mesh.boolean", a="@a", b="@b", operation="intersection")
    assert g.evaluate("i").n_faces == 0
    assert g.stats["i"].warnings == ["the intersection is empty"]


def test_operation_must_be_one_of_the_options():
    with pytest.raises(fg.GraphError, match="'xor' is not a valid option, must be one of"):
        run("mesh.boolean", a=run("mesh.box")[0], b=run("mesh.box")[0], operation="xor")


# -------------------------------------------------------------------------------- measures


def test_mesh_measure_of_an_open_mesh_warns_and_gives_no_volume():
    sheet, _ = run("mesh.plane", size=[2, 1])
    m, warnings = run("mesh.measure", mesh=sheet)
    assert (m.area, m.volume, m.watertight, m.faces) == (2.0, 0.0, False, 1)
    assert m.center == [0, 0, 0] and m.size == [2, 1, 0]
    assert warnings == ["mesh is not watertight (4 open or non-manifold edges): volume 0"]


def test_mesh_properties_are_cached_and_read_only():
    m, _ = run("mesh.sphere", radius=1)
    assert m.bounds is m.bounds and not m.bounds.flags.writeable
    assert m.area == pytest.approx(tm(m).area, rel=1e-12)


def test_curves_measure_a_circle_a_square_a_helix_and_an_open_arc():
    c, _ = run("curves.measure", curve=run("nurbs.circle", radius=2)[0])
    assert c.length == pytest.approx(4 * np.pi, rel=1e-12)
    assert c.area == pytest.approx(4 * np.pi, rel=1e-12) and c.closed
    sq = run("curves.polyline", points=[[0, 0], [2, 0], [2, 1], [0, 1]], closed=True)[0]
    s, _ = run("curves.measure", curve=sq)
    assert (s.length, s.closed) == (6.0, True) and s.area == pytest.approx(2.0, rel=1e-14)
    g = fg.Graph()
    g.add("h", "curves.parametric", x="cos(t)", y="sin(t)", z="t", t=[0, 4 * np.pi])
    g.add("m", "curves.measure", curve="@h")
    h = g.evaluate("m")
    # (a parametric curve's tangents are central differences: about 1e-9 relative)
    assert h.length == pytest.approx(4 * np.pi * np.sqrt(2), rel=1e-8) and h.area == 0.0
    assert not h.closed
    arc = run("nurbs.arc", radius=1, start=0, end=90)[0]
    a, _ = run("curves.measure", curve=arc)
    assert a.length == pytest.approx(np.pi / 2, rel=1e-12) and a.area == 0.0


def test_a_closed_curve_that_is_not_planar_has_no_area():
    pts = [[0, 0, 0], [1, 0, 0], [1, 1, 1], [0, 1, 0]]
    m, _ = run("curves.measure", curve=run("curves.polyline", points=pts, closed=True)[0])
    assert m.closed and m.area == 0.0


# ----------------------------------------------------------------------------------- poles


def test_a_revolve_to_the_axis_collapses_its_poles():
    g = fg.Graph()
    g.add("half", "nurbs.arc", radius=1, start=90, end=-90, center=[0, 0, 0])
    g.add("s", "nurbs.revolve", curve="@half", axis=[0, 1, 0])  # the arc lies in xy
    g.add("m", "nurbs.tessellate", surface="@s", u=16, v=32)
    g.add("x", "mesh.measure", mesh="@m")
    m = g.evaluate("m")
    r = mesh_report(m.vertices, m.face_indices, m.face_offsets)
    assert r.degenerate_triangles == 0 and m.is_watertight and m.euler_characteristic == 2
    assert m.n_vertices == 15 * 32 + 2
    assert (m.face_sizes == 3).sum() == 64
    assert is_solid(m)


# ------------------------------------------------------------------------------ --strict


def test_run_strict_turns_warnings_into_exit_1(tmp_path):
    p = tmp_path / "g.yaml"
    p.write_text(
        "formgraph: 1\nnodes:\n  s: {type: mesh.plane}\n"
        "  f: {type: export.stl, mesh: '@s', path: s.stl}\n"
    )
    loose = cli("run", str(p), "--out", str(tmp_path / "o"), "--no-cache")
    assert loose.returncode == 0 and "warning: mesh is not watertight" in loose.stderr
    strict = cli("run", str(p), "--out", str(tmp_path / "o"), "--no-cache", "--strict")
    assert strict.returncode == 1
    assert "error: mesh is not watertight" in strict.stderr
    assert "--strict: 1 warning (see above)" in strict.stderr


def test_quick_start_prints_no_warning(tmp_path):
    r = cli("run", str(ROOT / "graphs" / "spiral_tube.yaml"), "--out", str(tmp_path), "--strict")
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""


def test_primitives_refuse_a_size_over_the_budget_before_allocating():
    with pytest.raises(BudgetError, match=r"would make 500,000,000,000 faces, over the budget"):
        run("mesh.sphere", radius=1, segments=1_000_000)
    with pytest.raises(BudgetError, match=r"over the budget"):
        run("mesh.plane", divisions=[100_000, 100_000])


def test_boolean_refuses_an_inside_out_mesh():
    g = fg.Graph()
    g.add("box", "mesh.box", size=2)
    g.add("inside_out", "mesh.flip", mesh="@box")
    g.add("d", "mesh.boolean", a="@inside_out", b="@box")
    with pytest.raises(
        fg.NodeError,
        match=r"input 'a' \(mesh.boolean\): the mesh is inside out \(its volume is -8\); "
        r"mesh.orient turns it outward",
    ):
        g.evaluate("d")


def test_solidify_with_a_thickness_map():
    g = fg.Graph()
    g.add("p", "mesh.plane", size=[2, 2], divisions=[4, 4])
    g.add("s", "mesh.solidify", mesh="@p", thickness=0.1, thickness_map="thickness * (2 + x)")
    s = g.evaluate("s")
    # linear in x over each quad: the volume is the integral of 0.1 (2 + x) over the sheet
    assert is_solid(s) and s.volume == pytest.approx(0.8, rel=1e-12)
    g.set_input("s", "thickness_map", "thickness * x")
    with pytest.raises(
        fg.NodeError, match=r"input 'thickness_map'.*'thickness \* x' gives -0.1 at vertex 0"
    ):
        g.evaluate("s")


def test_empty_meshes_get_sentences_not_tracebacks():
    empty = fg.Mesh(np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(1, np.int64))
    with pytest.raises(fg.NodeError, match="input 'mesh'.*the surface has no faces to thicken"):
        run("mesh.solidify", mesh=empty, thickness=0.1)
    with pytest.raises(fg.NodeError, match="input 'a'.*the mesh has no faces"):
        run("mesh.boolean", a=empty, b=empty)
    m, warnings = run("mesh.measure", mesh=empty)
    assert (m.faces, m.area, m.watertight) == (0, 0.0, False)
    assert warnings == ["mesh has no faces: area and volume 0"]


@settings(max_examples=40, deadline=None)
@given(st.integers(4, 12), st.lists(st.tuples(*[st.integers(0, 11)] * 3), min_size=1, max_size=30))
def test_random_triangle_soups_never_crash_the_solid_nodes(n, tris):
    rng = np.random.default_rng(n)
    v = rng.random((n, 3))
    faces = [list(t) for t in tris if len({x % n for x in t}) == 3]
    if not faces:
        return
    mesh = fg.Mesh(v, [[x % n for x in f] for f in faces])
    for node_type in ("mesh.weld", "mesh.orient", "mesh.cap", "mesh.solidify", "mesh.measure"):
        extra = {"thickness": 0.05} if node_type == "mesh.solidify" else {}
        try:
            run(node_type, mesh=mesh, **extra)
        except fg.NodeError as exc:  # a sentence naming the input, never a numpy traceback
            assert "input 'mesh'" in str(exc), str(exc)
    try:
        out, _ = run("mesh.boolean", a=mesh, b=run("mesh.box")[0])
        assert out.n_faces == 0 or out.is_watertight
    except fg.NodeError as exc:
        assert "input 'a'" in str(exc) and "not" in str(exc), str(exc)


def test_orient_warns_about_a_one_sided_mesh():
    n = 16
    t = 2 * np.pi * np.arange(n) / n
    centre = np.stack([np.cos(t), np.sin(t), np.zeros(n)], 1)
    width = np.stack([np.cos(t / 2) * np.cos(t), np.cos(t / 2) * np.sin(t), np.sin(t / 2)], 1)
    v = np.concatenate([centre - 0.2 * width, centre + 0.2 * width])
    faces = [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n - 1)]
    faces.append([n - 1, n, 0, 2 * n - 1])  # the half twist
    _, warnings = run("mesh.orient", mesh=fg.Mesh(v, faces))
    assert warnings == [
        "part of the mesh cannot be oriented (it is one-sided, like a Moebius strip): "
        "faces still disagree across 1 of its edges"
    ]
