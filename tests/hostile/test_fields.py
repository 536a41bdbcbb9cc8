"""Hostile fields: unbounded, non-finite, oversized and degenerate inputs to field.* and
mesh.offset give a located error (never a numpy traceback, a hang or a huge allocation)."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg
from formgraph.core.errors import BudgetError
from formgraph.geometry import Field


def graph(**nodes):
    g = fg.Graph()
    for name, (kind, inputs) in nodes.items():
        g.add(name, kind, **inputs)
    return g


def test_an_expression_that_reads_attributes_is_refused_at_load():
    with pytest.raises(fg.GraphError, match="__class__|not allowed|attribute"):
        g = graph(
            e=("field.expression", {"value": "x.__class__", "bounds": [[0, 0, 0], [1, 1, 1]]})
        )
        g.evaluate("e")


def test_a_field_infinite_everywhere_is_a_node_error():
    g = graph(
        e=("field.expression", {"value": "log(0 * x)", "bounds": [[0, 0, 0], [1, 1, 1]]}),
        m=("field.mesh", {"field": "@e", "cell": 0.25}),
    )
    with pytest.raises(fg.NodeError, match="not finite"):
        g.evaluate("m")


def test_bounds_that_are_not_a_box_are_refused():
    g = graph(
        s=("field.sphere", {"radius": 1}),
        m=("field.mesh", {"field": "@s", "bounds": [[1, 1, 1], [0, 0, 0]]}),
    )
    with pytest.raises(fg.NodeError, match="x0 < x1"):
        g.evaluate("m")


def test_a_tiny_cell_over_a_huge_box_fails_before_allocating():
    g = graph(
        t=("field.tpms", {"period": 1.0, "thickness": 0.1}),
        m=("field.mesh", {"field": "@t", "cell": 1e-3, "bounds": [[0, 0, 0], [1e3, 1e3, 1e3]]}),
    )
    with pytest.raises(BudgetError, match="over the budget"):
        g.evaluate("m")


def test_a_hopeless_lipschitz_field_is_still_bounded_by_the_budget():
    # a field claiming no slope keeps every cell at every level: counted, then refused
    g = graph(
        e=(
            "field.expression",
            {
                "value": "sin(1000 * x) * 0.001",
                "bounds": [[-1, -1, -1], [1, 1, 1]],
                "lipschitz": 1e6,
            },
        ),
        m=("field.mesh", {"field": "@e", "cell": 0.002}),
    )
    with pytest.raises(BudgetError):
        g.evaluate("m")


def test_tpms_walls_thicker_than_half_a_period_are_refused():
    g = graph(t=("field.tpms", {"period": 2.0, "thickness": 1.5}))
    with pytest.raises(fg.NodeError, match="half the period"):
        g.evaluate("t")


def test_the_offset_of_a_mesh_without_area_is_a_closed_tube():
    flat = fg.Mesh(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]), [[0, 1, 2]])  # no area
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("o", "mesh.offset", mesh="=m", distance=0.1, cell=0.05)
    out = g.evaluate("o", m=flat)  # a tube round a segment: closed, outward
    assert out.is_watertight and out.volume > 0


def test_a_field_evaluated_at_2d_points_says_what_it_needs():
    f = fg.geometry.Field.sphere(1.0)
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        f.evaluate(np.zeros((4, 2)))


def test_remeshing_coarser_than_the_mesh_leaves_a_tetrahedron_not_a_flat_pillow():
    g = graph(
        s=("mesh.sphere", {"radius": 1.0}),
        r=("mesh.remesh", {"mesh": "@s", "edge_length": 50.0}),
    )
    m = g.evaluate("r")
    assert m.is_watertight and m.n_faces >= 4 and m.volume > 0


def test_remeshing_finer_than_the_budget_fails_before_allocating():
    g = graph(
        s=("mesh.sphere", {"radius": 1.0}),
        r=("mesh.remesh", {"mesh": "@s", "edge_length": 1e-5}),
    )
    with pytest.raises(BudgetError, match="vertices"):
        g.evaluate("r")


def test_a_cell_larger_than_the_box_is_refused_on_cell():
    g = graph(
        s=("field.sphere", {"radius": 5}),
        m=("field.mesh", {"field": "@s", "cell": 1e300}),
    )
    with pytest.raises(fg.NodeError, match=r"input 'cell'.*larger than the box.*side is 10"):
        g.evaluate("m")


@pytest.mark.parametrize(
    "nodes, what",
    [
        (  # a sheet of 1e-301 (it meshed 80k faces of aliasing noise without a word)
            {"t": ("field.tpms", {"period": 1e-300, "thickness": 1e-301})},
            "gyroid sheet",
        ),
        ({"t": ("field.tpms", {"period": 10, "thickness": 0.1})}, "gyroid sheet"),
        (
            {
                "s": ("field.sphere", {"radius": 4}),
                "t": ("field.shell", {"field": "@s", "thickness": 0.1}),
            },
            "shell",
        ),
        (  # a sheet of 1 made 0.1 thick by a transform's scale
            {
                "g": ("field.tpms", {"period": 40, "thickness": 1}),
                "t": ("field.transform", {"field": "@g", "scale": 0.1}),
            },
            r"scaled by 0\.1",
        ),
    ],
)
def test_a_wall_thinner_than_the_cell_is_warned_of(nodes, what):
    g = graph(
        **nodes,
        b=("field.box", {"size": [10, 10, 10]}),
        i=("field.intersection", {"fields": ["@t", "@b"]}),
        m=("field.mesh", {"field": "@i", "cell": 0.25}),
    )
    with pytest.warns(fg.FormgraphWarning, match=f"{what}.*thinner than the cell 0.25"):
        g.evaluate("m")


def test_a_wall_the_cell_resolves_is_not_warned_of(recwarn):
    g = graph(
        t=("field.tpms", {"period": 10, "thickness": 1}),
        b=("field.box", {"size": [10, 10, 10]}),
        i=("field.intersection", {"fields": ["@t", "@b"]}),
        m=("field.mesh", {"field": "@i", "cell": 0.25}),
    )
    assert g.evaluate("m").n_faces > 0
    assert not [w for w in recwarn if "thinner" in str(w.message)]


def test_the_mesher_refuses_a_box_too_many_cells_across_to_number():
    """Called directly (the node's budget stops this long before), a box 4e7 cells across
    overflowed the block keys and meshed an open, wrong surface; it is refused."""
    from formgraph.kernels.field import mesher

    def sphere(p):
        return np.linalg.norm(p, axis=-1) - 1.0

    with pytest.raises(ValueError, match="cells across"):
        mesher.mesh_field(sphere, np.full(3, -1e6), np.full(3, 1e6), 0.05, 1.0, 10**15)
    v, t = mesher.mesh_field(sphere, np.full(3, -1.5), np.full(3, 1.5), 0.05, 1.0)
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    assert len(v) and (np.unique(edges, axis=0, return_counts=True)[1] == 2).all()


def test_a_field_that_fails_while_the_vertices_are_placed_hands_out_nothing():
    """The vertices are written straight into an immutable buffer: a field finite at the
    lattice's corners but not on the edges between them (the root-finding samples) is
    refused with the field's message, and no half-placed vertices escape."""
    from formgraph.kernels.field import mesher

    f = Field.sphere(1.0)

    def lines(origin, step, ijk, axis, t):
        return np.full(len(t), np.nan)

    with pytest.raises(ValueError, match="not finite"):
        mesher.mesh_field(f.evaluate, [-1.2] * 3, [1.2] * 3, 0.1, grid=f.evaluate_grid, lines=lines)
    v, t = mesher.mesh_field(f.evaluate, [-1.2] * 3, [1.2] * 3, 0.1, grid=f.evaluate_grid)
    assert len(t) and np.abs(np.linalg.norm(v, axis=1) - 1).max() < 1e-4


# ------------------------------------------------------------ recipes thousands deep

DEPTH = 5000


def test_a_graph_of_5000_field_nodes_meshes():
    # today: RecursionError from 400 deep (Field.nbytes, the evaluation, the hashes), and an
    # unlocated "internal error" from 700
    lines = ["formgraph: 1", "nodes:", "  f0: {type: field.sphere, radius: 1}"]
    lines += [
        f"  f{i}: {{type: field.offset, field: '@f{i - 1}', distance: 0.0001}}"
        for i in range(1, DEPTH)
    ]
    lines.append(f"  m: {{type: field.mesh, field: '@f{DEPTH - 1}', cell: 0.25}}")
    g = fg.Graph.from_text("\n".join(lines) + "\n", file="deep.yaml")
    m = g.evaluate("m")
    r = np.linalg.norm(m.vertices, axis=1)
    assert m.n_faces > 100 and m.is_watertight
    np.testing.assert_allclose(r, 1 + (DEPTH - 1) * 0.0001, atol=0.01)


def _chain(op: str, depth: int = DEPTH) -> Field:
    f = Field.sphere(1.0)
    for _ in range(depth):
        if op == "offset":
            f = Field.offset(f, 0.0001)
        elif op == "transform":
            f = Field.transform(f, np.eye(3), [0.0001, 0, 0], 1.0)
        else:
            f = Field.union([f, Field.sphere(0.1, [3, 0, 0])])
    return f


@pytest.mark.parametrize("op", ["offset", "transform", "union"])
def test_a_recipe_5000_deep_is_walked_without_recursion(op):
    import pickle

    from formgraph.evaluation.cache import digest
    from formgraph.evaluation.cutoff import same_content

    f = _chain(op)
    p = np.random.default_rng(1).uniform(-2, 2, (500, 3))
    shift = {"offset": [0, 0, 0], "transform": [0.5, 0, 0], "union": [0, 0, 0]}[op]
    expected = np.linalg.norm(p - shift, axis=1) - (1.5 if op == "offset" else 1.0)
    if op == "union":
        expected = np.minimum(expected, np.linalg.norm(p - [3, 0, 0], axis=1) - 0.1)
    np.testing.assert_allclose(f.evaluate(p), expected, atol=1e-9)
    # on a lattice (tables all through) as at its points
    grid = f.evaluate_grid([-1, -1, -1], 0.5, (4, 5, 6))
    ijk = np.stack(np.meshgrid(np.arange(4), np.arange(5), np.arange(6), indexing="ij"), -1)
    at = ijk.reshape(-1, 3) * 0.5 - 1
    assert f.separable
    np.testing.assert_allclose(grid.reshape(-1), f.evaluate(at), atol=1e-9)
    # sized, hashed, compared and pickled (to a worker) the same way
    assert 256 * DEPTH < f.nbytes < 1024 * (DEPTH + 2)
    back = pickle.loads(pickle.dumps(f))
    assert back is not f and same_content(f, back) and digest(back) == digest(f)
    np.testing.assert_array_equal(back.evaluate(p[:5]), f.evaluate(p[:5]))


def test_a_recipe_that_shares_its_parts_is_walked_once_a_part():
    # each level the union of the last and its offset: 2^60 paths down, 121 parts
    f = Field.sphere(1.0)
    for _ in range(60):
        f = Field.union([f, Field.offset(f, 0.001)])
    assert len(f.parts) == 121
    assert f.nbytes < 121 * 1024  # each part counted once, not once a path
    p = np.random.default_rng(2).uniform(-2, 2, (200, 3))
    np.testing.assert_allclose(f.evaluate(p), np.linalg.norm(p, axis=1) - 1.06, atol=1e-9)
    np.testing.assert_allclose(
        f.evaluate_grid([0, 0, 0], 0.5, (2, 2, 2)).reshape(-1),
        f.evaluate(np.stack(np.meshgrid(*[[0, 0.5]] * 3, indexing="ij"), -1).reshape(-1, 3)),
        atol=1e-9,
    )


# ------------------------------------------------------------ a Lipschitz bound that lies

STEEP = """\
formgraph: 1
nodes:
  e:
    type: field.expression
    value: "VALUE"
    bounds: [[-2, -2, -2], [2, 2, 2]]
    lipschitz: LIP
  m: {type: field.mesh, field: "@e", cell: 0.1}
"""


def test_a_lipschitz_bound_the_samples_contradict_is_named_not_an_empty_mesh():
    # today: a warning that "the field has no surface inside its bounds" and an empty mesh
    text = STEEP.replace("VALUE", "sqrt(x*x + y*y + z*z) * 10 - 10").replace("LIP", "0.5")
    g = fg.Graph.from_text(text, file="steep.yaml")
    with pytest.raises(
        fg.NodeError,
        match=r"steep.yaml:8: node 'm', input 'field' \(field.mesh\): no surface was found, but "
        r"the field's samples contradict its Lipschitz bound 0.5: its values change by up to "
        r"9.9\d per unit length .* raise 'lipschitz' of node 'e' "
        r"\('sqrt\(x\*x \+ y\*y \+ z\*z\) \* 10 - 10': 0.5\) to about 13 or more",
    ):
        g.evaluate("m")
    # the advice works
    fixed = fg.Graph.from_text(text.replace("lipschitz: 0.5", "lipschitz: 13"), file="s.yaml")
    m = fixed.evaluate("m")
    assert m.n_faces > 1000
    np.testing.assert_allclose(np.linalg.norm(m.vertices, axis=1), 1.0, atol=1e-3)


def test_a_bound_that_loses_part_of_the_surface_is_warned_of():
    # a unit sphere (slope 1) and a small steep one (slope 20) beside it: the bound of 1
    # keeps the first and loses the second
    value = "min(sqrt(x*x + y*y + z*z) - 0.8, 20 * (sqrt((x - 1.4)**2 + y*y + z*z) - 0.3))"
    g = fg.Graph.from_text(STEEP.replace("VALUE", value).replace("LIP", "1"), file="s.yaml")
    with pytest.warns(
        fg.FormgraphWarning,
        match=r"parts of the surface may be missing: the field's samples contradict its "
        r"Lipschitz bound 1: .* raise 'lipschitz' of node 'e'",
    ):
        m = g.evaluate("m")
    assert m.n_faces > 0


def test_a_true_bound_is_not_doubted(recwarn):
    value = "sqrt(x*x + y*y + z*z) - 1 + 0.1 * sin(3 * x)"  # slope at most 1.3
    g = fg.Graph.from_text(STEEP.replace("VALUE", value).replace("LIP", "1.3"), file="s.yaml")
    assert g.evaluate("m").n_faces > 1000
    assert not [w for w in recwarn if "Lipschitz" in str(w.message)]


def test_the_flat_face_check_walks_a_deep_recipe_without_recursion():
    from formgraph.nodes.field import _blend

    f = Field.union([Field.box([1, 1, 1]), Field.box([1, 1, 1], [1, 0, 0])], smooth=0.5)
    for _ in range(5000):  # deeper than Python's recursion limit
        f = Field.offset(f, 0.0)
    assert _blend.smooth_unions(f) == [0.5]
    normals, offsets = _blend.flat_faces(f)
    assert len(normals) == 8  # the faces of both boxes, the four shared planes once
    sharp = _blend.sharpened(f)
    while sharp.op == "offset":
        sharp = sharp.children[0]
    assert sharp.op == "union" and sharp.args["smooth"] == 0


def test_a_hundred_blended_boxes_are_checked_in_blocks_and_warned_of_once():
    nodes = {
        f"b{i}": ("field.box", {"size": [1, 1, 1], "center": [0.9 * i, 0, 0.5]}) for i in range(100)
    }
    nodes["u"] = ("field.union", {"fields": [f"@b{i}" for i in range(100)], "smooth": 0.4})
    nodes["m"] = ("field.mesh", {"field": "@u", "cell": 0.25})
    g = graph(**nodes)
    v = g.evaluate("m").vertices
    (warning,) = g.stats["m"].warnings
    assert f"the face at z = 0 (facing -z) by {-v[:, 2].min():.3g}" in warning
