"""The canvas's engine half: gestures as minimal edits of the YAML text (formgraph.studio.
textedit), the ``layout:`` section (read, never checked, in no cache key), the drawing at
given positions, the palette and the spreadsheet. The browser half: test_studio_canvas_
browser.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import formgraph as fg
from formgraph.core.registry import node_types
from formgraph.drawgraph.layout import draw_graph
from formgraph.evaluation.graph import Graph
from formgraph.language.yamlio import parse
from formgraph.studio import textedit as te
from formgraph.studio.canvas import ROWS, canvas_svg, palette, sheet

GRAPHS = Path(__file__).resolve().parent.parent / "graphs"
ALL = sorted(GRAPHS.glob("*.yaml"))
TUBE = (GRAPHS / "spiral_tube.yaml").read_text()


def _only_changed(before: str, after: str, edits: list[te.Edit]) -> None:
    """Every byte outside the edited spans is as it was (and in the same order)."""
    at = 0
    out = []
    for e in te.merged(edits):
        out.append(before[at : e.start])
        out.append(e.new)
        at = e.end
    out.append(before[at:])
    assert "".join(out) == after
    kept = [
        before[a.end : b.start]
        for a, b in zip(te.merged(edits), te.merged(edits)[1:], strict=False)
    ]
    for piece in kept:
        assert piece in after


def _nodes(text: str) -> dict:
    return parse(text).nodes


# ---------------------------------------------------------------------------- text edits


@pytest.mark.parametrize("path", ALL, ids=lambda p: p.stem)
def test_every_gesture_on_every_graph_changes_only_its_span(path):
    """Rename, move, delete and add on each graph of graphs/: the text outside the edited
    spans stays byte for byte (comments, flow lists, blank lines), and the result reads as
    the gesture says."""
    text = path.read_text()
    names = list(_nodes(text))
    first, last = names[0], names[-1]
    edits = te.rename_node(text, first, "renamed_node")
    after = te.apply(text, edits)
    _only_changed(text, after, edits)
    doc = parse(after)
    assert "renamed_node" in doc.nodes and first not in doc.nodes
    assert list(doc.nodes) == ["renamed_node", *names[1:]]  # the order kept
    for nd in doc.nodes.values():  # no wire is left to the old name
        assert f"'@{first}'" not in repr(nd.inputs) and f'"@{first}"' not in repr(nd.inputs)
    assert not any(w.startswith(f"@{first}") for w in map(str, doc.outputs.values()))
    moved = te.apply(after, te.move_nodes(after, {"renamed_node": (12.4, 30)}))
    assert parse(moved).layout == {"renamed_node": (12.0, 30.0)}
    assert moved.startswith(after.rstrip("\n"))
    edits = te.add_node(moved, "fresh", "points.circle", [], (5, 6))
    added = te.apply(moved, edits)
    _only_changed(moved, added, edits)
    assert list(parse(added).nodes)[-1] == "fresh"
    assert parse(added).layout == {"renamed_node": (12.0, 30.0), "fresh": (5.0, 6.0)}
    if len(names) > 1:
        edits = te.delete_node(text, last)
        gone = te.apply(text, edits)
        _only_changed(text, gone, edits)
        assert list(parse(gone).nodes) == names[:-1]


def test_a_wire_into_an_absent_port_a_set_port_and_a_list():
    edits = te.wire(TUBE, "section", "", "closed", "mesh")
    assert te.apply(TUBE, edits).count('mesh: "@section"') == 1
    text = "formgraph: 1\nnodes:\n  a:\n    type: points.circle  # first\n  b:\n    type: x\n"
    added = te.apply(text, te.wire(text, "a", "", "b", "points"))
    assert added == text + '    points: "@a"\n'
    listed = te.apply(added, te.wire(added, "c", "out", "b", "points", listed=True))
    assert '    points: ["@a", "@c.out"]\n' in listed
    flow = te.apply(listed, te.wire(listed, "d", "", "b", "points", listed=True))
    assert '    points: ["@a", "@c.out", "@d"]\n' in flow
    block = text + '    items:\n      - "@a"   # one\n    after: 1\n'
    more = te.apply(block, te.wire(block, "z", "", "b", "items", listed=True))
    assert '      - "@a"   # one\n      - "@z"\n    after: 1\n' in more
    param = te.apply(text, te.wire(text, "radius", "", "b", "r", ref="=radius"))
    assert param.endswith('    r: "=radius"\n')


def test_a_flow_style_node_body_takes_an_entry_in_its_braces():
    text = "formgraph: 1\nnodes:\n  a: {type: points.circle, count: 3}\n"
    out = te.apply(text, te.wire(text, "p", "", "a", "radius"))
    assert out == 'formgraph: 1\nnodes:\n  a: {type: points.circle, count: 3, radius: "@p"}\n'
    back = te.apply(out, te.unwire(out, "p", "", "a", "radius"))
    assert back == text


def test_unwire_cuts_the_entry_or_the_list_element():
    cut = te.apply(TUBE, te.unwire(TUBE, "solid", "", "print", "mesh"))
    assert '"@solid"' not in cut and cut.count("\n") == TUBE.count("\n") - 1
    text = 'formgraph: 1\nnodes:\n  b:\n    type: x\n    items: ["@a", "@c.out", "@d"]\n'
    assert '["@a", "@d"]' in te.apply(text, te.unwire(text, "c", "", "b", "items"))
    assert '["@c.out", "@d"]' in te.apply(text, te.unwire(text, "a", "", "b", "items"))
    assert '["@a", "@c.out"]' in te.apply(text, te.unwire(text, "d", "", "b", "items"))
    with pytest.raises(te.EditError, match="no wire from 'q' into 'b.items'"):
        te.unwire(text, "q", "", "b", "items")


def test_rename_keeps_each_scalars_quoting_and_outputs_and_layout():
    text = (
        "formgraph: 1\nnodes:\n  a:\n    type: points.circle\n  b:\n    type: x\n"
        "    p: '@a.points'\n    q: [\"@a\", '@ab']\noutputs:\n  out: \"@a\"\nlayout:\n"
        "  a: [1, 2]\n  ab: [3, 4]\n"
    )
    out = te.apply(text, te.rename_node(text, "a", "start"))
    assert "  start:\n" in out and "    p: '@start.points'\n" in out
    assert "q: [\"@start\", '@ab']" in out  # '@ab' is another node's wire
    assert '  out: "@start"\n' in out and "  start: [1, 2]\n  ab: [3, 4]\n" in out


@pytest.mark.parametrize(
    "new, why",
    [
        ("2a", "not a node name"),
        ("a b", "not a node name"),
        ("a\nevil: 1", "not a node name"),
        ('a"', "not a node name"),
        ("_a", "not a node name"),
        ("turns", "is taken"),
        ("section", "is taken"),
    ],
)
def test_rename_refuses_a_bad_or_taken_name(new, why):
    with pytest.raises(te.EditError, match=why):
        te.rename_node(TUBE, "mesh", new)


def test_edits_refused_with_a_sentence():
    with pytest.raises(te.EditError, match="there is no node 'ghost'"):
        te.delete_node(TUBE, "ghost")
    with pytest.raises(te.EditError, match="not valid YAML"):
        te.wire("nodes: [\n", "a", "", "b", "c")
    with pytest.raises(te.EditError, match="already a node 'mesh'"):
        te.add_node(TUBE, "mesh", "points.circle")
    with pytest.raises(te.EditError, match="flow style"):
        te.add_node("formgraph: 1\nnodes: {a: {type: x}}\n", "b", "y")


def test_edits_are_placed_in_utf16_columns_for_monaco():
    text = "# é 😀 ü\nformgraph: 1\nnodes:\n  a:   # 😀\n    type: points.circle\n"
    [e] = te.rename_node(text, "a", "b")
    w = e.where(text)
    assert (w["line0"], w["col0"], w["col1"]) == (4, 3, 4)
    [e] = te.wire(text, "z", "", "a", "count")
    assert te.apply(text, [e]).endswith('    count: "@z"\n')


def test_merged_joins_insertions_at_one_place_in_order():
    edits = [te.Edit(3, 3, "b"), te.Edit(3, 3, "c"), te.Edit(0, 1, "X")]
    assert te.merged(edits) == [te.Edit(0, 1, "X"), te.Edit(3, 3, "bc")]
    assert te.apply("0123", edits) == "X12bc3"
    with pytest.raises(te.EditError, match="overlap"):
        te.merged([te.Edit(0, 3, ""), te.Edit(2, 4, "")])


# ------------------------------------------------------------------------- layout section


def test_the_layout_section_is_read_never_checked_and_in_no_key():
    laid = TUBE + "layout:\n  mesh: [10, 20]\n  nothing: here\n  bad: [.nan, 1]\n"
    g = Graph.from_text(TUBE)
    h = Graph.from_text(laid)  # checked: the malformed entries are no problem
    assert h.layout == {"mesh": (10.0, 20.0)}  # and are passed over
    g.evaluate("solid", turns=1)
    h.memory = g.memory  # the studio's hand-over: what keeps its key is not recomputed
    h.evaluate("solid", turns=1)
    assert {s.status for s in h.stats.values()} == {"cached"}


def test_a_subgraphs_layout_does_not_change_its_digest(tmp_path):
    part = (
        "formgraph: 1\nparams:\n  r: 1.0\nnodes:\n  c:\n    type: points.circle\n"
        '    count: 6\n    radius: "=r"\noutputs:\n  pts: "@c"\n'
    )
    (tmp_path / "part.yaml").write_text(part)
    top = "formgraph: 1\nnodes:\n  p:\n    type: part.yaml\n"
    (tmp_path / "top.yaml").write_text(top)
    digest = fg.load(tmp_path / "top.yaml").node_types()["part.yaml"].digest
    (tmp_path / "part.yaml").write_text(part + "layout:\n  c: [40, 50]\n")
    assert fg.load(tmp_path / "top.yaml").node_types()["part.yaml"].digest == digest
    (tmp_path / "part.yaml").write_text(part.replace("r: 1.0", "r: 2.0"))
    assert fg.load(tmp_path / "top.yaml").node_types()["part.yaml"].digest != digest


# -------------------------------------------------------------------------------- drawing


def test_boxes_drawn_where_placed_and_the_others_below():
    g = Graph.from_text(TUBE)
    free = draw_graph(g, all_ports=True).meta["boxes"]
    assert set(free["tube"]["ports"]) == {"profile", "path", "stations"}  # every input
    assert set(draw_graph(g).meta["boxes"]["tube"]["ports"]) == {"profile", "path"}
    placed = draw_graph(g, positions={"tube": (700, 400), "mesh": (40, 90)}).meta["boxes"]
    assert (placed["tube"]["x"], placed["tube"]["y"]) == (700, 400)
    assert (placed["mesh"]["x"], placed["mesh"]["y"]) == (40, 90)
    lowest = 400 + placed["tube"]["h"]
    assert all(b["y"] > lowest for n, b in placed.items() if n not in ("tube", "mesh"))
    # a node added later does not move the placed ones
    more = Graph.from_text(
        TUBE.replace("  print:", "  extra:\n    type: points.circle\n    count: 4\n  print:")
    )
    again = draw_graph(more, positions={n: (b["x"], b["y"]) for n, b in placed.items()})
    for n, b in placed.items():
        assert (again.meta["boxes"][n]["x"], again.meta["boxes"][n]["y"]) == (b["x"], b["y"])


def test_the_file_layout_is_what_formgraph_graph_draws():
    g = Graph.from_text(TUBE + "layout:\n  tube: [333, 222]\n")
    box = draw_graph(g).meta["boxes"]["tube"]
    assert (box["x"], box["y"]) == (333, 222)


def test_the_canvas_svg_has_a_target_per_box_port_and_wire():
    g = Graph.from_text(TUBE)
    svg = canvas_svg(draw_graph(g, all_ports=True), frozenset({"mesh"}))
    assert svg.startswith("<svg")
    assert svg.count("data-node=") == len(g.nodes) + len(g.params)
    assert 'data-node="mesh" data-subgraph="1"' in svg
    assert 'data-in="tube" data-port="stations"' in svg
    assert 'data-out="solid" data-output=""' in svg
    assert svg.count('class="fg-wire-hit"') == svg.count('class="wire"') + svg.count(
        'class="param-wire"'
    )


# --------------------------------------------------------------------- palette and sheet


def test_the_palette_lists_every_type_with_its_ports():
    entries = palette(node_types())
    names = [e["name"] for e in entries]
    assert names == sorted(node_types())
    cap = next(e for e in entries if e["name"] == "mesh.cap")
    assert cap["summary"] == node_types()["mesh.cap"].summary
    assert {"name": "mesh", "type": "Mesh", "required": True} in cap["inputs"]
    offset = next(e for e in entries if e["name"] == "mesh.offset")
    assert "``" in node_types()["mesh.offset"].summary
    assert offset["summary"] == node_types()["mesh.offset"].summary.replace("``", "")


def test_the_sheet_pages_points_and_attributes():
    g = Graph.from_text(TUBE)
    mesh = g.evaluate("solid", turns=1)
    data = mesh.to_pyvista()
    s = sheet([("solid", mesh)], "points", 2)
    assert s["columns"] == ["#", "x", "y", "z", "u", "v"]
    assert s["total"] == mesh.n_vertices and s["pages"] == -(-mesh.n_vertices // ROWS)
    row = s["rows"][0]
    assert row[0] == 2 * ROWS
    np.testing.assert_allclose(row[1:4], data.points[2 * ROWS], rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(row[4], data.point_data["u"][2 * ROWS], rtol=1e-5)
    last = sheet([("solid", mesh)], "points", 10**9)  # past the end: the last page
    assert last["page"] == last["pages"] - 1 and last["rows"][-1][0] == mesh.n_vertices - 1
    faces = sheet([("solid", mesh)], "faces", 0)
    assert faces["total"] == mesh.n_faces
    assert sheet([("n", 3.0)], "points", 0) is None  # nothing with elements


def test_a_node_added_with_placeholders_is_reported_by_the_checker():
    text = te.apply(TUBE, te.add_node(TUBE, "cap", "mesh.cap", ["mesh"], (1, 2)))
    with pytest.raises(fg.GraphError, match="node 'cap', input 'mesh': expected Mesh"):
        Graph.from_text(text)


def test_only_changed_reports_a_stray_byte():
    with pytest.raises(AssertionError):
        _only_changed("abc", "abX", [te.Edit(0, 1, "a")])


def test_a_subgraph_node_opens_its_file_and_nothing_else(tmp_path):
    import types

    from formgraph.studio.canvas import Canvas
    from formgraph.studio.session import StudioSession

    part = (
        'formgraph: 1\nnodes:\n  c:\n    type: points.circle\n    count: 6\noutputs:\n  pts: "@c"\n'
    )
    (tmp_path / "part.yaml").write_text(part)
    top = tmp_path / "top.yaml"
    top.write_text("formgraph: 1\nnodes:\n  p:\n    type: part.yaml\n")
    session = StudioSession(top, out_dir=tmp_path / "out")
    assert session.open().ok
    c = Canvas(types.SimpleNamespace(session=session), bind=False)
    shown = c.read_subgraph("p")
    assert shown["text"] == part and shown["path"].endswith("part.yaml")
    assert c.read_subgraph("ghost") is None
    svg = canvas_svg(draw_graph(session.graph), frozenset({"p"}))
    assert 'data-node="p" data-subgraph="1"' in svg


def test_an_accepted_wire_is_cooked_from_the_graph_its_check_read(tmp_path, monkeypatch):
    import types

    from formgraph.evaluation.graph import Graph
    from formgraph.studio.canvas import Canvas
    from formgraph.studio.session import StudioSession

    path = tmp_path / "tube.yaml"
    path.write_text(TUBE)
    session = StudioSession(path, out_dir=tmp_path / "out")
    assert session.open().ok
    c = Canvas(types.SimpleNamespace(session=session), bind=False)
    reads, whole = [], []
    real, edit = Graph.from_text.__func__, Graph.from_edit.__func__
    monkeypatch.setattr(
        Graph, "from_text", classmethod(lambda cls, *a, **k: whole.append(1) or real(cls, *a, **k))
    )
    monkeypatch.setattr(
        Graph, "from_edit", classmethod(lambda cls, *a, **k: reads.append(1) or edit(cls, *a, **k))
    )
    text = session.text
    # the session's own version is not read again; the wired one is read once, for the
    # gesture's check (its edited node's lines only), and then cooked as read
    reply = c.answer(1, "wire", ["spiral", "", "tube", "profile"], text)
    assert '    profile: "@spiral"\n' in reply["text"] and len(reads) == 1 and not whole
    graph = c.take_checked(reply["text"])
    assert isinstance(graph, Graph) and c.take_checked(reply["text"]) is None  # once
    cooked = session.open(reply["text"], graph)
    assert len(reads) == 1 and session.graph is graph
    assert cooked.ok and session.graph.nodes["tube"] == "nurbs.sweep"
    # the next gesture's "before" is this one's "after": not read again either
    again = c.answer(2, "wire", ["section", "", "tube", "profile"], reply["text"])
    assert '    profile: "@section"\n' in again["text"] and len(reads) == 2
    # a refused wire hands nothing over: the accepted one before it still goes to the session
    bad = c.answer(3, "wire", ["section", "", "closed", "mesh"], again["text"])
    assert "expected Mesh" in bad["refused"] and "text" not in bad
    assert isinstance(c.take_checked(again["text"]), Graph)
