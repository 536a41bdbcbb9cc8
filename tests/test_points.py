"""Point sources."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n")


def test_list_accepts_2d_and_3d():
    pts = run("points.list", points=[[0, 0], [1, 2, 3]])
    np.testing.assert_array_equal(pts.xyz, [[0, 0, 0], [1, 2, 3]])
    assert np.asarray(pts).shape == (2, 3)


def test_list_rejects_ragged_input():
    g = fg.Graph()
    g.add("n", "points.list", points=[[0, 0], [1]])
    with pytest.raises(fg.GraphError, match="input 'points': expected Points"):
        g.check()


@settings(max_examples=30, deadline=None)
@given(
    st.integers(1, 6),
    st.integers(1, 6),
    st.integers(1, 4),
    st.floats(0.1, 5),
    st.lists(st.floats(-10, 10), min_size=3, max_size=3),
)
def test_grid_counts_order_and_spacing(nx, ny, nz, spacing, origin):
    pts = run("points.grid", nx=nx, ny=ny, nz=nz, spacing=spacing, origin=origin).xyz
    assert pts.shape == (nx * ny * nz, 3)
    np.testing.assert_allclose(pts[0], origin)
    np.testing.assert_allclose(
        pts.max(axis=0) - pts.min(axis=0),
        [(nx - 1) * spacing, (ny - 1) * spacing, (nz - 1) * spacing],
        atol=1e-9,
    )
    if nx > 1:  # x varies fastest
        np.testing.assert_allclose(pts[1] - pts[0], [spacing, 0, 0], atol=1e-12)


def test_grid_per_axis_spacing():
    pts = run("points.grid", nx=2, ny=2, spacing=[1, 2, 3]).xyz
    np.testing.assert_array_equal(pts, [[0, 0, 0], [1, 0, 0], [0, 2, 0], [1, 2, 0]])


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 200), st.floats(0.01, 100))
def test_circle_is_on_the_circle_and_counter_clockwise(count, radius):
    pts = run("points.circle", count=count, radius=radius, center=[1, -2]).xyz
    d = pts - [1, -2, 0]
    np.testing.assert_allclose(np.hypot(d[:, 0], d[:, 1]), radius, rtol=1e-12)
    np.testing.assert_allclose(pts[0], [1 + radius, -2, 0], atol=1e-12 * radius)
    if count >= 3:
        angles = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
        assert np.all(np.diff(angles) > 0)


def test_random_is_reproducible_and_in_the_box():
    a = run("points.random", count=500, seed=7, min=[-1, 0, 2], max=[1, 5, 3]).xyz
    b = run("points.random", count=500, seed=7, min=[-1, 0, 2], max=[1, 5, 3]).xyz
    c = run("points.random", count=500, seed=8, min=[-1, 0, 2], max=[1, 5, 3]).xyz
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert np.all(a >= [-1, 0, 2]) and np.all(a <= [1, 5, 3])
    # the first values are pinned: the generator's stream is part of the contract
    expected = np.random.Generator(np.random.PCG64(7)).random((500, 3)) * [2, 5, 1] + [-1, 0, 2]
    np.testing.assert_array_equal(a, expected)


def test_random_bad_box():
    g = fg.Graph()
    g.add("n", "points.random", count=3, min=[1, 1, 1], max=[0, 2, 2])
    with pytest.raises(fg.NodeError, match=r"max \[0.0, 2.0, 2.0\] is below min"):
        g.evaluate("n")


def test_count_is_range_checked_and_budgeted():
    g = fg.Graph(budget=100)
    g.add("n", "points.circle", count=0)
    with pytest.raises(fg.GraphError, match="input 'count': must be >= 1, got 0"):
        g.check()
    g.add("n", "points.random", count=101)
    with pytest.raises(fg.BudgetError, match="101 points, over the budget of 100"):
        g.evaluate("n")
