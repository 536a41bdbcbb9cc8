"""Hostile and careless use of the Python API and the command line: every wrong argument is
a GraphError sentence (or exit code 2), never a raw TypeError."""

from __future__ import annotations

import warnings

import pytest

import formgraph as fg
from formgraph.cli import main as cli


@pytest.fixture
def g() -> fg.Graph:
    g = fg.Graph()
    g.add("p", "points.circle", count=4)
    return g


@pytest.mark.parametrize("nodes", [5, None, 3.5, ["p", 7], b"p"])
def test_evaluate_takes_names(g, nodes):
    with pytest.raises(fg.GraphError, match=r"evaluate\(\) takes a node name or a list"):
        g.evaluate(nodes)


def test_evaluate_takes_any_iterable_of_names(g):
    assert set(g.evaluate(("p",))) == {"p"}
    assert g.evaluate([]) == {}


@pytest.mark.parametrize(("name", "type_"), [(5, "points.circle"), ("p", None), (None, 3)])
def test_add_takes_strings(name, type_):
    with pytest.raises(fg.GraphError, match=r"add\(\) takes a node (name|type)"):
        fg.Graph().add(name, type_)


@pytest.mark.parametrize("path", [None, 5, ["g.yaml"]])
def test_load_takes_a_path(path):
    with pytest.raises(fg.GraphError, match=r"load\(\) takes the path of a graph file"):
        fg.load(path)


def test_add_param_with_an_unknown_type_is_a_param_error():
    with pytest.raises(fg.ParamError, match=r"param 'x': unknown type 'Nope' \(known: .*Points"):
        fg.Graph().add_param("x", type="Nope")
    with pytest.raises(fg.ParamError, match="min must be a number"):
        fg.Graph().add_param("x", 1, min="0")


@pytest.mark.parametrize("budget", ["x", 0, -1, 2.5, True, None])
def test_a_bad_budget_fails_at_once(tmp_path, budget):
    with pytest.raises(fg.GraphError, match="budget must be a whole number"):
        fg.load(tmp_path / "not-even-there.yaml", budget=budget)
    with pytest.raises(fg.GraphError, match="budget must be a whole number"):
        fg.Graph(budget=budget)


@pytest.fixture
def graph_file(tmp_path):
    p = tmp_path / "g.yaml"
    p.write_text(
        "formgraph: 1\n"
        "params:\n"
        "  waist: {default: 3, min: 0.5, max: 10}\n"
        "  height: {default: 20, min: 1, max: 100}\n"
        "  n: {default: 8, min: 3, max: 64, type: int}\n"
        "  sides: {default: 6, min: 3, max: 12}\n"
        "nodes:\n"
        "  c: {type: points.circle, count: '=n', radius: '=waist * height'}\n"
        "  d: {type: points.circle, count: '=sides'}\n"
    )
    return p


@pytest.mark.parametrize("budget", ["0", "-1", "lots"])
def test_cli_refuses_a_budget_below_one(graph_file, budget, capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["run", str(graph_file), "--budget", budget])
    assert exit_.value.code == 2
    assert "--budget" in capsys.readouterr().err


def test_a_param_is_int_only_when_everything_about_it_is_whole(graph_file):
    g = fg.load(graph_file)
    assert g.evaluate("c", waist=1.5).xyz[0, 0] == pytest.approx(30.0)
    # whole throughout, but it feeds only a radius (a float port): a float
    assert g.evaluate("c", height=1.5).xyz[0, 0] == pytest.approx(4.5)
    with pytest.raises(fg.ParamError, match=r"param 'sides': expected int, got float 1.5"):
        g.evaluate("d", sides=1.5)


def test_set_takes_several_values(graph_file, tmp_path, capsys):
    code = cli.main(
        [
            "run",
            str(graph_file),
            "c",
            "--no-cache",
            "--out",
            str(tmp_path / "out"),
            "--set",
            "waist=1.5",
            "height=30",
            "--set",
            "n=4",
        ]  # fmt: skip
    )
    assert code == 0, capsys.readouterr().err
    assert "Points(n=4)" in capsys.readouterr().out


def test_set_says_where_node_names_go(graph_file, capsys):
    assert cli.main(["run", str(graph_file), "--no-cache", "--set", "waist=2", "c"]) == 2
    assert "node names go before --set" in capsys.readouterr().err


def test_check_warns_when_it_guesses_int(graph_file, capsys):
    assert cli.main(["check", str(graph_file)]) == 0
    err = capsys.readouterr().err
    assert "g.yaml:6: warning: param 'sides' is read as int" in err
    # floats (one fed to a float port), and a declared int
    assert "'waist'" not in err and "'height'" not in err and "'n'" not in err


OPEN_BOX = {"vertices": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], "faces": [[0, 1, 2, 3]]}


def test_node_warnings_go_through_the_warnings_module(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("m", "mesh.from_faces", **OPEN_BOX)
    g.add("stl", "export.stl", mesh="@m", path="open.stl")
    with pytest.warns(fg.FormgraphWarning, match=r"node 'stl': mesh is not watertight") as rec:
        g.evaluate_all()
    assert rec[0].filename == __file__  # attributed to the caller, not to formgraph's insides
    assert g.stats["stl"].warnings  # still in the stats too
    with warnings.catch_warnings():
        warnings.simplefilter("error", fg.FormgraphWarning)
        g.set_input("stl", "path", "open2.stl")
        with pytest.raises(fg.FormgraphWarning):
            g.evaluate("stl")


def test_the_cli_prints_a_node_warning_once(tmp_path, capsys):
    p = tmp_path / "open.yaml"
    p.write_text(
        "formgraph: 1\nnodes:\n"
        f"  m: {{type: mesh.from_faces, vertices: {OPEN_BOX['vertices']}, "
        f"faces: {OPEN_BOX['faces']}}}\n"
        "  stl: {type: export.stl, mesh: '@m', path: open.stl}\n"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        assert cli.main(["run", str(p), "--no-cache", "--out", str(tmp_path / "out")]) == 0
    assert capsys.readouterr().err.count("not watertight") == 1


def test_a_subgraph_param_follows_the_same_int_rule(tmp_path):
    (tmp_path / "part.yaml").write_text(
        "formgraph: 1\nparams:\n  waist: {default: 3, min: 0.5, max: 10}\n"
        "nodes:\n  c: {type: nurbs.circle, radius: '=waist'}\noutputs: {curve: '@c'}\n"
    )
    (tmp_path / "top.yaml").write_text(
        "formgraph: 1\nnodes:\n  ring: {type: part.yaml, waist: 1.5}\n"
    )
    g = fg.load(tmp_path / "top.yaml")
    assert g.evaluate("ring").evaluate(0.0)[0] == pytest.approx(1.5)


@pytest.mark.parametrize(
    ("value", "why"),
    [("[" * 900 + "]" * 900, "nested too deeply"), ("!!float abc", "'abc' is not a number")],
)
def test_set_refuses_hostile_yaml_values(tmp_path, capsys, value, why):
    p = tmp_path / "v.yaml"
    p.write_text(
        "formgraph: 1\nparams:\n  v: [1, 2]\nnodes:\n  p: {type: points.circle, count: 3, "
        "center: '=v'}\n"
    )
    assert cli.main(["run", str(p), "--no-cache", "--set", f"v={value}"]) == 2
    assert why in capsys.readouterr().err


def _deep(levels: int) -> list:
    value: list = []
    for _ in range(levels):
        value = [value]
    return value


def test_deeply_nested_python_values_are_graph_errors():
    g = fg.Graph()
    with pytest.raises(fg.GraphError, match="input 'points' of 'p' is nested more than 64"):
        g.add("p", "points.list", points=_deep(5000))
    with pytest.raises(fg.GraphError, match="param 'v' is nested more than 64"):
        g.add_param("v", _deep(5000))
    g.add_param("v", [1, 2])
    g.add("c", "points.circle", count=3, center="=v")
    with pytest.raises(fg.ParamError, match="param 'v': the value is nested more than 64"):
        g.evaluate("c", v=_deep(5000))
