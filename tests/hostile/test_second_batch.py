"""Hostile use of the second batch: repeat:, subgraph files, solids. Each case ends as a
located sentence (file, line, node, input) or a correct result."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pytest

import formgraph as fg
from formgraph.cli import main as cli


def _graph(text: str) -> fg.Graph:
    return fg.Graph.from_text("formgraph: 1\nnodes:\n" + text, file="h.yaml")


# ---------------------------------------------------------------------------- repeat:


@pytest.mark.parametrize(
    ("items", "what"),
    [
        ("[true, false]", "item 0 is bool True"),
        ("[1, true]", "item 1 is bool True"),
        ("[[0, 0, 0], [1, false, 0]]", "item 1 is list of 3"),
        ("[a, b]", "item 0 is string 'a'"),
    ],
)
def test_a_loop_over_bools_or_strings_is_refused(items, what):
    text = f"  c: {{type: nurbs.circle, repeat: {{i: {items}}}, radius: 1}}\n"
    with pytest.raises(fg.GraphError, match=rf"h.yaml:3: node 'c', input 'repeat': .*{what}"):
        _graph(text).evaluate("c")


def test_a_loop_over_bools_is_refused_in_python_too():
    g = fg.Graph()
    g.add("c", "nurbs.circle", repeat={"i": [True, False]}, radius="=1 + i")
    with pytest.raises(fg.GraphError, match="node 'c', input 'repeat': .*write 1 and 0"):
        g.evaluate("c")


def test_a_loop_over_points_and_numbers_still_runs():
    g = fg.Graph()
    g.add("c", "nurbs.circle", repeat={"p": [[0, 0, 0], [1, 2, 3]]}, radius=1, center="=p")
    assert len(g.evaluate("c")) == 2


@pytest.mark.parametrize("count", ["1e9", "100000000000000000000000000000000000000000"])
def test_a_huge_loop_is_over_the_budget(count):
    text = f"  c: {{type: nurbs.circle, repeat: {{i: {count}}}, radius: '=1 + i'}}\n"
    with pytest.raises(fg.BudgetError, match="node 'c', input 'repeat': .*over the budget"):
        _graph(text).evaluate("c")


# ---------------------------------------------------------------------------- subgraphs


def _run(folder: Path, name: str, capsys) -> tuple[int, str]:
    code = cli.main(["run", str(folder / name)])
    return code, capsys.readouterr().err


def test_a_subgraph_path_with_a_nul_byte_is_a_sentence(tmp_path, capsys):
    (tmp_path / "top.yaml").write_text('formgraph: 1\nnodes:\n  n: {type: "a\\0.yaml"}\n')
    code, err = _run(tmp_path, "top.yaml", capsys)
    assert code == 1
    assert "top.yaml:3: node 'n': cannot use the subgraph path" in err and "NUL" in err
    assert "internal error" not in err


def test_a_subgraph_path_through_a_symlink_loop_is_a_sentence(tmp_path, capsys):
    os.symlink("b.yaml", tmp_path / "a.yaml")
    os.symlink("a.yaml", tmp_path / "b.yaml")
    (tmp_path / "top.yaml").write_text("formgraph: 1\nnodes:\n  n: {type: a.yaml}\n")
    code, err = _run(tmp_path, "top.yaml", capsys)
    assert code == 1 and "top.yaml:3: node 'n'" in err and "internal error" not in err


def test_a_symlink_out_of_the_folder_is_refused(tmp_path, capsys):
    top, outside = tmp_path / "top", tmp_path / "outside"
    top.mkdir()
    outside.mkdir()
    (outside / "o.yaml").write_text(
        "formgraph: 1\noutputs: {c: '@c'}\nnodes:\n  c: {type: nurbs.circle, radius: 1}\n"
    )
    os.symlink(outside / "o.yaml", top / "link.yaml")
    os.symlink(outside, top / "dir")
    for ref in ("link.yaml", "dir/o.yaml"):
        (top / "t.yaml").write_text(f"formgraph: 1\nnodes:\n  n: {{type: {ref}}}\n")
        code, err = _run(top, "t.yaml", capsys)
        assert code == 1 and "t.yaml:3: node 'n'" in err and "leaves the graph's folder" in err


def test_two_files_that_include_each_other_are_a_cycle(tmp_path, capsys):
    (tmp_path / "a.yaml").write_text(
        "formgraph: 1\noutputs: {c: '@x'}\nnodes:\n  x: {type: b.yaml}\n"
    )
    (tmp_path / "b.yaml").write_text(
        "formgraph: 1\noutputs: {c: '@y'}\nnodes:\n  y: {type: a.yaml}\n"
    )
    (tmp_path / "top.yaml").write_text("formgraph: 1\nnodes:\n  n: {type: a.yaml}\n")
    code, err = _run(tmp_path, "top.yaml", capsys)
    assert code == 1
    assert "b.yaml:4: node 'y': include cycle: a.yaml -> b.yaml -> a.yaml" in err


@pytest.mark.parametrize(("outer", "inner", "refused"), [(40, 40, True), (20, 20, False)])
def test_a_repeated_subgraph_budgets_its_own_repeat_times_the_outer_count(
    tmp_path, outer, inner, refused
):
    # each repeat alone fits 1,000 items; nested they run outer * inner
    (tmp_path / "ring.yaml").write_text(
        f"formgraph: 1\nparams: {{n: {inner}}}\noutputs: {{c: '@c'}}\nnodes:\n"
        "  c: {type: nurbs.circle, repeat: {j: '=n'}, radius: '=1 + j'}\n"
    )
    (tmp_path / "top.yaml").write_text(
        f"formgraph: 1\nnodes:\n  r: {{type: ring.yaml, repeat: {{i: {outer}}}, n: {inner}}}\n"
    )
    g = fg.load(tmp_path / "top.yaml", out_dir=tmp_path / "out", budget=1_000_000)
    if not refused:
        assert len(g.evaluate("r")) == outer * inner
        return
    with pytest.raises(fg.BudgetError, match=r"ring.yaml:5: node 'c', input 'repeat': .*") as e:
        g.evaluate("r")
    assert f"{inner} items for each of the {outer} items" in str(e.value)
    assert f"({outer * inner:,} in all)" in str(e.value)
    assert "(in the subgraph 'r' of " in str(e.value)


def test_a_nested_repeat_is_refused_before_the_nodes_upstream_run(tmp_path):
    (tmp_path / "ring.yaml").write_text(
        "formgraph: 1\nparams: {n: 40, r: 1.0}\noutputs: {c: '@c'}\nnodes:\n"
        "  c: {type: nurbs.circle, repeat: {j: '=n'}, radius: '=r + j'}\n"
    )
    (tmp_path / "top.yaml").write_text(
        "formgraph: 1\nnodes:\n  b: {type: mesh.box}\n  m: {type: mesh.measure, mesh: '@b'}\n"
        "  r: {type: ring.yaml, repeat: {i: 40}, r: '@m.area'}\n"
    )
    g = fg.load(tmp_path / "top.yaml", out_dir=tmp_path / "out", budget=1_000_000)
    with pytest.raises(fg.BudgetError, match=r"ring.yaml:5: .*1,600 in all"):
        g.evaluate("r")
    assert g.stats == {} or all(st.status != "computed" for st in g.stats.values())


@pytest.mark.parametrize(
    ("outputs", "error"),
    [
        ("outputs: {c: '@c'\n", "part.yaml:3: not valid YAML"),
        ("outputs: 3\n", "part.yaml:2: 'outputs' must be a mapping"),
        ("", "part.yaml:1: a graph used as a node needs 'outputs:'"),
    ],
)
def test_a_broken_subgraph_file_reports_only_its_real_error(tmp_path, capsys, outputs, error):
    # a file that is not YAML also got a spurious "needs 'outputs:'" line
    (tmp_path / "part.yaml").write_text(
        f"formgraph: 1\n{outputs}nodes:\n  c: {{type: nurbs.circle, radius: 1}}\n"
    )
    (tmp_path / "top.yaml").write_text("formgraph: 1\nnodes:\n  n: {type: part.yaml}\n")
    code, err = _run(tmp_path, "top.yaml", capsys)
    lines = [ln for ln in err.splitlines() if "part.yaml" in ln]
    assert code == 1 and len(lines) == 1 and f"{os.sep}{error}" in lines[0], err


# ---------------------------------------------------------------------------- solids


def test_a_non_finite_vector_says_so():
    with pytest.raises(fg.GraphError, match=r"input 'center': .*finite numbers, got \[nan, 0, 0\]"):
        _graph("  s: {type: mesh.sphere, radius: 1, center: [.nan, 0, 0]}\n").evaluate("s")


@pytest.mark.parametrize("tolerance", [1e-320, 1e-200, 5e-324, 1e-3])
def test_a_tolerance_tiny_against_the_coordinates_still_welds(tolerance):
    # the dense weld grid refused these (its cells would number more than 2^62); the sparse
    # one only stores occupied cells. A sphere's vertices are all farther apart than 1e-3.
    g = fg.Graph()
    g.add("s", "mesh.sphere", radius=1e10, segments=64)
    g.add("w", "mesh.weld", mesh="@s", tolerance=tolerance)
    s, w = g.evaluate("s"), g.evaluate("w")
    assert w.n_vertices == s.n_vertices and w.is_watertight


def test_a_small_tolerance_on_huge_coordinates_matches_a_kd_tree():
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    from formgraph.kernels.mesh import cells
    from formgraph.kernels.mesh import measure as km

    rng = np.random.default_rng(7)
    pts = 1e10 * rng.normal(size=(300, 3))
    pts = np.concatenate([pts, pts[:100] + rng.normal(0, 3e-4, (100, 3))])  # near copies
    i, j = cells.close_pairs(pts, 1e-3)
    root, _ = km.union_find(len(pts), i, j)
    pairs = np.array(sorted(cKDTree(pts).query_pairs(1e-3)), dtype=np.int64).reshape(-1, 2)
    assert len(pairs) > 20  # the near copies are found
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(pts),) * 2)
    _, labels = connected_components(graph, directed=False)
    assert len(set(zip(root.tolist(), labels.tolist(), strict=True))) == labels.max() + 1
    assert len(set(root.tolist())) == labels.max() + 1


def test_weld_tolerance_zero_merges_only_exact_duplicates():
    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("w", "mesh.weld", mesh="@b", tolerance=0)
    assert g.evaluate("w").n_vertices == 8


@pytest.mark.parametrize(
    ("vertices", "faces"),
    [
        # a tetrahedron pair pinched at one point (two vertices, one position)
        (
            [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 0], [-1, 0, 0], [0, -1, 0]]
            + [[0, 0, -1]],
            [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [4, 5, 6], [4, 7, 5], [4, 6, 7]]
            + [[5, 7, 6]],
        ),
        # every vertex at one point: a closed, oriented, zero-volume tetrahedron
        ([[0, 0, 0]] * 4, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
    ],
)
def test_degenerate_solids_into_booleans_give_true_volumes(vertices, faces):
    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("a", "mesh.from_faces", vertices=vertices, faces=faces)
    g.add("d", "mesh.boolean", a="@a", b="@b", operation="difference")
    g.add("u", "mesh.union", meshes=["@a", "@b"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fg.FormgraphWarning)  # "the difference is empty"
        d = g.evaluate("d")
        u = g.evaluate("u")
    # the tetrahedra of the pair stick out of the unit box by 1/16 each (1/6 - 5/48)
    outside = 0.0 if d.n_faces == 0 else 1 / 8
    assert d.n_faces == 0 or (d.is_watertight and d.volume == pytest.approx(outside))
    assert u.is_watertight and u.volume == pytest.approx(1.0 + outside)


def test_an_open_mesh_into_a_boolean_is_a_sentence():
    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("t", "mesh.cylinder", radius=0.3, height=2, caps=False)
    g.add("d", "mesh.boolean", a="@b", b="@t", operation="difference")
    with pytest.raises(fg.NodeError, match=r"input 'b'.*not a closed solid: it has \d+ open"):
        g.evaluate("d")


def test_cap_of_a_non_manifold_boundary_vertex_caps_each_fan():
    # two triangles touching at vertex 0: its boundary passes vertex 0 twice
    g = fg.Graph()
    g.add(
        "a",
        "mesh.from_faces",
        vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]],
        faces=[[0, 1, 2], [0, 3, 4]],
    )
    g.add("c", "mesh.cap", mesh="@a")
    m = g.evaluate("c")
    assert m.n_faces == 4 and m.is_watertight


@pytest.mark.parametrize(
    ("type_", "inputs"),
    [
        ("mesh.copy_to_points", {"mesh": "@b", "points": [[0, 0, 0], [3, 0, 0]]}),
        ("mesh.copy_to_points", {"mesh": "@b", "points": []}),
        ("mesh.weld", {"mesh": "@b"}),
        ("mesh.cap", {"mesh": "@b"}),
        ("mesh.union", {"meshes": ["@b"]}),
        ("geometry.transform", {"geometry": "@b", "scale": 2}),
    ],
)
def test_new_nodes_give_arrays_that_cannot_be_made_writable(type_, inputs):
    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("x", type_, **inputs)
    m = g.evaluate("x")
    for a in (m.vertices, m.face_indices, m.face_offsets):
        while isinstance(a, np.ndarray):
            with pytest.raises(ValueError):
                a.flags.writeable = True
            a = a.base


def test_a_loop_the_element_budget_allows_but_would_run_for_hours_is_refused():
    # 49 million items fit 50 million elements, but each item is a node run (~0.2 ms)
    text = "  c: {type: nurbs.circle, repeat: {i: 49000000}, radius: '=1 + i'}\n"
    with pytest.raises(fg.BudgetError, match=r"each item is a node run .* at most 50,000 items"):
        _graph(text).evaluate("c")


def test_a_loop_within_the_item_budget_runs():
    g = fg.Graph(budget=3000)
    g.add("c", "nurbs.circle", repeat={"i": 3}, radius="=1 + i")
    assert len(g.evaluate("c")) == 3
    g.add("d", "nurbs.circle", repeat={"i": 4}, radius="=1 + i")
    with pytest.raises(fg.BudgetError, match="would run 4 items, over the budget of 3,000"):
        g.evaluate("d")


def _star_prism(k: int) -> tuple[list[list[float]], list[list[int]]]:
    """A k-corner star (concave) as the floor and roof of a closed prism."""
    a = np.linspace(0, 2 * np.pi, k, endpoint=False)
    r = np.where(np.arange(k) % 2 == 0, 1.0, 0.5)
    ring = np.c_[r * np.cos(a), r * np.sin(a)]
    v = np.r_[np.c_[ring, np.zeros(k)], np.c_[ring, np.ones(k)]]
    j = np.arange(k)
    sides = np.c_[j, (j + 1) % k, (j + 1) % k + k, j + k].tolist()
    return v.tolist(), [list(range(k))[::-1], list(range(k, 2 * k)), *sides]


@pytest.mark.parametrize("type_", ["mesh.cap", "mesh.boolean", "mesh.union"])
def test_ear_clipping_inside_solids_counts_against_the_budget(type_):
    # mesh.triangulate refused this work; cap and the booleans clipped it unbounded
    v, faces = _star_prism(2000)
    g = fg.Graph(budget=100_000)
    if type_ == "mesh.cap":
        g.add("m", "mesh.from_faces", vertices=v[:2000], faces=[faces[0]])  # an open star
        g.add("x", "mesh.cap", mesh="@m")
    else:
        g.add("m", "mesh.from_faces", vertices=v, faces=faces)
        g.add("b", "mesh.box")
        inputs = {"a": "@m", "b": "@b"} if type_ == "mesh.boolean" else {"meshes": ["@m"]}
        g.add("x", type_, **inputs)
    with pytest.raises(fg.BudgetError, match="node 'x': would make .* triangle-corner tests"):
        g.evaluate("x")
    g.budget = 10**9
    assert g.evaluate("x").is_watertight


def test_a_loop_over_too_many_points_is_refused_by_their_count():
    g = fg.Graph(budget=1_000_000)
    g.add("p", "points.random", count=200_000)
    g.add("c", "nurbs.circle", repeat={"p": "@p"}, radius=1, center="=p")
    # refused before the points are made (the source is asked what it would make)
    with pytest.raises(
        fg.BudgetError, match="would run (about )?200,000 items, .* at most 1,000 items"
    ):
        g.evaluate("c")


# ---------------------------------------------------------------------------- long chains


def test_a_long_chain_of_same_type_nodes_checks_without_recursing(tmp_path, capsys):
    # geometry.transform's output type follows its input: the checker recursed once per
    # node and hit Python's recursion limit (an internal error) near 1,000 nodes
    lines = ["formgraph: 1", "nodes:", "  n0: {type: points.circle, count: 4}"]
    lines += [
        f"  n{i}: {{type: geometry.transform, geometry: '@n{i - 1}', translate: [1, 0, 0]}}"
        for i in range(1, 3000)
    ]
    (tmp_path / "chain.yaml").write_text("\n".join(lines[:2] + lines[:1:-1]) + "\n")  # sinks first
    assert cli.main(["check", str(tmp_path / "chain.yaml")]) == 0, capsys.readouterr().err
    g = fg.load(tmp_path / "chain.yaml")
    assert g.evaluate("n2999").xyz[0, 0] == pytest.approx(1 + 2999)


@pytest.mark.parametrize(
    "d", [[0.0, 3.7332462518125146e-162, -1.0], [0.0, 1e-310, -1.0], [1e-200, -1e-200, -1.0]]
)
def test_align_onto_almost_minus_z_is_a_rotation(d):
    # found by hypothesis: x^2 + y^2 underflowed to a subnormal and the matrix came out NaN
    from formgraph.kernels.geometry import affine

    r = affine.align_z(np.array([d]))[0]
    np.testing.assert_allclose(r @ [0, 0, 1], np.array(d) / np.linalg.norm(d), atol=1e-12)
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)


def test_drawing_a_graph_reads_its_node_table_a_fixed_number_of_times(monkeypatch):
    # graph.nodes builds a new dict; drawing read it for every node and wire (quadratic:
    # 92 s for a 20,000-node chain)
    g = fg.Graph()
    g.add("n0", "points.circle", count=4)
    for i in range(1, 200):
        g.add(f"n{i}", "geometry.transform", geometry=f"@n{i - 1}", translate=[1, 0, 0])
    calls = []
    table = fg.Graph.nodes.fget
    monkeypatch.setattr(fg.Graph, "nodes", property(lambda self: calls.append(1) or table(self)))
    fg.draw_graph(g)
    assert len(calls) < 10


@pytest.mark.parametrize(
    ("vertices", "faces"),
    [
        ([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]]),  # a square
        ([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]], [[0, 1, 2], [0, 3, 4]]),
        ([[0, 0, 0], [1, 0, 1], [1, 1, 2]], [[0, 1, 2]]),  # one tilted triangle
    ],
)
def test_capping_a_flat_sheet_warns_that_it_has_no_volume(vertices, faces):
    g = fg.Graph()
    g.add("a", "mesh.from_faces", vertices=vertices, faces=faces)
    g.add("c", "mesh.cap", mesh="@a")
    with pytest.warns(fg.FormgraphWarning, match=r"flat open sheet.*zero volume.*mesh\.solidify"):
        m = g.evaluate("c")
    assert m.volume == pytest.approx(0.0, abs=1e-12)


def test_capping_a_plane_warns_but_a_tube_or_a_cup_does_not():
    g = fg.Graph()
    g.add("p", "mesh.plane", divisions=[3, 2], center=[5, 0, 0])
    g.add("t", "mesh.cylinder", radius=1, height=2, caps=False)
    g.add("m", "mesh.merge", meshes=["@p", "@t"])
    g.add("c", "mesh.cap", mesh="@m")
    with pytest.warns(fg.FormgraphWarning, match=r"^.*1 part of the mesh is a flat open sheet"):
        g.evaluate("c")
    g.add("ct", "mesh.cap", mesh="@t")
    with warnings.catch_warnings():
        warnings.simplefilter("error", fg.FormgraphWarning)
        assert g.evaluate("ct").is_watertight


@pytest.mark.parametrize(
    ("type_", "inputs", "port"),
    [
        ("mesh.solidify", {"mesh": "@p", "thickness": 1e308, "offset": 1}, "thickness"),
        ("mesh.solidify", {"mesh": "@p", "thickness": 1e308, "offset": -1}, "thickness"),
        (
            "mesh.solidify",
            {"mesh": "@p", "thickness": 1, "thickness_map": "thickness * 1e308", "offset": 1},
            "thickness_map",
        ),
        ("mesh.sphere", {"radius": 1e308, "center": [1.7e308, 0, 0]}, "radius"),
        ("mesh.cylinder", {"radius": 1e308, "height": 1, "center": [1.7e308, 0, 0]}, "radius"),
        ("mesh.cylinder", {"radius": 1, "height": 1.7e308, "center": [0, 0, 1e308]}, "height"),
        ("mesh.torus", {"major": 1e308, "minor": 1, "center": [1.7e308, 0, 0]}, "major"),
        ("mesh.plane", {"size": [1e308, 1], "center": [1.7e308, 0, 0]}, "size"),
    ],
)
def test_a_size_that_overflows_the_floats_is_blamed_not_the_mesh(type_, inputs, port):
    g = fg.Graph()
    g.add("p", "mesh.plane")
    g.add("x", type_, **inputs)
    with pytest.raises(fg.NodeError, match=rf"input '{port}' .*beyond the largest float"):
        g.evaluate("x")


def test_measuring_an_inward_or_misoriented_closed_mesh_warns():
    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("f", "mesh.flip", mesh="@b")
    g.add("m", "mesh.measure", mesh="@f")
    with pytest.warns(fg.FormgraphWarning, match=r"faces inward.*negative \(-1\).*mesh\.orient"):
        assert g.evaluate("m").volume == pytest.approx(-1.0)
    # a box with its floor turned (a Mesh from Python; mesh.from_faces refuses it): closed,
    # but its faces disagree across the floor's 4 edges
    v = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
    faces = [0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7]
    x = fg.Mesh(np.array(v, float), np.array(faces), np.arange(0, 25, 4))
    g.add("mx", "mesh.measure", mesh=x)
    with pytest.warns(fg.FormgraphWarning, match=r"disagree in orientation across 4 edges"):
        g.evaluate("mx")
    g.add("mb", "mesh.measure", mesh="@b")
    with warnings.catch_warnings():
        warnings.simplefilter("error", fg.FormgraphWarning)
        assert g.evaluate("mb").volume == pytest.approx(1.0)
