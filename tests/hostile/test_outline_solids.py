"""Hostile use of the solids from outlines, parts and bounds (issue 34): open and tilted
outlines, regions of no area, twists and scales that would make a solid cross itself,
planes that miss, Minkowski sums past the budget, flat hulls, NaN, inf and empty lists.
Each case ends as a located sentence (file, line, node, input), a warning, or a result."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import time

import numpy as np
import pytest

import formgraph as fg

SQUARE = "{type: curves.rectangle, size: [10, 10]}"


def _graph(text: str, budget: int | None = None) -> fg.Graph:
    kw = {} if budget is None else {"budget": budget}
    return fg.Graph.from_text("formgraph: 1\nnodes:\n" + text, file="h.yaml", **kw)


def _extrude(extra: str, curves: str = '["@sq"]') -> fg.Graph:
    return _graph(f"  sq: {SQUARE}\n  e: {{type: mesh.extrude, curves: {curves}, {extra}}}\n")


# ----------------------------------------------------------------------------- outlines


def test_an_open_outline_is_refused_naming_the_curve():
    g = _graph(
        "  arc: {type: nurbs.interpolate, points: [[0, 0], [1, 1], [2, 0]]}\n"
        "  e: {type: mesh.extrude, curves: ['@arc'], height: 1}\n"
    )
    with pytest.raises(fg.NodeError, match=r"h.yaml:4: node 'e', input 'curves'.*curve 0 is open"):
        g.evaluate("e")


def test_a_tilted_outline_warns_that_its_projection_is_extruded():
    g = _graph(
        "  c: {type: nurbs.circle, radius: 2, normal: [1, 0, 1]}\n"
        "  e: {type: mesh.extrude, curves: ['@c'], height: 1}\n"
    )
    with pytest.warns(fg.FormgraphWarning, match="not parallel to the XY plane"):
        m = g.evaluate("e")
    assert m.is_watertight and m.volume > 0


@pytest.mark.parametrize("kind", ["mesh.extrude", "mesh.revolve"])
def test_a_region_of_no_area_is_refused(kind):
    extra = "height: 1" if kind == "mesh.extrude" else "angle: 90"
    g = _graph(
        "  sq: {type: curves.rectangle, size: [1, 1], center: [2, 0, 0]}\n"
        f"  e: {{type: {kind}, curves: ['@sq', '@sq'], {extra}}}\n"
    )
    with pytest.raises(fg.NodeError, match=r"h.yaml:4: node 'e', input 'curves'.*no area"):
        g.evaluate("e")


def test_no_curves_and_a_curve_of_one_point_are_refused():
    with pytest.raises(fg.NodeError, match=r"input 'curves'.*got none"):
        _extrude("height: 1", curves="[]").evaluate("e")
    dot = fg.NurbsCurve([[1, 1], [1, 1], [1, 1], [1, 1]], 1, [0, 0, 1, 2, 3, 3])
    g = fg.Graph()
    g.add("e", "mesh.extrude", curves=[dot], height=1)
    with pytest.raises(fg.NodeError, match=r"input 'curves'.*encloses no area"):
        g.evaluate("e")


# ----------------------------------------------------------------------- twist and scale


@pytest.mark.parametrize(
    ("extra", "port", "words"),
    [
        ("height: 0", "height", "height must be > 0"),
        ("height: -2", "height", "height must be > 0"),
        ("height: .nan", "height", "finite"),
        ("height: .inf", "height", "finite"),
        ("height: 1, twist: .nan", "twist", "finite"),
        ("height: 1, scale: -0.5", "scale", "self-intersecting"),
        ("height: 1, scale: [1, -1]", "scale", "self-intersecting"),
        ("height: 1, scale: [0, 1]", "scale", "knife edge"),
        ("height: 1, scale: [1, 2, 3]", "scale", "one number or"),
        ("height: 1, twist: 720, slices: 4", "slices", "intersect itself"),
    ],
)
def test_bad_heights_twists_and_scales_are_located_sentences(extra, port, words):
    with pytest.raises(
        (fg.NodeError, fg.GraphError), match=rf"h.yaml:\d+: node 'e', input '{port}'.*{words}"
    ):
        _extrude(extra).evaluate("e")


def test_a_huge_twist_is_over_the_budget_before_anything_is_made():
    t0 = time.process_time()
    with pytest.raises(fg.BudgetError, match=r"node 'e'.*over the budget"):
        _extrude("height: 1, twist: 1e9").evaluate("e")
    assert time.process_time() - t0 < 30  # (refused, not built: no timing claim beyond that)


def test_a_tolerance_finer_than_double_precision_is_refused():
    g = _graph(
        "  c: {type: nurbs.circle, radius: 1}\n"
        "  e: {type: mesh.extrude, curves: ['@c'], height: 1, tolerance: 1e-300}\n"
    )
    with pytest.raises(fg.NodeError, match=r"input 'tolerance'.*finer than double precision"):
        g.evaluate("e")


# ------------------------------------------------------------------------------ revolve


def test_a_profile_across_the_axis_is_refused():
    g = _graph(
        "  sq: {type: curves.rectangle, size: [2, 2]}\n  r: {type: mesh.revolve, curves: ['@sq']}\n"
    )
    with pytest.raises(fg.NodeError, match=r"h.yaml:4: node 'r', input 'curves'.*x >= 0"):
        g.evaluate("r")


@pytest.mark.parametrize(
    ("extra", "port", "error"),
    [
        ("angle: 0", "angle", fg.NodeError),
        ("angle: 400", "angle", fg.GraphError),
        ("angle: .nan", "angle", fg.GraphError),
        ("segments: 2", "segments", fg.NodeError),
        ("segments: 1000000000000", "r", fg.BudgetError),
    ],
)
def test_bad_angles_and_segments(extra, port, error):
    where = "node 'r'" if port == "r" else f"node 'r', input '{port}'"
    with pytest.raises(error, match=rf"h.yaml:4: {where}"):
        _graph(
            "  sq: {type: curves.rectangle, size: [2, 2], center: [2, 0, 0]}\n"
            f"  r: {{type: mesh.revolve, curves: ['@sq'], {extra}}}\n"
        ).evaluate("r")


# ------------------------------------------------------------------------- slice, split


def test_a_plane_that_misses_is_an_empty_list_and_a_warning():
    g = _graph(
        "  b: {type: mesh.box, size: [1, 1, 1]}\n"
        "  s: {type: mesh.slice, mesh: '@b', height: 7, axis: y}\n"
    )
    with pytest.warns(fg.FormgraphWarning, match=r"node 's'.*plane y = 7 misses the mesh"):
        assert g.evaluate("s") == []


@pytest.mark.parametrize("h", [".nan", ".inf", "-.inf"])
def test_a_plane_at_nan_or_infinity_is_refused(h):
    with pytest.raises(fg.GraphError, match=r"h.yaml:4: node 's', input 'height'.*finite"):
        _graph(
            "  b: {type: mesh.box, size: [1, 1, 1]}\n"
            f"  s: {{type: mesh.slice, mesh: '@b', height: {h}}}\n"
        ).evaluate("s")


def test_slicing_and_splitting_nothing_warns():
    empty = fg.Mesh(np.zeros((0, 3)), np.zeros(0), [0])
    for kind in ("mesh.slice", "mesh.split", "mesh.project"):
        g = fg.Graph()
        g.add("n", kind, mesh=empty)
        with pytest.warns(fg.FormgraphWarning, match="no faces"):
            assert g.evaluate("n") == []


def test_an_axis_that_is_not_one_is_refused_with_the_choices():
    with pytest.raises(fg.GraphError, match=r"h.yaml:4: node 's', input 'axis'.*'x', 'y', 'z'"):
        _graph("  b: {type: mesh.box}\n  s: {type: mesh.slice, mesh: '@b', axis: w}\n")


# ------------------------------------------------------------------------------- hulls


@pytest.mark.parametrize(
    ("points", "words"),
    [
        ("[[0, 0, 0], [1, 0, 0], [0, 1, 0]]", "3 point"),
        ("[[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [3, 2, 0]]", "lie in one plane"),
        ("[[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]]", "lie in one plane"),
    ],
)
def test_a_hull_of_points_spanning_no_volume_is_refused(points, words):
    g = _graph(
        f"  p: {{type: points.list, points: {points}}}\n  h: {{type: mesh.hull, geometry: '@p'}}\n"
    )
    with pytest.raises(
        fg.NodeError, match=rf"h.yaml:4: node 'h', input 'geometry'.*{words}.*curves.hull"
    ):
        g.evaluate("h")


def test_a_flat_hull_of_collinear_points_is_refused():
    g = _graph(
        "  p: {type: points.list, points: [[0, 0], [1, 1], [2, 2], [5, 5]]}\n"
        "  h: {type: curves.hull, geometry: '@p'}\n"
    )
    with pytest.raises(fg.NodeError, match=r"h.yaml:4: node 'h', input 'geometry'.*one line"):
        g.evaluate("h")


def test_a_hull_of_a_surface_or_of_nothing_is_refused():
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=1)
    g.add("s", "nurbs.extrude", curve="@c", direction=[0, 0, 1])
    g.add("h", "mesh.hull", geometry="@s")
    with pytest.raises(fg.NodeError, match=r"input 'geometry'.*got a NurbsSurface.*tessellate"):
        g.evaluate("h")
    g.add("n", "mesh.hull", geometry=[])
    with pytest.raises(fg.NodeError, match=r"input 'geometry'.*no points"):
        g.evaluate("n")


def test_hull_points_are_budgeted():
    g = fg.Graph(budget=1000)
    g.add("c", "nurbs.circle", radius=1)
    g.add("h", "mesh.hull", geometry="@c", tolerance=1e-12)
    with pytest.raises(fg.BudgetError, match="node 'h'.*points, over the budget"):
        g.evaluate("h")


# ---------------------------------------------------------------------------- minkowski


def test_a_minkowski_sum_past_the_budget_is_refused_before_it_runs():
    g = fg.Graph(budget=100_000)
    g.add("t", "mesh.torus", major=2, minor=0.5)  # not convex
    g.add("s", "mesh.sphere", radius=0.2, segments=32)
    g.add("m", "mesh.minkowski", a="@t", b="@s")
    t0 = time.process_time()
    with pytest.raises(fg.BudgetError, match=r"node 'm'.*elements of Minkowski hulls"):
        g.evaluate("m")
    assert time.process_time() - t0 < 30  # refused at once, not after minutes of hulls


def test_minkowski_of_an_open_mesh_names_the_input():
    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("p", "mesh.plane", size=[1, 1])
    g.add("m", "mesh.minkowski", a="@b", b="@p")
    with pytest.raises(fg.NodeError, match=r"node 'm', input 'b'.*not a closed solid"):
        g.evaluate("m")


# ------------------------------------------------------------------------- bounds, fit


def test_bounds_of_nothing_and_of_a_field_are_refused():
    g = fg.Graph()
    g.add("b", "geometry.bounds", geometry=[])
    with pytest.raises(fg.NodeError, match=r"input 'geometry'.*nothing to bound"):
        g.evaluate("b")
    g.add("f", "field.sphere", radius=1)
    g.add("bf", "geometry.bounds", geometry="@f")
    with pytest.raises(fg.NodeError, match=r"input 'geometry'.*Field has no exact extent"):
        g.evaluate("bf")
    g.add("e", "geometry.bounds", geometry=fg.Points(np.zeros((0, 3))))
    with pytest.raises(fg.NodeError, match=r"input 'geometry'.*no points"):
        g.evaluate("e")


@pytest.mark.parametrize(
    ("size", "words"),
    [
        ("[0, 0]", "every size is 0"),
        ("[0, 0, 5]", "flat along every axis given a size"),
        ("[1, -1]", "finite number >= 0"),
        ("[1, .nan]", "finite"),
        ("[1]", "width, height"),
    ],
)
def test_fit_into_a_box_that_cannot_hold_it(size, words):
    with pytest.raises(
        (fg.NodeError, fg.GraphError), match=rf"h.yaml:4: node 'f', input 'size'.*{words}"
    ):
        _graph(
            "  t: {type: curves.text, text: 'Hi', size: 5}\n"
            f"  f: {{type: geometry.fit, geometry: '@t', size: {size}}}\n"
        ).evaluate("f")


def test_a_spline_with_huge_coordinates_still_gets_a_finite_box():
    c = fg.NurbsCurve([[0, 0, 0], [1e150, 1e150, 0], [2e150, 0, 0]], 2, [0, 0, 0, 1, 1, 1])
    g = fg.Graph()
    g.add("b", "geometry.bounds", geometry=c)
    out = g.evaluate("b")
    assert all(math.isfinite(x) for x in out.max)
    assert out.max[1] == pytest.approx(0.5e150, rel=1e-9)


# ------------------------------------------------------------- the audit of issue 34

BOW_TIE = "{type: curves.polyline, points: [[0, 0], [10, 10], [10, 0], [0, 10]], closed: true}"


def _triangles(m: fg.Mesh) -> tuple[np.ndarray, np.ndarray]:
    from formgraph.kernels.mesh.meshops import triangulate

    v, fi, _ = triangulate(m.vertices, m.face_indices, m.face_offsets)
    return v, fi.reshape(-1, 3)


def test_a_bow_tie_is_two_parts_touching_along_an_edge_as_slicers_count_them(tmp_path):
    """Two prisms sharing one vertical edge (four faces on it once welded): two parts, not
    watertight, split into two closed solids of 25 each; trimesh and admesh agree."""
    import trimesh
    from tools import admesh

    g = _graph(
        f"  c: {BOW_TIE}\n"
        "  e: {type: mesh.extrude, curves: ['@c'], height: 1}\n"
        "  m: {type: mesh.measure, mesh: '@e'}\n"
        "  s: {type: mesh.split, mesh: '@e'}\n"
    )
    with pytest.warns(fg.FormgraphWarning, match=r"node 'e'.*touch at 1 point.*\(5, 5\)"):
        e = g.evaluate("e")
    with pytest.warns(fg.FormgraphWarning, match=r"node 'm'.*1 edge\(s\) lie on more than two"):
        m = g.evaluate("m")
    assert (m.parts, m.watertight, m.volume) == (2, False, pytest.approx(50))
    parts = g.evaluate("s")
    assert [p.is_watertight for p in parts] == [True, True]
    assert [p.volume for p in parts] == pytest.approx([25, 25])
    ref = trimesh.Trimesh(*_triangles(e))  # welded, as trimesh loads it
    assert not ref.is_watertight
    assert len(ref.split(only_watertight=False)) == 2
    path = tmp_path / "bow.stl"
    ref.export(path)
    if shutil.which("admesh"):
        assert admesh(path)["Number of parts"] == 2
    if shutil.which("prusa-slicer"):
        info = subprocess.run(
            ["prusa-slicer", "--info", str(path)], capture_output=True, text=True, timeout=120
        ).stdout
        assert re.search(r"number_of_parts\s*=\s*2", info)


def test_a_fin_on_a_box_is_its_own_open_part_and_the_box_stays_closed():
    """An edge on three faces joins none of them: the box (two of them) stays one closed
    part, the fin (one) is an open part, as trimesh splits it."""
    import trimesh

    box = trimesh.creation.box()
    v = np.vstack([box.vertices, [[0.5, 0.5, 1.5]]])
    edge = next(e for e in box.edges_unique if np.ptp(box.vertices[e][:, 0]) == 1.0)
    fin = [[edge[0], edge[1], len(v) - 1]]
    mesh = fg.Mesh(v, np.vstack([box.faces, fin]))
    g = fg.Graph()
    g.add("m", "mesh.measure", mesh=mesh)
    g.add("s", "mesh.split", mesh=mesh)
    with pytest.warns(fg.FormgraphWarning, match="not watertight"):
        m = g.evaluate("m")
    assert (m.parts, m.watertight) == (2, False)
    parts = g.evaluate("s")
    assert [(p.n_faces, p.is_watertight) for p in parts] == [(12, True), (1, False)]
    ref = trimesh.Trimesh(v, np.vstack([box.faces, fin])).split(only_watertight=False)
    assert sorted(len(r.faces) for r in ref) == [1, 12]


def test_a_revolved_region_touching_itself_off_the_axis_warns():
    g = _graph(
        "  a: {type: curves.rectangle, size: [1, 1], center: [1.5, 0.5, 0]}\n"
        "  b: {type: curves.rectangle, size: [1, 1], center: [2.5, 1.5, 0]}\n"
        "  r: {type: mesh.revolve, curves: ['@a', '@b'], segments: 16}\n"
        "  s: {type: mesh.split, mesh: '@r'}\n"
    )
    with pytest.warns(fg.FormgraphWarning, match=r"node 'r'.*touch at 1 point.*\(2, 1\)"):
        assert [p.is_watertight for p in g.evaluate("s")] == [True, True]


def test_the_shadow_of_an_upright_plane_is_nothing_and_a_warning():
    g = fg.Graph()
    g.add("p", "mesh.plane", size=[1, 1])
    g.add("r", "geometry.transform", geometry="@p", rotate=[90, 0, 0])  # cos 90 != 0
    g.add("s", "mesh.project", mesh="@r")
    with pytest.warns(fg.FormgraphWarning, match=r"node 's'.*shadow has no area.*edge-on"):
        assert g.evaluate("s") == []


@pytest.mark.parametrize("turn", [[90, 0, 0], [45, 0, 0], [0, 0, 30], [30, 0, 45]])
def test_the_shadow_of_a_turned_box_has_no_repeated_or_collinear_points(turn):
    """Its outline is the convex hull of its corners' shadows (scipy): exactly the hull's
    points, each once, none on the line through its neighbours."""
    from scipy.spatial import ConvexHull

    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("r", "geometry.transform", geometry="@b", rotate=turn)
    g.add("s", "mesh.project", mesh="@r")
    (loop,) = g.evaluate("s")
    pts = loop.control_points[:-1, :2]
    corners = g.evaluate("r").vertices[:, :2]
    hull = corners[ConvexHull(corners).vertices]
    assert len(pts) == len(hull)
    assert np.abs(pts[:, None] - hull[None]).max(axis=2).min(axis=1).max() < 1e-12


def test_a_drilled_block_sliced_beside_its_hole_is_a_rectangle_of_four_corners():
    """The section along x beside the hole cuts the top and bottom faces across the
    triangles fanned from the hole: 4 corners, exactly at the block's, not hundreds of
    collinear points; through the hole the sampled circle's points stay (each off its
    neighbours' chord by the polygon's sagitta, far above 1e-9)."""
    import shapely

    g = _graph(
        "  blk: {type: mesh.box, size: [40, 20, 10]}\n"
        "  cyl: {type: mesh.cylinder, radius: 4, height: 30, segments: 200}\n"
        "  d: {type: mesh.boolean, a: '@blk', b: '@cyl', operation: difference}\n"
        "  x: {type: mesh.slice, mesh: '@d', axis: x, height: 10}\n"
        "  z: {type: mesh.slice, mesh: '@d', height: 0}\n"
    )
    (rect,) = g.evaluate("x")
    corners = {tuple(p) for p in rect.control_points[:-1, 1:].tolist()}
    assert corners == {(-10.0, -5.0), (10.0, -5.0), (10.0, 5.0), (-10.0, 5.0)}
    outer, hole = g.evaluate("z")
    assert len(outer.control_points) == 5 and len(hole.control_points) == 201
    area = shapely.Polygon(outer.control_points[:, :2], [hole.control_points[:, :2]]).area
    assert area == pytest.approx(800 - 100 * 4**2 * math.sin(2 * math.pi / 200), rel=1e-12)


def test_dropping_collinear_points_keeps_arcs_and_corners_exactly():
    """Douglas-Peucker within a tolerance: a fine arc keeps a point wherever dropping it
    would move the loop by more than the tolerance; every kept point is an input point;
    a loop of no width goes."""
    from formgraph.kernels.mesh.section import drop_collinear

    t = np.linspace(0, 2 * np.pi, 20001)[:-1]
    circle = np.c_[np.cos(t), np.sin(t)]
    flat = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 1e-12], [1.0, 0.0]])
    square = np.array([[0, 0], [0.5, 0], [1, 0], [1, 1 - 1e-17], [1, 1], [0, 1], [0, 0.5]])
    xy = np.r_[flat, circle, square].astype(float)
    out, off = drop_collinear(xy, np.array([0, 4, 20004, 20011]), 1e-6)
    assert np.diff(off).tolist()[1] == 4
    assert out[off[1] :].tolist() == [[0, 0], [1, 0], [1, 1 - 1e-17], [0, 1]]
    arc = out[: off[1]]
    assert set(map(tuple, arc.tolist())) <= set(map(tuple, circle.tolist()))
    # every dropped point within the tolerance of the chord between the kept ones
    k = np.flatnonzero((circle[:, None] == arc[None]).all(axis=2).any(axis=1))
    for a, b in zip(k, np.r_[k[1:], k[0] + len(circle)], strict=True):
        mid = circle[np.arange(a + 1, b) % len(circle)]
        p, q = circle[a], circle[b % len(circle)]
        w, u = mid - p, q - p
        d = np.abs(u[0] * w[:, 1] - u[1] * w[:, 0]) / np.hypot(*u)
        assert d.max(initial=0) <= 1e-6
    # chords of sagitta 1e-6 on r = 1 span 2 acos(1 - 1e-6) each: at least 2222 of them;
    # splitting chords in two where they fail keeps fewer than twice that
    least = math.ceil(2 * math.pi / (2 * math.acos(1 - 1e-6)))
    assert least <= len(arc) < 2 * least


def test_a_plane_through_the_top_face_says_it_touches_it():
    g = _graph(
        "  b: {type: mesh.box, size: [1, 1, 1]}\n"
        "  s: {type: mesh.slice, mesh: '@b', height: 0.5}\n"
        "  t: {type: geometry.transform, geometry: '@b', rotate: [45, 0, 0]}\n"
    )
    g.add("e", "mesh.slice", mesh="@t", height=float(g.evaluate("t").vertices[:, 2].max()))
    with pytest.warns(
        fg.FormgraphWarning,
        match=r"z = 0.5 touches the mesh only at its top "
        r"\(a face lying in it\).*no section.*z = 0.499999",
    ):
        assert g.evaluate("s") == []
    with pytest.warns(fg.FormgraphWarning, match=r"touches the mesh only at its top \(an edge\)"):
        assert g.evaluate("e") == []


@pytest.mark.parametrize(
    "curve",
    [
        "{type: nurbs.circle, radius: 2, normal: [0, 1, 0]}",
        "{type: curves.polyline, points: [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]], "
        "closed: true}",
    ],
)
def test_an_outline_standing_across_the_xy_plane_is_said_to_be_so(curve):
    g = _graph(f"  c: {curve}\n  e: {{type: mesh.extrude, curves: ['@c'], height: 1}}\n")
    with pytest.raises(
        fg.NodeError, match=r"h.yaml:4: node 'e', input 'curves'.*curve\(s\) 0 are not in the XY"
    ):
        g.evaluate("e")


def test_a_square_turned_upright_by_rounding_is_no_sliver():
    g = _graph(
        "  s: {type: curves.rectangle, size: [2, 2]}\n"
        "  t: {type: geometry.transform, geometry: '@s', rotate: [90, 0, 0]}\n"
        "  e: {type: mesh.extrude, curves: ['@t'], height: 1}\n"
    )
    with pytest.raises(fg.NodeError, match="node 'e', input 'curves'.*not in the XY plane"):
        g.evaluate("e")


@pytest.mark.parametrize(("center", "span"), [(False, (5, 7)), (True, (4, 6))])
def test_an_outline_at_z_5_is_extruded_from_its_own_plane(center, span):
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=1, center=[0, 0, 5])
    g.add("e", "mesh.extrude", curves=["@c"], height=2, center=center)
    m = g.evaluate("e")
    assert g.stats["e"].warnings == []
    assert m.bounds[:, 2].tolist() == list(span)
    assert m.volume == pytest.approx(2 * math.pi, rel=1e-4)


def test_outlines_at_two_heights_warn_and_rise_from_zero():
    g = fg.Graph()
    g.add("a", "curves.rectangle", size=[4, 4], center=[0, 0, 5])
    g.add("b", "curves.rectangle", size=[1, 1], center=[0, 0, 2])
    g.add("e", "mesh.extrude", curves=["@a", "@b"], height=1)
    with pytest.warns(fg.FormgraphWarning, match=r"different heights \(z from 2 to 5\)"):
        m = g.evaluate("e")
    assert m.bounds[:, 2].tolist() == [0, 1] and m.volume == pytest.approx(15)


def test_a_profile_off_the_xy_plane_warns_when_revolved():
    g = fg.Graph()
    g.add("a", "curves.rectangle", size=[1, 1], center=[2, 0, 5])
    g.add("r", "mesh.revolve", curves=["@a"], segments=8)
    with pytest.warns(fg.FormgraphWarning, match=r"node 'r'.*plane z = 5, not z = 0"):
        g.evaluate("r")


def test_a_tolerance_the_size_of_the_curve_warns_that_it_turns_a_circle_into_a_square():
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=5)
    g.add("e", "mesh.extrude", curves=["@c"], height=2, tolerance=100)
    g.add("fine", "mesh.extrude", curves=["@c"], height=2, tolerance=0.01)
    with pytest.warns(
        fg.FormgraphWarning,
        match=r"node 'e'.*tolerance 100 is more than 1/50 of the size of curve 0 \(10\).*"
        r"polygon of 4 points",
    ):
        assert g.evaluate("e").volume == pytest.approx(100)  # the inscribed square
    assert g.evaluate("fine").volume == pytest.approx(50 * math.pi, rel=3e-3)
    assert g.stats["fine"].warnings == []


def test_the_pen_holders_label_faces_the_gallerys_camera():
    """The gallery looks from (+1, +1, +1): the label stands on the +y face (y = depth / 2),
    its letters standing out along +y, and reading left to right seen from +y (the text's
    +x goes to -x; geometry.transform keeps the vertex order, so vertices correspond)."""
    from pathlib import Path

    g = fg.load(Path(__file__).parents[2] / "graphs" / "pen_holder.yaml")
    flat, upright = g.evaluate("letters"), g.evaluate("upright")
    depth = 60.0  # the graph's default
    assert upright.bounds[0][1] == pytest.approx(depth / 2 - 0.4)
    x, z = flat.vertices[:, 0], flat.vertices[:, 2]
    moved = upright.vertices
    assert moved[np.argmax(x), 0] == pytest.approx(moved[:, 0].min())  # end of text: left
    assert moved[np.argmax(z), 1] == pytest.approx(moved[:, 1].max())  # relief: outward


def test_closed_rings_lose_a_collinear_first_point_and_rings_of_no_width():
    """The rings a section gives, each closed on its first point: a square starting halfway
    along an edge is closed again on its first corner, a ring of no width goes, the steps
    are the new rings' edge lengths (and the jump from one ring to the next)."""
    from formgraph.kernels.mesh.section import _simplified

    square = [[0.5, 0], [1, 0], [1, 1], [0, 1], [0, 0], [0.5, 0]]
    flat = [[2, 0], [3, 0], [4, 0], [2, 0]]
    tri = [[5, 0], [6, 0], [5, 1], [5, 0]]
    coords = np.array(square + flat + tri, dtype=float)
    out, off, step = _simplified(coords, np.array([0, 6, 10, 14]))
    assert off.tolist() == [0, 5, 9]
    assert out.tolist() == [[1, 0], [1, 1], [0, 1], [0, 0], [1, 0]] + tri
    assert step == pytest.approx(np.hypot(*np.diff(out, axis=0).T))
    same = np.array([[0, 0], [1, 0], [0, 1], [0, 0]], dtype=float)
    kept = _simplified(same, np.array([0, 4]))
    assert kept[0] is same and kept[2].tolist() == [1, 2**0.5, 1]
