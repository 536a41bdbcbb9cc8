"""The brep.* nodes against closed forms (all to 1e-6) and OpenCASCADE's own checks:
fillets by the Steiner formula and Pappus, chamfers, drilled blocks, extruded plates with
holes, revolutions, lofts, sewn surfaces, shells; selectors; warnings; the errors' words."""

from __future__ import annotations

import math

import numpy as np
import pytest

import formgraph as fg

pytest.importorskip("OCP")

from formgraph.kernels.brep import occ, topology  # noqa: E402

REL = 1e-6


def build(*nodes: tuple) -> fg.Graph:
    g = fg.Graph()
    for name, kind, inputs in nodes:
        g.add(name, kind, **inputs)
    return g


def measure(*nodes: tuple, of: str) -> object:
    g = build(*nodes, ("m", "brep.measure", {"solid": f"@{of}"}))
    return g.evaluate("m")


def steiner_box(a: float, b: float, c: float, r: float) -> float:
    """The volume of an a x b x c box with every edge rounded by r: the inner box grown by
    r (Steiner: V + S r + M r^2 + 4/3 pi r^3, M = pi/4 times the edge lengths)."""
    x, y, z = a - 2 * r, b - 2 * r, c - 2 * r
    area = 2 * (x * y + y * z + z * x)
    return x * y * z + area * r + math.pi * (x + y + z) * r * r + 4 / 3 * math.pi * r**3


@pytest.mark.parametrize("size,r", [((20, 20, 20), 2.0), ((30, 20, 10), 4.5), ((5, 6, 7), 0.3)])
def test_box_with_every_edge_filleted_is_the_steiner_volume(size, r):
    m = measure(
        ("b", "brep.box", {"size": list(size)}),
        ("f", "brep.fillet", {"solid": "@b", "radius": r}),
        of="f",
    )
    assert m.valid and m.solids == 1
    assert m.faces == 26  # 6 flats, 12 rounds, 8 corner spheres
    assert m.volume == pytest.approx(steiner_box(*size, r), rel=REL)
    x, y, z = (s - 2 * r for s in size)
    area = 2 * (x * y + y * z + z * x) + math.pi * r * (x + y + z) * 2 + 4 * math.pi * r * r
    assert m.area == pytest.approx(area, rel=REL)


def test_top_rim_of_a_cylinder_filleted_is_pappus():
    big, h, r = 5.0, 10.0, 1.0
    m = measure(
        ("c", "brep.cylinder", {"radius": big, "height": h}),
        ("f", "brep.fillet", {"solid": "@c", "radius": r, "edges": "=z > 4"}),
        of="f",
    )
    # the spandrel between the square corner and the quarter circle, turned about the axis
    spandrel = r * r * (1 - math.pi / 4)
    from_corner = (r**3 / 2 - math.pi * r * r / 4 * (r - 4 * r / (3 * math.pi))) / spandrel
    expected = math.pi * big**2 * h - 2 * math.pi * (big - from_corner) * spandrel
    assert m.valid
    assert m.volume == pytest.approx(expected, rel=REL)


def test_four_vertical_edges_chamfered():
    a, d = 20.0, 1.5
    g = build(
        ("b", "brep.box", {"size": [a, a, a]}),
        ("c", "brep.chamfer", {"solid": "@b", "distance": d, "edges": "=abs(z) < 1"}),
        ("m", "brep.measure", {"solid": "@c"}),
    )
    m = g.evaluate("m")
    assert m.volume == pytest.approx(a**3 - 4 * (d * d / 2) * a, rel=REL)
    assert m.faces == 10 and m.valid
    kinds = topology.face_table(g.evaluate("c").shape).kind
    assert np.all(kinds == topology.KINDS["plane"])


def test_drilled_block():
    a, b, c, r = 40.0, 30.0, 10.0, 4.0
    m = measure(
        ("b", "brep.box", {"size": [a, b, c]}),
        ("h1", "brep.cylinder", {"radius": r, "height": 3 * c, "center": [-10, 0, 0]}),
        ("h2", "brep.cylinder", {"radius": r, "height": 3 * c, "center": [10, 0, 0]}),
        ("d", "brep.boolean", {"a": "@b", "b": ["@h1", "@h2"], "operation": "difference"}),
        of="d",
    )
    assert m.volume == pytest.approx(a * b * c - 2 * math.pi * r * r * c, rel=REL)
    assert m.solids == 1 and m.faces == 8 and m.valid


def test_union_and_intersection_of_overlapping_boxes():
    nodes = [
        ("a", "brep.box", {"size": 10}),
        ("b", "brep.box", {"size": 10, "center": [5, 5, 5]}),
    ]
    u = measure(*nodes, ("u", "brep.boolean", {"a": "@a", "b": ["@b"]}), of="u")
    i = measure(
        *nodes, ("i", "brep.boolean", {"a": "@a", "b": ["@b"], "operation": "intersection"}), of="i"
    )
    assert u.volume == pytest.approx(2000 - 125, rel=REL) and u.solids == 1
    assert i.volume == pytest.approx(125, rel=REL)


def test_extruded_rounded_plate_with_a_hole_is_exact_lines_and_arcs():
    w, d, rr, hole, h = 60.0, 40.0, 8.0, 5.0, 6.0
    g = build(
        ("r", "curves.rectangle", {"size": [w, d], "radius": rr}),
        ("c", "nurbs.circle", {"radius": hole}),
        ("p", "brep.extrude", {"curves": ["@r", "@c"], "height": h}),
        ("m", "brep.measure", {"solid": "@p"}),
    )
    m = g.evaluate("m")
    area = w * d - (4 - math.pi) * rr * rr - math.pi * hole * hole
    assert m.volume == pytest.approx(area * h, rel=REL)
    faces = topology.face_table(g.evaluate("p").shape)
    names = sorted(faces.kind_name(i) for i in range(len(faces)))
    # 4 flat sides, 4 rounded corners, the hole's wall, top and bottom: no B-spline patches
    assert names == ["cylinder"] * 5 + ["plane"] * 6
    edges = topology.edge_table(g.evaluate("p").shape)
    assert set(edges.kind_name(i) for i in range(len(edges))) == {"line", "circle"}
    lo, hi = g.evaluate("p").bounds
    np.testing.assert_allclose(hi - lo, [w, d, h], atol=1e-7)


def test_extrude_centred_and_downwards():
    g = build(
        ("c", "nurbs.circle", {"radius": 2}),
        ("up", "brep.extrude", {"curves": ["@c"], "height": 4, "center": True}),
        ("down", "brep.extrude", {"curves": ["@c"], "height": -4}),
    )
    np.testing.assert_allclose(g.evaluate("up").bounds[:, 2], [-2, 2], atol=1e-9)
    np.testing.assert_allclose(g.evaluate("down").bounds[:, 2], [-4, 0], atol=1e-9)


def test_revolved_rectangle_is_an_annulus_and_a_quarter_turn_a_quarter():
    nodes = [("r", "curves.rectangle", {"size": [10, 5], "center": [15, 2.5]})]
    full = measure(*nodes, ("v", "brep.revolve", {"curves": ["@r"]}), of="v")
    quarter = measure(*nodes, ("v", "brep.revolve", {"curves": ["@r"], "angle": 90}), of="v")
    assert full.volume == pytest.approx(math.pi * (20**2 - 10**2) * 5, rel=REL)
    assert quarter.volume == pytest.approx(full.volume / 4, rel=REL)


def test_revolved_circle_is_a_torus():
    big, small = 10.0, 3.0
    m = measure(
        ("c", "nurbs.circle", {"radius": small, "center": [big, 0, 0]}),
        ("v", "brep.revolve", {"curves": ["@c"]}),
        of="v",
    )
    assert m.volume == pytest.approx(2 * math.pi**2 * big * small**2, rel=REL)


def test_loft_of_two_circles_is_a_cylinder():
    m = measure(
        ("a", "nurbs.circle", {"radius": 10}),
        ("b", "nurbs.circle", {"radius": 10, "center": [0, 0, 20]}),
        ("l", "brep.loft", {"curves": ["@a", "@b"], "ruled": True}),
        of="l",
    )
    assert m.volume == pytest.approx(math.pi * 100 * 20, rel=REL)


def _square_patch(corners: list) -> dict:
    c = np.asarray(corners, float).reshape(2, 2, 3).tolist()
    return {"points": c, "degree_u": 1, "degree_v": 1}


CUBE = [  # the six sides of the unit cube scaled by 10, as bilinear patches
    [[0, 0, 0], [10, 0, 0], [0, 10, 0], [10, 10, 0]],
    [[0, 0, 10], [10, 0, 10], [0, 10, 10], [10, 10, 10]],
    [[0, 0, 0], [10, 0, 0], [0, 0, 10], [10, 0, 10]],
    [[0, 10, 0], [10, 10, 0], [0, 10, 10], [10, 10, 10]],
    [[0, 0, 0], [0, 10, 0], [0, 0, 10], [0, 10, 10]],
    [[10, 0, 0], [10, 10, 0], [10, 0, 10], [10, 10, 10]],
]


def test_from_surfaces_sews_six_patches_into_a_cube_facing_out():
    nodes = [(f"s{k}", "nurbs.surface", _square_patch(c)) for k, c in enumerate(CUBE)]
    m = measure(
        *nodes,
        ("cube", "brep.from_surfaces", {"surfaces": [f"@s{k}" for k in range(6)]}),
        of="cube",
    )
    assert m.volume == pytest.approx(1000, rel=REL) and m.valid and m.faces == 6


def test_from_surfaces_of_an_open_shell_names_its_free_edges():
    nodes = [(f"s{k}", "nurbs.surface", _square_patch(c)) for k, c in enumerate(CUBE[:5])]
    g = build(*nodes, ("cube", "brep.from_surfaces", {"surfaces": [f"@s{k}" for k in range(5)]}))
    with pytest.raises(fg.NodeError, match=r"input 'surfaces'.*do not close: 4 free edge"):
        g.evaluate("cube")


def test_shell_with_the_top_removed():
    m = measure(
        ("b", "brep.box", {"size": 20}),
        ("s", "brep.shell", {"solid": "@b", "thickness": 2, "faces": "=nz > 0.9"}),
        of="s",
    )
    assert m.volume == pytest.approx(20**3 - 16 * 16 * 18, rel=REL) and m.valid


def test_sealed_shell_keeps_a_cavity():
    m = measure(
        ("b", "brep.box", {"size": 20}),
        ("s", "brep.shell", {"solid": "@b", "thickness": 2}),
        of="s",
    )
    assert m.volume == pytest.approx(20**3 - 16**3, rel=REL)


def test_fillet_too_large_says_why_in_the_part_s_measures():
    g = build(
        ("b", "brep.box", {"size": [10, 20, 30]}),
        ("f", "brep.fillet", {"solid": "@b", "radius": 6, "edges": "=z > 9"}),
    )
    with pytest.raises(
        fg.NodeError,
        match=r"node 'f', input 'radius' \(brep.fillet\): the radius 6 is larger than half the "
        r"narrowest adjacent face \(face \d+\), which is 10 wide and is cut on both sides "
        r"\(edges \d+ and \d+\)",
    ):
        g.evaluate("f")


def test_fillet_wider_than_a_face_across_one_edge():
    g = build(
        ("c", "brep.cylinder", {"radius": 5, "height": 10}),
        ("f", "brep.fillet", {"solid": "@c", "radius": 6, "edges": "=z > 1"}),
    )
    with pytest.raises(fg.NodeError, match=r"the radius 6 is larger than the narrowest adjacent"):
        g.evaluate("f")


def test_a_selector_selecting_nothing_is_a_warning_naming_it():
    g = build(
        ("b", "brep.box", {"size": 10}),
        ("f", "brep.fillet", {"solid": "@b", "radius": 1, "edges": "=kind == circle"}),
    )
    with pytest.warns(fg.FormgraphWarning):
        out = g.evaluate("f")
    (said,) = g.stats["f"].warnings
    assert "edges '=kind == circle' selects none of the 12 edges" in said
    assert out.key == g.evaluate("b").key  # left as it is


def test_selectors_read_length_kind_and_params():
    g = fg.Graph()
    g.add_param("top", 4.0)
    g.add("b", "brep.box", size=[10, 10, 10])
    g.add("f", "brep.fillet", solid="@b", radius=1, edges="=z > top and length > 9")
    g.add("m", "brep.measure", solid="@f")
    g.add("top4", "brep.fillet", solid="@b", radius=1, edges="=i < 0 or z > 4")
    g.add("m4", "brep.measure", solid="@top4")
    m, m4 = g.evaluate("m"), g.evaluate("m4")
    assert m.faces == 6 + 4  # the four top edges rounded, their rounds meeting mitred
    assert m.volume == pytest.approx(m4.volume, rel=1e-12)
    spandrel = 1 - math.pi / 4
    assert 1000 - 4 * 10 * spandrel < m.volume < 1000 - 4 * 8 * spandrel


def test_a_misspelt_selector_name_is_an_error_listing_the_names():
    g = build(
        ("b", "brep.box", {"size": 10}),
        ("f", "brep.fillet", {"solid": "@b", "radius": 1, "edges": "=hieght > 1"}),
    )
    with pytest.raises(fg.NodeError, match=r"input 'edges'.*'hieght'.*x y z.*length, kind"):
        g.evaluate("f")


def test_smooth_edges_are_left_with_a_warning():
    g = build(
        ("c", "brep.cylinder", {"radius": 5, "height": 10}),
        ("f", "brep.fillet", {"solid": "@c", "radius": 1, "edges": "=kind == line"}),
    )
    with pytest.warns(fg.FormgraphWarning):
        g.evaluate("f")
    assert "edge 1 joins its faces smoothly" in g.stats["f"].warnings[0]


@pytest.mark.parametrize(
    "offset,op,said",
    [
        ([30, 0, 0], "union", "the solids do not overlap: the union is 2 separate solids"),
        ([10, 10, 0], "union", "only touch (along an edge or at a point)"),
        ([30, 0, 0], "difference", "b does not reach a: nothing is cut away"),
        ([10, 0, 0], "intersection", "the solids only touch: their intersection has no volume"),
    ],
)
def test_booleans_that_do_nothing_meant_warn(offset, op, said):
    g = build(
        ("a", "brep.box", {"size": 10}),
        ("b", "brep.box", {"size": 10, "center": offset}),
        ("u", "brep.boolean", {"a": "@a", "b": ["@b"], "operation": op}),
    )
    with pytest.warns(fg.FormgraphWarning):
        g.evaluate("u")
    assert said in g.stats["u"].warnings[0]


def test_mesh_is_closed_outward_and_within_tolerance():
    trimesh = pytest.importorskip("trimesh")
    tol = 0.01
    g = build(
        ("c", "brep.cylinder", {"radius": 5, "height": 10}),
        ("f", "brep.fillet", {"solid": "@c", "radius": 1}),
        ("t", "brep.mesh", {"solid": "@f", "tolerance": tol}),
    )
    mesh = g.evaluate("t")
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.face_indices).reshape(-1, 3)
    tm = trimesh.Trimesh(v, f, process=False)
    assert tm.is_watertight and tm.is_winding_consistent and tm.volume > 0
    exact = occ.volume(g.evaluate("f").shape)
    # a chordal error of at most tol over the area bounds the volume's difference
    assert abs(tm.volume - exact) <= tol * tm.area
    # every vertex on the solid's surface: on the side, the rims' tori or the caps
    r = np.hypot(v[:, 0], v[:, 1])
    side = np.abs(v[:, 2]) <= 4 + 1e-9
    assert np.all(np.abs(r[side & (r > 4)] - 5) <= 1e-7)
    centres = v[f].mean(axis=1)
    rc = np.hypot(centres[:, 0], centres[:, 1])
    on_side = np.abs(centres[:, 2]) < 4 - 1e-6
    assert np.all(5 - rc[on_side & (rc > 4.5)] <= tol + 1e-9)


def test_solid_in_the_viewer_is_brep_mesh():
    g = build(("b", "brep.box", {"size": 10}), ("t", "brep.mesh", {"solid": "@b"}))
    solid = g.evaluate("b")
    poly = solid.to_pyvista()
    assert poly.n_cells == g.evaluate("t").n_faces == 12


def test_measure_of_an_invalid_input_is_never_reached_by_nodes():
    # every node's result passes OCC's check (the kernels ask BRepCheck_Analyzer)
    g = build(
        ("b", "brep.box", {"size": 10}),
        ("f", "brep.fillet", {"solid": "@b", "radius": 4.9}),
    )
    assert occ.is_valid(g.evaluate("f").shape)


def test_equal_recipes_make_equal_keys_and_early_cutoff():
    a = build(("b", "brep.box", {"size": [1, 2, 3]})).evaluate("b")
    b = build(("b", "brep.box", {"size": [1.0, 2.0, 3.0]})).evaluate("b")
    c = build(("b", "brep.box", {"size": [1, 2, 4]})).evaluate("b")
    assert a.key == b.key != c.key
