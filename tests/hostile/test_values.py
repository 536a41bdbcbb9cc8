"""Hostile values: bools and empty nests as points, overflowing numbers, extreme inputs that
make numpy warn, and attempts to write to values the read-only promise protects."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import formgraph as fg


def _graph(text: str) -> fg.Graph:
    return fg.Graph.from_text("formgraph: 1\nnodes:\n" + text, file="h.yaml")


@pytest.mark.parametrize(
    ("points", "why"),
    [
        ("[[true, false]]", "true/false"),
        ("[[1, 2], [true, 3]]", "numbers"),
        ("[[[[]]]]", r"shape \(1, 1, 1, 0\)"),
        ("[[]]", r"shape \(1, 0\)"),
    ],
)
def test_points_that_are_not_coordinates_are_refused(points, why):
    with pytest.raises(fg.GraphError, match=rf"h.yaml:5: node 'p', input 'points': .*{why}"):
        _graph(f"  p:\n    type: points.list\n    points: {points}\n")


def test_no_points_is_still_no_points():
    assert len(_graph("  p:\n    type: points.list\n    points: []\n").evaluate("p")) == 0


def test_bool_arrays_are_not_coordinates():
    with pytest.raises(ValueError, match="true/false"):
        fg.Points(np.ones((3, 3), dtype=bool))


def test_an_expression_that_fails_inside_a_list_is_located():
    with pytest.raises(fg.GraphError, match=r"h.yaml:5: node 'p', input 'points': .*'=1/0'"):
        _graph("  p:\n    type: points.list\n    points: [['=1/0', 2], [3, 4]]\n")


def test_a_400_digit_integer_in_an_expression_is_located():
    big = "1" * 400
    with pytest.raises(fg.GraphError, match=r"h.yaml:5: node 'c', input 'radius': .*too large"):
        _graph(f"  c:\n    type: nurbs.circle\n    radius: '={big} * 2'\n")
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=f"={big}")
    with pytest.raises(fg.GraphError, match="too large"):
        g.evaluate("c")


def test_enum_values_suggest_the_nearest():
    with pytest.raises(fg.GraphError, match=r"'centripedal' .*did you mean 'centripetal'"):
        _graph(
            "  p: {type: points.circle, count: 5}\n"
            "  c: {type: curves.catmull_rom, points: '@p', spacing: centripedal}\n"
        )


def _no_numpy_warnings(g: fg.Graph, node: str) -> pytest.ExceptionInfo | None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            g.evaluate(node)
            err = None
        except fg.FormgraphError as exc:
            err = exc
    noise = [w for w in caught if issubclass(w.category, RuntimeWarning)]
    assert noise == [], [str(w.message) for w in noise]
    return err


def test_extreme_values_give_a_located_error_and_no_numpy_warning():
    g = _graph(
        "  b: {type: mesh.box, size: [1.0e300, 1.0e300, 1.0e300]}\n"
        "  t: {type: mesh.transform, mesh: '@b', scale: 1.0e300}\n"
    )
    err = _no_numpy_warnings(g, "t")
    assert isinstance(err, fg.NodeError) and "h.yaml:4: node 't'" in str(err)
    assert "not finite" in str(err)


def test_numpy_warnings_inside_a_node_that_succeeds_stay_inside():
    g = _graph(
        "  c: {type: nurbs.circle, radius: 1.0e300}\n"
        "  o: {type: offset.marching_squares, curves: '@c', distance: 1.0e300}\n"
    )
    _no_numpy_warnings(g, "o")


def test_interpolating_overflowing_points_is_located():
    g = _graph(
        "  n: {type: nurbs.interpolate, points: [[0, 0], [1.0e308, 1], [-1.0e308, 3], [4, 9]]}\n"
    )
    err = _no_numpy_warnings(g, "n")
    assert isinstance(err, fg.NodeError) and "node 'n'" in str(err)


# ----------------------------------------------------------------- the read-only promise


def _arrays(value: fg.geometry.Geometry) -> list[np.ndarray]:
    return [v for v in value.state().values() if isinstance(v, np.ndarray)]


def _cannot_be_made_writable(a: np.ndarray) -> None:
    with pytest.raises(ValueError):
        a.flags.writeable = True
    base = a.base
    while isinstance(base, np.ndarray):
        with pytest.raises(ValueError):
            base.flags.writeable = True
        base = base.base


def test_a_mesh_from_a_node_cannot_be_made_writable():
    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("s", "mesh.catmull_clark", mesh="@b")
    m = g.evaluate("s")
    for a in _arrays(m):
        _cannot_be_made_writable(a)
    with pytest.raises(ValueError):
        m.vertices[:] = 0
    assert g.evaluate("s").vertices.any()  # the cached value is intact


def test_every_geometry_type_is_frozen():
    c = fg.NurbsCurve([[0, 0], [1, 1], [2, 0]], 2, [0, 0, 0, 1, 1, 1], [1, 2, 1])
    s = fg.NurbsSurface(np.zeros((2, 2, 3)), 1, 1, [0, 0, 1, 1], [0, 0, 1, 1])
    m = fg.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    for value in (fg.Points([[1, 2, 3]]), c, s, m):
        for a in _arrays(value):
            _cannot_be_made_writable(a)


def test_points_never_keep_the_callers_array():
    mine = np.arange(12, dtype=np.float64).reshape(4, 3)
    mine.flags.writeable = False  # read-only, but still mine: I can flip it back
    p = fg.Points(mine)
    mine.flags.writeable = True
    mine[:] = -1
    assert p.xyz[0].tolist() == [0.0, 1.0, 2.0]
    _cannot_be_made_writable(p.xyz)


def test_frozen_values_are_shared_not_copied():
    p = fg.Points([[1, 2, 3], [4, 5, 6]])
    assert fg.Points(p.xyz).xyz is p.xyz
    m = fg.Mesh(p.xyz.tolist() + [[0, 0, 1]], [[0, 1, 2]])
    assert fg.Mesh(m.vertices, m.face_indices, m.face_offsets).vertices is m.vertices


def test_values_read_from_the_disk_cache_are_frozen(tmp_path):
    def graph() -> fg.Graph:
        g = fg.Graph(cache_dir=tmp_path)
        g.add("b", "mesh.box")
        return g

    graph().evaluate("b")
    again = graph()
    m = again.evaluate("b")
    assert again.stats["b"].source == "disk"
    for a in _arrays(m):
        _cannot_be_made_writable(a)


def test_a_huge_integer_param_in_an_expression_is_located():
    # declared int: a whole number feeding only a float port would be read as a float
    text = (
        "formgraph: 1\nparams:\n  n: {type: int, default: 2}\nnodes:\n"
        "  c: {type: nurbs.circle, radius: '=n * 2'}\n"
    )
    g = fg.Graph.from_text(text, file="h.yaml")
    with pytest.raises(fg.GraphError, match=r"h.yaml:5: node 'c', input 'radius': .*too large"):
        g.evaluate("c", n=10**400)
    g.add("x", "curves.parametric", x="n * t", y="t")
    with pytest.raises(fg.NodeError, match=r"node 'x' .*too large"):
        g.evaluate("x", n=10**400)


def test_a_budget_message_stays_readable_for_absurd_counts():
    g = fg.Graph()
    g.add("p", "points.circle", count=10**400)
    with pytest.raises(fg.BudgetError, match=r"would make about 10\^400 points"):
        g.evaluate("p")


@pytest.mark.parametrize("count", [-(10**400), "=-1"])
def test_out_of_range_huge_numbers_are_located(count):
    g = fg.Graph()
    g.add("p", "points.circle", count=count)
    with pytest.raises(fg.GraphError, match=r"node 'p', input 'count': .*must be >= "):
        g.evaluate("p")


def test_a_param_out_of_range_by_a_huge_number_is_a_param_error():
    text = (
        "formgraph: 1\nparams:\n  n: {default: 3, min: 1, max: 9}\n"
        "nodes:\n  p: {type: points.circle, count: '=n'}\n"
    )
    g = fg.Graph.from_text(text, file="h.yaml")
    with pytest.raises(fg.ParamError, match="must be <= 9, got an integer of 401 digits"):
        g.evaluate("p", n=10**400)


def test_a_pickled_value_comes_back_frozen():
    import pickle

    c = fg.NurbsCurve([[0, 0], [1, 1], [2, 0]], 2, [0, 0, 0, 1, 1, 1], [1, 2, 1])
    m = fg.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    for value in (fg.Points([[1, 2, 3]]), c, m):
        copy = pickle.loads(pickle.dumps(value))
        assert type(copy) is type(value)
        for a, b in zip(_arrays(copy), _arrays(value), strict=True):
            assert np.array_equal(a, b)
            _cannot_be_made_writable(a)
