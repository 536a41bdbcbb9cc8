"""What tripped a new user: each first try now works, or says exactly what to change."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import formgraph as fg
from formgraph.cli import main as cli

ROOT = Path(__file__).resolve().parents[2]


def _graph(text: str) -> fg.Graph:
    return fg.Graph.from_text("formgraph: 1\n" + text, file="h.yaml")


@pytest.mark.parametrize("param", ["r: 2", "r: {default: 2}"])
def test_a_whole_number_feeding_a_float_port_takes_fractions(tmp_path, capsys, param):
    f = tmp_path / "g.yaml"
    f.write_text(
        f"formgraph: 1\nparams:\n  {param}\nnodes:\n  c: {{type: nurbs.circle, radius: '=r'}}\n"
    )
    assert cli.main(["run", str(f), "--no-cache", "--out", str(tmp_path), "--set", "r=2.5"]) == 0
    g = fg.load(f)
    g.set(r=2.5)
    assert np.linalg.norm(g.evaluate("c").evaluate(0.3)) == pytest.approx(2.5)


def test_a_whole_number_feeding_a_count_stays_an_int():
    g = _graph(
        "params:\n  n: 8\nnodes:\n  p: {type: points.circle, count: '=n', radius: '=n / 2'}\n"
    )
    with pytest.raises(fg.ParamError, match=r"param 'n': expected int, got float 2.5"):
        g.set(n=2.5)
    g.set(n=5)
    assert len(g.evaluate("p")) == 5


def test_an_expression_port_takes_the_equals_form_too():
    body = "params:\n  wall: 2.0\nnodes:\n  s: {{type: surfaces.parametric, x: u, y: v, z: {z}}}\n"
    plain = _graph(body.format(z="'wall / 2 + u * v'")).evaluate("s")
    eq = _graph(body.format(z="'=wall / 2 + u * v'")).evaluate("s")
    uv = np.array([[0.2, 0.7], [1.0, 0.5]])
    np.testing.assert_allclose(eq.evaluate(uv[:, 0], uv[:, 1]), plain.evaluate(uv[:, 0], uv[:, 1]))
    np.testing.assert_allclose(eq.evaluate(0.2, 0.7)[2], 1.0 + 0.14)
    g = _graph(body.format(z="'=wall / 2 + u * v'"))
    g.set(wall=4.0)  # still an expression over the params, not a value frozen at the default
    assert g.evaluate("s").evaluate(0.0, 0.0)[2] == pytest.approx(2.0)
    # a text param named by '=' still passes its text
    shape = _graph(
        "params:\n  f: 'u + v'\nnodes:\n  s: {type: surfaces.parametric, x: u, y: v, z: '=f'}\n"
    )
    assert shape.evaluate("s").evaluate(0.25, 0.5)[2] == pytest.approx(0.75)


def test_an_unquoted_comma_in_a_doc_says_to_quote_it():
    text = (
        "params:\n  tilt: {default: 30, doc: degrees, bottom to top}\n"
        "nodes:\n  c: {type: nurbs.circle, radius: 1, label: a ring, one of two}\n"
    )
    with pytest.raises(fg.GraphError) as info:
        _graph(text).check()
    msg = str(info.value)
    assert re.search(
        r"h.yaml:3: param 'tilt': the text 'bottom to top' became a key of its own, because "
        r"inside \{\.\.\.\} a ', ' ends a value: put text that holds ', ' in quotes",
        msg,
    ), msg
    assert "unknown key(s) bottom to top" not in msg
    assert "input 'one of two': the text 'one of two' became an input of its own" in msg


def test_nodes_of_a_part_lists_its_inputs_without_none(tmp_path, capsys):
    (tmp_path / "part.yaml").write_text(
        "formgraph: 1\ndescription: A ring.\nparams:\n  r: {type: float, default: 2}\n"
        "  n: {type: int, default: 8}\n  k: 3\nnodes:\n"
        "  p: {type: points.circle, count: '=n', radius: '=r * k'}\noutputs: {pts: '@p'}\n"
    )
    assert cli.main(["nodes", str(tmp_path / "part.yaml")]) == 0
    out = capsys.readouterr().out
    assert "None" not in out
    assert re.search(r"^\s+r\s+float\s", out, re.M) and re.search(r"^\s+n\s+int\s", out, re.M)
    assert re.search(r"^\s+k\s+float\s", out, re.M)  # whole, but it feeds a radius


def test_evaluate_takes_a_named_output_as_a_wire_spells_it():
    g = fg.Graph()
    g.add("b", "mesh.box", size=[1, 2, 3])
    g.add("a", "mesh.measure", mesh="@b")
    assert g.evaluate("a.volume") == pytest.approx(6.0)
    both = g.evaluate(["a.size", "a.faces", "b"])
    assert list(both["a.size"]) == [1, 2, 3] and both["a.faces"] == 6
    with pytest.raises(fg.GraphError, match=r"node 'a' \(mesh.measure\) has no output 'vol'; "):
        g.evaluate("a.vol")
    with pytest.raises(fg.GraphError, match=r"node 'b' \(mesh.box\) has no output 'x'"):
        g.evaluate("b.x")


def test_the_manual_shows_the_geometry_constructors_and_they_run():
    section = (ROOT / "docs" / "python.md").read_text()
    for call in ("fg.Mesh(", "fg.Points(", "fg.NurbsCurve(", "fg.NurbsSurface("):
        assert call in section, call
    blocks = [b.split("```")[0] for b in section.split("```python")[1:]]
    block = next(b for b in blocks if "fg.Mesh(" in b)
    scope: dict = {"fg": fg}
    exec(block, scope)  # the manual's own example, as a reader would paste it
    assert scope["quad"].n_faces == 1 and scope["pts"].xyz.shape == (3, 3)
    np.testing.assert_allclose(np.linalg.norm(scope["arc"].evaluate(0.37)), 1.0)
