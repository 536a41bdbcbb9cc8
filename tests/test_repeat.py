"""repeat: on any node: counts, lists, wires to lists and Points; per-item caching; types."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from stubs import CALLS

import formgraph as fg
from formgraph.cli.main import main

RINGS = """\
formgraph: 1
params:
  n: {default: 5, min: 2, max: 50}
  height: 4.0
nodes:
  rings:
    type: nurbs.circle
    repeat: {i: "=n"}
    radius: "=1 + 0.1 * i"
    center: [0, 0, "=height * i"]
  vase: {type: nurbs.loft, curves: "@rings"}
"""


def test_repeat_over_a_count_makes_a_list_that_lofts():
    g = fg.Graph.from_text(RINGS)
    rings = g.evaluate("rings")
    assert isinstance(rings, list) and len(rings) == 5
    for i, c in enumerate(rings):
        p = c.sample(50)
        np.testing.assert_allclose(np.linalg.norm(p[:, :2], axis=1), 1 + 0.1 * i, atol=1e-12)
        np.testing.assert_allclose(p[:, 2], 4.0 * i)
    vase = g.evaluate("vase")
    np.testing.assert_allclose(vase.evaluate(0.0, 1.0)[2], 16.0, atol=1e-12)


def test_one_more_item_computes_exactly_one_item():
    g = fg.Graph()
    g.add_param("n", 5)
    g.add("v", "stub.value", repeat={"i": "=n"}, x="=2 * i", label="=i" if False else "v")
    g.add("s", "stub.sum", items="@v")
    assert g.evaluate("s") == 20.0
    assert CALLS.count("value:v") == 5
    st = g.stats["v"]
    assert (st.status, st.items, st.computed_items) == ("computed", 5, 5)
    CALLS.clear()
    assert g.evaluate("s", n=6) == 30.0
    assert CALLS.count("value:v") == 1
    st = g.stats["v"]
    assert (st.status, st.items, st.computed_items) == ("computed", 6, 1)
    CALLS.clear()
    assert g.evaluate("s", n=4) == 12.0  # every item of 4 is cached
    assert CALLS == ["sum:"]
    assert g.stats["v"].status == "cached" and g.stats["v"].items == 4


def test_repeat_over_a_literal_list_and_an_expression_list():
    g = fg.Graph()
    g.add_param("radii", [1.0, 2.0])
    g.add("a", "nurbs.circle", repeat={"r": [1, 2, 5]}, radius="=r")
    g.add("b", "nurbs.circle", repeat={"r": "=radii"}, radius="=r * 2")
    a, b = g.evaluate("a"), g.evaluate("b")
    assert [float(np.linalg.norm(c.evaluate(0.0))) for c in a] == pytest.approx([1, 2, 5])
    assert [float(np.linalg.norm(c.evaluate(0.0))) for c in b] == pytest.approx([2, 4])


def test_repeat_over_points_gives_each_point_as_a_vec3():
    g = fg.Graph()
    g.add("pts", "points.circle", count=6, radius=3)
    g.add("boxes", "mesh.box", repeat={"p": "@pts"}, center="=p", size=0.5)
    g.add("all", "mesh.merge", meshes="@boxes")
    boxes, merged = g.evaluate("boxes"), g.evaluate("all")
    pts = g.evaluate("pts").xyz
    assert len(boxes) == 6 and merged.n_faces == 36
    for b, p in zip(boxes, pts, strict=True):
        np.testing.assert_allclose(b.vertices.mean(axis=0), p, atol=1e-12)
    # the points moving recomputes the items (their keys hold the wire's identity)
    g.set_input("pts", "radius", 4)
    g.evaluate("all")
    assert g.stats["boxes"].computed_items == 6


def test_repeat_over_a_list_wire_and_a_loop_name_in_a_geometry_input():
    g = fg.Graph()
    g.add("pts", "points.circle", count=4, radius=3)
    g.add("rings", "curves.copy_to_points", curve="@c", points="@pts")
    g.add("c", "nurbs.circle", radius=0.5)
    g.add("tubes", "nurbs.extrude", repeat={"ring": "@rings"}, curve="=ring", direction=[0, 0, 1])
    g.add("meshes", "nurbs.tessellate", repeat={"s": "@tubes"}, surface="=s", u=8, v=4)
    g.add("all", "mesh.merge", meshes="@meshes")
    assert g.evaluate("all").n_faces == 4 * 32


def test_loop_name_in_an_expression_port_and_a_multi_output_node():
    g = fg.Graph()
    g.add(
        "h",
        "curves.parametric",
        repeat={"k": 3},
        x="cos(t) * (k + 1)",
        y="sin(t)",
        t=[0, 6.283185307179586],
    )
    hs = g.evaluate("h")
    assert [round(float(c.evaluate(0.0)[0]), 12) for c in hs] == [1, 2, 3]
    g.add("wall", "surfaces.parametric", x="u", y="v", z="0")
    g.add("s", "geometry.sample_surface", repeat={"k": [1, 2]}, surface="@wall", u="=k", v=1)
    out = g.evaluate("s")
    assert [len(p) for p in out.points] == [1, 2] and len(out.normals) == 3


def test_a_repeated_output_where_one_item_is_expected_is_a_type_error():
    g = fg.Graph.from_text(
        RINGS + "  one: {type: nurbs.tessellate, surface: '@lofts'}\n"
        "  lofts: {type: nurbs.loft, repeat: {j: 2}, curves: '@rings'}\n"
        "  c: {type: nurbs.extrude, curve: '@rings'}\n",
        check=False,
    )
    with pytest.raises(fg.GraphError) as err:
        g.check()
    text = str(err.value)
    assert (
        "node 'one', input 'surface': expected Surface, got list[NurbsSurface] from '@lofts' "
        "('lofts' is repeated over 'j': it gives a list, one item per j)"
    ) in text
    assert "node 'c', input 'curve': expected Curve, got list[NurbsCurve] from '@rings'" in text
    assert "<graph>:12:" in text and "<graph>:14:" in text


def test_repeat_problems_are_collected_with_their_lines():
    text = """\
formgraph: 1
params: {n: 3}
nodes:
  c: {type: nurbs.circle}
  a:
    type: nurbs.circle
    repeat: {n: 3}
  b:
    type: nurbs.circle
    repeat: {i: "@c"}
  d:
    type: nurbs.circle
    repeat: {i: 3}
    radius: "=j + 1"
  e:
    type: nurbs.circle
    repeat: {i: -2}
  f:
    type: nurbs.circle
    repeat: [1, 2]
  h:
    type: nurbs.circle
    repeat: {i: 3}
    center: "=i"
"""
    with pytest.raises(fg.GraphError) as err:
        fg.Graph.from_text(text, file="r.yaml")
    msg = str(err.value)
    assert "r.yaml:7: node 'a', input 'repeat': loop name 'n' would hide a param" in msg
    assert (
        "r.yaml:10: node 'b', input 'repeat': repeat 'i' runs over a count (int), a list, "
        "or a wire to a list or to Points; '@c' gives NurbsCurve" in msg
    )
    assert "r.yaml:14: node 'd', input 'radius': expression '=j + 1' names unknown param 'j'" in msg
    assert "r.yaml:17: node 'e', input 'repeat': repeat 'i': a count must be >= 0, got -2" in msg
    assert "r.yaml:20: node 'f', input 'repeat': repeat takes one loop name" in msg
    assert (
        "r.yaml:24: node 'h', input 'center': expected Vec3, got int from the loop name 'i'" in msg
    )


def test_the_budget_applies_to_the_count_before_anything_runs():
    g = fg.Graph(budget=100)
    g.add_param("n", 10)
    g.add("first", "stub.value", x=1.0, label="first")
    g.add("v", "stub.add", repeat={"i": "=n * n * 10"}, a="@first", b="=i", label="v")
    with pytest.raises(
        fg.BudgetError,
        match=r"node 'v', input 'repeat': repeat 'i' would run 1,000 items, over the budget of 100",
    ):
        g.evaluate("v")
    assert CALLS == []


def test_save_round_trips_repeat(tmp_path):
    g = fg.Graph.from_text(RINGS)
    g.add("pts", "points.circle", count=3)
    g.add("boxes", "mesh.box", repeat={"p": "@pts"}, center="=p")
    path = tmp_path / "r.yaml"
    g.save(path)
    h = fg.load(path)
    assert h == g
    assert len(h.evaluate("boxes")) == 3
    assert "repeat: {i: =n}" in path.read_text() or "repeat:\n      i: =n" in path.read_text()


def test_profile_shows_a_repeated_node_once_with_its_items(tmp_path, capsys):
    path = tmp_path / "r.yaml"
    path.write_text(RINGS)
    assert main(["run", str(path), "--no-cache", "--profile", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    rows = [r for r in out.splitlines() if r.startswith("rings")]
    assert len(rows) == 1 and "5 items" in rows[0] and "5/5" in rows[0]


def test_items_come_back_from_the_disk_cache(tmp_path):
    def make():
        g = fg.Graph(cache_dir=tmp_path / "cache")
        g.add(
            "wall",
            "nurbs.surface",
            points=[[[0, 0], [0, 1]], [[1, 0], [1, 1]]],
            degree_u=1,
            degree_v=1,
        )
        g.add("s", "geometry.sample_surface", repeat={"k": [1, 2]}, surface="@wall", u="=k")
        g.add("rings", "nurbs.circle", repeat={"r": [1, 2]}, radius="=r")
        return g

    first = make().evaluate(["s", "rings"])
    g = make()
    again = g.evaluate(["s", "rings"])
    assert g.stats["s"].status == "cached" and g.stats["s"].source == "disk"
    assert [len(p) for p in again["s"].points] == [8, 16]
    for a, b in zip(first["rings"], again["rings"], strict=True):
        np.testing.assert_array_equal(a.control_points, b.control_points)


def test_set_input_changes_the_loop():
    g = fg.Graph()
    g.add("c", "nurbs.circle", repeat={"i": 2}, radius="=i + 1")
    assert len(g.evaluate("c")) == 2
    g.set_input("c", "repeat", {"i": 4})
    assert len(g.evaluate("c")) == 4
    g.set_input("c", "repeat", None)
    with pytest.raises(fg.GraphError, match="names unknown param 'i'"):
        g.evaluate("c")


def test_a_repeated_transform_of_the_loop_item_keeps_its_type():
    g = fg.Graph()
    g.add("pts", "points.circle", count=3)
    g.add("c", "nurbs.circle", radius=0.3)
    g.add("cs", "curves.copy_to_points", curve="@c", points="@pts")
    g.add("t", "geometry.transform", repeat={"k": "@cs"}, geometry="=k", translate=[0, 0, 1])
    g.add("loft", "nurbs.loft", curves="@t", degree_v=2)
    assert g.evaluate("loft").evaluate(0.0, 0.0)[2] == pytest.approx(1.0)
    g.add("bad", "nurbs.extrude", curve="@t")
    with pytest.raises(
        fg.GraphError, match=r"expected Curve, got list\[Curve\] from '@t' \('t' is"
    ):
        g.check()


def test_repeat_over_a_list_of_wires_twice():
    g = fg.Graph()
    g.add("a", "nurbs.circle", radius=1)
    g.add("b", "nurbs.circle", radius=2)
    g.add("e", "nurbs.extrude", repeat={"c": ["@a", "@b"]}, curve="=c")
    assert len(g.evaluate("e")) == 2
    g.add("f", "mesh.box")  # a change elsewhere; a, b and e come from the cache
    assert len(g.evaluate("e")) == 2
    assert g.stats["e"].status == "cached" and g.stats["e"].items == 2


def test_the_readme_repeat_example_runs():
    import re
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    (block,) = [
        b
        for b in re.findall(r"```yaml\n(.*?)```", readme, flags=re.S)
        if "repeat: {i:" in b and "rings:" in b
    ]
    g = fg.Graph.from_text("formgraph: 1\n" + block)
    assert len(g.evaluate("rings")) == 7
    assert g.evaluate("body").evaluate(0.0, 1.0)[2] == pytest.approx(6.0)


def test_a_wire_beside_the_loop_name_in_one_input_still_invalidates():
    g = fg.Graph()
    g.add_param("t", 0.5)
    g.add("a", "nurbs.circle")
    g.add("pts", "points.circle", count=2, radius=5)
    g.add("rings", "curves.copy_to_points", curve="@a", points="@pts")
    g.add("top", "nurbs.circle", radius="=t", center=[0, 0, 3])
    # each item lofts one ring to the top circle: the input reads the loop name and a wire
    g.add("lofts", "nurbs.loft", repeat={"c": "@rings"}, curves=["=c", "@top"], degree_v=1)
    first = g.evaluate("lofts")
    again = g.evaluate("lofts", t=1.5)  # only the wired circle changes
    assert g.stats["lofts"].computed_items == 2
    assert not np.allclose(first[0].control_points, again[0].control_points)


@given(first=st.integers(0, 30), second=st.integers(0, 30))
@settings(max_examples=30, deadline=None)
def test_changing_the_count_computes_only_new_items(first, second):
    g = fg.Graph()
    g.add_param("n", first)
    g.add("v", "stub.value", repeat={"i": "=n"}, x="=i * i", label="v")
    assert g.evaluate("v") == [float(i * i) for i in range(first)]
    CALLS.clear()
    assert g.evaluate("v", n=second) == [float(i * i) for i in range(second)]
    assert CALLS.count("value:v") == max(0, second - first)
    assert g.stats["v"].items == second
