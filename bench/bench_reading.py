"""Reading graph files from disk: ``fg.load`` against PyYAML reading the same file.

- A 1.7 MB file of 90,000 points: ``fg.load`` reads it, composes it with libyaml, reads the
  long number array with the json module and checks the whole graph (types, values) --
  against ``yaml.load(f, Loader=yaml.CSafeLoader)``, the fastest PyYAML reading of the same
  file (Python objects only, nothing checked), and the pure-Python ``yaml.safe_load``.
- A graph of 20,000 nodes, read and checked, against the same two.

Each implementation reads the file itself (a warm page cache); pure-Python ``safe_load``
takes tens of seconds: no warm-up call, three rounds.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

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
    with tempfile.TemporaryDirectory() as d:
        for case, text, rounds in (
            ("fg.load of a 1.7 MB graph of 90,000 points", _points_text(90_000), 3),
            ("fg.load of a 1.1 MB graph of 20,000 nodes", _nodes_text(20_000), 3),
        ):
            path = Path(d) / "g.yaml"
            path.write_text(text)

            def c_loader(path=path):
                with open(path, "rb") as f:
                    return yaml.load(f, Loader=loader)

            def safe_load(path=path):
                with open(path, "rb") as f:
                    return yaml.safe_load(f)

            table.compare(
                case,
                api=lambda path=path: fg.load(path),
                references={"PyYAML CSafeLoader": c_loader, "PyYAML safe_load": safe_load},
                rounds=rounds,
                note="read, parsed and checked (types, values); the references parse only",
                warmup=False,
            )
