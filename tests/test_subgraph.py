"""Subgraphs: graph files used as node types (language/subgraph.py, evaluation/items.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import formgraph as fg
from formgraph.cli.main import main
from formgraph.language.catalogue import json_schema

RING = """\
formgraph: 1
description: A tube ring swept along a path.
params:
  radius: {default: 1.0, min: 0.1, doc: ring radius}
  thickness: 0.1
  path: {type: Curve}
outputs:
  mesh: "@tess"
  outline: "@c"
nodes:
  c: {type: nurbs.circle, radius: "=radius"}
  sec: {type: nurbs.circle, radius: "=thickness"}
  tube: {type: nurbs.sweep, profile: "@sec", path: "=path"}
  tess: {type: nurbs.tessellate, surface: "@tube", u: 8, v: 16}
  out: {type: export.stl, mesh: "@tess", path: ring.stl}
"""

TOP = """\
formgraph: 1
params:
  r: 2.0
nodes:
  track: {type: nurbs.circle, radius: 3}
  left: {type: parts/ring.yaml, radius: "=r", path: "@track"}
  right: {type: parts/ring.yaml, radius: 0.5, thickness: 0.05, path: "@track"}
  both: {type: mesh.merge, meshes: ["@left.mesh", "@right.mesh"]}
  rims: {type: nurbs.loft, curves: ["@left.outline", "@right.outline"]}
"""


def write(tmp_path, files):
    for name, text in files.items():
        p = tmp_path / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return tmp_path


@pytest.fixture
def tree(tmp_path):
    return write(tmp_path, {"parts/ring.yaml": RING, "top.yaml": TOP})


def test_a_part_used_twice_with_different_inputs(tree):
    g = fg.load(tree / "top.yaml", out_dir=tree / "out")
    out = g.evaluate(["both", "left", "rims"])
    left, rims = out["left"], out["rims"]
    assert out["both"].n_faces == 2 * 8 * 16
    np.testing.assert_allclose(np.linalg.norm(left.outline.evaluate(0.3)), 2.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(rims.evaluate(0.2, 1.0)), 0.5, atol=1e-12)
    # the track feeds both rings, the sweep inside each follows it at its thickness
    r = np.linalg.norm(left.mesh.vertices[:, :2], axis=1)
    assert r.min() == pytest.approx(2.9, abs=1e-3) and r.max() == pytest.approx(3.1, abs=1e-3)
    assert not (tree / "out").exists()  # the part's export does not run as a node
    assert g.stats["left"].inner is not None and "tube" in g.stats["left"].inner
    assert {p.name for p in g.files} == {"top.yaml", "ring.yaml"}


def test_a_single_output_is_the_node_itself(tree):
    write(
        tree,
        {
            "parts/circle.yaml": "formgraph: 1\nparams: {r: 1.0}\noutputs: {curve: '@c'}\n"
            "nodes:\n  c: {type: nurbs.circle, radius: '=r'}\n",
            "one.yaml": "formgraph: 1\nnodes:\n  a: {type: parts/circle.yaml, r: 2}\n"
            "  b: {type: nurbs.extrude, curve: '@a'}\n"
            "  c: {type: nurbs.extrude, curve: '@a.curve'}\n",
        },
    )
    g = fg.load(tree / "one.yaml")
    assert g.evaluate("b").evaluate(0.0, 0.0) == pytest.approx(g.evaluate("c").evaluate(0.0, 0.0))


def test_the_interface_is_typed_and_checked_with_the_parent(tree):
    write(
        tree,
        {
            "bad.yaml": """\
formgraph: 1
nodes:
  box: {type: mesh.box}
  a: {type: parts/ring.yaml, radius: 0.01, path: "@box", thikness: 2}
  b: {type: parts/ring.yaml}
  c: {type: nurbs.tessellate, surface: "@a.mesh"}
  d: {type: nurbs.tessellate, surface: "@a.nothing"}
"""
        },
    )
    with pytest.raises(fg.GraphError) as err:
        fg.load(tree / "bad.yaml")
    msg = str(err.value)
    assert "bad.yaml:4: node 'a', input 'radius': must be >= 0.1, got 0.01" in msg
    assert "bad.yaml:4: node 'a', input 'path': expected Curve, got Mesh from '@box'" in msg
    assert (
        "input 'thikness': 'parts/ring.yaml' has no input 'thikness' (did you mean 'thickness'?)"
        in msg
    )
    assert "bad.yaml:5: node 'b', input 'path': missing required input (Curve)" in msg
    assert "bad.yaml:6: node 'c', input 'surface': expected Surface, got Mesh from '@a.mesh'" in msg
    assert "'parts/ring.yaml' has no output 'nothing'; its outputs are mesh, outline" in msg


def test_a_broken_subgraph_is_reported_with_its_own_file_and_line(tree):
    write(
        tree,
        {
            "parts/broken.yaml": "formgraph: 1\noutputs: {m: '@t'}\nnodes:\n"
            "  c: {type: nurbs.circle}\n  t: {type: nurbs.tessellate, surface: '@c'}\n",
            "mid.yaml": "formgraph: 1\noutputs: {m: '@x.m'}\nnodes:\n"
            "  x: {type: parts/broken.yaml}\n",
            "top2.yaml": "formgraph: 1\nnodes:\n  user: {type: mid.yaml}\n",
        },
    )
    with pytest.raises(fg.GraphError) as err:
        fg.load(tree / "top2.yaml")
    msg = str(err.value)
    broken = str(tree / "parts" / "broken.yaml")
    assert msg == (
        f"{broken}:5: node 't', input 'surface': expected Surface, got NurbsCurve from '@c' "
        f"(in the subgraph used by node 'x' of {tree / 'mid.yaml'}, used by node 'user' of "
        f"{tree / 'top2.yaml'})"
    )


def test_include_cycles_are_errors(tree):
    write(
        tree,
        {
            "a.yaml": "formgraph: 1\noutputs: {o: '@n.o'}\nnodes:\n  n: {type: b.yaml}\n",
            "b.yaml": "formgraph: 1\noutputs: {o: '@n.o'}\nnodes:\n  n: {type: a.yaml}\n",
            "self.yaml": "formgraph: 1\noutputs: {o: '@n'}\nnodes:\n  n: {type: self.yaml}\n",
        },
    )
    with pytest.raises(
        fg.GraphError, match=r"b.yaml:4: node 'n': include cycle: a.yaml -> b.yaml -> a.yaml"
    ):
        fg.load(tree / "a.yaml")
    with pytest.raises(fg.GraphError, match=r"include cycle: self.yaml -> self.yaml"):
        fg.load(tree / "self.yaml")


def test_paths_that_leave_the_top_folder_are_refused(tmp_path):
    write(
        tmp_path,
        {
            "outside.yaml": "formgraph: 1\noutputs: {o: '@c'}\nnodes:\n  c: {type: nurbs.circle}\n",
            "g/top.yaml": "formgraph: 1\nnodes:\n  a: {type: ../outside.yaml}\n"
            f"  b: {{type: {tmp_path / 'outside.yaml'}}}\n",
            "g/parts/p.yaml": "formgraph: 1\noutputs: {o: '@c'}\nnodes:\n"
            "  c: {type: ../../outside.yaml}\n",
            "g/top2.yaml": "formgraph: 1\nnodes:\n  a: {type: parts/p.yaml}\n"
            "  b: {type: missing.yaml}\n",
        },
    )
    with pytest.raises(fg.GraphError) as err:
        fg.load(tmp_path / "g" / "top.yaml")
    msg = str(err.value)
    assert "top.yaml:3: node 'a': subgraph path '../outside.yaml' leaves the graph's folder" in msg
    assert f"top.yaml:4: node 'b': subgraph path '{tmp_path / 'outside.yaml'}' is absolute" in msg
    with pytest.raises(fg.GraphError) as err:
        fg.load(tmp_path / "g" / "top2.yaml")
    msg = str(err.value)
    assert "p.yaml:4: node 'c': subgraph path '../../outside.yaml' leaves the graph's folder" in msg
    assert "top2.yaml:4: node 'b': cannot read the subgraph file 'missing.yaml'" in msg


def test_an_edit_of_a_subgraph_file_invalidates_exactly_its_users(tree):
    write(
        tree,
        {
            "parts/disc.yaml": "formgraph: 1\nparams: {r: 1.0}\noutputs: {c: '@c'}\n"
            "nodes:\n  c: {type: nurbs.circle, radius: '=r'}\n",
            "two.yaml": TOP + "  disc: {type: parts/disc.yaml, r: 4}\n",
        },
    )
    g = fg.load(tree / "two.yaml")
    g.evaluate(["both", "disc"])
    (tree / "parts" / "disc.yaml").write_text(
        "formgraph: 1\nparams: {r: 1.0}\noutputs: {c: '@c'}\nnodes:\n"
        "  c: {type: nurbs.circle, radius: '=r * 2'}\n"
    )
    h = fg.load(tree / "two.yaml")
    h.memory = g.memory  # as watch does: the new version shares the cache
    out = h.evaluate(["both", "disc"])
    assert h.stats["disc"].status == "computed"
    assert {n: s.status for n, s in h.stats.items() if n != "disc"} == {
        "track": "cached",
        "left": "cached",
        "right": "cached",
        "both": "cached",
    }
    np.testing.assert_allclose(np.linalg.norm(out["disc"].evaluate(0.0)), 8.0)


def test_repeat_inside_a_subgraph_and_on_a_subgraph_node(tree):
    write(
        tree,
        {
            "parts/stack.yaml": """\
formgraph: 1
params: {n: 3, r: 1.0}
outputs: {rings: "@rings"}
nodes:
  rings: {type: nurbs.circle, repeat: {i: "=n"}, radius: "=r", center: [0, 0, "=i"]}
""",
            "use.yaml": """\
formgraph: 1
nodes:
  s: {type: parts/stack.yaml, n: 4}
  loft: {type: nurbs.loft, curves: "@s"}
  many: {type: parts/stack.yaml, repeat: {k: [1, 2]}, r: "=k", n: 2}
  all: {type: nurbs.loft, curves: "@many"}
  bad: {type: nurbs.extrude, curve: "@s"}
""",
        },
    )
    with pytest.raises(
        fg.GraphError,
        match=r"node 'bad', input 'curve': expected Curve, got list\[NurbsCurve\] from '@s'",
    ):
        fg.load(tree / "use.yaml")
    text = (
        (tree / "use.yaml").read_text().replace('  bad: {type: nurbs.extrude, curve: "@s"}\n', "")
    )
    (tree / "use.yaml").write_text(text)
    g = fg.load(tree / "use.yaml")
    assert len(g.evaluate("s")) == 4
    np.testing.assert_allclose(g.evaluate("loft").evaluate(0.0, 1.0)[2], 3.0, atol=1e-12)
    many = g.evaluate("many")
    assert [round(float(np.linalg.norm(c.evaluate(0.0)[:2])), 12) for c in many] == [1, 1, 2, 2]
    assert g.stats["many"].items == 2


def test_a_failure_inside_names_the_subgraph_and_the_chain(tree):
    write(
        tree,
        {
            "parts/fail.yaml": "formgraph: 1\nparams: {x: 1.0}\noutputs: {o: '@f'}\n"
            "nodes:\n  f: {type: stub.fail, x: '=x'}\n",
            "f.yaml": "formgraph: 1\nnodes:\n  user: {type: parts/fail.yaml}\n",
        },
    )
    g = fg.load(tree / "f.yaml")
    with pytest.raises(fg.NodeError) as err:
        g.evaluate("user")
    msg = str(err.value)
    assert msg.startswith(f"{tree / 'parts' / 'fail.yaml'}:5: node 'f' (stub.fail):")
    assert msg.count("(stub.fail)") == 1
    assert msg.endswith(f"(in the subgraph 'user' of {tree / 'f.yaml'})")


def test_save_round_trips_subgraphs_and_outputs(tree, tmp_path):
    g = fg.load(tree / "parts" / "ring.yaml")
    g.save(tree / "parts" / "copy.yaml")
    assert fg.load(tree / "parts" / "copy.yaml") == g
    assert "outputs:" in (tree / "parts" / "copy.yaml").read_text()
    t = fg.load(tree / "top.yaml")
    t.save(tree / "top_copy.yaml")
    assert fg.load(tree / "top_copy.yaml") == t


def test_nodes_prints_a_graph_files_interface(tree, capsys):
    assert main(["nodes", str(tree / "parts" / "ring.yaml")]) == 0
    out = capsys.readouterr().out
    assert "A tube ring swept along a path." in out
    assert "radius       float" in out and "path         Curve" in out and "[required]" in out
    assert "mesh         Mesh" in out and "outline      NurbsCurve" in out


def test_the_schema_accepts_graph_file_types_repeat_and_outputs():
    jsonschema = pytest.importorskip("jsonschema")
    validator = jsonschema.Draft202012Validator(json.loads(json.dumps(json_schema())))
    import yaml

    for text in (RING, TOP):
        assert not list(validator.iter_errors(yaml.safe_load(text)))
    doc = {
        "formgraph": 1,
        "nodes": {"r": {"type": "nurbs.circle", "repeat": {"i": 3}, "radius": "=i"}},
    }
    assert not list(validator.iter_errors(doc))
    doc["nodes"]["r"]["repeat"] = {"i": 3, "j": 2}
    assert list(validator.iter_errors(doc))


def test_watch_reloads_when_a_subgraph_file_changes(tree):
    import os

    pv = pytest.importorskip("pyvista")
    from formgraph import viewer

    def touch(path, text):
        path.write_text(text)
        st = path.stat()  # a new stamp even when the clock has not moved
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))

    plotter = pv.Plotter(off_screen=True, window_size=[320, 240])
    try:
        w = viewer.Watcher(tree / "top.yaml", "both", plotter=plotter, out_dir=tree / "out")
        assert w.reload() is True
        assert w.poll() is None
        part = tree / "parts" / "ring.yaml"
        touch(part, RING.replace("u: 8, v: 16", "u: 4, v: 16"))
        assert w.poll() is True
        assert w.session.graph.evaluate("both").n_faces == 2 * 4 * 16
        touch(part, RING.replace('radius: "=radius"', 'radius: "=radiu"'))
        assert w.poll() is False and "radiu" in w.error_text()
        touch(part, RING)  # the broken part is still watched: fixing it redraws
        assert w.poll() is True and w.error_text() is None
    finally:
        plotter.close()


def test_a_new_version_of_a_node_inside_changes_the_subgraphs_key(tree, monkeypatch):
    import dataclasses

    from formgraph.core import registry

    before = fg.load(tree / "top.yaml").node_types()["parts/ring.yaml"].digest
    spec = registry._REGISTRY["nurbs.sweep"]
    monkeypatch.setitem(registry._REGISTRY, "nurbs.sweep", dataclasses.replace(spec, version=99))
    after = fg.load(tree / "top.yaml").node_types()["parts/ring.yaml"].digest
    assert before != after
