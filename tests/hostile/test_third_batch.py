"""Hostile use of the third batch: the read nodes' drawings (SVG ``use``, huge paths, DXF
MINSERT grids) and the cutting shapes' counts. Each case ends as a located sentence (file,
line, node, input) before the time or memory goes, or as a correct result."""

from __future__ import annotations

from pathlib import Path

import pytest

import formgraph as fg

HEAD = "formgraph: 1\nnodes:\n"


def _read(folder: Path, name: str, data: bytes):
    (folder / name).write_bytes(data)
    (folder / "g.yaml").write_text(HEAD + f"  c: {{type: read.curves, path: {name}}}\n")
    return fg.load(folder / "g.yaml").evaluate("c")


def _svg(body: str) -> bytes:
    return (
        '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" '
        f'viewBox="0 0 100 100">{body}</svg>'
    ).encode()


# ---------------------------------------------------------------------------- cutting counts


def test_a_polygon_of_a_billion_sides_is_over_the_budget():
    # was: "MemoryError: Unable to allocate 7.45 GiB for an array with shape (1000000000,)"
    g = fg.Graph.from_text(
        HEAD + "  p: {type: curves.polygon, sides: 1000000000, radius: 1}\n", file="h.yaml"
    )
    with pytest.raises(
        fg.BudgetError,
        match=r"h.yaml:3: node 'p'.*1,000,000,000 corners, "
        r"over the budget",
    ):
        g.evaluate("p")
