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


TEXT = "  c: {type: curves.text, text: 'Hi', size: 10}\n"


@pytest.mark.parametrize("keep", ["'=area < 0'", "false"])
def test_filtering_all_curves_away_gives_an_empty_list_of_curves_and_says_so(keep, tmp_path):
    text = TEXT + f"  f: {{type: geometry.filter, geometry: '@c', keep: {keep}}}\n"
    text += "  s: {type: export.svg, curves: '@f', path: out.svg}\n"
    g = _graph(text, out_dir=tmp_path)
    with pytest.warns(fg.FormgraphWarning, match=r"node 'f': keep is false for all 3 curves"):
        assert g.evaluate("f") == []
    # the next node sees no curves (not an empty point set of the wrong type)
    with pytest.raises(fg.NodeError, match="node 's'.*needs at least one path, got none"):
        g.evaluate("s")


def test_a_filter_on_an_empty_list_of_curves_reads_the_curve_names():
    text = "  c: {type: curves.text, text: ' ', size: 10}\n"
    text += "  f: {type: geometry.filter, geometry: '@c', keep: '=length > 0'}\n"
    assert _graph(text).evaluate("f") == []


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
        ("count: 5, seed: -3", "seed", "must be >= 0, got -3"),
    ],
)
def test_scatter_counts_and_spacings_that_cannot_be(inputs, port, message):
    text = BALL + f"  s: {{type: points.scatter, geometry: '@ball', {inputs}}}\n"
    where = f", input '{port}'" if port else ""
    with pytest.raises(fg.FormgraphError, match=rf"h.yaml:4: node 's'{where}.*{message}"):
        _graph(text).evaluate("s")


def test_scatter_on_a_surface_past_the_largest_coordinate_is_refused_in_words():
    text = "  box: {type: mesh.box, size: [1e200, 1e200, 1e200]}\n"
    text += "  s: {type: points.scatter, geometry: '@box', spacing: 1e190}\n"
    with pytest.raises(
        fg.NodeError,
        match=r"h.yaml:4: node 's', input 'geometry'.*reaches a coordinate of 5e\+199, past "
        r"1e\+15",
    ):
        _graph(text).evaluate("s")


def test_a_spacing_past_the_surface_takes_one_point_without_overflow():
    text = "  box: {type: mesh.box, size: [1, 1, 1]}\n"
    text += "  s: {type: points.scatter, geometry: '@box', spacing: 1e190}\n"
    out = _graph(text).evaluate("s")
    assert len(out) == 1 and np.all(np.abs(out.xyz) <= 0.5)


def test_a_negative_seed_of_random_points_names_the_input_and_the_rule():
    text = "  r: {type: points.random, count: 3, seed: -3}\n"
    with pytest.raises(fg.GraphError, match=r"h.yaml:3: node 'r', input 'seed': must be >= 0"):
        _graph(text).evaluate("r")


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


CIRCLE = (
    "  p: {type: points.list, points: [[0, 0, 0], [2, 0, 0], [0, 3, 0], [0.5, 0.5, 0]]}\n"
    "  c: {type: nurbs.circle, radius: 1}\n"
)


@pytest.mark.parametrize("tol", ["1e-12", "1e-300"])
def test_a_tolerance_below_double_precision_is_refused_before_sampling(tol):
    text = CIRCLE + f"  d: {{type: attr.distance, geometry: '@p', to: '@c', tolerance: {tol}}}\n"
    with pytest.raises(
        fg.NodeError,
        match=rf"h.yaml:5: node 'd', input 'tolerance'.*a tolerance of {tol} is below what "
        r"double precision resolves on curves 2 across: use 2e-11 or more",
    ):
        _graph(text).evaluate("d")


def test_curve_samples_a_tolerance_asks_for_are_counted_before_sampling():
    text = CIRCLE + "  d: {type: attr.distance, geometry: '@p', to: '@c', tolerance: 1e-8}\n"
    # a circle sampled within 1e-8 needs about 2 pi / sqrt(8e-8) = 22,214 chords
    with pytest.raises(
        fg.BudgetError,
        match=r"h.yaml:5: node 'd': a tolerance of 1e-08 asks for about 22,\d{3} curve "
        r"samples, over the budget of 10,000: use a tolerance of ([\d.]+e-07) or more",
    ) as err:
        _graph(text, budget=10_000).evaluate("d")
    enough = err.value.args[0].split("use a tolerance of ")[1].split()[0]
    out = _graph(text.replace("1e-8", enough), budget=10_000).evaluate("d")
    # the tolerance it names does fit, and the distances are within it of the exact ones
    assert np.allclose(out.point_data["distance"], [1, 1, 2, 1 - np.sqrt(0.5)], atol=float(enough))


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


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (
            "[[0, 0], [1e-13, 0], [1, 1]]",
            r"points 0 and 1 are only 1e-13 apart, under 1e-09 of the diagram's extent 1.1",
        ),
        (
            "[[0, 0], [1e300, 0], [0, 1e300]]",
            r"point 1 at \(1e\+300, 0\) lies past 1e\+15 from the origin \(2 points do\)",
        ),
        (
            "[[0, 0], [1e-300, 0], [0, 1e-300]]",
            r"the points and their region span only 1.1e-300: a Voronoi diagram needs 1e-100",
        ),
    ],
)
def test_voronoi_of_points_past_double_arithmetic_is_refused_in_words(points, message):
    text = f"  p: {{type: points.list, points: {points}}}\n"
    text += "  v: {type: curves.voronoi, points: '@p'}\n"
    with pytest.raises(fg.NodeError, match=rf"h.yaml:4: node 'v', input 'points'.*: {message}"):
        _graph(text).evaluate("v")


def test_voronoi_of_points_just_apart_enough_still_tiles_the_box():
    text = "  p: {type: points.list, points: [[0, 0], [2e-9, 0], [1, 1]]}\n"
    text += "  v: {type: curves.voronoi, points: '@p'}\n"
    cells = _graph(text).evaluate("v")
    assert len(cells) == 3


def test_a_failure_of_geos_is_a_located_sentence(monkeypatch):
    import shapely

    from formgraph.kernels.curves import voronoi as kvoronoi

    def fails(*_):
        raise shapely.errors.GEOSException("TopologyException: side location conflict at 0 0")

    monkeypatch.setattr(kvoronoi, "cells", fails)
    text = "  p: {type: points.list, points: [[0, 0], [1, 0], [1, 1]]}\n"
    text += "  v: {type: curves.voronoi, points: '@p'}\n"
    with pytest.raises(
        fg.NodeError,
        match=r"h.yaml:4: node 'v', input 'points'.*GEOS could not build the diagram of these "
        r"points \(side location conflict\): they are too near together or too far apart",
    ):
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


def test_a_300000_point_voronoi_is_over_the_default_budget_before_it_is_built():
    """It ran 37 s: every cell is a curve object of its own, counted as 200 elements."""
    text = "  p: {type: points.random, count: 300000, seed: 1}\n"
    text += "  v: {type: curves.voronoi, points: '@p'}\n"
    with pytest.raises(
        fg.BudgetError,
        match=r"h.yaml:4: node 'v': would make 60,000,000 elements' worth of cells \(200 a "
        r"cell\), over the budget of 50,000,000",
    ):
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
