"""Hostile graph files: YAML 1.1 surprises, bad tags, and files too big to be worth reading."""

from __future__ import annotations

import time

import numpy as np
import pytest

import formgraph as fg
from formgraph.language import yamlio, yamlread


def _graph(inputs: str, node_type: str = "points.circle") -> fg.Graph:
    text = f"formgraph: 1\nnodes:\n  n:\n    type: {node_type}\n{inputs}"
    return fg.Graph.from_text(text, file="h.yaml")


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("1e-3", 0.001),  # YAML 1.1 (PyYAML) reads these two as strings
        ("1.0e308", 1.0e308),
        ("-2E+2", -200.0),
        ("012", 12),  # not octal
        ("0o17", 15),
        ("0x1f", 31),
        (".5", 0.5),
        ("1:30", "1:30"),  # not 90 (base 60)
        ("yes", "yes"),  # not a bool
        ("1_000", "1_000"),
        ("2024-01-31", "2024-01-31"),  # not a date
        ("true", True),
        ("~", None),
    ],
)
def test_plain_scalars_read_as_yaml_1_2(text, value):
    assert yamlread.load_value(text) == value
    assert type(yamlread.load_value(text)) is type(value)


def test_base_60_is_not_a_count():
    with pytest.raises(fg.GraphError, match=r"h.yaml:5: node 'n', input 'count': .*'1:30'"):
        _graph("    count: 1:30\n")


def test_exponent_floats_are_numbers():
    g = _graph("    count: 4\n    radius: 1e-3\n")
    assert abs(g.evaluate("n").xyz).max() == pytest.approx(1e-3)


def test_yes_is_not_a_bool():
    with pytest.raises(fg.GraphError, match=r"input 'closed': expected bool, got string 'yes'"):
        fg.Graph.from_text(
            "formgraph: 1\nnodes:\n  p: {type: points.circle, count: 4}\n"
            "  c: {type: curves.polyline, points: '@p', closed: yes}\n",
            file="h.yaml",
        )


@pytest.mark.parametrize(
    ("value", "why"),
    [
        ("!!float 'abc'", "'abc' is not a number"),
        ("!!int '1.5'", "'1.5' is not an integer"),
        ("!!timestamp 'soon'", "cannot read this value"),
        ("!!binary 'AAAA'", "expected float, got bytes"),
        ("1" * 5000, "too long"),
    ],
)
def test_unreadable_tagged_values_are_located(value, why):
    with pytest.raises(fg.GraphError, match=rf"h.yaml:6: node 'n', input 'radius': .*{why}"):
        _graph(f"    count: 3\n    radius: {value}\n")


def test_an_unknown_type_is_reported_at_its_type_line():
    text = "formgraph: 1\nnodes:\n  n:\n    count: 3\n    type: points.circel\n"
    with pytest.raises(fg.GraphError, match=r"h.yaml:5: unknown node type 'points.circel'"):
        fg.Graph.from_text(text, file="h.yaml")


def _points_file(n: int) -> str:
    rows = ",".join(f"[{i % 97},{i % 89},{i % 83}]" for i in range(n))
    return f"formgraph: 1\nnodes:\n  p:\n    type: points.list\n    points: [{rows}]\n"


def test_a_huge_file_is_refused_by_a_cheap_count_with_a_true_message():
    text = _points_file(1_000_000)  # ~10 MB, under the byte limit: 4 million values
    t0 = time.process_time()
    with pytest.raises(fg.GraphError) as err:
        fg.Graph.from_text(text, file="h.yaml")
    message = str(err.value)
    assert "values" in message and "aliases" not in message
    assert time.process_time() - t0 < 60  # CPU seconds: a bound against a hang, not a benchmark


def test_the_exact_count_does_not_blame_aliases(monkeypatch):
    monkeypatch.setattr(yamlio, "MAX_VALUES", 1000)
    with pytest.raises(fg.GraphError, match=r"holds more than 1,000 values") as err:
        fg.Graph.from_text(_points_file(300), file="h.yaml")  # 1,200 values, no alias
    assert "aliases" not in str(err.value)


def test_aliases_that_multiply_are_still_called_aliases():
    lines = ["formgraph: 1", "a0: &a0 [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]"]
    for i in range(1, 8):
        lines.append(f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]")
    lines.append("nodes: {}")
    with pytest.raises(fg.GraphError, match="aliases"):
        fg.Graph.from_text("\n".join(lines) + "\n", file="h.yaml")


def test_a_large_but_reasonable_file_loads():
    g = fg.Graph.from_text(_points_file(40_000), file="h.yaml")  # about 0.6 MB
    assert len(g.evaluate("p")) == 40_000


def test_deep_flow_nesting_is_refused():
    text = "formgraph: 1\nnodes:\n  p: {type: points.list, points: " + "[" * 50_000
    text += "]" * 50_000 + "}\n"
    with pytest.raises(fg.GraphError, match="nest"):
        fg.Graph.from_text(text, file="h.yaml")


def test_merge_keys_give_a_node_its_base_inputs():
    g = fg.Graph.from_text(
        "formgraph: 1\nnodes:\n  base: &b {type: points.circle, count: 3}\n"
        "  q: {<<: *b, radius: 2}\n",
        file="h.yaml",
    )
    assert np.abs(g.evaluate("q").xyz).max() == pytest.approx(2.0)


@pytest.mark.parametrize("value", ["[points.circle]", "{x: 1}", "3"])
def test_a_type_that_is_not_a_name_says_so(value):
    with pytest.raises(fg.GraphError, match=r"h.yaml:3: node 'a': 'type' must be a node type"):
        fg.Graph.from_text(f"formgraph: 1\nnodes:\n  a: {{type: {value}}}\n", file="h.yaml")


@pytest.mark.parametrize("bound", [".nan", ".inf", "-.inf"])
def test_param_bounds_must_be_finite(bound):
    with pytest.raises(fg.GraphError, match=r"param 'a': min must be a finite number"):
        fg.Graph.from_text(
            f"formgraph: 1\nparams:\n  a: {{default: 3, min: {bound}}}\nnodes: {{}}\n",
            file="h.yaml",
        )


def test_a_yaml_1_1_bool_gets_a_hint():
    with pytest.raises(fg.GraphError, match=r"got string 'on' \(YAML 1.2 reads it as text"):
        fg.Graph.from_text(
            "formgraph: 1\nnodes:\n  p: {type: points.circle, count: 4}\n"
            "  c: {type: curves.polyline, points: '@p', closed: on}\n",
            file="h.yaml",
        )


# ------------------------------------------ long number arrays read by json, equivalently

A = "[[1, 2, 3], [4.5, -6e-1, 7E+2],\n   [0, -0, 1e400]]"  # spans lines on purpose


@pytest.mark.parametrize(
    "body",
    [
        f"nodes:\n  p:\n    type: points.list\n    points: {A}\n  q: {{type: nope}}\n",
        f"nodes:\n  p: {{type: points.list, points: {A}}}\n  q: {{type: nope}}\n",
        f"params:\n  pts: &a {A}\nnodes:\n  p: {{type: points.list, points: *a}}\n",
        f"nodes:\n  p: {{type: points.list, points: !!seq {A}}}\n",
        f"nodes:\n  p: {{type: points.list, points: !!str {A}}}\n",
        f"nodes:\n  p: {{type: points.list, points: [[1, 2, 3]]}}  # {A.replace(chr(10), ' ')}\n",
        f"nodes:\n  p: {{type: points.list, points: [[1, 2, 3]]}}  # {A}\n",
        f'description: "{A}"\nnodes: {{}}\n',
        f"description: |\n  {A.replace(chr(10), chr(10) + '  ')}\nnodes: {{}}\n",
        f"description: see {A}\nnodes: {{}}\n",
        f"params:\n  ? {A}\n  : 1\nnodes: {{}}\n",
        "nodes:\n  p: {type: points.list, points: [[.5, 012, +1], [1, 2, 3], [4, 5, 6]]}\n",
        "nodes:\n  p: {type: points.list, points: [[1, 2, 3], [4, 5, 6], [7, 8, 9],]}\n",
        "nodes:\n  p: {type: points.list, points: [[1" + "1" * 5000 + ", 2, 3], [4, 5, 6]]}\n",
        "nodes:\n  p: {type: points.list, points: [[[[[[1, 2, 3]]]]], [[[[[4, 5, 6]]]]]]}\n",
        f"nodes:\n  p:\n    type: points.list\n    points:\n      - {A}\n      - {A}\n  q: {{}}\n",
        f"nodes:\n  b: &b {{type: points.list, points: {A}}}\n  p: {{<<: *b}}\n  q: {{type: x}}\n",
        "nodes:\n  p: {type: points.list, points: [           \n\n     ]}\n  q: {type: x}\n",
        f"nodes:\n  p: {{type: points.list, points: {A}, points: {A}}}\n",
        f"description: \ufdd00\ufdd0\nnodes:\n  p: {{type: points.list, points: {A}}}\n",
    ],
)
def test_lifted_number_arrays_read_exactly_as_yaml_would(monkeypatch, body):
    def read(bulk_chars: int) -> object:
        monkeypatch.setattr(yamlread, "BULK_CHARS", bulk_chars)
        doc = yamlio.parse("formgraph: 1\n" + body, "h.yaml")
        nodes = {
            n: (nd.type, nd.raw, nd.line, nd.input_lines, nd.parse_errors)
            for n, nd in doc.nodes.items()
        }
        params = {n: (p.default, p.line) for n, p in doc.params.items()}
        return doc.description, nodes, params, [str(p) for p in doc.problems]

    assert read(8) == read(10**9)


def test_a_lifted_array_counts_as_the_values_it_holds(monkeypatch):
    monkeypatch.setattr(yamlio, "MAX_VALUES", 1000)
    rows = ", ".join("[1, 2, 3]" for _ in range(300))  # 1,201 values in one long array
    with pytest.raises(fg.GraphError, match=r"holds more than 1,000 values"):
        fg.Graph.from_text(f"formgraph: 1\nnodes:\n  p: {{type: points.list, points: [{rows}]}}\n")


def test_long_arrays_are_lifted_and_keep_their_lines(monkeypatch):
    monkeypatch.setattr(yamlread, "BULK_CHARS", 8)
    text = f"formgraph: 1\nnodes:\n  p: {{type: points.list, points: {A}}}\n  q: {{type: nope}}\n"
    lifted, bulk = yamlread.lift_number_arrays(text)
    assert len(bulk) == 1 and lifted.count("\n") == text.count("\n")
    with pytest.raises(fg.GraphError, match=r"h.yaml:5: unknown node type 'nope'"):
        fg.Graph.from_text(text, file="h.yaml")


@pytest.mark.parametrize(
    "points",
    [
        "[" * 200_000,  # unclosed: the array scan must not backtrack over it from every '['
        "[1, 2, 3], " * 2_000 + "x",
        "[" * 1000 + "1" + "]" * 1000,
    ],
)
def test_pathological_arrays_are_refused_promptly(points):
    with pytest.raises(fg.GraphError):
        fg.Graph.from_text(f"formgraph: 1\nnodes:\n  p: {{type: points.list, points: {points}}}\n")


@pytest.mark.parametrize("levels", [58, 59, 60, 61, 62])
def test_a_lifted_array_nests_as_deep_as_it_is(monkeypatch, levels):
    body = "params:\n  x: " + "{a: " * levels + A + "}" * levels + "\nnodes: {}\n"

    def problems(bulk_chars: int) -> list[str]:
        monkeypatch.setattr(yamlread, "BULK_CHARS", bulk_chars)
        return [str(p) for p in yamlio.parse("formgraph: 1\n" + body, "h.yaml").problems]

    assert problems(10**9) == problems(8)
    assert len(yamlread.lift_number_arrays("formgraph: 1\n" + body)[1]) == 1  # it was lifted
