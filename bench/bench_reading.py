"""Reading graph files: a graph with a long point list, against PyYAML reading the same text.

- A 1.7 MB file of 90,000 points: ``formgraph`` composes it with libyaml, reads the long
  number array with the json module and checks the whole graph (types, values) — against
  ``yaml.load(..., Loader=yaml.CSafeLoader)``, the fastest PyYAML reading of the same text
  (Python objects only, nothing checked), and the pure-Python ``yaml.safe_load``. Ours
  includes checking the graph.
- A graph of 20,000 nodes, read and checked, against the same two.
"""

from __future__ import annotations

import numpy as np
import yaml

import formgraph as fg


def _points_text(n: int) -> str:
    rng = np.random.default_rng(0)
    rows = ", ".join(f"[{x:.2f}, {y:.2f}, {z:.1f}]" for x, y, z in rng.random((n, 3)))
    return f"formgraph: 1\nnodes:\n  p:\n    type: points.list\n    points: [{rows}]\n"


def _nodes_text(n: int) -> str:
    lines = ["formgraph: 1", "nodes:"]
    lines += [f"  p{i}: {{type: points.circle, count: 8, radius: {i + 1}}}" for i in range(n)]
    return "\n".join(lines) + "\n"


def run(table) -> None:
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    for case, text in (
        ("read a 1.7 MB graph of 90,000 points", _points_text(90_000)),
        ("read a 1.1 MB graph of 20,000 nodes", _nodes_text(20_000)),
    ):
        table.time(case, "formgraph", lambda t=text: fg.Graph.from_text(t), repeat=3)
        table.time(case, "PyYAML CSafeLoader", lambda t=text: yaml.load(t, Loader=loader))
        table.time(case, "PyYAML safe_load", lambda t=text: yaml.safe_load(t), repeat=1)
