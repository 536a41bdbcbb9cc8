"""Hostile simulations: malformed simulate: mappings, step counts that would run for
hours, growth that would allocate without end, and parameters that break the kernels
are each a located error before the work, never a traceback or a hang."""

from __future__ import annotations

import pytest

import formgraph as fg


@pytest.mark.parametrize(
    ("simulate", "message"),
    [
        ("[curve, '@seed', 3]", "simulate takes state, from and steps"),
        ("{state: 3, from: '@seed', steps: 3}", "simulate's state is the name of an input"),
        ("{state: curve, from: '@seed', steps: true}", "simulate's steps is a count"),
        (
            "{state: curve, from: '@seed', steps: 2.5}",
            "steps is a count (an int >= 0), got float 2.5",
        ),
        ("{state: curve, from: '@seed', steps: '=1 / 0'}", "fails with the param defaults"),
        ("{state: curve, from: '@nowhere', steps: 3}", "wire to missing node '@nowhere'"),
        ("{state: curve, from: '@seed', steps: 3, speed: 2}", "simulate has no 'speed'"),
    ],
)
def test_malformed_simulations_are_located(simulate: str, message: str):
    text = f"""\
formgraph: 1
nodes:
  seed: {{type: nurbs.circle}}
  grown:
    type: curves.grow
    simulate: {simulate}
"""
    with pytest.raises(fg.GraphError) as err:
        fg.Graph.from_text(text)
    assert message in str(err.value) and "<graph>:6: node 'grown', input 'simulate'" in str(
        err.value
    )


def test_a_step_count_from_a_param_is_budgeted_before_anything_runs():
    text = """\
formgraph: 1
params: {n: 3}
nodes:
  seed: {type: nurbs.circle}
  grown: {type: curves.grow, simulate: {state: curve, from: "@seed", steps: "=n"}}
"""
    g = fg.Graph.from_text(text)
    with pytest.raises(fg.BudgetError, match="simulate would run 1,000,000,000,000 steps"):
        g.evaluate("grown", n=10**12)
    assert g.stats == {} or "seed" not in g.stats


def test_a_tiny_split_is_refused_before_the_points_are_made():
    g = fg.Graph()
    g.add("seed", "nurbs.circle", radius=3)
    g.add(
        "grown", "curves.grow", split=1e-6, simulate={"state": "curve", "from": "@seed", "steps": 2}
    )
    with pytest.raises(fg.BudgetError, match="elements \\(growing points\\)"):
        g.evaluate("grown")


def test_a_radius_far_below_the_spacing_still_steps_and_stays_simple():
    import numpy as np
    import shapely

    g = fg.Graph()
    g.add("seed", "nurbs.circle", radius=1e6)
    g.add(
        "grown",
        "curves.grow",
        split=1e6,
        radius=1e-9,
        simulate={"state": "curve", "from": "@seed", "steps": 5},
    )
    p = np.asarray(g.evaluate("grown").control_points)[:-1, :2]
    assert shapely.LinearRing(p).is_simple


def test_an_enormous_load_stays_finite_or_is_refused():
    g = fg.Graph()
    g.add("net", "mesh.plane", divisions=[4, 4])
    g.add(
        "hang",
        "mesh.relax",
        load=[0, 0, -1e300],
        anchors=[0],
        reference="@net",
        simulate={"state": "mesh", "from": "@net", "steps": 3},
    )
    try:
        out = g.evaluate("hang")
    except fg.NodeError as exc:
        assert "diverged" in str(exc) or "finite" in str(exc)
    else:
        assert out.vertices.size and (abs(out.vertices) < float("inf")).all()
