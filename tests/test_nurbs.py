"""The nurbs.* nodes: curves, circles, arcs, interpolation, knot operations, surfaces,
loft, extrusion, revolution, sweep and tessellation, and their errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import formgraph as fg
from formgraph.kernels import nurbs as K

RNG = np.random.default_rng(3)
GRAPHS = Path(__file__).resolve().parents[1] / "graphs"
T = np.linspace(0.0, 1.0, 97)


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n")


def run_graph(nodes: dict, target: str):
    g = fg.Graph()
    for name, (node_type, inputs) in nodes.items():
        g.add(name, node_type, **inputs)
    value = g.evaluate(target)
    return value, g.stats


# ------------------------------------------------------------------------------ curves


def test_curve_defaults_to_clamped_uniform_cubic():
    pts = [[0, 0], [1, 2], [3, 2], [4, 0], [5, 1]]
    c = run("nurbs.curve", points=pts)
    assert isinstance(c, fg.NurbsCurve) and c.degree == 3
    np.testing.assert_allclose(c.knots, K.clamped_uniform_knots(5, 3))
    np.testing.assert_allclose(c.evaluate(np.array([0.0, 1.0])), [[0, 0, 0], [5, 1, 0]])


def test_curve_with_knots_and_weights_is_that_nurbs():
    pts = [[1, 0], [1, 1], [0, 1]]
    c = run(
        "nurbs.curve",
        points=pts,
        degree=2,
        knots=[0, 0, 0, 1, 1, 1],
        weights=[1, math.sqrt(0.5), 1],
    )
    assert c.rational
    np.testing.assert_allclose(np.linalg.norm(c.evaluate(T), axis=1), 1.0, atol=1e-14)


def test_closed_curve_is_periodic_and_smooth():
    pts = [[1, 0], [0, 1], [-1, 0], [0, -1], [1, 0]]  # a repeated last point is dropped
    c = run("nurbs.curve", points=pts, closed=True)
    assert c.closed and len(c.control_points) == 4 + 3
    t0, t1 = c.domain
    d = c.derivative(np.array([t0, t1]))
    np.testing.assert_allclose(d[0], d[1], atol=1e-12)


def test_curve_degree_is_lowered_with_a_warning():
    c, stats = run_graph({"c": ("nurbs.curve", {"points": [[0, 0], [1, 1], [2, 0]]})}, "c")
    assert c.degree == 2
    assert any("using 2" in w for w in stats["c"].warnings)


def test_circle_and_arc_are_exact():
    c = run("nurbs.circle", radius=2.5, center=[1, 2, 3], normal=[1, 1, 0])
    pts = c.evaluate(np.linspace(0, 1, 500))
    np.testing.assert_allclose(np.linalg.norm(pts - [1, 2, 3], axis=1), 2.5, rtol=1e-14)
    a = run("nurbs.arc", radius=1, start=90, end=180)
    np.testing.assert_allclose(
        a.evaluate(np.array([0.0, 1.0])), [[0, 1, 0], [-1, 0, 0]], atol=1e-15
    )


def test_interpolate_passes_through_points_open_and_closed():
    pts = RNG.normal(size=(7, 3))
    for closed in (False, True):
        c = run(
            "nurbs.interpolate", points=pts.tolist(), closed=closed, parametrization="centripetal"
        )
        u = K.interpolation_parameters(pts, closed, "centripetal")
        np.testing.assert_allclose(c.evaluate(u), pts, atol=1e-12)
        assert c.closed == closed


def test_insert_knot_and_elevate_degree_keep_the_shape():
    base = ("nurbs.interpolate", {"points": RNG.normal(size=(6, 3)).tolist()})
    k, _ = run_graph(
        {"c": base, "k": ("nurbs.insert_knot", {"curve": "@c", "t": 0.3, "times": 2})}, "k"
    )
    e, _ = run_graph({"c": base, "e": ("nurbs.elevate_degree", {"curve": "@c", "times": 2})}, "e")
    c = run("nurbs.interpolate", **base[1])
    assert len(k.control_points) == len(c.control_points) + 2
    assert e.degree == 5
    np.testing.assert_allclose(k.evaluate(T), c.evaluate(T), atol=1e-12)
    np.testing.assert_allclose(e.evaluate(T), c.evaluate(T), atol=1e-10)


# ---------------------------------------------------------------------------- surfaces


def test_surface_from_rows_of_points():
    i, j = np.meshgrid(np.arange(4), np.arange(5), indexing="ij")
    net = np.stack([i, j, RNG.normal(size=(4, 5))], -1).astype(float)
    s = run("nurbs.surface", points=net.tolist(), degree_u=2, degree_v=3)
    assert isinstance(s, fg.NurbsSurface) and (s.degree_u, s.degree_v) == (2, 3)
    np.testing.assert_allclose(
        s.evaluate(np.array([0.0, 1.0]), np.array([0.0, 1.0])), net[[0, -1], [0, -1]]
    )
    w = np.ones(20)
    w[7] = 3.0
    sw = run("nurbs.surface", points=net.tolist(), weights=w.tolist())
    assert sw.rational and sw.weights[1, 2] == 3.0


def test_loft_of_differently_built_curves_passes_through_each():
    g = fg.load(GRAPHS / "canopy.yaml")
    canopy = g.evaluate("canopy")
    names = ["front", "middle", "back", "end"]
    curves = [g.evaluate(n) for n in names]
    compat = K.make_compatible(
        [(c.control_points, c.degree, c.knots, c.weights if c.rational else None) for c in curves]
    )
    v = K.interpolation_parameters(np.stack([c[0] for c in compat]))
    for c, vk in zip(curves, v, strict=True):
        t0, t1 = c.domain
        np.testing.assert_allclose(
            canopy.evaluate(T, vk), c.evaluate(t0 + T * (t1 - t0)), atol=1e-12
        )


def test_loft_accepts_parametric_curves():
    nodes = {
        "a": ("nurbs.circle", {}),
        "b": (
            "curves.parametric",
            {"x": "2*cos(t)", "y": "2*sin(t)", "z": "1", "t": [0, 2 * math.pi], "samples": 64},
        ),
        "l": ("nurbs.loft", {"curves": ["@a", "@b"]}),
    }
    s, _ = run_graph(nodes, "l")
    ring = s.evaluate(T, 1.0)
    np.testing.assert_allclose(np.linalg.norm(ring[:, :2], axis=1), 2.0, atol=1e-5)
    np.testing.assert_allclose(ring[:, 2], 1.0, atol=1e-12)


def test_extrude_and_revolve():
    e, _ = run_graph(
        {
            "c": ("nurbs.circle", {}),
            "e": ("nurbs.extrude", {"curve": "@c", "direction": [0, 0, 3]}),
        },
        "e",
    )
    np.testing.assert_allclose(e.evaluate(T, 1.0)[:, 2], 3.0)
    prof = [[1, 0, 0], [1.5, 0, 1], [1, 0, 2]]
    r, _ = run_graph(
        {
            "p": ("nurbs.interpolate", {"points": prof, "degree": 2}),
            "r": ("nurbs.revolve", {"curve": "@p", "angle": 270}),
        },
        "r",
    )
    pts = r.evaluate(T[:, None], np.linspace(0, 1, 13)[None, :])
    radius = np.linalg.norm(pts[..., :2], axis=-1)
    np.testing.assert_allclose(radius, radius[:, :1] * np.ones((1, 13)), atol=1e-12)
    end = r.evaluate(0.0, 1.0)
    np.testing.assert_allclose(end, [0, -1, 0], atol=1e-14)  # 270 degrees counter-clockwise


def test_spiral_tube_keeps_its_radius_and_meshes_to_quads():
    g = fg.load(GRAPHS / "spiral_tube.yaml")
    tube, mesh, spiral = g.evaluate("tube"), g.evaluate("mesh"), g.evaluate("spiral")
    assert isinstance(tube, fg.NurbsSurface)
    assert mesh.n_faces == 64 * 256 and np.all(np.asarray(mesh.face_sizes) == 4)
    t = np.linspace(*spiral.domain, 256)
    centre = spiral.evaluate(t)
    v = K.interpolation_parameters(centre)
    ring = tube.evaluate(np.linspace(0, 1, 30)[:, None], v[None, :])
    np.testing.assert_allclose(np.linalg.norm(ring - centre[None], axis=-1), 0.3, atol=1e-12)
    # the u seam of the circle is joined: no duplicate vertices there
    assert mesh.n_vertices == 64 * 257


def test_sweep_along_a_nurbs_path_with_explicit_stations():
    nodes = {
        "path": ("nurbs.interpolate", {"points": [[0, 0, 0], [2, 1, 0], [4, -1, 1], [6, 0, 2]]}),
        "sq": (
            "curves.polyline",
            {"points": [[-0.2, -0.2], [0.2, -0.2], [0.2, 0.2], [-0.2, 0.2]], "closed": True},
        ),
        "s": ("nurbs.sweep", {"profile": "@sq", "path": "@path", "stations": 40}),
    }
    s, _ = run_graph(nodes, "s")
    assert s.control_points.shape[:2] == (5, 40)


def test_vase_faces_outward():
    from formgraph.kernels.mesh import meshops, repair

    mesh = fg.load(GRAPHS / "vase.yaml").evaluate("mesh")
    v, fi, fo = mesh.vertices, mesh.face_indices, mesh.face_offsets
    n = meshops.face_normals(v, fi, fo)
    centre = np.add.reduceat(v[fi], fo[:-1]) / mesh.face_sizes[:, None]
    side = np.abs(n[:, 2]) < 0.5  # the wall; the bottom is checked by orient below
    radial = centre * [1, 1, 0]
    assert side.sum() > mesh.n_faces / 4
    assert np.all(np.sum(n * radial, axis=1)[side] > 0)
    # already as mesh.orient would make it: every face looks away from the vase's middle
    assert np.array_equal(repair.orient(v, fi, fo)[0], fi)


def test_tessellate_a_parametric_surface():
    nodes = {
        "s": ("surfaces.parametric", {"x": "u", "y": "v", "z": "u*v"}),
        "m": ("nurbs.tessellate", {"surface": "@s", "u": 4, "v": 3}),
    }
    m, _ = run_graph(nodes, "m")
    assert m.n_faces == 12 and m.n_vertices == 20


@pytest.mark.parametrize(
    "name,change,recomputed",
    [
        ("canopy", {"rise": 4.0}, {"front", "canopy", "mesh"}),
        ("vase", {"angle": 270}, {"vase", "mesh", "shell", "print"}),
        (
            "spiral_tube",
            {"thickness": 0.2},
            {"section", "tube", "mesh", "closed", "solid", "print"},
        ),
    ],
)
def test_example_graphs_recompute_only_what_a_param_reaches(name, change, recomputed, tmp_path):
    g = fg.load(GRAPHS / f"{name}.yaml", out_dir=tmp_path)
    g.evaluate_all()
    g.evaluate_all(**change)
    computed = {n for n, s in g.stats.items() if s.status == "computed"}
    assert computed == recomputed


# ------------------------------------------------------------------------------ errors


@pytest.mark.parametrize(
    "node_type,inputs,port,match",
    [
        (
            "nurbs.curve",
            {"points": [[0, 0], [1, 1], [2, 0]], "weights": [1, 1]},
            "weights",
            r"3 points, 2 weights",
        ),
        (
            "nurbs.curve",
            {"points": [[0, 0], [1, 1], [2, 0]], "weights": [1, -1, 1]},
            "weights",
            r"weights must be positive",
        ),
        (
            "nurbs.curve",
            {"points": [[0, 0], [1, 1], [2, 0]], "degree": 2, "knots": [0, 1, 2]},
            "knots",
            r"need 6 knots",
        ),
        (
            "nurbs.curve",
            {"points": [[0, 0], [1, 1], [2, 0]], "degree": 2, "knots": [0, 0, 0, 1, 0.5, 1]},
            "knots",
            r"non-decreasing",
        ),
        (
            "nurbs.curve",
            {"points": [[0, 0], [1, 1], [2, 0]], "closed": True, "knots": [0, 1]},
            "knots",
            r"periodic knots",
        ),
        (
            "nurbs.curve",
            {"points": [[0, 0], [1, 1]], "closed": True},
            "points",
            r"closed curve needs at least 3 points, got 2",
        ),
        ("nurbs.circle", {"radius": -1}, "radius", r"positive number, got -1"),
        ("nurbs.circle", {"normal": [0, 0, 0]}, "normal", r"non-zero"),
        ("nurbs.arc", {"radius": 1, "start": 0, "end": 0}, "end", r"more than 0"),
        (
            "nurbs.interpolate",
            {"points": [[0, 0], [0, 0], [1, 1]]},
            "points",
            r"points 0 and 1 coincide",
        ),
        ("nurbs.interpolate", {"points": [[0, 0]]}, "points", r"at least 2 points"),
        (
            "nurbs.surface",
            {"points": [[[0, 0], [1, 0]], [[0, 1]]]},
            "points",
            r"row 0 has 2, row 1 has 1",
        ),
        (
            "nurbs.surface",
            {"points": [[[0, 0], [1, 0]]]},
            "points",
            r"at least 2 rows of points, got 1",
        ),
        (
            "nurbs.surface",
            {"points": [[[0, 0], [1, 0]], [[0, 1], [1, 1]]], "weights": [1, 1]},
            "weights",
            r"2 x 2 = 4, got 2",
        ),
        (
            "nurbs.surface",
            {"points": [[[0, 0], [1, 0]], [[0, 1], [1, 1]]], "degree_u": 1, "knots_u": [0, 0, 1]},
            "knots_u",
            r"need 4 knots",
        ),
        ("nurbs.revolve", {"curve": "@c", "axis": [0, 0, 0]}, "axis", r"non-zero"),
        ("nurbs.revolve", {"curve": "@c", "angle": 400}, "angle", r"at most 360"),
        ("nurbs.extrude", {"curve": "@c", "direction": [0, 0, 0]}, "direction", r"non-zero"),
        ("nurbs.insert_knot", {"curve": "@c", "t": 5.0}, "t", r"outside the curve's domain"),
        (
            "nurbs.insert_knot",
            {"curve": "@c", "t": 0.5, "times": 3},
            "times",
            r"would exceed the degree 2",
        ),
        ("nurbs.elevate_degree", {"curve": "@c", "times": 40}, "times", r"above 32"),
        ("nurbs.loft", {"curves": ["@c"]}, "curves", r"at least 2 curves, got 1"),
        ("nurbs.loft", {"curves": ["@c", "@c", "@c"]}, "curves", r"coincide"),
        (
            "nurbs.sweep",
            {"profile": "@c", "path": "@c", "stations": 1},
            "stations",
            r"at least 2 stations",
        ),
    ],
)
def test_bad_inputs_raise_node_errors_naming_the_input(node_type, inputs, port, match):
    g = fg.Graph()
    g.add("c", "nurbs.circle")  # a degree-2 curve for the wired inputs
    g.add("n", node_type, **inputs)
    where = rf"node 'n', input '{port}' \({node_type.replace('.', '[.]')}\): "
    with pytest.raises(fg.NodeError, match=where + ".*" + match):
        g.evaluate("n")


def test_type_errors_are_caught_before_running():
    g = fg.Graph()
    g.add("m", "mesh.box")
    g.add("l", "nurbs.loft", curves=["@m"])
    with pytest.raises(fg.GraphError, match=r"node 'l', input 'curves'.*Mesh"):
        g.evaluate("l")
    g = fg.Graph()
    g.add("p", "curves.parametric", x="t", y="t*t")
    g.add("k", "nurbs.insert_knot", curve="@p", t=0.5)
    with pytest.raises(fg.GraphError, match=r"node 'k', input 'curve'.*NurbsCurve"):
        g.evaluate("k")
    g = fg.Graph()
    g.add("i", "nurbs.interpolate", points=[[0, 0], [1, 1]], parametrization="arc")
    with pytest.raises(fg.GraphError, match=r"'arc' is not a valid option.*'chord'"):
        g.evaluate("i")
    g = fg.Graph()
    g.add("t", "nurbs.tessellate", surface="@x", u=0)
    with pytest.raises(fg.GraphError, match=r"input 'u'.*>= 1"):
        g.evaluate("t")


def test_tessellation_budget_is_checked_before_allocating():
    g = fg.Graph()
    g.add("s", "surfaces.parametric", x="u", y="v", z="0")
    g.add("m", "nurbs.tessellate", surface="@s", u=100_000, v=100_000)
    with pytest.raises(fg.GraphError, match="over the budget"):
        g.evaluate("m")


def test_interpolation_of_too_many_points_is_refused_before_solving():
    g = fg.Graph(budget=4_000)
    g.add("pts", "points.random", count=1001, seed=1)
    g.add("c", "nurbs.interpolate", points="@pts")
    # 1,001 points, cubic: 48 numbers a point (kernels.nurbs.banded_entries), not 4
    with pytest.raises(fg.BudgetError, match=r"48,048 entries of the interpolation system"):
        g.evaluate("c")


def test_parametric_samples_into_extrude_are_charged_what_the_solve_holds():
    # 10 million samples: 4 entries a sample would pass the default budget of 50 million;
    # the solve holds ten times that.
    g = fg.Graph()
    g.add("c", "curves.parametric", x="cos(t)", y="sin(t)", samples=10_000_000)
    g.add("e", "nurbs.extrude", curve="@c", direction=[0, 0, 1])
    with pytest.raises(fg.BudgetError, match=r"560,000,000 entries of the interpolation system"):
        g.evaluate("e")
