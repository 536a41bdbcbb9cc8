"""Graph params (formgraph.language.params): a param declared with ``choices:``.

A choice param takes only the values listed; the check says where a declaration is wrong
(the param's line), a value outside the list is refused with the list (and a "did you
mean"), and ``save()`` writes the choices back.
"""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg
from formgraph.core.errors import GraphError, ParamError
from formgraph.evaluation.graph import Graph
from formgraph.language.params import parse_sets

GRAPH = """\
formgraph: 1
params:
  lattice: {default: gyroid, choices: [gyroid, schwarz_p, diamond], doc: which TPMS}
  period: {type: float, default: 10, choices: [5, 10, 20]}
nodes:
  cell:
    type: field.tpms
    kind: "=lattice"
    period: "=period"
"""


def test_choices_are_read_and_kept(tmp_path):
    g = Graph.from_text(GRAPH, file="g.yaml")
    assert g.param_defs["lattice"].choices == ("gyroid", "schwarz_p", "diamond")
    assert g.param_defs["period"].choices == (5, 10, 20)
    assert g.params == {"lattice": "gyroid", "period": 10.0}
    # a float param takes 20 for the choice 20 (the same number), and the field follows
    a = g.evaluate("cell", lattice="diamond", period=20)
    b = g.evaluate("cell", lattice="diamond", period=20.0)
    p = [[0.7, 1.3, 2.1], [3.0, 1.0, 0.2]]
    assert a.evaluate(p) == pytest.approx(b.evaluate(p))
    c = g.evaluate("cell", lattice="gyroid", period=20)
    assert not np.allclose(a.evaluate(p), c.evaluate(p))
    path = tmp_path / "again.yaml"
    g.save(path)
    again = fg.load(path)
    for name in ("lattice", "period"):
        assert again.param_defs[name].choices == g.param_defs[name].choices
    assert "choices: [gyroid, schwarz_p, diamond]" in path.read_text()


def test_a_value_outside_the_choices_is_refused():
    g = Graph.from_text(GRAPH, file="g.yaml")
    with pytest.raises(ParamError) as exc:
        g.evaluate("cell", lattice="gyriod")
    text = str(exc.value)
    assert text.startswith("g.yaml:3:")  # the param's line
    assert "must be one of 'gyroid', 'schwarz_p', 'diamond'" in text
    assert "did you mean 'gyroid'" in text
    with pytest.raises(ParamError, match="must be one of 5, 10, 20, got 7.0"):
        g.evaluate("cell", period=7)
    assert parse_sets(g, ["lattice=diamond", "period=5"]) == {"lattice": "diamond", "period": 5.0}


@pytest.mark.parametrize(
    ("declaration", "message"),
    [
        ("{default: a, choices: a}", "choices must be a non-empty list, got 'a'"),
        ("{default: a, choices: []}", "choices must be a non-empty list"),
        ("{default: a, choices: [a, [b]]}", "a choice is a number, a text or true/false"),
        ("{default: a, choices: [a, b, a]}", "the choice 'a' is listed twice"),
        ("{default: c, choices: [a, b]}", "default must be one of 'a', 'b', got 'c'"),
        ("{default: 1.5, choices: [1.5, x]}", "choice expected float, got string 'x'"),
        ("{default: 2, min: 0, max: 4, choices: [2, 9]}", "choice must be <= 4, got 9"),
    ],
)
def test_a_wrong_declaration_is_located(declaration, message):
    text = f"formgraph: 1\nparams:\n  first: 1\n  p: {declaration}\nnodes: {{}}\n"
    with pytest.raises(GraphError) as exc:
        Graph.from_text(text, file="g.yaml")
    problems = exc.value.problems
    assert any(p.where.line == 4 and message in p.message for p in problems), problems


def test_true_is_not_the_choice_one():
    text = "formgraph: 1\nparams:\n  p: {default: 1, choices: [0, 1]}\nnodes: {}\n"
    g = Graph.from_text(text, file="g.yaml")
    with pytest.raises(ParamError):
        g.set(p=True)
    g.set(p=0)
    assert g.params["p"] == 0


def test_add_param_with_choices():
    g = Graph()
    g.add_param("ends", "flat", choices=["flat", "round"])
    assert g.param_defs["ends"].choices == ("flat", "round")
    with pytest.raises(ParamError, match="listed twice"):
        g.add_param("bad", "x", choices=["x", "x"])
    with pytest.raises(ParamError, match="must be one of 'flat', 'round'"):
        g.set(ends="square")
