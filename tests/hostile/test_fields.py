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
