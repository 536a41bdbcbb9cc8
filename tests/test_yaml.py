"""Reading graph files: checked whole, every problem with file:line, node and input."""

from __future__ import annotations

import textwrap

import pytest

import formgraph as fg


def write(tmp_path, text: str, name: str = "g.yaml"):
    p = tmp_path / name
    p.write_text(textwrap.dedent(text).lstrip())
    return p


GOOD = """
formgraph: 1
description: a chain
params:
  k: {default: 2.0, min: 0, max: 10, doc: the start}
  j: 3.0
nodes:
  x:
    type: stub.value
    x: "=k * 2"
  y:
    type: stub.add
    a: "@x"
    b: "=j"
  s:
    type: stub.sum
    items: ["@x", "@y", "=k"]
"""


def test_load_evaluate_and_params(tmp_path):
    g = fg.load(write(tmp_path, GOOD))
    assert g.params == {"k": 2.0, "j": 3.0}
    assert g.description == "a chain"
    assert g.evaluate("s") == 4.0 + 7.0 + 2.0
    assert g.evaluate("y", k=1.0) == 5.0
    assert g.param_defs["k"].doc == "the start"


def test_round_trip_keeps_order_and_equality(tmp_path):
    g = fg.load(write(tmp_path, GOOD))
    g.save(tmp_path / "copy.yaml")
    again = fg.load(tmp_path / "copy.yaml")
    assert again == g
    assert list(again.nodes) == ["x", "y", "s"]
    assert again.evaluate("s") == g.evaluate("s")
    text = (tmp_path / "copy.yaml").read_text()
    assert text.index("\n  x:") < text.index("\n  y:") < text.index("\n  s:")


def test_round_trip_of_a_graph_built_in_code(tmp_path):
    g = fg.Graph()
    g.add_param("n", 8, min=3, doc="count")
    g.add("pts", "points.circle", count="=n", radius=2, center=[1, 2])
    g.add("raw", "stub.value", x=1.0, label={"value": "@not-a-wire"})
    g.save(tmp_path / "c.yaml")
    again = fg.load(tmp_path / "c.yaml")
    assert again == g
    assert again.evaluate("raw") == 1.0
    assert again.evaluate("pts").xyz.shape == (8, 3)


def test_type_mismatch_message_names_file_line_node_input(tmp_path):
    p = write(
        tmp_path,
        """
        formgraph: 1
        nodes:
          box:
            type: stub.points
            n: 3
          loft:
            type: stub.sum
            items: "@box"
        """,
    )
    with pytest.raises(fg.GraphError) as e:
        fg.load(p)
    assert str(e.value) == (
        f"{p}:8: node 'loft', input 'items': expected list[float], got Points from '@box'"
    )


def test_unknown_type_suggests(tmp_path):
    p = write(
        tmp_path,
        """
        formgraph: 1
        nodes:
          outline:
            type: curves.polylin
            points: [[0, 0], [1, 1]]
        """,
    )
    with pytest.raises(
        fg.GraphError,
        match=r"g.yaml:4: unknown node type 'curves.polylin' "
        r"\(did you mean 'curves.polyline'\?\)",
    ):
        fg.load(p)


def test_python_tags_are_refused(tmp_path):
    p = write(
        tmp_path,
        """
        formgraph: 1
        nodes:
          x:
            type: stub.value
            x: !!python/object/apply:os.system ["echo pwned"]
        """,
    )
    with pytest.raises(
        fg.GraphError,
        match=r"g.yaml:5: node 'x', input 'x': cannot read this "
        r"value.*no !!python tags",
    ):
        fg.load(p)


def test_duplicates_and_structure(tmp_path):
    p = write(
        tmp_path,
        """
        formgraph: 1
        extra: 3
        params:
          k: 1.0
        nodes:
          x:
            type: stub.value
            x: 1.0
            x: 2.0
          x:
            type: stub.value
          k:
            type: stub.value
        """,
    )
    with pytest.raises(fg.GraphError) as e:
        fg.load(p)
    text = str(e.value)
    assert "g.yaml:2: unknown top-level key 'extra'" in text
    assert "g.yaml:9: node 'x', input 'x': input appears twice" in text
    assert "g.yaml:10: node 'x': node name appears twice" in text
    assert "node 'k': the name 'k' is both a param and a node" in text


def test_missing_version_and_bad_yaml(tmp_path):
    with pytest.raises(fg.GraphError, match="missing 'formgraph: 1'"):
        fg.load(write(tmp_path, "nodes: {}\n"))
    with pytest.raises(fg.GraphError, match=r"g.yaml:3: not valid YAML"):
        fg.load(write(tmp_path, "formgraph: 1\nnodes: [\n  - {\n"))
    with pytest.raises(fg.GraphError, match="format version 2 is not supported"):
        fg.load(write(tmp_path, "formgraph: 2\nnodes: {}\n"))


def test_expression_problems_are_reported_at_load(tmp_path):
    p = write(
        tmp_path,
        """
        formgraph: 1
        params:
          turns: 3
        nodes:
          a:
            type: stub.value
            x: "=turns.__class__"
          b:
            type: stub.value
            x: "=tunrs * 2"
          c:
            type: stub.value
            x: "=(lambda: 1)()"
          d:
            type: stub.points
            n: "=turns - 10"
        """,
    )
    with pytest.raises(fg.GraphError) as e:
        fg.load(p)
    text = str(e.value)
    assert "g.yaml:7: node 'a', input 'x': attribute is not allowed" in text
    assert "unknown param 'tunrs' (did you mean 'turns'?)" in text
    assert "g.yaml:13: node 'c', input 'x': calling this is not allowed" in text
    assert "g.yaml:16: node 'd', input 'n': must be >= 0, got -7 (from '=turns - 10')" in text


def test_wire_to_param_and_bad_wire(tmp_path):
    p = write(
        tmp_path,
        """
        formgraph: 1
        params:
          k: 1.0
        nodes:
          a:
            type: stub.value
            x: "@k"
          b:
            type: stub.value
            x: "@a.out.more"
        """,
    )
    with pytest.raises(fg.GraphError) as e:
        fg.load(p)
    assert "'@k' wires to a node, but 'k' is a param: write '=k'" in str(e.value)
    assert "'@a.out.more' is not a wire" in str(e.value)


def test_unreadable_file():
    with pytest.raises(fg.GraphError, match="cannot read the graph file"):
        fg.load("/nonexistent/graph.yaml")


def test_source_text_is_the_file_until_the_graph_changes():
    text = "formgraph: 1\n# a comment\nnodes:\n  a: {type: points.circle, radius: 2, count: 8}\n"
    g = fg.Graph.from_text(text)
    assert g.source_text() == text  # sweep workers rebuild from it: the file's lines
    g.set_input("a", "radius", 3)
    assert g.source_text() == g.to_yaml() and "radius: 3" in g.source_text()
