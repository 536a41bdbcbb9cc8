"""Hostile graph files: YAML 1.1 surprises, bad tags, and files too big to be worth reading."""

from __future__ import annotations

import time

import numpy as np
import pytest

import formgraph as fg
from formgraph import yamlio


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
    assert yamlio.load_value(text) == value
    assert type(yamlio.load_value(text)) is type(value)


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
    t0 = time.perf_counter()
    with pytest.raises(fg.GraphError) as err:
        fg.Graph.from_text(text, file="h.yaml")
    message = str(err.value)
    assert "values" in message and "aliases" not in message
    assert time.perf_counter() - t0 < 60  # a bound against a hang, not a benchmark


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
