"""Budgets that count what is made, not how many nodes make it: a repeat's items times what
one item makes, a repeat's source before it runs, and what a whole run holds at once. Each
is refused before the memory is taken, as a located BudgetError."""

from __future__ import annotations

import resource
import time

import pytest

import formgraph as fg


def _graph(text: str, budget: int | None = None) -> fg.Graph:
    kwargs = {} if budget is None else {"budget": budget}
    return fg.Graph.from_text("formgraph: 1\nnodes:\n" + text, file="h.yaml", **kwargs)


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def test_a_repeat_of_big_items_is_refused_by_their_total_before_any_runs():
    before = _peak_mb()
    t0 = time.process_time()
    g = _graph("  s: {type: mesh.sphere, repeat: {i: 100}, radius: '=1 + i', segments: 2000}\n")
    with pytest.raises(
        fg.BudgetError,
        match=r"h.yaml:3: node 's', input 'repeat': repeat 'i' would run 100 items of about "
        r"[\d,]+ elements each, [\d,]+ in all, over the budget of 50,000,000",
    ):
        g.evaluate("s")
    # refused before any item runs: no memory taken, and no minutes of spheres (this
    # process's CPU seconds, to which other processes' load adds nothing, only tell that
    # from a run of 100 spheres)
    assert _peak_mb() - before < 500 and time.process_time() - t0 < 60


def test_a_repeat_of_merges_is_refused_by_their_total():
    g = _graph(
        "  b: {type: mesh.box, repeat: {i: 200}, center: ['=i', 0, 0]}\n"
        "  m: {type: mesh.merge, meshes: '@b', repeat: {k: 180}}\n",
        budget=200_000,
    )
    # 180 items fit the count (180,000 of 200,000), but each merges 1,200 faces
    with pytest.raises(
        fg.BudgetError,
        match=r"node 'm', input 'repeat': repeat 'k' would run 180 items of about 1,200 "
        r"elements each, 216,000 in all",
    ):
        g.evaluate("m")
    assert g.stats.get("m") is None or g.stats["m"].computed_items == 0


def test_a_repeat_source_too_big_to_loop_over_is_refused_before_it_runs():
    before = _peak_mb()
    g = _graph(
        "  pts: {type: points.random, count: 40000000}\n"
        "  c: {type: nurbs.circle, repeat: {p: '@pts'}, radius: 1, center: '=p'}\n"
    )
    with pytest.raises(
        fg.BudgetError,
        match=r"h.yaml:4: node 'c', input 'repeat': repeat 'p' would run about 40,000,000 items.*"
        r"40,000,000,000 in all, over the budget of 50,000,000.*refused before 'pts' runs",
    ):
        g.evaluate("c")
    assert _peak_mb() - before < 300  # 40M points would be ~1 GB


def test_the_count_message_says_it_is_over():
    g = _graph("  c: {type: nurbs.circle, repeat: {i: 60000}, radius: '=1 + i'}\n")
    with pytest.raises(fg.BudgetError) as info:
        g.evaluate("c")
    msg = str(info.value)
    assert "60,000,000 in all, and at most 50,000 items fit" in msg


def test_a_whole_run_is_bounded_by_what_it_holds():
    nodes = "".join(f"  p{i}: {{type: points.random, count: 999, seed: {i}}}\n" for i in range(8))
    g = _graph(nodes, budget=1000)
    with pytest.raises(
        fg.BudgetError,
        match=r"h.yaml:7: node 'p4', input 'count': would make 999 points while the run already "
        r"holds about 3,996 elements from earlier nodes: together over 4 x the budget of 1,000",
    ):
        g.evaluate([f"p{i}" for i in range(8)])
    # each alone, or four of them, still runs
    assert len(g.evaluate("p7")) == 999
    assert len(g.evaluate(["p0", "p1", "p2", "p3"])) == 4
