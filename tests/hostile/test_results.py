"""Hostile values that used to give a wrong result or an internal error: each now gives
the right result or a located error."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg


def _octagon(g: fg.Graph) -> None:
    g.add("pts", "points.circle", count=8, radius=1)
    g.add("c", "curves.polyline", points="@pts", closed=True)


@pytest.mark.parametrize("distance", [-2.0, -0.95, -1e12])
def test_an_inward_offset_past_the_inradius_is_an_error_not_an_inverted_polygon(distance):
    # the 8-gon's inradius is cos(22.5 deg) = 0.924; -2 used to give an 8-gon of radius 1.16
    g = fg.Graph()
    _octagon(g)
    g.add("o", "curves.offset", curve="@c", distance=distance)
    with pytest.raises(fg.NodeError, match=r"input 'distance'.*inside out.*inradius.*"
                       r"offset\.marching_squares"):  # fmt: skip
        g.evaluate("o")


@pytest.mark.parametrize("distance, radius", [(-0.5, 1 - 0.5 / np.cos(np.pi / 8)), (0.5, None)])
def test_offsets_inside_the_inradius_stay_right(distance, radius):
    g = fg.Graph()
    _octagon(g)
    g.add("o", "curves.offset", curve="@c", distance=distance)
    o = g.evaluate("o")
    r = np.linalg.norm(np.asarray(o.control_points)[:-1, :2], axis=1)
    expected = radius if radius is not None else 1 + distance / np.cos(np.pi / 8)
    assert np.allclose(r, expected)
    assert g.stats["o"].warnings == []


def test_marching_squares_agrees_that_nothing_is_left():
    g = fg.Graph()
    _octagon(g)
    g.add("o", "offset.marching_squares", curves=["@c"], distance=-2)
    assert g.evaluate("o") == []
    assert "empty" in g.stats["o"].warnings[0]


def test_an_offset_that_folds_locally_warns():
    # a narrow slot into a square: growing it by more than half the slot folds its walls over
    pts = [[0, 0], [10, 0], [10, 10], [5.5, 10], [5.5, 4], [4.5, 4], [4.5, 10], [0, 10]]
    g = fg.Graph()
    g.add("c", "curves.polyline", points=pts, closed=True)
    g.add("o", "curves.offset", curve="@c", distance=0.8)
    g.evaluate("o")
    assert any("folds over itself" in w for w in g.stats["o"].warnings)


def test_a_grid_of_no_rows_is_a_located_error():
    g = fg.Graph()
    g.add("m", "surfaces.grid", points=[])
    with pytest.raises(fg.NodeError, match=r"input 'points'.*got none"):
        g.evaluate("m")


@pytest.mark.parametrize(
    "kwargs, port",
    [({"distance": 1.0e-300}, "distance"), ({"distance": 1, "cell": 1e-300}, "cell")],
)
def test_marching_squares_tiny_values_are_located_errors(kwargs, port):
    g = fg.Graph()
    g.add("c", "nurbs.circle")
    g.add("o", "offset.marching_squares", curves=["@c"], **kwargs)
    with pytest.raises(fg.NodeError, match=rf"input '{port}'.*below 1e-9"):
        g.evaluate("o")


_NET = [[[0, 0, 0], [0, 1, 0], [0, 2, 0]], [[1, 0, 1], [1, 1, 2], [1, 2, 1]],
        [[2, 0, 0], [2, 1, 0], [2, 2, 0]]]  # fmt: skip


def test_surface_weights_as_a_grid_or_flat_give_the_same_surface():
    g = fg.Graph()
    g.add("a", "nurbs.surface", points=_NET, degree_u=2, degree_v=2,
          weights=[[1, 1, 1], [1, 3, 1], [1, 1, 1]])  # fmt: skip
    g.add("b", "nurbs.surface", points=_NET, degree_u=2, degree_v=2,
          weights=[1, 1, 1, 1, 3, 1, 1, 1, 1])  # fmt: skip
    out = g.evaluate(["a", "b"])
    assert np.array_equal(np.asarray(out["a"].weights), np.asarray(out["b"].weights))
    assert float(np.asarray(out["a"].weights)[1, 1]) == 3.0


@pytest.mark.parametrize(
    "weights, match",
    [
        ([[1, 1], [1, 1, 1], [1, 1, 1]], "shaped like the points, 3 rows of 3"),
        ([1, 1, 1], "one weight per control point"),
        ([[1, 1, 1], 1, 1], r"expected list\[float\] \| list\[list\[float\]\]"),
    ],
)
def test_badly_shaped_surface_weights_are_located_errors(weights, match):
    g = fg.Graph()
    g.add("a", "nurbs.surface", points=_NET, weights=weights)
    with pytest.raises(fg.FormgraphError, match=match):
        g.evaluate("a")


@pytest.mark.parametrize("direction", ["u", "v"])
def test_surface_knot_insertion_keeps_the_surface(direction):
    g = fg.Graph()
    g.add("c", "nurbs.circle")
    g.add("s", "nurbs.extrude", curve="@c", direction=[0, 0, 2])
    g.add("k", "nurbs.insert_knot", curve="@s", t=0.3, direction=direction, times=1)
    out = g.evaluate(["s", "k"])
    s, k = out["s"], out["k"]
    grow = (1, 0) if direction == "u" else (0, 1)
    assert np.asarray(k.control_points).shape[:2] == tuple(
        np.add(np.asarray(s.control_points).shape[:2], grow)
    )
    u, v = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 5))
    assert np.allclose(k.evaluate(u, v), s.evaluate(u, v), atol=1e-12)


def test_surface_knot_insertion_errors_name_the_input():
    g = fg.Graph()
    g.add("c", "nurbs.circle")
    g.add("s", "nurbs.extrude", curve="@c")
    g.add("k", "nurbs.insert_knot", curve="@s", t=0.5, direction="v", times=2)
    with pytest.raises(fg.NodeError, match=r"input 'times'.*exceed the degree 1"):
        g.evaluate("k")


def test_grid_weights_validate_against_the_json_schema():
    jsonschema = pytest.importorskip("jsonschema")
    from formgraph.language.catalogue import json_schema

    doc = {
        "formgraph": 1,
        "nodes": {
            "a": {
                "type": "nurbs.surface",
                "points": _NET,
                "weights": [[1, 1, 1], [1, 3, 1], [1, 1, 1]],
            },
            "b": {"type": "nurbs.surface", "points": _NET, "weights": [1] * 9},
        },
    }
    jsonschema.validate(doc, json_schema())


def test_a_surface_from_insert_knot_wires_into_tessellate():
    # the output is typed like the input: a surface in, a surface out, checked at load
    g = fg.Graph()
    g.add("c", "nurbs.circle")
    g.add("s", "nurbs.extrude", curve="@c")
    g.add("k", "nurbs.insert_knot", curve="@s", t=0.5, direction="v")
    g.add("m", "nurbs.tessellate", surface="@k", u=8, v=4)
    assert g.evaluate("m").n_faces == 32
    g.add("bad", "nurbs.tessellate", surface="@kc", u=8, v=4)
    g.add("kc", "nurbs.insert_knot", curve="@c", t=0.5)
    with pytest.raises(fg.GraphError, match=r"input 'surface': expected Surface, got NurbsCurve"):
        g.evaluate("bad")
