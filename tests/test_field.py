"""Field nodes (nodes/field/): the Field type, field.*, field.mesh and mesh.offset."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.core.errors import BudgetError
from formgraph.evaluation.cache import DiskCache, digest
from formgraph.geometry import Field


def build(**nodes):
    g = fg.Graph()
    for name, (kind, inputs) in nodes.items():
        g.add(name, kind, **inputs)
    return g


def tm(mesh: fg.Mesh) -> trimesh.Trimesh:
    t = trimesh.Trimesh(mesh.vertices, mesh.face_indices.reshape(-1, 3), process=False)
    assert mesh.is_watertight and t.is_winding_consistent and t.volume > 0
    return t


def test_field_is_immutable_and_keyed_by_its_recipe():
    a = Field.sphere(1.0, [0, 0, 1])
    with pytest.raises(AttributeError):
        a.op = "box"  # type: ignore[misc]
    with pytest.raises(TypeError):
        a.args["radius"] = 2.0
    assert not a.args["center"].flags.writeable
    assert digest(Field.sphere(1.0, [0, 0, 1])) == digest(a)
    assert digest(Field.sphere(1.0, [0, 0, 1.5])) != digest(a)
    u = Field.union([a, Field.box([1, 1, 1])], smooth=0.2)
    assert digest(u) != digest(Field.union([a, Field.box([1, 1, 1])], smooth=0.3))
    np.testing.assert_allclose(a.evaluate([[0, 0, 3.0]]), [1.0])


def test_bounds_come_from_construction():
    s = Field.sphere(1.0)
    assert np.allclose(s.bounds, [[-1, -1, -1], [1, 1, 1]])
    assert Field.tpms("gyroid", 10, 1).bounds is None
    cut = Field.intersection([Field.tpms("gyroid", 10, 1), s])
    assert np.allclose(cut.bounds, s.bounds)
    moved = Field.transform(s, np.eye(3), [5, 0, 0], 2.0)
    assert np.allclose(moved.bounds, [[3, -2, -2], [7, 2, 2]])
    np.testing.assert_allclose(moved.evaluate([[5, 0, 0], [9, 0, 0]]), [-2, 2])


def test_sphere_node_meshes_to_the_sphere_volume():
    g = build(s=("field.sphere", {"radius": 2.0}), m=("field.mesh", {"field": "@s", "cell": 0.1}))
    m = g.evaluate("m")
    assert tm(m).volume == pytest.approx(4 / 3 * np.pi * 8, rel=0.01)
    assert m.euler_characteristic == 2


def test_smooth_union_adds_material_where_shapes_meet():
    def volume(smooth):
        g = build(
            a=("field.sphere", {"radius": 1.0}),
            b=("field.sphere", {"radius": 1.0, "center": [1.5, 0, 0]}),
            u=("field.union", {"fields": ["@a", "@b"], "smooth": smooth}),
            m=("field.mesh", {"field": "@u", "cell": 0.08}),
        )
        return tm(g.evaluate("m")).volume

    r, d = 1.0, 1.5
    lens = np.pi * (4 * r + d) * (2 * r - d) ** 2 / 12
    assert volume(0.0) == pytest.approx(2 * 4 / 3 * np.pi - lens, rel=0.01)
    assert volume(0.6) > volume(0.0) * 1.01


def test_difference_cuts_a_hole_of_the_right_volume():
    g = build(
        box=("field.box", {"size": [2, 2, 2]}),
        hole=("field.cylinder", {"radius": 0.5, "height": 3}),
        d=("field.difference", {"a": "@box", "b": "@hole"}),
        m=("field.mesh", {"field": "@d", "cell": 0.05}),
    )
    m = g.evaluate("m")
    assert tm(m).volume == pytest.approx(8 - np.pi * 0.25 * 2, rel=0.01)
    assert m.euler_characteristic == 0  # a block with a hole through it: genus 1


def test_shell_and_offset_volumes():
    g = build(
        s=("field.sphere", {"radius": 1.0}),
        sh=("field.shell", {"field": "@s", "thickness": 0.2}),
        m=("field.mesh", {"field": "@sh", "cell": 0.04}),
        o=("field.offset", {"field": "@s", "distance": 0.5}),
        mo=("field.mesh", {"field": "@o", "cell": 0.06}),
    )
    shell = g.evaluate("m")
    assert tm(shell).volume == pytest.approx(4 / 3 * np.pi * (1.1**3 - 0.9**3), rel=0.02)
    assert shell.euler_characteristic == 4  # two spheres
    assert tm(g.evaluate("mo")).volume == pytest.approx(4 / 3 * np.pi * 1.5**3, rel=0.01)


def test_tpms_needs_bounds_and_then_closes_against_them():
    g = build(
        t=("field.tpms", {"kind": "gyroid", "period": 5.0, "thickness": 0.6}),
        m=("field.mesh", {"field": "@t", "cell": 0.25}),
    )
    with pytest.raises(fg.NodeError, match=r"input 'bounds'.*unbounded"):
        g.evaluate("m")
    g.add("mb", "field.mesh", field="@t", cell=0.25, bounds=[[0, 0, 0], [5, 5, 5]])
    m = g.evaluate("mb")
    t = tm(m)
    assert np.allclose(t.bounds, [[0, 0, 0], [5, 5, 5]], atol=0.01)
    with pytest.raises(fg.GraphError, match="not a valid|one of|schwarz_p"):
        g.add("bad", "field.tpms", kind="lidinoid")
        g.evaluate("bad")


def test_expression_field_with_bounds_and_params():
    g = fg.Graph()
    g.add_param("r", 1.5)
    g.add(
        "e", "field.expression", value="sqrt(x*x + y*y + z*z) - r", bounds=[[-2, -2, -2], [2, 2, 2]]
    )
    g.add("m", "field.mesh", field="@e", cell=0.1)
    assert tm(g.evaluate("m")).volume == pytest.approx(4 / 3 * np.pi * 1.5**3, rel=0.01)
    assert tm(g.evaluate("m", r=1.0)).volume == pytest.approx(4 / 3 * np.pi, rel=0.01)
    g.add("bad", "field.expression", value="1 / (x - x)", bounds=[[-1, -1, -1], [1, 1, 1]])
    g.add("mb", "field.mesh", field="@bad", cell=0.5)
    with pytest.raises(fg.NodeError, match="not finite"):
        g.evaluate("mb")


def test_transform_moves_rotates_and_scales_the_shape():
    g = build(
        b=("field.box", {"size": [2, 1, 1]}),
        t=(
            "field.transform",
            {"field": "@b", "translate": [5, 0, 0], "rotate": [0, 0, 90], "scale": 2},
        ),
        m=("field.mesh", {"field": "@t", "cell": 0.1}),
    )
    m = tm(g.evaluate("m"))
    assert m.volume == pytest.approx(16, rel=0.01)
    assert np.allclose(m.bounds, [[4, -2, -1], [6, 2, 1]], atol=0.02)


def test_from_mesh_signed_distance_matches_trimesh():
    ref = trimesh.creation.icosphere(3)
    ref = trimesh.Trimesh(ref.vertices * [1, 0.8, 0.6], ref.faces)
    mesh = fg.Mesh(ref.vertices, ref.faces.reshape(-1), np.arange(0, ref.faces.size + 1, 3))
    f = Field.from_mesh(mesh)
    rng = np.random.default_rng(0)
    p = rng.uniform(-1.2, 1.2, (800, 3))
    # trimesh is positive inside
    np.testing.assert_allclose(f.evaluate(p), -trimesh.proximity.signed_distance(ref, p), atol=1e-7)


def test_from_mesh_keeps_an_inside_through_a_small_hole():
    ref = trimesh.creation.icosphere(3)
    faces = ref.faces[1:]  # one triangle missing
    mesh = fg.Mesh(ref.vertices, faces.reshape(-1), np.arange(0, faces.size + 1, 3))
    f = Field.from_mesh(mesh)
    p = np.array([[0, 0, 0], [0.5, 0.1, 0.2], [1.5, 0, 0], [0, 0, -2]])
    assert (np.sign(f.evaluate(p)) == [-1, -1, 1, 1]).all()


def test_from_curves_makes_a_torus_of_tubes():
    g = build(
        c=("nurbs.circle", {"radius": 2.0}),
        f=("field.from_curves", {"curves": ["@c"], "radius": 0.4, "samples": 256}),
        m=("field.mesh", {"field": "@f", "cell": 0.08}),
    )
    m = g.evaluate("m")
    assert tm(m).volume == pytest.approx(2 * np.pi**2 * 2.0 * 0.16, rel=0.01)
    assert m.euler_characteristic == 0


def test_mesh_offset_of_a_box_is_the_minkowski_sum():
    a, d = 2.0, 0.3
    g = build(
        b=("mesh.box", {"size": [a, a, a]}),
        o=("mesh.offset", {"mesh": "@b", "distance": d, "cell": 0.06}),
    )
    exact = a**3 + 6 * a * a * d + 3 * np.pi * a * d * d + 4 / 3 * np.pi * d**3
    assert tm(g.evaluate("o")).volume == pytest.approx(exact, rel=0.01)
    g.add("i", "mesh.offset", mesh="@b", distance=-0.3, cell=0.06)
    assert tm(g.evaluate("i")).volume == pytest.approx((a - 2 * d) ** 3, rel=0.02)


def test_budget_refuses_a_hopeless_cell_before_meshing():
    g = build(s=("field.sphere", {"radius": 1.0}), m=("field.mesh", {"field": "@s", "cell": 1e-5}))
    with pytest.raises(BudgetError, match="surface cells, over the budget"):
        g.evaluate("m")


def test_a_field_is_not_written_to_the_disk_cache_but_its_mesh_is(tmp_path):
    g = fg.Graph(cache_dir=tmp_path)
    g.add("s", "field.sphere", radius=1.0)
    g.add("m", "field.mesh", field="@s", cell=0.2)
    first = g.evaluate("m")
    g2 = fg.Graph(cache_dir=tmp_path)
    g2.add("s", "field.sphere", radius=1.0)
    g2.add("m", "field.mesh", field="@s", cell=0.2)
    again = g2.evaluate("m")
    assert g2.stats["m"].status == "cached"
    np.testing.assert_array_equal(first.vertices, again.vertices)
    assert DiskCache(tmp_path).put("k" * 40, Field.sphere(1.0)) is False


def test_a_field_previews_as_a_mesh_and_a_tpms_in_two_periods():
    preview = Field.sphere(1.0).display_mesh()
    assert preview.is_watertight and tm(preview).volume == pytest.approx(4 / 3 * np.pi, rel=0.02)
    g = Field.tpms("schwarz_p", 4.0, 0.5).display_mesh()
    assert np.allclose(g.bounds, [[0, 0, 0], [8, 8, 8]], atol=0.2) and g.is_watertight
    assert Field.expression(lambda x, y, z: x).display_mesh() is None


def _lattice_fields():
    g = Field.tpms("gyroid", 7.3, 0.8)
    p = Field.tpms("schwarz_p", 5.0, 0.5)
    d = Field.tpms("diamond", 6.1, 1.2)
    ball, box = Field.sphere(2.0, [0.3, -0.1, 0.2]), Field.box([1, 2, 3], [0.1, 0, 0], 0.3)
    turn = [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]
    return [
        g,
        p,
        d,
        ball,
        box,
        Field.torus(2.0, 0.5),
        Field.intersection([g, box], 0.2),
        Field.union([ball, Field.offset(box, 0.1)], 0.5),
        Field.difference(Field.shell(ball, 0.2), d, 0.1),
        Field.transform(Field.intersection([d, ball]), np.eye(3), [1, 2, 3], [1, 2, 0.5]),
        Field.transform(ball, turn, [1, 2, 3], 1.5),
        Field.expression(lambda x, y, z: x * y - z),
        Field.intersection([g, Field.box([30, 30, 30], [1, 0, 0])]),  # lattices in and out
    ]


@settings(max_examples=30, deadline=None)
@given(
    st.integers(0, 12),
    st.lists(st.floats(-20, 20), min_size=6, max_size=6),
    st.lists(st.floats(1e-3, 2.0), min_size=3, max_size=3),
    st.lists(st.integers(1, 9), min_size=3, max_size=3),
)
def test_lattice_values_are_the_point_values(which, origin, step, shape):
    # the separable tables (TPMS, box, sphere, their blends, axis-aligned transforms) and
    # the point-wise fallback (rotations, tori, expressions) give what evaluate gives
    field = _lattice_fields()[which]
    key = digest(field)
    o = np.array(origin).reshape(2, 3)
    lattice = field.evaluate_grid(o, step, shape)
    ijk = np.stack(np.meshgrid(*(np.arange(k) for k in shape), indexing="ij"), -1)
    p = o[:, None, None, None, :] + ijk[None] * np.array(step)
    points = field.evaluate(p.reshape(-1, 3)).reshape(2, *shape)
    assert lattice.shape == (2, *shape)
    np.testing.assert_allclose(lattice, points, rtol=0, atol=1e-12)
    assert field.evaluate_grid(o[0], step, shape).shape == tuple(shape)
    # on the lattice's lines: two coordinates on it, the third anywhere along an edge
    rng = np.random.default_rng(which)
    ijk = rng.integers(-40, 40, (50, 3))
    axis, t = rng.integers(0, 3, 50), rng.uniform(0, 1, 50)
    on_lines = field.evaluate_lines(o[0], step, ijk, axis, t)
    p = o[0] + (ijk + np.eye(3)[axis] * t[:, None]) * np.array(step)
    np.testing.assert_allclose(on_lines, field.evaluate(p), rtol=0, atol=1e-12)
    assert digest(field) == key  # sampling does not change the key


def test_separable_fields_are_the_ones_sampled_on_tables():
    g = Field.tpms("gyroid", 10.0, 1.0)
    assert Field.intersection([g, Field.box([5, 5, 5])]).separable
    assert Field.transform(g, np.eye(3), [1, 0, 0], [1, 2, 3]).separable
    assert not Field.transform(g, [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], [0, 0, 0], 1).separable
    assert not Field.union([g, Field.torus(2.0, 0.5)]).separable  # a torus is point-wise


def four_blocks(smooth, **extra):
    """Four 10 x 10 x 5 blocks standing on z = 0 in a 2 x 2 square, unioned."""
    nodes = {
        name: ("field.box", {"size": [10, 10, 5], "center": [5 + 10 * i, 5 + 10 * j, 2.5]})
        for name, (i, j) in zip("abcd", [(0, 0), (1, 0), (0, 1), (1, 1)], strict=True)
    }
    nodes["u"] = ("field.union", {"fields": ["@a", "@b", "@c", "@d"], "smooth": smooth})
    nodes.update(extra)
    nodes.setdefault("m", ("field.mesh", {"field": "@u", "cell": 0.5}))
    return build(**nodes)


def test_a_smooth_union_that_pushes_a_flat_bottom_below_the_bed_is_warned_of():
    g = four_blocks(1.0)
    v = g.evaluate("m").vertices
    (warning,) = g.stats["m"].warnings
    below, above = -v[:, 2].min(), v[:, 2].max() - 5
    assert below > 0.4 and above > 0.4  # the ridges under and over the seams, up to k/4 and more
    assert "the smooth union (its input smooth: 1)" in warning
    assert f"the face at z = 5 (facing +z) by {above:.3g}, at (" in warning
    assert f"the face at z = 0 (facing -z) by {below:.3g}, at (" in warning
    assert "; and 2 more" in warning  # the four sides, by about k / 4
    assert "intersect the blend with a box" in warning
    # the advice works: cut back to the blocks' box, the blend stays inside, no warning
    cut = four_blocks(
        1.0,
        box=("field.box", {"size": [20, 20, 5], "center": [10, 10, 2.5]}),
        cut=("field.intersection", {"fields": ["@u", "@box"]}),
        m=("field.mesh", {"field": "@cut", "cell": 0.5}),
    )
    v = cut.evaluate("m").vertices
    assert cut.stats["m"].warnings == []
    assert v[:, 2].min() > -0.05 and v[:, 2].max() < 5.05  # within a tenth of the cell
    sharp = four_blocks(0.0)
    sharp.evaluate("m")
    assert sharp.stats["m"].warnings == []


def test_fillets_and_shapes_that_cross_the_plane_are_not_warned_of():
    g = build(
        plate=("field.box", {"size": [20, 20, 2], "center": [0, 0, 1]}),
        post=("field.cylinder", {"radius": 2, "height": 10, "center": [0, 0, 7]}),
        ball=("field.sphere", {"radius": 2, "center": [6, 0, 0.5]}),  # through the bed
        u=("field.union", {"fields": ["@plate", "@post", "@ball"], "smooth": 1.5}),
        m=("field.mesh", {"field": "@u", "cell": 0.4}),
        s=("field.union", {"fields": ["@plate", "@post", "@ball"]}),
        ms=("field.mesh", {"field": "@s", "cell": 0.4}),
    )
    blended, sharp = g.evaluate(["m", "ms"]).values()
    assert tm(blended).volume > tm(sharp).volume + 1  # the fillets are there
    assert g.stats["m"].warnings == []


def test_a_slanted_flat_face_and_a_mesh_s_faces_are_checked_too():
    g = four_blocks(
        1.0,
        t=("field.transform", {"field": "@u", "rotate": [30, 0, 0]}),
        m=("field.mesh", {"field": "@t", "cell": 0.5}),
    )
    g.evaluate("m")
    (warning,) = g.stats["m"].warnings
    assert "n = [0, -0.5, 0.866]" in warning  # the top face's normal, turned 30 deg about x
    h = build(
        a=("mesh.box", {"size": [2, 2, 2], "center": [1, 1, 1]}),
        b=("mesh.box", {"size": [2, 2, 2], "center": [3, 1, 1]}),
        fa=("field.from_mesh", {"mesh": "@a"}),
        fb=("field.from_mesh", {"mesh": "@b"}),
        u=("field.union", {"fields": ["@fa", "@fb"], "smooth": 0.8}),
        m=("field.mesh", {"field": "@u", "cell": 0.1}),
    )
    v = h.evaluate("m").vertices
    (warning,) = h.stats["m"].warnings
    assert f"the face at z = 0 (facing -z) by {-v[:, 2].min():.3g}, at (" in warning


@settings(max_examples=8, deadline=None)
@given(
    gap=st.floats(0.0, 1.5),
    smooth=st.floats(0.2, 2.0),
    height=st.floats(1.0, 4.0),
)
def test_a_blend_is_warned_of_exactly_when_its_mesh_passes_the_bed(gap, smooth, height):
    g = build(
        a=("field.box", {"size": [3, 3, 2], "center": [0, 0, 1]}),
        b=("field.box", {"size": [3, 3, height], "center": [3 + gap, 0, height / 2]}),
        u=("field.union", {"fields": ["@a", "@b"], "smooth": smooth}),
        m=("field.mesh", {"field": "@u", "cell": 0.25}),
    )
    v = g.evaluate("m").vertices
    warned = any("z = 0 (facing -z)" in w for w in g.stats["m"].warnings)
    assert warned == (v[:, 2].min() < -0.025)


def _dense_reference(field: Field, lo, hi, cell: float) -> trimesh.Trimesh:
    """The field sampled on a dense grid point by point (``Field.evaluate``, not the
    lattices' tables) and meshed by scikit-image's marching cubes."""
    skimage = pytest.importorskip("skimage.measure")
    n = np.ceil((np.asarray(hi) - lo) / cell).astype(int) + 3
    # shifted by a generic fraction of a cell, as the mesher's grid is: no corner lies on
    # a box's face (a value of exactly 0 there makes marching cubes' surface non-manifold)
    shift = np.array([0.31, 0.17, 0.23]) * cell
    axes = [lo[k] - cell + shift[k] + np.arange(n[k]) * cell for k in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    values = field.evaluate(grid).reshape(*n)
    v, t, _, _ = skimage.marching_cubes(values, 0.0, spacing=(cell,) * 3)
    ref = trimesh.Trimesh(v + [a[0] for a in axes], t)
    ref.update_faces(ref.nondegenerate_faces())  # skimage leaves zero-area slivers
    ref.merge_vertices()
    return ref


# each kind, and whether its surface has sharp edges (marching cubes bevels those by up
# to about 0.7 of a cell, each grid differently; a smooth surface is off its chords by
# ~cell^2 / 8r only)
_KINDS = {
    "sphere": (lambda: Field.sphere(1.3, [0.1, -0.05, 0.02]), False),
    "box": (lambda: Field.box([2.2, 1.6, 1.9], [0.05, 0, -0.1], radius=0.2), False),
    "smooth union": (
        lambda: Field.union(
            [Field.sphere(0.9, [-0.5, 0, 0]), Field.box([1.4, 1.2, 1.0], [0.6, 0.1, 0])],
            smooth=0.4,
        ),
        True,
    ),
    "gyroid in a box": (
        lambda: Field.intersection([Field.tpms("gyroid", 2.0, 0.3), Field.box([2.6, 2.4, 2.2])]),
        True,
    ),
    "torus (point by point)": (lambda: Field.torus(1.0, 0.35), False),
}


@pytest.mark.parametrize("kind", list(_KINDS))
def test_field_mesh_is_the_dense_marching_cubes_surface(kind):
    # every kind of field the mesher samples (on the lattices' tables, or point by point
    # for a torus) against a dense grid sampled at the points and meshed by scikit-image:
    # the same surface to a fraction of the cell (both ways), the same area, closed alike
    make, sharp = _KINDS[kind]
    field, cell = make(), 0.08
    assert field.separable == (kind != "torus (point by point)")
    g = fg.Graph()
    g.add_param("f", type="Field")
    g.add("m", "field.mesh", field="=f", cell=cell)
    mesh = g.evaluate("m", f=field)
    ours = trimesh.Trimesh(mesh.vertices, mesh.face_indices.reshape(-1, 3), process=False)
    lo, hi = field.bounds
    ref = _dense_reference(field, lo, hi, cell)
    assert ours.is_watertight and ours.is_winding_consistent
    assert ref.is_watertight  # every kind here closes in its bounds
    assert ours.euler_number == ref.euler_number
    assert ours.area == pytest.approx(ref.area, rel=0.01)
    assert ours.volume == pytest.approx(abs(ref.volume), rel=0.01)
    # the grids differ by a fraction of a cell; each vertex of either is within a
    # fraction of a cell of the other's triangles (the Hausdorff distance of the two).
    # Where a sharp edge is bevelled (by each grid its own way; a gyroid's wall meets
    # the box's face at any angle, a grazing one makes a long thin wedge) the two differ
    # by up to a cell or so there, and coincide everywhere else
    for a, b in ((ours, ref), (ref, ours)):
        _, d, _ = trimesh.proximity.closest_point(b, a.vertices)
        if sharp:
            assert np.median(d) < 0.05 * cell and d.max() < 1.5 * cell
        else:
            assert d.max() < 0.15 * cell
    # ours are roots of the field itself: on its zero set, not a chord's length off it
    assert np.abs(field.evaluate(mesh.vertices)).max() < 1e-3 * cell
