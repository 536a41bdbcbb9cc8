"""Hostile sizes: allocations that scale with an input are budgeted before they happen,
and what used to be a dense n x n system is now linear."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg


@pytest.mark.parametrize("node", ["nurbs.extrude", "nurbs.revolve"])
def test_a_finely_sampled_parametric_curve_enters_surfaces_in_linear_memory(node):
    # 20,000 samples: a dense interpolation took 6.3 GB and two minutes
    g = fg.Graph()
    g.add("c", "curves.parametric", x="3 + cos(t)", y="0", z="sin(t)", t=[0, 3], samples=20_000)
    g.add("s", node, curve="@c")
    s = g.evaluate("s")
    t = np.linspace(0, 3, 20_000)
    at = np.asarray(s.evaluate(np.linspace(0, 1, 20_000)[::997], 0.0))
    assert np.allclose(at[:, [0, 2]], np.column_stack([3 + np.cos(t), np.sin(t)])[::997], atol=1e-9)


def test_loft_and_sweep_take_long_parametric_curves():
    g = fg.Graph()
    g.add("a", "curves.parametric", x="cos(t)", y="sin(t)", z="0", t=[0, 6.28], samples=20_000)
    g.add("b", "curves.parametric", x="cos(t)", y="sin(t)", z="1", t=[0, 6.28], samples=20_000)
    g.add("loft", "nurbs.loft", curves=["@a", "@b"])
    g.add("p", "nurbs.circle", radius=0.1)
    g.add("sweep", "nurbs.sweep", profile="@p", path="@a")
    out = g.evaluate(["loft", "sweep"])
    assert out["loft"].control_points.shape[0] == 20_000


def test_the_interpolation_of_parametric_samples_is_budgeted():
    g = fg.Graph(budget=50_000)
    g.add("c", "curves.parametric", x="cos(t)", y="sin(t)", t=[0, 3], samples=20_000)
    g.add("s", "nurbs.extrude", curve="@c")
    with pytest.raises(fg.BudgetError, match="interpolation system of input 'curve'"):
        g.evaluate("s")


def test_a_hundred_thousand_points_interpolate_within_the_default_budget():
    t = np.linspace(0, 60, 100_000)
    g = fg.Graph()
    g.add_param("pts", type="Points")
    g.add("c", "nurbs.interpolate", points="=pts")
    pts = fg.geometry.Points(np.column_stack([np.cos(t), np.sin(t), 0.01 * t]))
    c = g.evaluate("c", pts=pts)
    assert len(c.control_points) == 100_000


def test_surface_knot_insertion_is_budgeted():
    g = fg.Graph(budget=19)  # 9 x 2 control points, 10 x 2 after the insertion
    g.add("c", "nurbs.circle")
    g.add("s", "nurbs.extrude", curve="@c")
    g.add("k", "nurbs.insert_knot", curve="@s", t=0.5, direction="v")
    with pytest.raises(fg.BudgetError):
        g.evaluate("k")
