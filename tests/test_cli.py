"""The command line, through a real subprocess: exit codes, messages, no tracebacks."""

from __future__ import annotations

import json
import re
import textwrap
from pathlib import Path

import pytest
from tools import cli

ROOT = Path(__file__).resolve().parents[1]

GRAPH = """
formgraph: 1
params:
  n: {default: 8, min: 3, max: 64}
  r: 2.0
nodes:
  pts:
    type: points.circle
    count: "=n"
    radius: "=r"
"""


@pytest.fixture
def graph_file(tmp_path: Path) -> Path:
    p = tmp_path / "g.yaml"
    p.write_text(textwrap.dedent(GRAPH).lstrip())
    return p


def test_run_prints_outputs_and_profile(graph_file, tmp_path):
    r = cli("run", str(graph_file), "--set", "n=5", "--no-cache", "--profile", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "pts: Points(n=5)" in r.stdout
    assert "computed" in r.stdout and "seconds" in r.stdout


def test_run_with_disk_cache_reports_cached(graph_file, tmp_path):
    args = ("run", str(graph_file), "--cache-dir", str(tmp_path / "c"), "--profile")
    assert cli(*args, cwd=tmp_path).returncode == 0
    r = cli(*args, cwd=tmp_path)
    assert r.returncode == 0
    assert "cached" in r.stdout


def test_set_is_parsed_by_the_param_type(graph_file, tmp_path):
    r = cli("run", str(graph_file), "--set", "n=2.5", "--no-cache", cwd=tmp_path)
    assert r.returncode == 1
    assert "param 'n': expected int, got float 2.5" in r.stderr
    r = cli("run", str(graph_file), "--set", "n=100", "--no-cache", cwd=tmp_path)
    assert r.returncode == 1 and "must be <= 64" in r.stderr
    r = cli("run", str(graph_file), "--set", "r=3", "--no-cache", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    r = cli("run", str(graph_file), "--set", "radius=3", "--no-cache", cwd=tmp_path)
    assert r.returncode == 1 and "unknown param" in r.stderr
    r = cli("run", str(graph_file), "--set", "oops", "--no-cache", cwd=tmp_path)
    assert r.returncode == 2 and "NAME=VALUE" in r.stderr


def test_check_exit_codes(graph_file, tmp_path):
    assert cli("check", str(graph_file)).returncode == 0
    bad = tmp_path / "bad.yaml"
    bad.write_text("formgraph: 1\nnodes:\n  a:\n    type: points.circel\n    count: 3\n")
    r = cli("check", str(bad))
    assert r.returncode == 1
    assert (
        "bad.yaml:4: unknown node type 'points.circel' (did you mean 'points.circle'?)" in r.stderr
    )
    assert "Traceback" not in r.stderr


def test_usage_error_is_exit_2():
    assert cli("frobnicate").returncode == 2
    assert cli("run").returncode == 2


def test_node_failure_has_no_traceback_unless_debug(tmp_path):
    g = tmp_path / "g.yaml"
    g.write_text(
        "formgraph: 1\nnodes:\n  c:\n    type: curves.polyline\n    points: [[0, 0], [0, 0]]\n"
    )
    r = cli("run", str(g), "--no-cache", cwd=tmp_path)
    assert r.returncode == 1
    assert "node 'c' (curves.polyline)" in r.stderr
    assert "Traceback" not in r.stderr
    r = cli("--debug", "run", str(g), "--no-cache", cwd=tmp_path)
    assert r.returncode == 1
    assert "Traceback" in r.stderr


def test_nodes_catalogue_and_one_node():
    r = cli("nodes")
    assert r.returncode == 0 and "points.circle(count, [radius], [center]) -> Points" in r.stdout
    r = cli("nodes", "points.grid")
    assert r.returncode == 0 and "spacing" in r.stdout
    r = cli("nodes", "points.gird")
    assert r.returncode == 1 and "did you mean 'points.grid'" in r.stderr


def test_nodes_of_a_graph_file_lists_the_types_it_uses(graph_file, tmp_path):
    # a graph without outputs: its node types, and a sentence for what it is not
    r = cli("nodes", graph_file.name, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[:2] == [
        "g.yaml uses 1 node type in 1 node:",
        "  points.circle  pts",
    ]
    assert "It has no 'outputs:', so it is not a node type" in r.stdout
    assert "formgraph params g.yaml" in r.stdout
    # a part: its interface as a node, then what it uses
    r = cli("nodes", "graphs/parts/ring.yaml", cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert "inputs:\n  radius" in r.stdout and "outputs:\n  mesh         Mesh" in r.stdout
    assert "  nurbs.circle      path, section" in r.stdout
    r = cli("nodes", "graphs/vase_repeat.yaml", cwd=ROOT)
    assert r.returncode == 0 and "(repeat " in r.stdout
    r = cli("nodes", "missing.yaml", cwd=tmp_path)
    assert r.returncode == 1 and "missing.yaml" in r.stderr and "Traceback" not in r.stderr


def test_params_lists_types_defaults_ranges_steps_and_docs():
    import yaml

    path = ROOT / "graphs" / "lattice_part.yaml"
    r = cli("params", str(path), "--json")
    assert r.returncode == 0, r.stderr
    rows = json.loads(r.stdout)
    declared = yaml.safe_load(path.read_text())["params"]
    assert [row["name"] for row in rows] == list(declared)
    for row in rows:
        p = declared[row["name"]]
        assert (row["default"], row["doc"]) == (p["default"], p["doc"])
        assert (row["min"], row["max"], row["choices"]) == (
            p.get("min"),
            p.get("max"),
            p.get("choices"),
        )
    steps = {row["name"]: row["step"] for row in rows}
    # a hundredth of the range, rounded up to 1, 2 or 5 x 10^k: 3.6 / 100 -> 0.05
    assert steps == {"wall": 0.05, "lattice": None, "period": 0.5, "sheet": 0.05, "cell": 0.02}
    assert {row["name"]: row["type"] for row in rows}["lattice"] == "choice"
    text = cli("params", str(path)).stdout.splitlines()
    assert text[1].split() == ["name", "type", "default", "range", "step", "doc"]
    assert text[2].split()[:7] == ["wall", "float", "1.2", "0.4", "..", "4", "0.05"]
    assert "gyroid | schwarz_p | diamond" in text[3]
    r = cli("params", "--help")
    assert r.returncode == 0 and "--json" in r.stdout
    assert "params" in cli("--help").stdout


def test_schema_validates_the_example_graphs():
    jsonschema = pytest.importorskip("jsonschema")
    import yaml

    r = cli("schema")
    assert r.returncode == 0
    schema = json.loads(r.stdout)
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    graphs = sorted((ROOT / "graphs").glob("*.yaml"))
    for path in graphs:
        errors = list(validator.iter_errors(yaml.safe_load(path.read_text())))
        assert not errors, f"{path.name}: {errors[0].message}"
    bad = {"formgraph": 1, "nodes": {"a": {"type": "points.circle", "count": "many"}}}
    assert list(validator.iter_errors(bad))
    typo = {"formgraph": 1, "nodes": {"a": {"type": "points.circel", "count": 3}}}
    assert list(validator.iter_errors(typo))


def test_nodes_markdown_documents_every_node_with_its_ports():
    # the whole catalogue as one file: every node of the registry, each with its input table
    r = cli("nodes", "--markdown")
    assert r.returncode == 0, r.stderr
    from formgraph.core.registry import node_types

    shipped = [
        n for n, s in node_types().items() if s.func.__module__.startswith("formgraph.nodes")
    ]
    headings = re.findall(r"^### `([\w.]+)`", r.stdout, flags=re.M)
    assert sorted(headings) == sorted(shipped)
    solidify = r.stdout.split("### `mesh.solidify`")[1].split("\n### ")[0]
    assert "| `thickness` | float | required |" in solidify
    assert "| `planar_rims` | bool | true |" in solidify


def test_schema_accepts_expressions_inside_coordinates():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(cli("schema").stdout)
    graph = {
        "formgraph": 1,
        "params": {"h": 2.0},
        "nodes": {"p": {"type": "points.list", "points": [[0, 0, "=h"], [1, 2]]}},
    }
    assert not list(jsonschema.Draft202012Validator(schema).iter_errors(graph))


def test_progress_line_on_a_terminal_only():
    import io

    from formgraph.cli.main import _ProgressLine

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    term = Terminal()
    line = _ProgressLine(term)
    line("quick", 0, 3)  # the first half second stays quiet
    assert term.getvalue() == ""
    line.start -= 1.0
    line("mesh", 1, 3)
    assert "cooking 'mesh' (2/3 nodes)" in term.getvalue()
    line("next", 2, 3)  # at once after: not written (at most 20 updates a second)
    assert "next" not in term.getvalue()
    line.last -= 1.0
    line("last", 2, 3)
    assert "cooking 'last' (3/3 nodes)" in term.getvalue()
    line.clear()
    assert term.getvalue().endswith("\r\x1b[K")
    pipe = io.StringIO()  # not a terminal: never a progress line
    quiet = _ProgressLine(pipe)
    quiet.start -= 1.0
    quiet("mesh", 1, 3)
    assert pipe.getvalue() == ""
