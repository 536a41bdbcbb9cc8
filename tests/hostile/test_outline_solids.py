"""Hostile use of the solids from outlines, parts and bounds (issue 34): open and tilted
outlines, regions of no area, twists and scales that would make a solid cross itself,
planes that miss, Minkowski sums past the budget, flat hulls, NaN, inf and empty lists.
Each case ends as a located sentence (file, line, node, input), a warning, or a result."""

from __future__ import annotations

import math
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
    t0 = time.perf_counter()
    with pytest.raises(fg.BudgetError, match=r"node 'e'.*over the budget"):
        _extrude("height: 1, twist: 1e9").evaluate("e")
    assert time.perf_counter() - t0 < 30  # (refused, not built: no timing claim beyond that)


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
    t0 = time.perf_counter()
    with pytest.raises(fg.BudgetError, match=r"node 'm'.*elements of Minkowski hulls"):
        g.evaluate("m")
    assert time.perf_counter() - t0 < 30  # refused at once, not after minutes of hulls


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
