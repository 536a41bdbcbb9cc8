"""simulate: on any node — each step cached under its own key (raising steps runs only the
new ones), frames, 'step' in expressions, the check (state types, steps), budgets before
anything runs, save/schema round trips, and how stats, --profile and the drawing show it.

Stub nodes with a run record (tests/stubs.py): stub.add steps a number (a + b)."""

from __future__ import annotations

import json

import jsonschema
import pytest
import yaml
from stubs import CALLS

import formgraph as fg
from formgraph.cli.main import main
from formgraph.drawgraph.layout import draw_graph, node_marks
from formgraph.language.catalogue import json_schema

COUNT = """\
formgraph: 1
params:
  steps: {default: 20, min: 0, max: 500}
  rate: 1.0
nodes:
  start: {type: stub.value, x: 0.5, label: start}
  count:
    type: stub.add
    simulate: {state: a, from: "@start", steps: "=steps"}
    a: "=a"
    b: "=rate"
    label: count
"""


def calls(label: str) -> int:
    return CALLS.count(f"add:{label}")


def test_raising_steps_runs_only_the_new_steps_and_lowering_runs_none():
    g = fg.Graph.from_text(COUNT)
    assert g.evaluate("count") == 20.5  # 0.5, then + 1 twenty times
    st = g.stats["count"]
    assert (st.status, st.items, st.computed_items, st.unit) == ("computed", 20, 20, "steps")
    assert calls("count") == 20
    CALLS.clear()
    assert g.evaluate("count", steps=25) == 25.5
    st = g.stats["count"]
    assert (st.items, st.computed_items) == (25, 5) and calls("count") == 5
    CALLS.clear()
    assert g.evaluate("count", steps=22) == 22.5  # step 22 is cached
    st = g.stats["count"]
    assert (st.status, st.items, st.computed_items) == ("cached", 22, 0) and calls("count") == 0


def test_a_changed_input_recomputes_from_step_one_and_an_unrelated_one_nothing():
    g = fg.Graph.from_text(COUNT)
    g.evaluate("count")
    CALLS.clear()
    assert g.evaluate("count", rate=2.0) == 40.5
    assert g.stats["count"].computed_items == 20 and calls("count") == 20
    CALLS.clear()
    g.set_input("start", "x", 1.5)  # a new step 0
    assert g.evaluate("count", rate=2.0) == 41.5 and calls("count") == 20
    CALLS.clear()
    g.add("other", "stub.value", x=3.0)
    assert g.evaluate("count", rate=2.0) == 41.5 and calls("count") == 0


def test_step_is_visible_in_expressions_and_frames_hold_every_step():
    g = fg.Graph.from_text(COUNT.replace('b: "=rate"', 'b: "=step * rate"'))
    g.add("frames", "stub.sum", items="@count.frames", label="frames")
    n = 20
    assert g.evaluate("count") == 0.5 + n * (n + 1) / 2
    partial = [0.5 + k * (k + 1) / 2 for k in range(1, n + 1)]
    assert g.evaluate("frames") == pytest.approx(sum(partial))
    CALLS.clear()
    # the frames come from the caches: nothing steps again
    g.set_input("frames", "label", "again")
    assert g.evaluate("frames") == pytest.approx(sum(partial)) and calls("count") == 0


def test_frames_lost_from_the_caches_are_recomputed_from_the_step_before():
    g = fg.Graph.from_text(COUNT, memory_bytes=1 << 20)
    g.add("frames", "stub.sum", items="@count.frames", label="frames")
    g.evaluate("count")
    g.memory.clear()
    CALLS.clear()
    assert g.evaluate("frames") == pytest.approx(sum(0.5 + k for k in range(1, 21)))
    assert calls("count") == 20


def test_zero_steps_is_the_start_and_no_frames():
    g = fg.Graph.from_text(COUNT)
    g.add("frames", "stub.sum", items="@count.frames", label="frames")
    assert g.evaluate("count", steps=0) == 0.5
    assert g.evaluate("frames", steps=0) == 0.0
    assert calls("count") == 0


def test_the_disk_cache_keeps_steps_across_graphs(tmp_path):
    g = fg.Graph.from_text(COUNT, cache_dir=tmp_path / "cache")
    g.evaluate("count")
    CALLS.clear()
    fresh = fg.Graph.from_text(COUNT, cache_dir=tmp_path / "cache")
    assert fresh.evaluate("count", steps=23) == 23.5
    assert fresh.stats["count"].computed_items == 3 and calls("count") == 3


def test_each_run_is_the_same():
    text = """\
formgraph: 1
nodes:
  seed: {type: nurbs.circle, radius: 4}
  ring: {type: curves.resample, curve: "@seed", count: 30}
  grown:
    type: curves.grow
    simulate: {state: curve, from: "@ring", steps: 12}
"""
    a = fg.Graph.from_text(text).evaluate("grown")
    b = fg.Graph.from_text(text).evaluate("grown")
    assert a.control_points.tobytes() == b.control_points.tobytes()


@pytest.mark.parametrize(
    ("node", "message"),
    [
        (
            "  s: {type: stub.points, n: 3, simulate: {state: n, from: 3, steps: 2}}",
            "the state input 'n' (int) cannot take the node's own output (Points)",
        ),
        (
            "  s: {type: stub.add, simulate: {state: a, from: '@pts', steps: 2}}",
            "from: expected float, got Points from '@pts'",
        ),
        (
            "  s: {type: stub.split, simulate: {state: x, from: 1, steps: 2}}",
            "simulate needs a node with one output",
        ),
        (
            "  s: {type: stub.add, simulate: {state: c, from: 1, steps: 2}}",
            "'stub.add' has no input 'c' to take the state; its inputs are a, b, label",
        ),
        (
            "  s: {type: stub.add, a: 3, simulate: {state: a, from: 1, steps: 2}}",
            "input 'a' is the simulation's state (the previous step's output): leave it out",
        ),
        (
            "  s: {type: stub.add, repeat: {i: 2}, simulate: {state: a, from: 1, steps: 2}}",
            "a node cannot both repeat and simulate",
        ),
        (
            "  s: {type: stub.add, simulate: {state: a, from: 1, steps: -2}}",
            "steps must be >= 0, got -2",
        ),
        (
            "  s: {type: stub.add, simulate: {state: a, from: 1, steps: '@pts'}}",
            "steps is a count known before anything runs",
        ),
        (
            "  s: {type: stub.add, simulate: {state: a, from: 1, steps: '=stepz'}}",
            "steps: expression '=stepz' names unknown param 'stepz'",
        ),
        (
            "  s: {type: stub.add, simulate: {state: a, from: 1}}",
            "simulate needs steps: it takes state, from and steps",
        ),
        (
            "  s: {type: stub.add, b: '=steps', simulate: {state: a, from: 1, steps: 2}}",
            "names unknown param 'steps'",
        ),
    ],
)
def test_simulate_problems_are_reported_at_their_node(node: str, message: str):
    text = f"formgraph: 1\nnodes:\n  pts: {{type: stub.points, n: 2}}\n{node}\n"
    g = fg.Graph.from_text(text, check=False)
    with pytest.raises(fg.GraphError) as err:
        g.check()
    assert message in str(err.value)
    assert "<graph>:4: node 's'" in str(err.value)


def test_frames_of_a_node_that_does_not_simulate_is_a_problem_and_types_follow():
    text = COUNT + "  one: {type: stub.value, x: '@count.frames'}\n"
    with pytest.raises(
        fg.GraphError, match=r"expected float, got list\[float\] from '@count.frames'"
    ):
        fg.Graph.from_text(text)
    text = COUNT + "  bad: {type: stub.sum, items: '@start.frames'}\n"
    with pytest.raises(fg.GraphError, match="has a single output"):
        fg.Graph.from_text(text)


def test_a_param_named_step_is_refused_on_a_simulated_node():
    text = COUNT.replace("  rate: 1.0", "  rate: 1.0\n  step: 2")
    with pytest.raises(fg.GraphError, match="param 'step' would be hidden"):
        fg.Graph.from_text(text)


def test_the_budget_refuses_too_many_steps_before_anything_runs():
    g = fg.Graph.from_text(COUNT, budget=100_000)
    CALLS.clear()
    with pytest.raises(fg.BudgetError, match=r"simulate would run 500 steps.*at most 100 steps"):
        g.evaluate("count", steps=500)
    assert CALLS == []  # not even the start ran


def test_the_budget_counts_steps_times_the_state_before_the_first_step():
    text = """\
formgraph: 1
nodes:
  net: {type: mesh.plane, size: [10, 10], divisions: [40, 40]}
  hang:
    type: mesh.relax
    simulate: {state: mesh, from: "@net", steps: 90}
    reference: "@net"
"""
    g = fg.Graph.from_text(text, budget=200_000)
    with pytest.raises(fg.BudgetError, match=r"90 steps on a state of 3,281 elements"):
        g.evaluate("hang")
    assert "hang" not in g.stats


def test_a_failing_step_says_which():
    text = "formgraph: 1\nnodes:\n  f: {type: stub.fail, simulate: {state: x, from: 1, steps: 3}}\n"
    with pytest.raises(
        fg.NodeError, match=r"node 'f' \(stub.fail\): step 1: this node always fails"
    ):
        fg.Graph.from_text(text).evaluate("f")


def test_save_round_trips_and_the_schema_knows_simulate(tmp_path):
    g = fg.Graph.from_text(COUNT)
    path = tmp_path / "count.yaml"
    g.save(path)
    again = fg.load(path)
    assert again == g
    assert again.evaluate("count") == 20.5
    data = yaml.safe_load(path.read_text())
    assert data["nodes"]["count"]["simulate"] == {"state": "a", "from": "@start", "steps": "=steps"}
    schema = json_schema()
    json.dumps(schema)
    check = jsonschema.Draft202012Validator(schema)  # (validate() would check the schema too)
    check.validate(data)
    data["nodes"]["count"]["simulate"] = {"state": "a", "from": "@start"}
    with pytest.raises(jsonschema.ValidationError):
        check.validate(data)


def test_set_input_changes_and_removes_a_simulation():
    g = fg.Graph.from_text(COUNT)
    g.set_input("count", "simulate", {"state": "a", "from": 2.0, "steps": 3})
    assert g.evaluate("count") == 5.0
    g.set_input("count", "simulate", None)
    g.set_input("count", "a", 1.0)
    assert g.evaluate("count") == 2.0 and g.stats["count"].items is None


def test_profile_and_drawing_show_steps(tmp_path, capsys):
    path = tmp_path / "count.yaml"
    path.write_text(COUNT)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--profile", "--no-cache"]) == 0
    assert "20 steps, 20/20 computed" in capsys.readouterr().out
    g = fg.load(path)
    assert node_marks(g, "count") == ["simulate a"]
    assert main(["graph", str(path), "-o", str(tmp_path / "g.svg")]) == 0
    svg = (tmp_path / "g.svg").read_text()
    assert "simulate a" in svg and "frames" in svg and "stack" in svg


def test_plans_key_the_steps_and_compute_step_runs_only_the_new_ones():
    # the sweep's path: keys before anything runs, then each node from its inputs
    g = fg.Graph.from_text(COUNT)
    done: dict[str, object] = {}
    for steps, computed in ((7, 7), (9, 2)):
        plan = g.plan("count", steps=steps)
        assert [s.name for s in plan] == ["start", "count"]
        for step in plan:
            value, st = g.compute_step(step, {u: done[u] for u in step.upstream}, steps=steps)
            done[step.name] = value
        assert done["count"] == steps + 0.5
        assert (st.items, st.computed_items) == (steps, computed)
    assert g.plan("count", steps=9)[-1].key == g.plan("count", steps=9)[-1].key
    assert g.plan("count", steps=9)[-1].key != g.plan("count", steps=8)[-1].key


def test_a_subgraph_node_can_simulate(tmp_path):
    (tmp_path / "step.yaml").write_text(
        """\
formgraph: 1
params:
  curve: {type: Curve}
  amount: 1.0
nodes:
  moved: {type: geometry.transform, geometry: "=curve", translate: ["=amount", 0, 0]}
outputs:
  curve: "@moved"
"""
    )
    (tmp_path / "main.yaml").write_text(
        """\
formgraph: 1
params:
  steps: {default: 4, min: 0, max: 20}
nodes:
  c: {type: nurbs.circle}
  walk:
    type: step.yaml
    simulate: {state: curve, from: "@c", steps: "=steps"}
    amount: "=step"
"""
    )
    g = fg.load(tmp_path / "main.yaml")
    assert g.evaluate("walk").evaluate(0.0)[0] == pytest.approx(1 + (1 + 2 + 3 + 4))
    assert g.evaluate("walk", steps=6).evaluate(0.0)[0] == pytest.approx(1 + 21)
    assert g.stats["walk"].computed_items == 2


def test_the_drawing_after_a_run_says_how_many_steps_ran():
    g = fg.Graph.from_text(COUNT)
    g.evaluate("count")
    g.evaluate("count", steps=25)
    assert "computed 5/25 steps" in draw_graph(g).svg


LADDER = """\
formgraph: 1
params:
  steps: {type: int, default: 200, min: 0, max: 2000}
nodes:
  net: {type: mesh.plane, size: [8, 1], divisions: [16, 1]}
  hang:
    type: mesh.relax
    simulate: {state: mesh, from: "@net", steps: "=steps"}
    anchors: [0, 1, 32, 33]          # the ends of both rails (vertex ix * 2 + iy)
    load: [0, 0, -0.5]               # 1 a unit of the rails' unstretched length (0.5 apart)
    stiffness: 40.0
"""


def test_a_net_comes_to_rest_without_a_reference():
    # today each step took its own edge lengths as the rest lengths: the net never rests
    # (53,000 units of sag on a 10-unit net after 400 steps)
    import numpy as np
    from test_kernel_relax import elastic_catenary

    g = fg.Graph.from_text(LADDER)
    hung = g.evaluate("hang")
    assert np.abs(hung.point_data["relax_velocity"]).max() < 1e-9  # at rest
    after = g.evaluate("hang", steps=201)
    assert np.abs(after.vertices - hung.vertices).max() < 1e-9
    # each rail of a ladder whose rungs keep their length hangs as an elastic catenary of
    # unstretched length 8 between points 8 apart: Irvine's closed form (as the kernel's
    # chain test), to the point loads' second-order error
    links, a, length = 16, 4.0, 8.0
    rail = hung.vertices[::2]
    s = np.linspace(-length / 2, length / 2, links + 1)
    assert np.allclose(rail[:, 1], -0.5)  # (the rungs keep the rails in their planes)
    cx, cy = elastic_catenary(a, length, w=1.0, ea=40.0)(s)
    sag = -rail[:, 2].min()
    assert 0.3 < sag < 2.0
    err = max(np.abs(rail[:, 0] - cx).max(), np.abs(rail[:, 2] - rail[8, 2] - cy).max())
    assert err < 2.0 / links**2, err
    # the same as wiring the first state as the reference, bit for bit
    wired = fg.Graph.from_text(
        LADDER.replace("    stiffness", '    reference: "@net"\n    stiffness')
    )
    assert wired.evaluate("hang").vertices.tobytes() == hung.vertices.tobytes()
