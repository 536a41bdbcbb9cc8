"""Evaluation and the cache: what computes, what comes from cache, after each kind of change."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from stubs import CALLS

import formgraph as fg


def chain(n: int = 3) -> fg.Graph:
    """x -> a1 -> a2 -> ... with param k feeding a1 and param j feeding the last."""
    g = fg.Graph()
    g.add_param("k", 1.0)
    g.add_param("j", 10.0)
    g.add("x", "stub.value", x="=k", label="x")
    prev = "x"
    for i in range(1, n + 1):
        b = "=j" if i == n else 1.0
        g.add(f"a{i}", "stub.add", a=f"@{prev}", b=b, label=f"a{i}")
        prev = f"a{i}"
    return g


def test_pull_based_evaluates_only_ancestors():
    g = chain(3)
    g.add("other", "stub.value", x=5.0, label="other")
    assert g.evaluate("a2") == 3.0
    assert CALLS == ["value:x", "add:a1", "add:a2"]
    assert set(g.stats) == {"x", "a1", "a2"}
    assert all(s.status == "computed" for s in g.stats.values())


def test_second_evaluation_is_cached():
    g = chain(3)
    assert g.evaluate("a3") == 13.0
    CALLS.clear()
    assert g.evaluate("a3") == 13.0
    assert CALLS == []
    assert g.stats["a3"].status == "cached"


def test_param_change_recomputes_exactly_what_it_reaches():
    g = chain(3)
    g.evaluate("a3")
    CALLS.clear()
    assert g.evaluate("a3", j=20.0) == 23.0  # j feeds only a3
    assert CALLS == ["add:a3"]
    assert g.stats["a3"].status == "computed"
    assert g.stats["a2"].status == "cached"
    CALLS.clear()
    assert g.evaluate("a3", k=2.0) == 14.0  # k feeds x, so everything
    assert CALLS == ["value:x", "add:a1", "add:a2", "add:a3"]


def test_override_is_for_one_call_and_set_is_lasting():
    g = chain(1)
    assert g.evaluate("a1", j=5.0) == 6.0
    assert g.params["j"] == 10.0
    assert g.evaluate("a1") == 11.0
    g.set(j=3.0)
    assert g.params["j"] == 3.0
    assert g.evaluate("a1") == 4.0


def test_early_cutoff_keeps_descendants_cached():
    g = fg.Graph()
    g.add_param("k", 1.2)
    g.add("x", "stub.value", x="=k", label="x")
    g.add("f", "stub.floor", a="@x", label="f")
    g.add("d", "stub.add", a="@f", b=1.0, label="d")
    assert g.evaluate("d") == 2.0
    CALLS.clear()
    assert g.evaluate("d", k=1.7) == 2.0  # floor(1.7) == floor(1.2)
    assert CALLS == ["value:x", "floor:f"]
    assert g.stats["d"].status == "cached"


def test_input_edit_recomputes_that_node_and_descendants():
    g = chain(2)
    g.evaluate("a2")
    CALLS.clear()
    g.set_input("a1", "b", 5.0)
    assert g.evaluate("a2") == 16.0  # 1 + 5 + j
    assert CALLS == ["add:a1", "add:a2"]


def test_list_of_wires_and_several_outputs():
    g = fg.Graph()
    for i in range(3):
        g.add(f"v{i}", "stub.value", x=float(i + 1), label=f"v{i}")
    g.add("s", "stub.sum", items=["@v0", "@v1", "@v2"])
    g.add("one", "stub.sum", items="@v2")  # a single item where a list is asked
    assert g.evaluate(["s", "one"]) == {"s": 6.0, "one": 3.0}


def test_evaluate_all_evaluates_the_sinks():
    g = chain(2)
    g.add("side", "stub.value", x=7.0, label="side")
    assert g.sinks() == ["a2", "side"]
    assert g.evaluate_all() == {"a2": 12.0, "side": 7.0}
    # the sinks are kept between runs and follow every change of the graph
    g.sinks().append("not a node")  # the caller's list is its own
    assert g.sinks() == ["a2", "side"]
    g.add("reader", "stub.sum", items=["@side"])
    assert g.sinks() == ["a2", "reader"]
    g.set_input("reader", "items", ["@a2"])
    assert g.sinks() == ["side", "reader"]
    g.remove("reader")
    assert g.sinks() == ["a2", "side"]


def test_memory_cache_is_bounded_by_bytes():
    g = fg.Graph(memory_bytes=20_000)
    g.add_param("n", 100)
    g.add("p", "stub.points", n="=n")
    for n in range(100, 110):
        g.evaluate("p", n=n)  # 100 points are 2,400 bytes each
    assert g.memory.bytes <= 20_000
    assert len(g.memory) < 10
    CALLS.clear()
    g.evaluate("p", n=109)  # the most recent survives
    assert CALLS == []


def test_outputs_are_immutable():
    g = fg.Graph()
    g.add("p", "stub.points", n=4)
    pts = g.evaluate("p")
    with pytest.raises(ValueError, match="read-only"):
        pts.xyz[0, 0] = 5.0


def test_geometry_param_from_python():
    g = fg.Graph()
    g.add_param("pts", type="Points")
    g.add("c", "curves.polyline", points="=pts")
    pts = fg.Points([[0, 0], [1, 0], [1, 1]])
    with pytest.raises(fg.GraphError, match="param 'pts' has no value"):
        g.evaluate("c")
    curve = g.evaluate("c", pts=pts)
    assert curve.degree == 1
    np.testing.assert_allclose(curve.control_points, pts.xyz)
    with pytest.raises(fg.ParamError, match="expected Points, got Mesh"):
        g.evaluate("c", pts=fg.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]))


def test_unknown_param_and_range():
    g = fg.Graph()
    g.add_param("count", 5, min=1, max=10)
    g.add("p", "stub.points", n="=count")
    with pytest.raises(fg.ParamError, match=r"unknown param 'cuont' \(did you mean 'count'\?\)"):
        g.evaluate("p", cuont=3)
    with pytest.raises(fg.ParamError, match="param 'count': must be <= 10, got 11"):
        g.set(count=11)
    with pytest.raises(fg.ParamError, match="param 'count': expected int, got float 2.5"):
        g.set(count=2.5)
    g.set(count=4.0)  # an integral float is an int
    assert g.params["count"] == 4


def test_node_errors_name_node_type_and_input():
    g = fg.Graph()
    g.add("v", "stub.fail", x=1.0)
    with pytest.raises(fg.NodeError, match=r"node 'v' \(stub.fail\): this node always fails") as e:
        g.evaluate("v")
    assert isinstance(e.value.__cause__, ValueError)
    g.add("w", "stub.fail", x=1.0, how="input")
    with pytest.raises(fg.NodeError, match=r"node 'w', input 'x' \(stub.fail\): x must be prime"):
        g.evaluate("w")
    g.add("b", "stub.fail", x=1.0, how="bug")
    with pytest.raises(fg.NodeError, match=r"IndexError") as e:
        g.evaluate("b")
    assert isinstance(e.value.__cause__, IndexError)


def test_budget_refuses_before_allocating():
    g = fg.Graph(budget=1000)
    g.add("p", "stub.points", n=1001)
    with pytest.raises(fg.BudgetError, match=r"node 'p'.*1,001 points, over the budget of 1,000"):
        g.evaluate("p")
    assert CALLS == []  # refused before the work


def test_check_reports_every_problem_at_once():
    g = fg.Graph()
    g.add("a", "stub.add", a="@nope")
    g.add("b", "stub.ad", a=1.0)
    g.add("c", "stub.add", a=1.0, c=2.0)
    g.add("d", "stub.add")
    with pytest.raises(fg.GraphError) as e:
        g.check()
    text = str(e.value)
    assert "node 'a', input 'a': wire to missing node '@nope'" in text
    assert "unknown node type 'stub.ad' (did you mean 'stub.add'?)" in text
    assert "node 'c', input 'c': 'stub.add' has no input 'c'" in text
    assert "node 'd', input 'a': missing required input (float)" in text
    assert len(e.value.problems) == 4


def test_type_mismatch_on_wire():
    g = fg.Graph()
    g.add("p", "stub.points", n=3)
    g.add("a", "stub.add", a="@p")
    with pytest.raises(fg.GraphError, match="input 'a': expected float, got Points from '@p'"):
        g.check()


def test_cycle_is_reported_with_its_path():
    g = fg.Graph()
    g.add("a", "stub.add", a="@c")
    g.add("b", "stub.add", a="@a")
    g.add("c", "stub.add", a="@b")
    with pytest.raises(fg.CycleError, match=r"cycle: a -> b -> c -> a"):
        g.check()


@settings(max_examples=25, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from(["k", "j", "edit"]),
            st.floats(-100, 100, allow_nan=False).map(lambda x: round(x, 3)),
        ),
        min_size=1,
        max_size=12,
    )
)
def test_random_edit_sequences_match_a_fresh_evaluation(edits):
    g = chain(3)
    g.add("f", "stub.floor", a="@a2", label="f")
    g.add("s", "stub.sum", items=["@a3", "@f", "@x"], label="s")
    for what, value in edits:
        if what == "edit":
            g.set_input("a1", "b", value)
        else:
            g.set(**{what: value})
        got = g.evaluate(["s", "a3"])
        fresh = fg.Graph.from_text(g.to_yaml())
        fresh.set(**g.params)
        assert fresh.evaluate(["s", "a3"]) == got


def test_list_params_act_as_vectors_in_expressions():
    g = fg.Graph()
    g.add_param("c", [1.0, 2.0, 0.0])
    g.add("pts", "points.circle", count=4, radius=1, center="=c * 2")
    g.add("same", "points.circle", count=4, radius=1, center="=c")
    np.testing.assert_allclose(g.evaluate("pts").xyz.mean(axis=0), [2, 4, 0], atol=1e-12)
    np.testing.assert_allclose(g.evaluate("same").xyz.mean(axis=0), [1, 2, 0], atol=1e-12)


def test_param_names_may_not_hide_the_language():
    g = fg.Graph()
    g.add_param("pi", 3.0)
    g.add_param("sqrt", 1.0)
    g.add("v", "stub.value", x=1.0)
    with pytest.raises(fg.GraphError) as e:
        g.check()
    assert "param 'pi' would hide the expression constant 'pi'" in str(e.value)
    assert "param 'sqrt' would hide the expression function 'sqrt'" in str(e.value)


def test_a_list_from_a_wire_joins_a_list_port():
    g = fg.Graph()
    g.add("a", "stub.value", x=1.0, label="a")
    g.add("b", "stub.value", x=2.0, label="b")
    g.add("ab", "stub.pair", a="@a", b="@b")
    g.add("s", "stub.sum", items=["@ab", "@a", 10.0])
    assert g.evaluate("s") == 1.0 + 2.0 + 1.0 + 10.0
    g.add("bad", "stub.sum", items=["@ab", "@p"])
    g.add("p", "stub.points", n=2)
    with pytest.raises(fg.GraphError, match="expected float, got Points from '@p'"):
        g.check()


def test_progress_counts_the_nodes_computed_so_far():
    g = fg.Graph()
    g.add_param("x", 1.0)
    g.add("a", "stub.value", x="=x")
    g.add("b", "stub.add", a="@a", b=1.0)
    g.add("c", "stub.add", a="@b", b=2.0)
    seen = []
    g.progress = lambda node, done, total: seen.append((node, done, total))
    g.evaluate("c")
    assert seen == [("a", 0, 3), ("b", 1, 3), ("c", 2, 3)]
    seen.clear()
    g.set(x=2.0)  # the cached ones do not count
    g.evaluate("c")
    assert [done for _, done, _ in seen] == [0, 1, 2]
    g.add("d", "stub.add", a="@c", b=0.0)
    seen.clear()
    g.evaluate("d")
    assert seen == [("d", 0, 4)]
