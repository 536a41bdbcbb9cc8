"""Hostile use of the third batch: the read nodes' drawings (SVG ``use``, huge paths, DXF
MINSERT grids) and the cutting shapes' counts. Each case ends as a located sentence (file,
line, node, input) before the time or memory goes, or as a correct result."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import formgraph as fg
from formgraph.kernels.io import svg_read

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


# ---------------------------------------------------------------------------- SVG use


@pytest.mark.parametrize(
    "body",
    [
        '<g id="a"><use href="#a"/><path d="M0 0 L1 1"/></g>',
        '<defs><g id="a"><use href="#b"/></g><g id="b"><use href="#a"/></g></defs><use href="#a"/>',
    ],
    ids=["itself", "a cycle"],
)
def test_a_use_that_contains_itself_is_refused_by_name(tmp_path, body):
    # was: "not an SVG document (RecursionError: maximum recursion depth exceeded ...)"
    with pytest.raises(
        fg.NodeError,
        match=r"g.yaml:3: node 'c', input 'path'.*'use' refers "
        r"to an element that contains it \(id 'a'\)",
    ):
        _read(tmp_path, "a.svg", _svg(body))


def test_uses_that_double_per_level_are_refused_before_expanding(tmp_path):
    # was: svgelements expanded 2^40 copies (a 3 KB file hung)
    levels = "".join(
        f'<g id="p{i + 1}"><use href="#p{i}"/><use href="#p{i}"/></g>' for i in range(40)
    )
    body = f'<defs><path id="p0" d="M0 0 L1 1"/>{levels}</defs><use href="#p40"/>'
    with pytest.raises(
        fg.NodeError,
        match=r"'use' references expand to more than 250,000 "
        r"elements, over the budget",
    ):
        _read(tmp_path, "a.svg", _svg(body))


def test_a_use_draws_its_copy_where_it_is_placed(tmp_path):
    # was: nothing (a Use is not a Group, so the walk skipped it): an empty drawing
    body = (
        '<defs><path id="p0" d="M0 0 L1 1"/></defs><use href="#p0"/>'
        '<g transform="translate(5 0)"><use href="#p0" x="3"/></g>'
    )
    curves = _read(tmp_path, "a.svg", _svg(body))
    starts = sorted(c.control_points[0][0] for c in curves)
    np.testing.assert_allclose(starts, [0.0, 8.0], atol=1e-9)
    for c in curves:  # the copy's own segment, a unit diagonal, flipped to y up
        np.testing.assert_allclose(np.diff(c.control_points, axis=0), [[1.0, -1.0, 0.0]], atol=1e-9)


def test_a_path_of_millions_of_numbers_is_refused_before_parsing(tmp_path, monkeypatch):
    # was: 3,000,000 "L1 1" segments (15 MB) ran past 25 s in svgelements' Python parser;
    # the budget is lowered here so the case stays small
    monkeypatch.setattr(svg_read, "MAX_NUMBERS", 1_000, raising=False)
    body = '<path d="M0 0 ' + "L1 1 " * 600 + '"/>'
    with pytest.raises(fg.NodeError, match=r"holds 1,2\d\d numbers .*over the budget of 1,000"):
        _read(tmp_path, "a.svg", _svg(body))


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
        match=r"node 'c', input 'path'.*blocks expand to 10,000,000,001 entities, over the "
        r"budget of 1,000,000: INSERT \w+ of block 'B' \(10,000,000,000 copies, a MINSERT's "
        r"rows x columns\) alone makes 10,000,000,000",
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
        match=r"h.yaml:3: node 'p'.*1,000,000,000 polygon corners, "
        r"over the budget",
    ):
        g.evaluate("p")
