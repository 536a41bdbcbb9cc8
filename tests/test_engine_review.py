"""Defects found in review of the engine (issue 2), each pinned by a test that fails today.

Every test names the defect it pins in a comment; the right behaviour is the one SPEC.md and
issue 2 ask for. Stub node types come from tests/stubs.py (registered by conftest).
"""

from __future__ import annotations

import io
import json
import tracemalloc

import numpy as np
import pytest

import formgraph as fg
from formgraph.cli.main import main
from formgraph.core.registry import node
from formgraph.evaluation.cache import FORMAT, DiskCache
from formgraph.geometry import Curve, ParametricCurve
from formgraph.language.expr import compile_expression

# ------------------------------------------------------------------ probe node types


@node("review.lines")
def _lines(k: float) -> list[Curve]:
    """One parametric line of slope k, in a list.

    Parameters
    ----------
    k : float
        The slope.
    """
    return [ParametricCurve(lambda t: k * t, lambda t: 0 * t, lambda t: 0 * t)]


@node("review.end_x")
def _end_x(curves: list[Curve]) -> float:
    """x at the end of the first curve.

    Parameters
    ----------
    curves : list[Curve]
        The curves.
    """
    return float(curves[0].evaluate(1.0)[0])


def _line(x_end: float) -> ParametricCurve:
    return ParametricCurve(lambda t: x_end * t, lambda t: 0 * t, lambda t: 0 * t)


# ------------------------------------------------------------------------ evaluation


def test_long_chain_evaluates_without_recursion_error():
    # Defect: evaluation recurses value -> compute -> resolve -> value per wire, so a plain
    # chain of ~330 nodes raises a raw RecursionError (the CLI prints "internal error").
    g = fg.Graph()
    g.add("n0", "stub.value", x=1.0)
    for i in range(1, 600):
        g.add(f"n{i}", "stub.add", a=f"@n{i - 1}", b=1.0)
    assert g.evaluate("n599") == 600.0
    assert g.evaluate("n599") == 600.0  # the fully cached path recurses too (identity/key)


def test_parametric_curve_params_do_not_share_a_cache_key():
    # Defect: cache.canonical() keys a Geometry by digest(), which is None for every
    # ParametricCurve/ParametricSurface, so two different curves passed from Python give
    # the same cache key and the second call returns the first curve's result.
    g = fg.Graph()
    g.add_param("crv", type="Curve")
    g.add("r", "curves.resample", curve="=crv", count=5)
    a = g.evaluate("r", crv=_line(1.0)).control_points
    b = g.evaluate("r", crv=_line(3.0)).control_points
    assert a[-1][0] == pytest.approx(1.0)
    assert b[-1][0] == pytest.approx(3.0)


def test_early_cutoff_does_not_treat_different_parametric_outputs_as_equal():
    # Defect: digest() of a list of ParametricCurves is the same for any curves (each item
    # hashes to {"g": ..., "h": None}), so early cutoff keeps the old identity and the
    # descendant returns a stale value after the param changes.
    g = fg.Graph()
    g.add_param("k", 1.0)
    g.add("c", "review.lines", k="=k")
    g.add("x", "review.end_x", curves="@c")
    assert g.evaluate("x") == pytest.approx(1.0)
    assert g.evaluate("x", k=2.0) == pytest.approx(2.0)


def test_expression_text_from_a_param_keys_on_the_params_it_reads():
    # Defect: an Expression port fed by "=fx" (a param holding the text) is keyed by the
    # text only, not by the params the text reads, so changing r returns a stale curve.
    g = fg.Graph.from_text(
        "formgraph: 1\nparams:\n  r: 1.0\n  fx: 'r * t'\n"
        "nodes:\n  c: {type: curves.parametric, x: '=fx', y: '0'}\n"
    )
    assert g.evaluate("c").evaluate(1.0)[0] == pytest.approx(1.0)
    assert g.evaluate("c", r=5.0).evaluate(1.0)[0] == pytest.approx(5.0)


def test_cached_export_is_rewritten_when_the_file_holds_other_bytes(tmp_path):
    # Defect: Run.lookup trusts a cached export whenever the file exists, so after writing
    # "b" then asking for "a" again (or after the user edits the file) the file keeps the
    # wrong content.
    g = fg.Graph(out_dir=tmp_path)
    g.add_param("text", "a")
    g.add("w", "stub.write", text="=text", path="f.txt")
    g.evaluate("w")
    g.evaluate("w", text="b")
    g.evaluate("w", text="a")
    assert (tmp_path / "f.txt").read_text() == "a"
    (tmp_path / "f.txt").write_text("edited")
    g.evaluate("w", text="a")
    assert (tmp_path / "f.txt").read_text() == "a"


def test_multi_output_node_survives_the_disk_cache(tmp_path):
    # Defect: cache._encode stores a NamedTuple as a plain list, so a disk hit gives a
    # list and '@s.hi' raises a raw AttributeError out of evaluate().
    def build() -> fg.Graph:
        g = fg.Graph(cache_dir=tmp_path)
        g.add("s", "stub.split", x=2.0)
        g.add("a", "stub.add", a="@s.hi", label="x")
        return g

    assert build().evaluate("a") == 3.0
    g = build()
    g.add("a", "stub.add", a="@s.hi", b=1.0, label="x")  # new key downstream, s from disk
    assert g.evaluate("a") == 4.0


def test_budget_error_names_the_node_once():
    # Defect: Context.guard already writes "node 'x': ..." and _Run.compute prefixes the
    # Where again: "<graph>: node 's': node 's': would make ...".
    g = fg.Graph(budget=10)
    g.add("s", "stub.points", n=100)
    with pytest.raises(fg.BudgetError, match="would make 100 points") as info:
        g.evaluate("s")
    assert str(info.value).count("node 's'") == 1


# ---------------------------------------------------------------------- YAML and check


def test_yaml_alias_bomb_is_refused():
    # Defect: aliases are composed shared but model.parse_input walks (and copies) the
    # expansion, so a few hundred bytes of nested aliases cost exponential time and memory
    # (depth 8 here never finishes); the loader should refuse expanding aliases up front.
    lines = ["formgraph: 1", "params:", "  b0: &l0 [x, x, x, x, x, x, x, x, x]"]
    for i in range(1, 6):
        lines.append(f"  b{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 9) + "]")
    lines += ["nodes:", "  a:", "    type: stub.value", "    label: *l5"]
    with pytest.raises(fg.GraphError, match="(?i)alias"):
        fg.Graph.from_text("\n".join(lines) + "\n")


def test_deeply_nested_yaml_is_a_graph_error():
    # Defect: PyYAML's composer recurses per nesting level; the RecursionError escapes
    # yamlio.parse (only YAMLError is caught) instead of becoming a GraphError.
    depth = 2000
    text = "formgraph: 1\nnodes:\n  p: {type: stub.sum, items: " + "[" * depth + "1"
    text += "]" * depth + "}\n"
    with pytest.raises(fg.GraphError):
        fg.Graph.from_text(text)


@pytest.mark.parametrize("text", ["-" * 700 + "r", "not " * 700 + "r", "1" + "+1" * 600])
def test_deeply_nested_expression_is_an_expression_error(text):
    # Defect: within MAX_NODES, _Compiler.visit recurses per level and raises a raw
    # RecursionError (load() then fails with it, the CLI with "internal error").
    with pytest.raises(fg.ExpressionError):
        compile_expression(text)


def test_nested_list_with_expressions_is_checked_at_load():
    # Defect: check._static_value gives up on nested Items, so a bad literal inside a list
    # of lists holding an expression is only found when the node runs.
    text = (
        "formgraph: 1\nparams:\n  r: 2.0\nnodes:\n"
        "  p: {type: points.list, points: [['=r', 0, 0], [0, 'oops', 0]]}\n"
    )
    with pytest.raises(fg.GraphError, match="node 'p', input 'points'"):
        fg.Graph.from_text(text)


def test_unreadable_file_message_has_one_location(tmp_path):
    # Defect: load() wraps the message in GraphError(str), whose Where() adds "<graph>: "
    # in front of the file name: "<graph>: bad.yaml: cannot read the graph file: ...".
    bad = tmp_path / "bad.yaml"
    bad.write_bytes(b"\xff\xfe")
    with pytest.raises(fg.GraphError) as info:
        fg.load(bad)
    assert str(info.value).startswith(f"{bad}: cannot read")


def test_load_does_not_read_a_huge_file_whole(tmp_path):
    # Defect: load() reads and decodes the whole file before the 16 MiB check, so
    # `formgraph check /dev/zero` grows without bound; read at most MAX_BYTES + 1.
    big = tmp_path / "big.yaml"
    with open(big, "wb") as fh:
        fh.truncate(64 * 1024 * 1024)
    tracemalloc.start()
    try:
        with pytest.raises(fg.GraphError, match="larger than"):
            fg.load(big)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 40 * 1024 * 1024


# ---------------------------------------------------------------------- save / load


def test_save_round_trips_a_graph_built_with_tuples(tmp_path):
    # Defect: raw inputs are kept as given; safe_dump writes a tuple as a list, so the
    # loaded graph is not equal to the saved one.
    g = fg.Graph()
    g.add("b", "mesh.box", center=(1, 2, 3))
    g.save(tmp_path / "g.yaml")
    assert fg.load(tmp_path / "g.yaml") == g


def test_save_accepts_numpy_numbers(tmp_path):
    # Defect: numpy scalars (np.int64, np.float64) in inputs make save() raise
    # yaml.RepresenterError, although the graph evaluates fine.
    g = fg.Graph()
    g.add("c", "points.circle", count=np.int64(8), radius=np.float64(2.0))
    assert len(g.evaluate("c")) == 8
    g.save(tmp_path / "g.yaml")
    h = fg.load(tmp_path / "g.yaml")
    assert len(h.evaluate("c")) == 8
    assert h.node_inputs("c") == {"count": 8, "radius": 2.0}


# ---------------------------------------------------------------------- cache, geometry


def test_foreign_disk_entry_with_non_object_meta_is_a_miss(tmp_path):
    # Defect: DiskCache.get_entry calls meta.get on whatever JSON came; a list raises
    # AttributeError out of evaluate instead of being dropped and recomputed.
    cache = DiskCache(tmp_path)
    key = "ab" + "0" * 38
    cache.put(key, 1.5)
    buf = io.BytesIO()
    np.savez(buf, meta=np.frombuffer(json.dumps([FORMAT, key]).encode(), np.uint8))
    cache._path(key).write_bytes(buf.getvalue())
    assert cache.get(key) == (False, None)
    assert not cache._path(key).exists()


def test_mesh_without_faces_has_no_faces():
    # Defect: Mesh.faces splits at face_offsets[1:-1] == [], giving one empty face.
    m = fg.Mesh(np.zeros((3, 3)), [])
    assert m.n_faces == 0
    assert len(m.faces) == 0


def test_points_do_not_alias_a_writable_array():
    # Defect: Points keeps any read-only float64 (n, 3) array as is, even a read-only view
    # of a writable array, so the owner of the base can change the "immutable" points.
    base = np.zeros((2, 3))
    view = base.view()
    view.flags.writeable = False
    p = fg.Points(view)
    base[0, 0] = 7.0
    assert p.xyz[0, 0] == 0.0


# ------------------------------------------------------------------------------ CLI


def test_cli_set_parses_exponent_floats(tmp_path, capsys):
    # Defect: parse_sets uses yaml.safe_load (YAML 1.1), which reads "1e3" as a string,
    # so `--set r=1e3` on a float param exits 1 with "expected float, got string '1e3'".
    graph = tmp_path / "g.yaml"
    graph.write_text("formgraph: 1\nparams:\n  r: 1.0\nnodes:\n  a: {type: stub.value, x: '=r'}\n")
    code = main(["run", str(graph), "--no-cache", "--out", str(tmp_path / "out"), "--set", "r=1e3"])
    assert code == 0, capsys.readouterr().err
    assert "a: 1000.0" in capsys.readouterr().out


@pytest.mark.parametrize(
    "inputs",
    [
        "{type: stub.value, x: BIG}",
        "{type: mesh.box, center: [BIG, 0, 0]}",
        "{type: points.list, points: [[BIG, 0, 0]]}",
    ],
)
def test_huge_integer_literal_is_a_graph_error(inputs):
    # Defect: float(int) raises OverflowError for a 400-digit integer; types._coerce_kind,
    # _vec3 and as_xyz catch only TypeError/ValueError, so a raw OverflowError escapes
    # load() (CLI: "internal error") instead of a GraphError naming node and input.
    text = "formgraph: 1\nnodes:\n  a: " + inputs.replace("BIG", "1" + "0" * 400) + "\n"
    with pytest.raises(fg.GraphError, match="node 'a', input"):
        fg.Graph.from_text(text)


def test_huge_integer_param_override_is_a_param_error():
    # Defect: the same OverflowError escapes Graph.evaluate(..., r=10**400).
    g = fg.Graph.from_text("formgraph: 1\nparams:\n  r: 1.0\nnodes:\n  a: {type: stub.value}\n")
    with pytest.raises(fg.ParamError, match="param 'r'"):
        g.evaluate("a", r=10**400)
