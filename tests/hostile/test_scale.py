"""Big graphs: the run's bookkeeping stays linear in the number of nodes."""

from __future__ import annotations

import formgraph as fg


def test_progress_counts_each_computed_node_once():
    g = fg.Graph()
    n = 3000
    g.add("n0", "stub.value", x=0.0, label="0")
    for i in range(1, n):
        g.add(f"n{i}", "stub.add", a=f"@n{i - 1}", b=1.0, label=str(i))
    seen: list[tuple[str, int, int]] = []
    g.progress = lambda node, done, total: seen.append((node, done, total))
    assert g.evaluate(f"n{n - 1}") == n - 1
    assert [s[1] for s in seen] == list(range(n))  # done so far, before each node cooks
    assert {s[2] for s in seen} == {n}
    seen.clear()
    g.evaluate(f"n{n - 1}")  # all cached: nothing cooks
    assert seen == []
