"""Hostile texts under a canvas wire, where the edited node is read and checked alone
(:mod:`formgraph.language.incremental`): an anchor another node aliases, a flow list that
runs on at column 0 after the last node, a tag, a text at the size limit. Each gesture's
reply, and the graph handed to the session, are those of reading and checking the whole
text (the shortcut turned off)."""

from __future__ import annotations

import types

import pytest

from formgraph.evaluation.graph import Graph
from formgraph.language import incremental, yamlio
from formgraph.studio.canvas import Canvas
from formgraph.studio.session import StudioSession

HEAD = """formgraph: 1
params:
  dz: 0.01
nodes:
  a:
    type: points.circle
    count: 8
  a2:
    type: points.circle
    count: 5
"""


def _replies(tmp_path, text: str, gestures: list[list[str]], fast: bool, monkeypatch) -> list:
    """Each gesture's reply and the graph it hands over (as comparable text), in turn."""
    if not fast:
        monkeypatch.setattr(
            Graph,
            "from_edit",
            classmethod(lambda cls, before, new, node, **k: cls.from_text(new, **k)),
        )
    path = tmp_path / ("fast" if fast else "whole") / "g.yaml"
    path.parent.mkdir()
    path.write_text(text)
    session = StudioSession(path, out_dir=path.parent / "out")
    session.open()
    canvas = Canvas(types.SimpleNamespace(session=session), bind=False)
    out = []
    for args in gestures:
        reply = canvas.answer(1, "wire", args, text)
        handed = canvas.take_checked(reply.get("text", ""))
        graph = None if handed is None else (handed.to_yaml(), handed._clean is not None)
        out.append((reply, graph))
        text = reply.get("text", text)
    monkeypatch.undo()
    return out


def _agree(tmp_path, text, gestures, monkeypatch) -> list:
    fast = _replies(tmp_path, text, gestures, True, monkeypatch)
    assert fast == _replies(tmp_path, text, gestures, False, monkeypatch)
    return fast


def test_an_anchor_in_the_wired_node_that_another_node_aliases(tmp_path, monkeypatch):
    text = HEAD + (
        '  b:\n    type: geometry.transform\n    geometry: &g "@a"\n'
        "  c:\n    type: geometry.transform\n    geometry: *g\n"
    )
    before = Graph.from_text(text)
    new = text.replace('&g "@a"', '&g "@a2"')
    assert incremental.reparse(before._read, text, new, "b", "g.yaml") is None  # read whole
    (reply, handed), *_ = _agree(tmp_path, text, [["a2", "", "b", "geometry"]], monkeypatch)
    assert handed is not None and "geometry: '@a'" in handed[0]  # c's alias, read whole


def test_a_flow_list_running_on_at_column_zero_after_the_last_node(tmp_path, monkeypatch):
    text = HEAD + '  b:\n    type: geometry.transform\n    geometry: "@a"\n'
    text += "    translate: [0, 0,\n0.01]\n"  # libyaml reads it; the node's lines end earlier
    doc = yamlio.parse(text)
    assert not doc.problems and doc.nodes["b"].raw["translate"] == [0, 0, 0.01]
    assert incremental.node_span(text, doc.nodes, "b")[1] < len(text)
    (reply, handed), *_ = _agree(tmp_path, text, [["a2", "", "b", "geometry"]], monkeypatch)
    assert "text" in reply and handed is not None


def test_a_tag_in_the_wired_node(tmp_path, monkeypatch):
    text = HEAD + '  b:\n    type: geometry.transform\n    geometry: "@a"\n'
    text += "    translate: !!python/tuple [0, 0, 1]\n"
    _agree(tmp_path, text, [["a", "", "b", "geometry"]], monkeypatch)


def test_a_text_at_the_value_limit_stays_refused(tmp_path, monkeypatch):
    text = HEAD + "".join(
        f'  n{i}:\n    type: geometry.transform\n    geometry: "@a"\n' for i in range(30)
    )
    limit = yamlio.parse(text).sizes[0] + 2  # two values more than the text holds
    monkeypatch.setattr(yamlio, "MAX_VALUES", limit)
    monkeypatch.setattr(incremental, "MAX_VALUES", limit)
    # a second wire into a port that takes a list makes a list: two values more, at the
    # limit; a new input is two more again: over it
    gestures = [["n3", "", "n4", "geometry"], ["n3", "", "n5", "scale"]]
    fast = _replies(tmp_path, text, gestures, True, monkeypatch)
    monkeypatch.setattr(yamlio, "MAX_VALUES", limit)
    monkeypatch.setattr(incremental, "MAX_VALUES", limit)
    assert fast == _replies(tmp_path, text, gestures, False, monkeypatch)
    (_, same), (over, refused) = fast
    assert same is not None and "text" in over and refused is None


@pytest.mark.parametrize("port", ["geometry", "translate", "scale"])
def test_gestures_on_a_long_chain_hand_over_what_the_whole_check_would(tmp_path, monkeypatch, port):
    chain = [
        f'  n{i}:\n    type: geometry.transform\n    geometry: "@n{i - 1}"\n' for i in range(40)
    ]
    text = HEAD + "".join(chain).replace("@n-1", "@a")
    gestures = [["n5", "", "n20", port], ["n30", "", "n20", port], ["n39", "", "n0", port]]
    _agree(tmp_path, text, gestures, monkeypatch)
