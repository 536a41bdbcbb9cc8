"""A graph's text edited within one node, read and checked where the edit reaches
(:mod:`formgraph.language.incremental`, :meth:`Graph.from_edit`), against reading and
checking the whole text: the same graph (every node, param, line) and the same problems, on
wires drawn across every graph in ``graphs/`` (accepted and refused ones: type mismatches,
cycles, several outputs) and on hand edits that break a node or read in context."""

from __future__ import annotations

import random
import re
from pathlib import Path

import pytest

from formgraph.core.errors import GraphError
from formgraph.core.registry import node_types
from formgraph.evaluation.graph import Graph
from formgraph.language import incremental
from formgraph.language.model import Expr, Items, Literal, Wire
from formgraph.studio import textedit as te

GRAPHS = Path(__file__).resolve().parents[1] / "graphs"
WIRES_PER_GRAPH = 12


def _input(value):
    if isinstance(value, Expr):
        return ("=", value.text)
    if isinstance(value, Items):
        return tuple(_input(i) for i in value.items)
    if isinstance(value, Wire):
        return str(value)
    assert isinstance(value, Literal)
    return ("literal", repr(value.value))


def _state(g: Graph) -> tuple:
    """Everything a graph read from text holds, in comparable form."""
    params = {
        n: (p.default, p.type_name, p.min, p.max, p.doc, p.line, p.long_form, p.choices, p.fed)
        for n, p in g._params.items()
    }
    nodes = [
        (n, nd.type, nd.raw, nd.line, nd.input_lines, nd.parse_errors, nd.repeat_raw,
         nd.simulate_raw, {p: _input(v) for p, v in nd.inputs.items()})
        for n, nd in g._nodes.items()
    ]  # fmt: skip
    return (g.description, params, nodes, g.outputs, g._output_lines, g.layout, g._values)


def _read(text: str, path: Path, before: Graph | None = None, node: str = "") -> tuple:
    """The graph of ``text`` and its check's outcome (problems, as located, or None)."""
    how = dict(file=str(path), out_dir="out")  # (checked only: nothing is written)
    if before is None:
        g = Graph.from_text(text, check=False, **how)
    else:
        g = Graph.from_edit(before, text, node, check=False, **how)
    try:
        g.check()
        outcome = None
    except GraphError as exc:
        outcome = (type(exc).__name__, [(p.where, p.message) for p in exc.problems])
    return g, outcome


def _agree(before: Graph, text: str, node: str, path: Path) -> tuple[Graph, object]:
    whole, problems = _read(text, path)
    edited, problems_edited = _read(text, path, before, node)
    assert problems_edited == problems, node
    assert _state(edited) == _state(whole), node
    return edited, problems


def _wires(g: Graph, rng: random.Random) -> list[tuple[str, str, str]]:
    """(source, node, port) for wires the canvas could draw: into inputs the node has and
    ports its type offers, from any other node (upstream, downstream: cycles) or a param."""
    types = node_types()
    names = list(g._nodes)
    out = []
    for dst in names:
        spec = types.get(g._nodes[dst].type)
        if spec is None:
            continue
        for port in spec.inputs:
            for src in rng.sample(names, min(3, len(names))):
                if src != dst:
                    out.append((src, dst, port))
    rng.shuffle(out)
    return out[:WIRES_PER_GRAPH]


@pytest.mark.parametrize("name", sorted(p.name for p in GRAPHS.glob("*.yaml")))
def test_wires_read_and_checked_where_they_reach_agree_with_the_whole(name):
    path = GRAPHS / name  # (its subgraph files beside it)
    text = path.read_text()
    before, problems = _read(text, path)
    assert problems is None
    rng = random.Random(name)
    fast = 0
    for src, dst, port in _wires(before, rng):
        whole_edits = te.wire(text, src, "", dst, port)
        within = incremental.node_span(text, before._nodes, dst)
        assert within is not None
        assert te.wire(text, src, "", dst, port, within=within) == whole_edits
        new = te.apply(text, whole_edits)
        fast += incremental.reparse(before._read, text, new, dst, str(path)) is not None
        after, problems = _agree(before, new, dst, path)
        if problems is None:  # the next edit starts from an edited graph, as gestures do
            before, text = after, new
    print(name, fast)


CHAIN = """formgraph: 1
params:
  dz: {default: 0.01}
  k: 2
nodes:
  a:
    type: points.circle
    count: 8
  line:
    type: curves.polyline
    points: "@a"
  b:
    type: geometry.transform
    geometry: "@a"
    translate: [0, 0, "=dz"]
  c:
    type: geometry.transform
    geometry: "@b"  # a step up
    translate: [0, 0, 0.01]

  d:
    type: geometry.transform
    geometry: "@c"
    scale: "=k"
  e:
    type: curves.polyline
    points: "@d"  # points only: a curve from upstream is refused here
outputs:
  top: "@d"
layout:
  a: [0, 0]
"""


def _edit(text: str, node: str, old: str, new: str) -> str:
    """``text`` with ``old`` replaced by ``new`` inside node ``node``'s lines only."""
    start = text.index(f"\n  {node}:\n") + 1
    stop = re.search(r"^  \S|^\S", text[start + 1 :], re.MULTILINE)
    end = start + 1 + stop.start() if stop else len(text)
    body = text[start:end]
    assert old in body, (old, body)
    return text[:start] + body.replace(old, new, 1) + text[end:]


HAND_EDITS = [
    # (node, old, new): accepted, refused, and read only in context
    ("c", '"@b"', '"@a"'),
    ("c", "translate: [0, 0, 0.01]", "translate: [0, 0, 0.01]\n    scale: 2"),  # a line more
    ("c", "    translate: [0, 0, 0.01]\n", ""),  # a line less
    ("c", '"@b"', '"@d"'),  # a cycle
    ("c", '"@b"', '"@ghost"'),
    ("c", '"@b"', '"@b.curve"'),
    ("c", "geometry.transform", "geometry.nope"),
    ("c", "geometry.transform", "points.circle"),  # its output type changes
    ("c", "    type: geometry.transform\n", ""),
    ("c", "0.01]", "0.01"),  # not YAML
    ("c", "translate", "geometry"),  # an input twice
    ("c", '"@b"', '&g "@b"'),  # an anchor
    ("c", "[0, 0, 0.01]", "&v [0, 0, 0.01]\n    center: *v"),  # and its alias
    ("c", "[0, 0, 0.01]", "*nowhere"),  # an alias of nothing
    ("c", "[0, 0, 0.01]", "{<<: {x: 1}}"),  # a merge key
    ("c", '"@b"', "!!python/name:os.system"),
    ("c", '"@b"', '"=k"'),
    ("c", "[0, 0, 0.01]", '"=k * 2"'),  # '*' in an expression: read whole, same result
    ("b", '"@a"', '"@line"'),  # a curve down to e, two nodes further
    ("b", '"=dz"', '"=nope"'),
    ("b", '"=dz"', '"=k"'),  # k feeds a float port now
    ("d", '"=k"', '"=dz"'),  # the last node
    ("d", '"=k"', "[1, 2]"),
    ("a", "count: 8", "count: -1"),
    ("a", "count: 8", "count: 8\n    radius: 2\n  e:\n    type: points.circle"),  # a node more
    ("d", '"@c"', '"@c"\n  d:\n    type: points.circle'),  # a node twice
]


@pytest.mark.parametrize(("node", "old", "new"), HAND_EDITS)
def test_hand_edits_of_one_node_agree_with_the_whole(node, old, new, tmp_path):
    path = tmp_path / "chain.yaml"
    path.write_text(CHAIN)
    before, problems = _read(CHAIN, path)
    assert problems is None
    _agree(before, _edit(CHAIN, node, old, new), node, path)


def test_an_anchor_elsewhere_aliased_into_the_node_reads_the_whole(tmp_path):
    text = CHAIN.replace("    count: 8\n", "    count: &n 8\n").replace(
        "translate: [0, 0, 0.01]", "translate: [0, 0, 0.01]\n    scale: *n"
    )
    path = tmp_path / "chain.yaml"
    before, problems = _read(text, path)
    assert problems is None and before._read.sizes[0] > before._read.sizes[1]
    new = _edit(text, "b", '"=dz"', "0.5")
    assert incremental.reparse(before._read, text, new, "b", str(path)) is None
    _agree(before, new, "b", path)


def test_an_edit_outside_the_node_is_not_read_as_the_node(tmp_path):
    path = tmp_path / "chain.yaml"
    before, _ = _read(CHAIN, path)
    new = _edit(CHAIN, "b", '"=dz"', "0.5").replace("count: 8", "count: 9")
    assert incremental.reparse(before._read, CHAIN, new, "b", str(path)) is None
    _agree(before, new, "b", path)


def test_the_graph_before_that_did_not_check_gives_no_shortcut(tmp_path):
    path = tmp_path / "chain.yaml"
    broken = _edit(CHAIN, "a", "count: 8", "count: -1")
    before, problems = _read(broken, path)
    assert problems is not None and before._clean is None
    _agree(before, _edit(broken, "c", '"@b"', '"@a"'), "c", path)


def test_a_wire_the_check_refuses_gets_the_whole_checks_sentence(tmp_path):
    path = tmp_path / "chain.yaml"
    before, _ = _read(CHAIN, path)
    new = _edit(CHAIN, "c", '"@b"', '"@d"')
    _, problems = _agree(before, new, "c", path)
    assert "cycle: c -> d -> c" in [message for _, message in problems[1]]
    _, problems = _agree(before, _edit(CHAIN, "b", '"@a"', '"@line"'), "b", path)
    (where, message), *_ = problems[1]
    assert (where.node, where.input) == ("e", "points")
    assert message == "expected Points, got NurbsCurve from '@d'"
