"""The curves.* nodes, run through graphs (checked, cached, errors naming node and input)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline

import formgraph as fg

RNG = np.random.default_rng(7)
BLOB = [[0, 0], [4, -1], [6, 2], [3, 5], [-1, 3]]


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n")


def chain(*steps):
    """Build a linear graph: each step (type, inputs) may wire '@prev'."""
    g = fg.Graph()
    for i, (node_type, inputs) in enumerate(steps):
        inputs = {k: (f"@n{i - 1}" if v == "@prev" else v) for k, v in inputs.items()}
        g.add(f"n{i}", node_type, **inputs)
    return g, f"n{len(steps) - 1}"


def arc_lengths(curve, t: np.ndarray, n: int = 20001) -> np.ndarray:
    """Arc length from the start to each t, by a dense polyline (independent of the node)."""
    tt = np.linspace(*curve.domain, n)
    pts = curve.evaluate(tt)
    cum = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    return np.interp(t, tt, cum)


# --------------------------------------------------------------------------- bezier


def test_bezier_is_exact_and_evaluates_like_scipy():
    p = RNG.normal(size=(7, 3))
    c = run("curves.bezier", points=p.tolist())
    assert isinstance(c, fg.NurbsCurve) and c.degree == 3 and c.domain == (0.0, 2.0)
    for i in range(2):
        q = p[3 * i : 3 * i + 4]
        np.testing.assert_allclose(c.evaluate(i + 0.5), (q[0] + 3 * q[1] + 3 * q[2] + q[3]) / 8)
    t = np.linspace(0, 2, 17)
    ref = BSpline(np.asarray(c.knots), p, 3)(t)
    np.testing.assert_allclose(c.evaluate(t), ref, atol=1e-12)


def test_bezier_bad_count_names_the_input():
    with pytest.raises(fg.NodeError, match=r"input 'points'.*3k\+1 points .*got 5"):
        run("curves.bezier", points=[[0, 0], [1, 0], [2, 0], [3, 0], [4, 0]])


# --------------------------------------------------------------------------- catmull-rom


@pytest.mark.parametrize("spacing", ["uniform", "centripetal", "chordal"])
def test_catmull_rom_closed_passes_through_and_is_c1(spacing):
    c = run("curves.catmull_rom", points=BLOB, closed=True, spacing=spacing)
    assert c.closed
    breaks = np.unique(np.asarray(c.knots))
    np.testing.assert_allclose(c.evaluate(breaks[:-1])[:, :2], BLOB, atol=1e-12)
    eps = 1e-9 * (breaks[-1] - breaks[0])
    left = c.derivative(np.append(breaks[1:-1], breaks[-1]) - eps)
    right = c.derivative(np.append(breaks[1:-1], breaks[0]) + eps)
    np.testing.assert_allclose(left, right, rtol=1e-5, atol=1e-5)


def test_catmull_rom_processing_midpoint_and_defaults():
    p = RNG.normal(size=(5, 3))
    c = run("curves.catmull_rom", points=p.tolist())
    assert c.domain == (0.0, 2.0)  # uniform, ends: processing -> 2 segments
    q = p[:4]
    np.testing.assert_allclose(c.evaluate(0.5), (-q[0] + 9 * q[1] + 9 * q[2] - q[3]) / 16)


def test_catmull_rom_bad_option_is_caught_at_check():
    g = fg.Graph()
    g.add("c", "curves.catmull_rom", points=BLOB, spacing="centripedal")
    with pytest.raises(fg.GraphError, match=r"input 'spacing'.*must be one of 'uniform'"):
        g.check()


def test_catmull_rom_repeats_never_nan():
    pts = [[0, 0], [0, 0], [1, 0], [1, 0], [1, 1], [1, 1]]
    for spacing in ("uniform", "centripetal", "chordal"):
        c = run("curves.catmull_rom", points=pts, ends="clamped", spacing=spacing)
        assert np.isfinite(c.sample(50)).all()
    with pytest.raises(fg.NodeError, match=r"input 'points'.*at least 3 distinct points"):
        run("curves.catmull_rom", points=[[0, 0], [1, 1], [0, 0]], closed=True)


# --------------------------------------------------------------------------- subdivide


def test_subdivide_closed_polyline_converges_to_bspline():
    g, last = chain(
        ("curves.polyline", {"points": BLOB, "closed": True}),
        ("curves.subdivide", {"curve": "@prev", "iterations": 8}),
    )
    c = g.evaluate(last)
    assert c.degree == 1 and c.closed
    pts = np.asarray(c.control_points)[:-1]
    assert len(pts) == 5 * 2**8
    p = np.array(BLOB, float)
    limit = (np.roll(p, 1, 0) + 4 * p + np.roll(p, -1, 0)) / 6
    np.testing.assert_allclose(pts[:: 2**8, :2], limit, atol=1e-4)


def test_subdivide_open_catmull_rom_control_polygon_keeps_ends():
    g, last = chain(
        ("curves.catmull_rom", {"points": BLOB, "ends": "clamped"}),
        ("curves.subdivide", {"curve": "@prev", "iterations": 3}),
    )
    c = g.evaluate(last)
    cp = np.asarray(c.control_points)
    assert len(cp) == (13 - 1) * 8 + 1 and not c.closed
    np.testing.assert_allclose(cp[[0, -1], :2], [BLOB[0], BLOB[-1]])


def test_subdivide_is_budgeted_before_allocating():
    g = fg.Graph(budget=10_000)
    g.add("p", "curves.polyline", points=BLOB, closed=True)
    g.add("s", "curves.subdivide", curve="@p", iterations=40)
    with pytest.raises(fg.BudgetError, match=r"5,497,558,138,880 points, over the budget"):
        g.evaluate("s")


# --------------------------------------------------------------------------- parametric


def test_parametric_uses_params_and_t_expressions(tmp_path):
    path = tmp_path / "helix.yaml"
    path.write_text(
        "formgraph: 1\n"
        "params:\n  turns: 2\n  radius: 3.0\n"
        "nodes:\n"
        "  helix:\n"
        "    type: curves.parametric\n"
        "    x: radius * cos(t)\n    y: radius * sin(t)\n    z: t / (2*pi)\n"
        '    t: ["=0", "=2*pi*turns"]\n'
    )
    g = fg.load(path, out_dir=tmp_path)
    c = g.evaluate("helix")
    assert isinstance(c, fg.ParametricCurve)
    assert c.domain == pytest.approx((0, 4 * np.pi))
    np.testing.assert_allclose(c.evaluate(np.pi / 2), [0, 3, 0.25], atol=1e-12)
    np.testing.assert_allclose(c.derivative(1.0), [-3 * np.sin(1), 3 * np.cos(1), 1 / (2 * np.pi)],
                               rtol=1e-6)  # fmt: skip
    c5 = g.evaluate("helix", turns=5)
    assert c5.domain[1] == pytest.approx(10 * np.pi)


def test_parametric_z_defaults_to_zero():
    c = run("curves.parametric", x="t", y="t**2")
    np.testing.assert_allclose(c.evaluate(np.array([0.5])), [[0.5, 0.25, 0]])


def test_parametric_nan_names_the_expression_and_t():
    with pytest.raises(fg.NodeError, match=r"y = 'sqrt\(t - 0.5\)' is not finite at t = 0"):
        run("curves.parametric", x="t", y="sqrt(t - 0.5)")
    with pytest.raises(fg.NodeError, match=r"input 't'.*start < end, got \[1.0, 0.0\]"):
        run("curves.parametric", x="t", y="t", t=[1, 0])


def test_parametric_refuses_unknown_names_at_check():
    g = fg.Graph()
    g.add("c", "curves.parametric", x="cos(s)", y="t")
    with pytest.raises(fg.GraphError, match=r"input 'x'"):
        g.check()


# --------------------------------------------------------------------------- resample


def test_resample_bezier_with_uneven_speed_is_even_in_arc_length():
    # a straight Bezier whose speed varies a lot: arc length is just x
    c = run("curves.bezier", points=[[0, 0], [0.1, 0], [0.2, 0], [3, 0]])
    g, last = chain(
        ("curves.bezier", {"points": [[0, 0], [0.1, 0], [0.2, 0], [3, 0]]}),
        ("curves.resample", {"curve": "@prev", "count": 7}),
    )
    assert c.evaluate(0.5)[0] != pytest.approx(1.5)  # the parameter is not arc length
    out = np.asarray(g.evaluate(last).control_points)
    np.testing.assert_allclose(out[:, 0], np.linspace(0, 3, 7), atol=1e-10)


def test_resample_closed_catmull_rom_against_dense_arc_length():
    g, last = chain(
        ("curves.catmull_rom", {"points": BLOB, "closed": True, "spacing": "centripetal"}),
        ("curves.resample", {"curve": "@prev", "count": 40}),
    )
    curve = g.evaluate("n0")
    out = g.evaluate(last)
    assert out.closed and len(out.control_points) == 41
    pts = np.asarray(out.control_points)[:-1]
    # the points lie on the curve: find their parameters on a dense sampling
    tt = np.linspace(*curve.domain, 200001)
    dense = curve.evaluate(tt)
    nearest = np.array([np.argmin(np.linalg.norm(dense - p, axis=1)) for p in pts])
    assert np.linalg.norm(dense[nearest] - pts, axis=1).max() < 1e-3
    s = arc_lengths(curve, tt[nearest], n=200001)
    total = arc_lengths(curve, np.array([curve.domain[1]]), n=200001)[0]
    np.testing.assert_allclose(s, np.arange(40) * total / 40, atol=1e-3 * total / 40 + 1e-6)


def test_resample_polyline_spacing_and_port_errors():
    g, last = chain(
        ("curves.polyline", {"points": [[0, 0], [10, 0]]}),
        ("curves.resample", {"curve": "@prev", "spacing": 3.0}),
    )
    np.testing.assert_allclose(np.asarray(g.evaluate(last).control_points)[:, 0],
                               [0, 10 / 3, 20 / 3, 10])  # fmt: skip
    g.add("both", "curves.resample", curve="@n0", count=3, spacing=1.0)
    with pytest.raises(fg.NodeError, match=r"input 'count'.*exactly one of count and spacing"):
        g.evaluate("both")
    g.add("none", "curves.resample", curve="@n0")
    with pytest.raises(fg.NodeError, match=r"exactly one of count and spacing"):
        g.evaluate("none")
    g.add("zero", "curves.resample", curve="@n0", spacing=0.0)  # the kernel's ValueError
    with pytest.raises(fg.NodeError, match=r"input 'spacing'.*spacing must be a positive"):
        g.evaluate("zero")
    g.add("tiny", "curves.resample", curve="@n0", spacing=1e-12)
    with pytest.raises(fg.BudgetError, match=r"points, over the budget"):
        g.evaluate("tiny")


# --------------------------------------------------------------------------- offset


@pytest.mark.parametrize("order", [1, -1])
def test_offset_grows_closed_polyline_either_way(order):
    square = [[0, 0], [2, 0], [2, 2], [0, 2]][::order]
    g, last = chain(
        ("curves.polyline", {"points": square, "closed": True}),
        ("curves.offset", {"curve": "@prev", "distance": 0.5}),
    )
    out = g.evaluate(last)
    assert out.closed
    ring = shapely.Polygon(np.asarray(out.control_points)[:, :2])
    assert ring.area == pytest.approx(9.0)
    assert ring.equals(shapely.box(-0.5, -0.5, 2.5, 2.5))


def test_offset_open_is_left_of_travel_like_shapely():
    pts = [[0, 0], [3, 0], [4, 2], [2, 3]]
    g, last = chain(
        ("curves.polyline", {"points": pts}),
        ("curves.offset", {"curve": "@prev", "distance": 0.25, "miter_limit": 2.0}),
    )
    out = np.asarray(g.evaluate(last).control_points)[:, :2]
    ref = shapely.offset_curve(shapely.LineString(pts), 0.25, join_style="mitre", mitre_limit=2.0)
    np.testing.assert_allclose(out, shapely.get_coordinates(ref), atol=1e-12)


def test_offset_smooth_curve_stays_at_distance():
    g, last = chain(
        ("points.circle", {"count": 8, "radius": 3.0}),
        ("curves.catmull_rom", {"points": "@prev", "closed": True, "spacing": "centripetal"}),
        ("curves.resample", {"curve": "@prev", "count": 400}),
        ("curves.offset", {"curve": "@prev", "distance": -0.4}),
    )
    out = np.asarray(g.evaluate(last).control_points)
    base = shapely.LinearRing(np.asarray(g.evaluate("n2").control_points)[:, :2])
    d = shapely.distance(base, shapely.points(out[:, :2]))
    np.testing.assert_allclose(d, 0.4, rtol=1e-3)
    assert shapely.Polygon(out[:, :2]).area < shapely.Polygon(base).area


def test_offset_miter_limit_is_range_checked():
    g = fg.Graph()
    g.add("p", "curves.polyline", points=BLOB)
    g.add("o", "curves.offset", curve="@p", distance=1.0, miter_limit=0.5)
    with pytest.raises(fg.GraphError, match=r"input 'miter_limit': must be >= 1, got 0.5"):
        g.check()


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(3, 12),
    closed=st.booleans(),
    spacing=st.sampled_from(["uniform", "centripetal", "chordal"]),
    seed=st.integers(0, 2**31),
)
def test_random_point_sets_through_the_whole_family(n, closed, spacing, seed):
    """Catmull-Rom -> subdivide -> resample on random points: finite everywhere, and the
    spline passes through its points."""
    pts = np.random.default_rng(seed).integers(-3, 4, size=(n, 2)).astype(float)
    g = fg.Graph()
    g.add("c", "curves.catmull_rom", points=pts.tolist(), closed=closed, spacing=spacing,
          ends="clamped")  # fmt: skip
    g.add("s", "curves.subdivide", curve="@c", iterations=2)
    g.add("r", "curves.resample", curve="@c", count=20)
    try:
        c = g.evaluate("c")
    except fg.NodeError as exc:
        assert "distinct points" in str(exc)
        return
    keep = np.ones(n, bool)
    keep[1:] = np.any(pts[1:] != pts[:-1], axis=1)
    through = pts[keep]
    breaks = np.unique(np.asarray(c.knots))
    got = c.evaluate(breaks)[:, :2]
    for p in through:
        assert np.min(np.linalg.norm(got - p, axis=1)) < 1e-9
    for name in ("s", "r"):
        assert np.isfinite(np.asarray(g.evaluate(name).control_points)).all()


def test_subdivide_merges_repeated_control_points():
    # tension 1 puts each Bezier handle on its end point: the control polygon repeats every
    # through point three times, which a polyline must not keep as zero-length spans
    g, last = chain(
        ("curves.catmull_rom", {"points": BLOB, "ends": "clamped", "tension": 1.0}),
        ("curves.subdivide", {"curve": "@prev", "iterations": 0}),
    )
    np.testing.assert_allclose(np.asarray(g.evaluate(last).control_points)[:, :2], BLOB)
