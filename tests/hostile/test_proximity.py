"""Hostile use of selection and proximity: geometry.filter, attr.distance / transfer /
curvature, points.scatter, curves.voronoi / delaunay. Each case ends as a located sentence
(file, line, node, input) or a correct result, never a numpy traceback or a hang."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg


def _graph(text: str, **kw) -> fg.Graph:
    return fg.Graph.from_text("formgraph: 1\nnodes:\n" + text, file="h.yaml", **kw)


BALL = "  ball: {type: mesh.sphere, radius: 1}\n"
PTS = "  pts: {type: points.grid, nx: 4, ny: 4, nz: 4, spacing: 0.5, origin: [-1, -1, -1]}\n"


# ------------------------------------------------------------------------- geometry.filter


@pytest.mark.parametrize(
    ("keep", "message"),
    [
        ("'=z + 1'", r"'=z \+ 1' gives numbers, not true or false"),
        ("'=where(z > 0, 1, 0)'", "gives numbers, not true or false"),
        ("['=z > 0', '=x > 0']", "is a list; a test is one expression"),
        ("'=heigth > 0'", r"names 'heigth'.*\(attributes: none\)"),
    ],
)
def test_a_keep_that_is_no_test_is_a_located_error(keep, message):
    text = PTS + f"  f: {{type: geometry.filter, geometry: '@pts', keep: {keep}}}\n"
    with pytest.raises(fg.NodeError, match=rf"h.yaml:4: node 'f', input 'keep'.*{message}"):
        _graph(text).evaluate("f")


def test_a_keep_of_a_number_literal_is_refused_by_the_check():
    text = PTS + "  f: {type: geometry.filter, geometry: '@pts', keep: 3}\n"
    with pytest.raises(fg.GraphError, match="h.yaml:4: node 'f', input 'keep': expected bool"):
        _graph(text).evaluate("f")


def test_a_test_that_is_nan_somewhere_drops_those_elements():
    text = PTS + "  f: {type: geometry.filter, geometry: '@pts', keep: '=sqrt(x) >= 0'}\n"
    out = _graph(text).evaluate("f")
    assert len(out) and np.all(out.xyz[:, 0] >= 0)  # NaN >= 0 is false: dropped, no error


def test_filtering_everything_away_gives_an_empty_value_not_an_error():
    text = BALL + "  f: {type: geometry.filter, geometry: '@ball', keep: '=z > 5'}\n"
    out = _graph(text).evaluate("f")
    assert out.n_faces == 0 and out.n_vertices == 0


# ------------------------------------------------------------------------- attr.distance


def test_to_a_surface_which_has_no_distance_is_refused_by_the_check():
    text = (
        PTS
        + "  s: {type: surfaces.parametric, x: u, y: v, z: '0', u: [0, 1], v: [0, 1]}\n"
        + "  d: {type: attr.distance, geometry: '@pts', to: '@s'}\n"
    )
    with pytest.raises(
        fg.GraphError, match=r"h.yaml:5: node 'd', input 'to': expected .*Mesh.*got"
    ):
        _graph(text).evaluate("d")


@pytest.mark.parametrize("to", ["'@pts'", "'@ring'"])
def test_a_signed_distance_to_what_has_no_inside_is_refused(to):
    text = PTS + "  ring: {type: nurbs.circle, radius: 1}\n"
    text += f"  d: {{type: attr.distance, geometry: '@pts', to: {to}, signed: true}}\n"
    with pytest.raises(fg.NodeError, match="h.yaml:5: node 'd', input 'signed'.* have no inside"):
        _graph(text).evaluate("d")


def test_a_signed_distance_to_an_open_mesh_warns_that_the_sign_is_the_winding_numbers():
    text = PTS + "  sheet: {type: mesh.plane, size: [4, 4]}\n"
    text += "  d: {type: attr.distance, geometry: '@pts', to: '@sheet', signed: true}\n"
    with pytest.warns(fg.FormgraphWarning, match="the mesh is open .* winding number"):
        out = _graph(text).evaluate("d")
    assert np.all(np.isfinite(out.point_data["distance"]))


def test_a_field_that_is_nan_is_refused_not_carried():
    text = PTS + "  f: {type: field.expression, value: 'sqrt(x)'}\n"
    text += "  d: {type: attr.distance, geometry: '@pts', to: '@f'}\n"
    with pytest.raises(fg.NodeError, match="h.yaml:5: node 'd'"):
        _graph(text).evaluate("d")


def test_the_name_closest_and_variable_names_are_refused():
    for name, message in [("closest", "the attribute of the nearest point"), ("x", "a variable")]:
        text = (
            PTS
            + BALL
            + f"  d: {{type: attr.distance, geometry: '@pts', to: '@ball', name: {name}}}\n"
        )
        with pytest.raises(fg.NodeError, match=f"input 'name'.*{message}"):
            _graph(text).evaluate("d")


def test_an_unknown_attribute_to_transfer_lists_those_that_exist():
    text = (
        PTS + BALL + "  t: {type: attr.transfer, geometry: '@pts', source: '@ball', names: [h]}\n"
    )
    with pytest.raises(
        fg.NodeError, match=r"h.yaml:5: node 't', input 'names'.*\(its point attributes: none\)"
    ):
        _graph(text).evaluate("t")


# ------------------------------------------------------------------------- points.scatter


def test_a_spacing_too_small_is_over_the_budget_before_anything_is_drawn():
    text = "  box: {type: mesh.box, size: [1000, 1000, 1000]}\n"
    text += "  s: {type: points.scatter, geometry: '@box', spacing: 1e-6}\n"
    with pytest.raises(fg.BudgetError, match=r"h.yaml:4: node 's'.*over the budget"):
        _graph(text).evaluate("s")


@pytest.mark.parametrize(
    ("inputs", "port", "message"),
    [
        ("count: 1000000000000", "", "over the budget"),
        ("spacing: 0", "spacing", "spacing must be > 0"),
        ("count: 5, spacing: 1", "count", "not both"),
    ],
)
def test_scatter_counts_and_spacings_that_cannot_be(inputs, port, message):
    text = BALL + f"  s: {{type: points.scatter, geometry: '@ball', {inputs}}}\n"
    where = f", input '{port}'" if port else ""
    with pytest.raises(fg.FormgraphError, match=rf"h.yaml:4: node 's'{where}.*{message}"):
        _graph(text).evaluate("s")


def test_scatter_on_a_mesh_without_area_is_a_located_error():
    text = "  flat: {type: mesh.from_faces, vertices: [[0, 0, 0], [1, 0, 0], [2, 0, 0]],"
    text += " faces: [[0, 1, 2]]}\n"
    text += "  s: {type: points.scatter, geometry: '@flat', count: 10}\n"
    with pytest.raises(
        fg.NodeError, match="h.yaml:4: node 's', input 'geometry'.*: the surface has no area"
    ):
        _graph(text).evaluate("s")


# ------------------------------------------------------------------------- curvature


def test_curvature_of_degenerate_triangles_is_finite():
    text = (
        "  m: {type: mesh.from_faces, vertices: [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]],"
        " faces: [[0, 1, 2], [1, 0, 3]]}\n"
        "  k: {type: attr.curvature, mesh: '@m'}\n"
    )
    with pytest.warns(fg.FormgraphWarning, match="open or non-manifold edge"):
        out = _graph(text).evaluate("k")
    assert np.all(np.isfinite(out.point_data["mean_curvature"]))
    assert np.all(np.isfinite(out.point_data["gaussian_curvature"]))


# ------------------------------------------------------------------------- voronoi


@pytest.mark.parametrize(
    ("points", "message"),
    [
        ("[[0, 0]]", "needs at least 2 points, got 1"),
        ("[[0, 0], [1, 1], [0, 0]]", r"points 0 and 2 coincide at \(0, 0\)"),
        ("[[0, 0, 1], [0, 0, 2]]", r"points 0 and 1 coincide at \(0, 0\) in XY"),
    ],
)
def test_voronoi_of_too_few_or_coincident_points_is_located(points, message):
    text = f"  p: {{type: points.list, points: {points}}}\n"
    text += "  v: {type: curves.voronoi, points: '@p'}\n"
    with pytest.raises(fg.NodeError, match=rf"h.yaml:4: node 'v', input 'points'.*: .*{message}"):
        _graph(text).evaluate("v")


def test_voronoi_of_collinear_points_still_tiles_the_box():
    text = "  p: {type: points.list, points: [[0, 0], [1, 0], [2, 0], [3, 0]]}\n"
    text += "  v: {type: curves.voronoi, points: '@p'}\n"
    cells = _graph(text).evaluate("v")
    assert len(cells) == 4 and all(c.closed for c in cells)


def test_voronoi_with_an_open_region_curve_is_refused():
    text = "  p: {type: points.list, points: [[0.2, 0.2], [0.5, 0.5]]}\n"
    text += "  r: {type: curves.polyline, points: [[0, 0], [1, 0], [1, 1]]}\n"
    text += "  v: {type: curves.voronoi, points: '@p', region: '@r'}\n"
    with pytest.raises(fg.NodeError, match="h.yaml:5: node 'v', input 'region'.*: curve 0 is open"):
        _graph(text).evaluate("v")


def test_huge_voronoi_and_delaunay_counts_are_over_a_small_budget():
    text = "  p: {type: points.random, count: 100000, seed: 1}\n"
    text += (
        "  v: {type: curves.voronoi, points: '@p'}\n  d: {type: curves.delaunay, points: '@p'}\n"
    )
    g = _graph(text, budget=150_000)
    with pytest.raises(fg.BudgetError, match="h.yaml:4: node 'v'.*over the budget"):
        g.evaluate("v")
    with pytest.raises(fg.BudgetError, match="h.yaml:5: node 'd'.*over the budget"):
        g.evaluate("d")
