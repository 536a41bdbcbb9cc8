"""mesh.slice and mesh.project (nodes/mesh/section.py, kernels/mesh/section.py): sections of
a drilled block against shapely (outer loop counter-clockwise, hole clockwise), against
manifold3d's slice and project, stacks by repeat:, and the loop machinery alone."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.kernels.mesh import section as ks


def drilled_block() -> fg.Graph:
    """A 40 x 30 x 10 block with a vertical hole of radius 5 and a horizontal one of
    radius 2 along x at z = 2 (booleans through manifold3d)."""
    g = fg.Graph()
    g.add("b", "mesh.box", size=[40, 30, 10], center=[0, 0, 5])
    g.add("v", "mesh.cylinder", radius=5, height=14, segments=48, center=[4, 0, 5])
    g.add("h", "mesh.cylinder", radius=2, height=50, segments=32, center=[0, 0, 0])
    g.add("ht", "geometry.transform", geometry="@h", rotate=[0, 90, 0], translate=[0, 0, 2])
    g.add("cut", "mesh.union", meshes=["@v", "@ht"])
    g.add("part", "mesh.boolean", a="@b", b="@cut", operation="difference")
    return g


def region_of(curves) -> shapely.Geometry:
    out = shapely.Polygon()
    for c in curves:
        out = out.symmetric_difference(shapely.Polygon(c.control_points[:, :2]))
    return out


def test_the_section_of_a_drilled_block_is_the_plate_minus_the_hole():
    g = drilled_block()
    g.add("s", "mesh.slice", mesh="@part", height=7)
    loops = g.evaluate("s")
    assert g.stats["s"].warnings == []
    assert len(loops) == 2
    outer, hole = sorted(loops, key=lambda c: -shapely.Polygon(c.control_points[:, :2]).area)
    assert shapely.LinearRing(outer.control_points[:, :2]).is_ccw
    assert not shapely.LinearRing(hole.control_points[:, :2]).is_ccw
    for c in loops:
        assert c.closed and c.degree == 1 and np.all(c.control_points[:, 2] == 7)
    # shapely's section of the same solid: the box's rectangle minus the 48-gon hole
    a = 2 * np.pi * np.arange(48) / 48
    gon = shapely.Polygon(np.column_stack([4 + 5 * np.cos(a), 5 * np.sin(a)]))
    ref = shapely.box(-20, -15, 20, 15).difference(gon)
    got = region_of(loops)
    assert got.symmetric_difference(ref).area <= 1e-9 * ref.area
    assert got.area == pytest.approx(1200 - 0.5 * 48 * 25 * math.sin(2 * math.pi / 48))


def test_sections_agree_with_manifold3ds_slice_at_many_heights():
    import manifold3d

    g = drilled_block()
    part = g.evaluate("part")
    ref = manifold3d.Manifold(
        manifold3d.Mesh64(
            vert_properties=np.array(part.vertices),
            tri_verts=np.array(part.face_indices.reshape(-1, 3), dtype=np.uint64),
        )
    )
    g.add_param("z", 1.0)
    g.add("s", "mesh.slice", mesh="@part", height="=z")
    for z in (0.0, 0.5, 1.999, 2.0, 3.3, 9.99):
        loops = g.evaluate("s", z=z)
        theirs = ref.slice(z)
        assert region_of(loops).area == pytest.approx(theirs.area(), rel=1e-7, abs=1e-9), z
        if z > 0:  # (at 0 the channel's lowest line touches the plane: GEOS cuts the face
            assert len(loops) == theirs.num_contour(), z  # in two along it, Clipper not)


def test_the_plane_at_the_bottom_gives_the_bottom_face_and_at_the_top_nothing():
    g = fg.Graph()
    g.add("b", "mesh.box", size=[2, 3, 4], center=[0, 0, 2])
    g.add("lo", "mesh.slice", mesh="@b", height=0)
    g.add("hi", "mesh.slice", mesh="@b", height=4)
    assert region_of(g.evaluate("lo")).area == pytest.approx(6.0)
    with pytest.warns(fg.FormgraphWarning, match=r"the plane z = 4 misses the mesh"):
        assert g.evaluate("hi") == []


def test_slices_along_x_and_y_run_counter_clockwise_seen_from_plus_axis():
    g = fg.Graph()
    g.add("b", "mesh.box", size=[2, 4, 6])
    g.add("sx", "mesh.slice", mesh="@b", height=0.25, axis="x")
    g.add("sy", "mesh.slice", mesh="@b", height=-0.5, axis="y")
    (cx,) = g.evaluate("sx")
    (cy,) = g.evaluate("sy")
    assert np.all(cx.control_points[:, 0] == 0.25) and np.all(cy.control_points[:, 1] == -0.5)
    # seen from +x the plane's right-handed axes are (y, z); from +y they are (z, x)
    assert shapely.LinearRing(cx.control_points[:, [1, 2]]).is_ccw
    assert shapely.LinearRing(cy.control_points[:, [2, 0]]).is_ccw
    assert shapely.Polygon(cx.control_points[:, [1, 2]]).area == pytest.approx(24)
    assert shapely.Polygon(cy.control_points[:, [2, 0]]).area == pytest.approx(12)


def test_a_stack_by_repeat_gives_one_list_of_loops_per_layer():
    g = drilled_block()
    g.add("layers", "mesh.slice", repeat={"i": 4}, mesh="@part", height="=1 + 2.5 * i")
    layers = g.evaluate("layers")
    assert len(layers) == 8  # two loops per layer, joined into one list
    heights = sorted({float(c.control_points[0, 2]) for c in layers})
    assert heights == [1.0, 3.5, 6.0, 8.5]


def test_overlapping_parts_are_united_by_their_winding_numbers():
    g = fg.Graph()
    g.add("a", "mesh.box", size=[2, 2, 2])
    g.add("b", "mesh.box", size=[2, 2, 2], center=[1, 0, 0])
    g.add("m", "mesh.merge", meshes=["@a", "@b"])  # not fused: the boxes overlap
    g.add("s", "mesh.slice", mesh="@m", height=0.1)
    loops = g.evaluate("s")
    assert "united by their winding numbers" in g.stats["s"].warnings[0]
    assert len(loops) == 1 and region_of(loops).area == pytest.approx(6.0)


def test_an_open_mesh_gives_the_loops_that_close_and_says_so():
    g = fg.Graph()
    g.add("c", "mesh.cylinder", radius=1, height=2, segments=16, caps=False)
    g.add("b", "mesh.box", size=[1, 1, 1], center=[5, 0, 0])
    g.add("m", "mesh.merge", meshes=["@c", "@b"])
    g.add("t", "mesh.triangulate", mesh="@m")
    g.add("s", "mesh.slice", mesh="@t", height=0.2)
    loops = g.evaluate("s")
    assert len(loops) == 2  # the open tube still closes around; the box too
    cyl = fg.Mesh(
        np.array([[0, 0, -1], [1, 0, -1], [0, 1, -1], [0, 0, 1]], float),
        [[0, 1, 3], [1, 2, 3]],  # two faces of a tetrahedron: an open chain
    )
    g.add("s2", "mesh.slice", mesh=cyl, height=0)
    assert g.evaluate("s2") == []
    assert "found no neighbour across an edge" in g.stats["s2"].warnings[0]


def test_project_is_the_union_of_the_projected_faces():
    import manifold3d

    g = fg.Graph()
    g.add("t", "mesh.torus", major=3, minor=1, segments_u=48, segments_v=24)
    g.add("r", "geometry.transform", geometry="@t", rotate=[35, 10, 0])
    g.add("p", "mesh.project", mesh="@r")
    mesh = g.evaluate("r")
    loops = g.evaluate("p")
    got = region_of(loops)
    from formgraph.kernels.mesh.meshops import triangulate

    v, fi, _ = triangulate(mesh.vertices, mesh.face_indices, mesh.face_offsets)
    tris = shapely.polygons(v[fi.reshape(-1, 3)][:, :, :2])
    ref = shapely.union_all(tris[shapely.area(tris) > 0])
    assert got.symmetric_difference(ref).area <= 1e-9 * ref.area
    assert all(np.all(c.control_points[:, 2] == 0) for c in loops)
    for c in loops:  # outer counter-clockwise, the hole clockwise
        ring = shapely.LinearRing(c.control_points[:, :2])
        inner = ref.exterior.distance(shapely.Point(c.control_points[0, :2])) > 1e-9
        assert ring.is_ccw != inner
    m3 = manifold3d.Manifold(
        manifold3d.Mesh64(
            vert_properties=np.array(v), tri_verts=np.array(fi.reshape(-1, 3)).astype(np.uint64)
        )
    )
    assert got.area == pytest.approx(m3.project().area(), rel=1e-7)


def test_project_of_a_soup_and_of_an_open_sheet():
    g = fg.Graph()
    g.add("p", "mesh.plane", size=[4, 2], divisions=[3, 2])
    g.add("tilted", "geometry.transform", geometry="@p", rotate=[0, 60, 0])
    g.add("flip", "mesh.flip", mesh="@tilted")  # facing down: still a shadow
    g.add("s", "mesh.project", mesh="@flip")
    (outline,) = g.evaluate("s")
    assert shapely.Polygon(outline.control_points[:, :2]).area == pytest.approx(4 * 2 * 0.5)
    edge_on = fg.Mesh([[0, 0, 0], [1, 0, 0], [1, 0, 1]], [[0, 1, 2]])
    g.add("e", "mesh.project", mesh=edge_on)
    assert g.evaluate("e") == []
    assert "edge-on" in g.stats["e"].warnings[0]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 10_000), min_size=1, max_size=300))
def test_cycles_lists_every_cycle_of_a_permutation_in_order(keys):
    succ = np.argsort(np.array(keys), kind="stable")
    order, offsets = ks.cycles(succ)
    assert sorted(order.tolist()) == list(range(len(succ)))
    for a, b in zip(offsets[:-1], offsets[1:], strict=True):
        c = order[a:b]
        assert c[0] == c.min()
        assert np.array_equal(succ[c], np.roll(c, -1))


def test_slice_index_finds_the_same_triangles_as_a_scan():
    rng = np.random.default_rng(5)
    z = rng.normal(size=2000)
    tri = rng.integers(0, 2000, (20_000, 3))
    index = ks.SliceIndex(z, tri)
    for h in (-3.0, -0.5, 0.0, 0.123, 1.7, z.max(), 9.0):
        zt = z[tri]
        scan = np.flatnonzero((zt.min(axis=1) <= h) & (zt.max(axis=1) > h))
        assert np.array_equal(index.cut(h), scan), h
