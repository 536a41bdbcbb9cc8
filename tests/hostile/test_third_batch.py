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


# ---------------------------------------------------------------------------- DXF MINSERT


def test_a_minsert_grid_over_the_budget_is_refused_before_expanding(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new()
    doc.blocks.new("B").add_line((0, 0), (1, 1))
    doc.modelspace().add_blockref("B", (0, 0)).grid(size=(100_000, 100_000), spacing=(1, 1))
    doc.saveas(tmp_path / "a.dxf")
    # was: 10^10 copies expanded one virtual entity at a time (hung)
    with pytest.raises(
        fg.NodeError,
        match=r"node 'c', input 'path'.*a MINSERT of "
        r"10,000,000,000 copies expands to more than 1,000,000 entities",
    ):
        _read(tmp_path, "a.dxf", (tmp_path / "a.dxf").read_bytes())


def test_a_small_minsert_grid_still_expands(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new(units=4)  # millimetres
    doc.blocks.new("B").add_line((0, 0), (1, 0))
    doc.modelspace().add_blockref("B", (0, 0)).grid(size=(2, 3), spacing=(10, 20))
    doc.saveas(tmp_path / "a.dxf")
    curves = _read(tmp_path, "a.dxf", (tmp_path / "a.dxf").read_bytes())
    starts = sorted(tuple(c.control_points[0][:2]) for c in curves)
    assert starts == [(x, y) for x in (0.0, 20.0, 40.0) for y in (0.0, 10.0)]


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
