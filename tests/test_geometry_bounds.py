"""geometry.bounds and geometry.fit (nodes/geometry/bounds.py, kernels/geometry/bounds.py):
exact boxes of circles, tori and splines against closed forms and dense sampling, never
the control points' box; fitting text into a box."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.kernels import nurbs
from formgraph.kernels.geometry import bounds as kb


def evaluate(**nodes):
    g = fg.Graph()
    for name, (kind, inputs) in nodes.items():
        g.add(name, kind, **inputs)
    return g


def box(geometry) -> tuple[np.ndarray, np.ndarray]:
    g = fg.Graph()
    g.add("b", "geometry.bounds", geometry=geometry)
    out = g.evaluate("b")
    assert np.allclose(np.asarray(out.size), np.subtract(out.max, out.min), rtol=0, atol=0)
    assert np.allclose(out.center, (np.asarray(out.min) + out.max) / 2, rtol=0, atol=0)
    return np.asarray(out.min), np.asarray(out.max)


def test_the_box_of_a_turned_circle_is_its_square_not_its_control_polygons():
    g = evaluate(
        c=("nurbs.circle", {"radius": 2}),
        t=("geometry.transform", {"geometry": "@c", "rotate": [0, 0, 45], "translate": [1, -1, 3]}),
    )
    c = g.evaluate("t")
    lo, hi = box(c)
    assert lo == pytest.approx([-1, -3, 3], abs=1e-12) and hi == pytest.approx([3, 1, 3], abs=1e-12)
    cp = c.control_points
    assert np.ptp(cp[:, 0]) == pytest.approx(4 * math.sqrt(2))  # its control square: 41 % more


def test_a_tilted_circle_has_the_closed_form_box():
    """A circle of radius r about unit normal n spans r sqrt(1 - n_i^2) along axis i."""
    g = evaluate(
        c=("nurbs.circle", {"radius": 1.5}),
        t=("geometry.transform", {"geometry": "@c", "rotate": [30, 50, 0]}),
    )
    lo, hi = box(g.evaluate("t"))
    r = 1.5
    ax, ay = math.radians(30), math.radians(50)
    rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    n = ry @ rx @ np.array([0, 0, 1.0])
    half = r * np.sqrt(1 - n**2)
    assert hi == pytest.approx(half, abs=1e-9 * 3) and lo == pytest.approx(-half, abs=1e-9 * 3)


def test_a_torus_surface_has_the_closed_form_box():
    g = evaluate(
        c=("nurbs.circle", {"radius": 1, "center": [3, 0, 0], "normal": [0, 1, 0]}),
        s=("nurbs.revolve", {"curve": "@c", "axis": [0, 0, 1]}),
        t=("geometry.transform", {"geometry": "@s", "rotate": [0, 0, 17], "translate": [1, 2, 3]}),
    )
    lo, hi = box(g.evaluate("t"))
    assert lo == pytest.approx([-3, -2, 2], abs=4e-9) and hi == pytest.approx([5, 6, 4], abs=4e-9)


@settings(max_examples=25, deadline=None)
@given(
    st.integers(2, 5),
    st.lists(
        st.tuples(st.floats(-10, 10), st.floats(-10, 10), st.floats(-10, 10)),
        min_size=6,
        max_size=12,
    ),
    st.lists(st.floats(0.2, 5.0), min_size=12, max_size=12),
)
def test_spline_boxes_hold_every_dense_sample_and_reach_them(degree, points, weights):
    pts = np.array(points)
    n = len(pts)
    knots = np.concatenate([np.zeros(degree), np.linspace(0, 1, n - degree + 1), np.ones(degree)])
    c = fg.NurbsCurve(pts, degree, knots, weights[:n])
    lo, hi = box(c)
    size = float(np.ptp(pts, axis=0).max())
    ref_lo, ref_hi = _dense_extremes(c)
    assert np.all(np.abs(lo - ref_lo) <= 1e-9 * size)
    assert np.all(np.abs(hi - ref_hi) <= 1e-9 * size)


def _dense_extremes(c: fg.NurbsCurve) -> tuple[np.ndarray, np.ndarray]:
    """Each coordinate's extremes by dense sampling, polished by scipy's bounded Brent
    search around the best sample (an independent reference)."""
    from scipy.optimize import minimize_scalar

    t = np.linspace(0, 1, 20_001)
    p = c.evaluate(t)
    out = np.empty((2, 3))
    for axis in range(3):
        for side, sense in ((0, 1.0), (1, -1.0)):
            i = int(np.argmin(sense * p[:, axis]))
            a, b = t[max(i - 1, 0)], t[min(i + 1, len(t) - 1)]
            r = minimize_scalar(
                lambda x, s=sense, k=axis: s * c.evaluate(x)[k],
                bounds=(a, b),
                method="bounded",
                options={"xatol": 1e-13},
            )
            out[side, axis] = sense * min(sense * p[i, axis], r.fun)
    return out[0], out[1]


def test_branch_and_bound_reaches_1e_9_of_the_size_on_a_narrow_peak():
    """A sharp cubic spike: its control point stands 3 times higher than its top."""
    c = fg.NurbsCurve(
        [[0, 0, 0], [1, 0, 0], [1.5, 3, 0], [2, 0, 0], [3, 0, 0]], 3, [0, 0, 0, 0, 0.5, 1, 1, 1, 1]
    )
    lo, hi = box(c)
    seg, _ = nurbs.decompose_bezier(c.control_points, 3, c.knots, None)
    # the exact top: the largest y of the two cubic pieces, from their derivative's roots
    tops = []
    for piece in seg:
        y = piece[:, 1]
        d = (
            np.polynomial.Polynomial(
                [y[1] - y[0], 2 * (y[0] - 2 * y[1] + y[2]), y[3] - 3 * y[2] + 3 * y[1] - y[0]]
            )
            * 3
        )
        cand = [0.0, 1.0] + [r.real for r in d.roots() if abs(r.imag) < 1e-12 and 0 <= r.real <= 1]
        b = [math.comb(3, k) for k in range(4)]
        tops += [sum(b[k] * t**k * (1 - t) ** (3 - k) * y[k] for k in range(4)) for t in cand]
    assert hi[1] == pytest.approx(max(tops), abs=1e-9 * 3)
    assert hi[1] <= max(tops) + 1e-15


def test_boxes_of_points_meshes_parametric_curves_and_lists():
    g = fg.Graph()
    g.add("p", "points.list", points=[[0, 0, 0], [1, 2, 3]])
    g.add("s", "mesh.sphere", radius=2, center=[5, 0, 0])
    g.add("h", "curves.parametric", x="cos(t)", y="sin(2 * t)", z="0", t=[0, 6.283185307179586])
    lo, hi = box(g.evaluate("h"))
    assert lo == pytest.approx([-1, -1, 0], abs=1e-12) and hi == pytest.approx([1, 1, 0], abs=1e-12)
    g.add("all", "geometry.bounds", geometry=["@p", "@s", "@h"])
    out = g.evaluate("all")
    assert out.min == pytest.approx([-1, -2, -2]) and out.max == pytest.approx([7, 2, 3])


def test_the_box_of_a_parametric_surface_is_found_by_refined_sampling():
    g = fg.Graph()
    g.add(
        "s",
        "surfaces.parametric",
        x="(2 + cos(v)) * cos(u)",
        y="(2 + cos(v)) * sin(u)",
        z="sin(v) + 0.1 * u",
        u=[0, 6],
        v=[0, 6.283185307179586],
    )
    lo, hi = box(g.evaluate("s"))
    assert lo[2] == pytest.approx(-1.0, abs=1e-10) and hi[2] == pytest.approx(1.6, abs=1e-10)
    assert hi[0] == pytest.approx(3.0, abs=1e-10)


def test_fit_puts_a_label_in_its_box_keeping_its_aspect():
    g = fg.Graph()
    g.add("t", "curves.text", text="Plate 12", size=9)
    g.add("f", "geometry.fit", geometry="@t", size=[60, 8, 0], center=[10, -5, 2])
    g.add("b", "geometry.bounds", geometry="@f")
    g.add("b0", "geometry.bounds", geometry="@t")
    b, b0 = g.evaluate("b"), g.evaluate("b0")
    assert b.center == pytest.approx([10, -5, 2], abs=1e-12)
    assert b.size[0] <= 60 + 1e-9 and b.size[1] <= 8 + 1e-9
    assert max(b.size[0] - 60, b.size[1] - 8) == pytest.approx(0, abs=1e-9)
    ratio = np.asarray(b.size[:2]) / np.asarray(b0.size[:2])
    assert ratio[0] == pytest.approx(ratio[1], rel=1e-12)
    for c in g.evaluate("f"):
        assert isinstance(c, fg.NurbsCurve)


def test_fit_without_aspect_fills_each_given_axis_and_leaves_the_others():
    g = fg.Graph()
    g.add("s", "mesh.sphere", radius=1, center=[3, 3, 3])
    g.add("f", "geometry.fit", geometry="@s", size=[4, 0, 1], keep_aspect=False)
    g.add("b", "geometry.bounds", geometry="@f")
    b = g.evaluate("b")
    assert b.size == pytest.approx([4, 2, 1]) and b.center == pytest.approx([0, 0, 0], abs=1e-12)


def test_sampled_extremes_zoom_onto_an_interior_peak():
    f = lambda t: np.column_stack([np.sin(7 * t[:, 0]), t[:, 0] * 0, t[:, 0] * 0])  # noqa: E731
    lo, hi = kb.sampled_extremes(f, np.array([0.0]), np.array([1.0]), (9,))
    assert hi[0] == pytest.approx(1.0, abs=1e-14) and lo[0] == pytest.approx(-1.0, abs=1e-14)
