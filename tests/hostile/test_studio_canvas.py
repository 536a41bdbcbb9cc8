"""Hostile requests to the studio's canvas: names that would write YAML of their own, positions
that are not numbers, types that do not exist, texts that are not graphs. Each is refused
with a sentence or written as plain, quoted data; none writes a file (the canvas writes only
through Save)."""

from __future__ import annotations

import shutil
import types
from pathlib import Path

import pytest

from formgraph.language.yamlio import parse
from formgraph.studio import textedit as te
from formgraph.studio.canvas import Canvas
from formgraph.studio.session import StudioSession

TUBE = Path(__file__).resolve().parents[2] / "graphs" / "spiral_tube.yaml"


@pytest.fixture
def canvas(tmp_path):
    path = tmp_path / "tube.yaml"
    shutil.copy(TUBE, path)
    session = StudioSession(path, out_dir=tmp_path / "out")
    c = Canvas(types.SimpleNamespace(session=session), bind=False)  # (no trame page)
    return c


def _files(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.mark.parametrize(
    "op, args, said",
    [
        ("rename", ["mesh", "x:\n  evil: 1"], "not a node name"),
        ("rename", ["mesh", "a' b"], "not a node name"),
        ("rename", ["mesh", "a" * 10 + "\u2028"], "not a node name"),
        ("rename", ["ghost", "b"], "no node 'ghost'"),
        ("wire", ["section", "", "closed", "mesh: 1\n    evil"], "not a port name"),
        ("wire", ["section", "", "ghost", "mesh"], "no node 'ghost'"),
        ("wire", ["mesh", "", "mesh", "surface"], "its own output"),
        ("move", ["mesh", float("nan"), 1], "two finite numbers"),
        ("move", ["mesh", float("inf"), 1], "two finite numbers"),
        ("move", ["mesh", "1e999", 1], "two finite numbers"),
        ("move", ["ghost", 1, 1], "no node 'ghost'"),
        ("add", ["os.system", 1, 1], "no node type 'os.system'"),
        ("add", ["mesh.cap\nevil: 1", 1, 1], "no node type"),
        ("add", ["mesh.cap", "x", 1], "not understood"),
        ("delete", ["ghost"], "no node 'ghost'"),
        ("unwire", ["turns", "spiral.t"], "edit it in the text"),
        ("bogus", [], "not understood"),
    ],
)
def test_hostile_gestures_are_refused_with_a_sentence(canvas, tmp_path, op, args, said):
    before = _files(tmp_path)
    text = TUBE.read_text()
    reply = canvas.answer(1, op, args, text)
    assert said in reply["refused"] and "edits" not in reply
    assert _files(tmp_path) == before  # nothing written


def test_a_hostile_wire_source_is_written_as_quoted_data(canvas):
    text = TUBE.read_text()
    src = 'a"\n  evil: 1 #'
    reply = canvas.answer(2, "wire", [src, "", "closed", "mesh"], text)
    # refused by the checker (no such node), the sentence being the checker's own
    assert "is not a wire" in reply["refused"] and reply["port"] == ["closed", "mesh"]
    out = te.apply(text, te.wire(text, src, "", "closed", "mesh"))
    nodes = parse(out).nodes
    assert set(nodes) == set(parse(text).nodes)  # no node or key of its own
    assert "evil" not in nodes["closed"].inputs


def test_a_position_far_out_is_kept_within_the_page(canvas):
    reply = canvas.answer(3, "move", ["mesh", 1e300, -5], TUBE.read_text())
    assert parse(reply["text"]).layout == {"mesh": (1e6, 0.0)}


def test_texts_that_are_not_graphs(canvas):
    for text in ("", "- a\n- b\n", "nodes: [\n", "formgraph: 1\nnodes: {a: {type: x}}\n"):
        reply = canvas.answer(4, "delete", ["a"], text)
        assert reply["refused"]


def test_a_layout_section_cannot_smuggle_problems_or_values(tmp_path):
    text = TUBE.read_text() + (
        "layout:\n  mesh: !!python/object:os.system [1, 2]\n  big: [1e999, 1]\n"
        "  deep: [[[[1]]], 2]\n"
    )
    doc = parse(text)
    assert doc.layout == {}  # (the tagged entry is no position either)
    assert any("python" in p.message for p in doc.problems)  # the tag, refused as anywhere
