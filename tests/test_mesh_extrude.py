"""mesh.extrude and mesh.revolve (nodes/mesh/extrude.py, kernels/mesh/extrude.py): closed
forms of volumes, trimesh's solid checks, manifold3d's extrusion of the same polygons, and
hypothesis through extrude -> slice (the section at mid-height is the region)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.kernels.mesh import extrude as ke
from formgraph.kernels.mesh.measure import is_closed_oriented


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n"), g.stats["n"].warnings


def tm(mesh: fg.Mesh) -> trimesh.Trimesh:
    from formgraph.kernels.mesh.meshops import triangulate

    v, fi, _ = triangulate(mesh.vertices, mesh.face_indices, mesh.face_offsets)
    return trimesh.Trimesh(v, fi.reshape(-1, 3), process=False)


def assert_solid(mesh: fg.Mesh) -> trimesh.Trimesh:
    t = tm(mesh)
    assert mesh.is_watertight and t.is_watertight and t.is_winding_consistent
    assert is_closed_oriented(mesh.face_indices, mesh.face_offsets, mesh.n_vertices)
    assert t.volume > 0 and mesh.volume == pytest.approx(t.volume, rel=1e-12)
    return t


def square(side: float, center=(0.0, 0.0), cw: bool = False) -> fg.NurbsCurve:
    h = side / 2
    cx, cy = center
    pts = [[cx - h, cy - h], [cx + h, cy - h], [cx + h, cy + h], [cx - h, cy + h]]
    return fg.NurbsCurve.polyline(pts[::-1] if cw else pts, closed=True)


# ------------------------------------------------------------------------------- extrude


def test_a_prism_with_a_hole_has_the_volume_of_its_region():
    m, warnings = run("mesh.extrude", curves=[square(10), square(4, (1, 1))], height=3)
    assert warnings == []
    assert_solid(m)
    assert m.volume == pytest.approx((100 - 16) * 3, rel=1e-14)
    assert m.bounds.tolist() == [[-5, -5, 0], [5, 5, 3]]
    assert m.euler_characteristic == 0  # a solid with one hole through it: genus 1


def test_hole_orientation_does_not_matter_and_center_puts_it_around_zero():
    a, _ = run("mesh.extrude", curves=[square(10), square(4, cw=True)], height=2, center=True)
    b, _ = run("mesh.extrude", curves=[square(10, cw=True), square(4)], height=2, center=True)
    for m in (a, b):
        assert_solid(m)
        assert m.volume == pytest.approx(168.0, rel=1e-14)
        assert m.bounds[:, 2].tolist() == [-1.0, 1.0]


def test_the_same_polygons_extruded_by_manifold3d_have_the_same_volume(tmp_path):
    import manifold3d

    from formgraph.core.registry import Context
    from formgraph.nodes import _outlines as _o

    g = fg.Graph()
    g.add("t", "curves.text", text="Bg8", size=10)
    g.add("e", "mesh.extrude", curves="@t", height=2)
    m = g.evaluate("e")
    assert_solid(m)
    xy, off, _, _ = _o.region_rings(g.evaluate("t"), None, Context("x", tmp_path))
    rings = [np.ascontiguousarray(xy[a:b]) for a, b in zip(off[:-1], off[1:], strict=True)]
    ref = manifold3d.CrossSection(rings, manifold3d.FillRule.EvenOdd).extrude(2.0)
    assert m.volume == pytest.approx(ref.volume(), rel=1e-7)  # Clipper2 rounds to 1e-8


def test_a_frustum_under_twist_and_scale_has_the_closed_form_volume():
    side, h, s = 2.0, 3.0, 0.5
    m, _ = run("mesh.extrude", curves=[square(side)], height=h, twist=90, scale=s, tolerance=1e-4)
    assert_solid(m)
    # every level is the square turned and scaled: V = h A (1 + s + s^2) / 3
    exact = h * side**2 * (1 + s + s * s) / 3
    assert m.volume == pytest.approx(exact, rel=3e-4)
    top = m.vertices[m.vertices[:, 2] == h][:, :2]
    turned = (s * np.array([[0, -1], [1, 0]]) @ np.array([[-1, 1, 1, -1], [-1, -1, 1, 1]])).T
    near = np.linalg.norm(top[:, None] - turned[None], axis=2).min(axis=0)
    assert near.max() <= 1e-15  # the corners, turned a quarter and halved
    # every top point lies on the turned square's outline (|x| + |y| = side * s / sqrt(2) ...)
    assert np.allclose(np.abs(top).max(axis=1), s * side / 2, atol=1e-15)


def test_unequal_scale_and_twist_follow_manifold3ds_order():
    """The scale is applied after the turn, as manifold3d's extrude does: the top corners
    agree; the volume is the closed form (each level's area times its two scales)."""
    import manifold3d

    m, _ = run(
        "mesh.extrude",
        curves=[square(2)],
        height=1,
        twist=60,
        scale=[2, 0.5],
        slices=8,
        tolerance=1e-2,
    )
    assert_solid(m)
    pts = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)
    ref = manifold3d.CrossSection([pts]).extrude(1.0, 7, 60.0, (2.0, 0.5))
    rv = np.asarray(ref.to_mesh().vert_properties)[:, :3]
    ref_top = rv[np.isclose(rv[:, 2], 1.0)][:, :2]
    top = m.vertices[m.vertices[:, 2] == 1.0][:, :2]
    near = np.linalg.norm(top[:, None] - ref_top[None], axis=2).min(axis=0)
    assert near.max() <= 1e-6  # (manifold3d's mesh is float32)
    fine, _ = run(
        "mesh.extrude", curves=[square(2)], height=1, twist=60, scale=[2, 0.5], tolerance=1e-3
    )
    assert_solid(fine)
    exact = 4.0 * (1 + 0.25 - 1 / 6)  # h A int (1 + t)(1 - t / 2) dt
    assert fine.volume == pytest.approx(exact, rel=2e-3)


def test_a_scale_of_zero_makes_a_cone_with_one_apex_per_ring():
    m, _ = run("mesh.extrude", curves=[square(10), square(4)], height=6, scale=0)
    assert_solid(m)
    assert m.volume == pytest.approx(6 * 84 / 3, rel=1e-14)
    assert np.count_nonzero(m.vertices[:, 2] == 6) == 2  # the outer's apex and the hole's


def test_twist_slices_keep_each_helix_within_the_tolerance():
    r, tol = 5.0, 1e-3
    n = ke.twist_slices(180.0, r, tol)
    step = math.pi / n
    assert r * (1 - math.cos(step / 2)) <= tol
    assert r * (1 - math.cos(math.pi / (n - 1) / 2)) > tol  # and not more slices than needed
    assert ke.twist_slices(0.0, r, tol) == 1
    assert ke.twist_slices(720.0, r, 10 * r) == math.ceil(720 / ke.MAX_TWIST_STEP)


def test_curved_outlines_are_sampled_within_the_tolerance():
    tol = 1e-3
    m, _ = run("mesh.extrude", curves=[circle(3.0)], height=1, tolerance=tol)
    assert_solid(m)
    bottom = m.vertices[m.vertices[:, 2] == 0][:, :2]
    r = np.hypot(*bottom.T)
    assert np.allclose(r, 3.0, atol=1e-12)  # the samples are on the circle
    ang = np.sort(np.arctan2(bottom[:, 1], bottom[:, 0]))
    gaps = np.diff(np.r_[ang, ang[0] + 2 * np.pi])
    assert (3.0 * (1 - np.cos(gaps / 2))).max() <= tol  # every chord within tol
    assert m.volume == pytest.approx(math.pi * 9, rel=2 * tol / 3)


def circle(r: float, center=(0.0, 0.0, 0.0)) -> fg.NurbsCurve:
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=r, center=list(center))
    return g.evaluate("c")


def test_text_is_extruded_letter_holes_and_all():
    g = fg.Graph()
    g.add("t", "curves.text", text="ABO 8%", size=12)
    g.add("e", "mesh.extrude", curves="@t", height=1.5)
    m = g.evaluate("e")
    t = assert_solid(m)
    pieces = t.split(only_watertight=False)
    assert len(pieces) >= 6  # letters, and the islands inside % and 8


def test_cap_triangles_fall_back_to_manifold3d_where_earcut_does_not_tile():
    # a hole touching its outer ring at a vertex: the rings share a point
    outer = np.array([[0, 0], [4, 0], [4, 4], [2, 4], [0, 4]], float)
    hole = np.array([[2, 4], [3, 2], [1, 2]], float)  # clockwise, touching at (2, 4)
    xy = np.concatenate([outer, hole])
    off = np.array([0, 5, 8])
    v, fi, fo = ke.extrude(xy, off, np.array([False, True]), 1.0)
    assert is_closed_oriented(fi, fo, len(v))
    mesh = fg.Mesh(v, fi, fo)
    assert mesh.volume == pytest.approx(16 - 2, rel=1e-14)


# ------------------------------------------------------------------------------- revolve


def test_a_ring_by_revolution_has_the_volume_of_its_polygonal_solid():
    """A region R turned in N steps of angle a sweeps N wedges of volume sin(a) * int_R r dA
    (each point's chord is ruled between the two planes): Pappus's 2 pi r A as N grows."""
    rect = fg.NurbsCurve.polyline([[1, 0], [2, 0], [2, 1], [1, 1]], closed=True)
    for n, angle in ((64, 360.0), (10, 90.0)):
        m, _ = run("mesh.revolve", curves=[rect], angle=angle, segments=n)
        assert_solid(m)
        moment = 1.5  # int r dA over [1, 2] x [0, 1]
        exact = n * math.sin(math.radians(angle) / n) * moment
        assert m.volume == pytest.approx(exact, rel=1e-13)
    m, _ = run("mesh.revolve", curves=[rect])
    assert m.volume == pytest.approx(3 * math.pi, rel=1e-5)  # Pappus, within the tolerance
    assert m.euler_characteristic == 0


def test_points_on_the_axis_are_poles_and_edges_on_it_make_no_faces():
    rect = fg.NurbsCurve.polyline([[0, 0], [1, 0], [1, 2], [0, 2]], closed=True)
    m, _ = run("mesh.revolve", curves=[rect], segments=32)
    assert_solid(m)
    assert m.euler_characteristic == 2
    assert np.count_nonzero(np.hypot(m.vertices[:, 0], m.vertices[:, 1]) == 0) == 2
    assert m.volume == pytest.approx(32 * math.sin(2 * math.pi / 32) * 1.0, rel=1e-13)
    part, _ = run("mesh.revolve", curves=[rect], angle=120, segments=8)
    assert_solid(part)
    assert part.volume == pytest.approx(8 * math.sin(math.radians(15)) * 1.0, rel=1e-13)


def test_a_revolved_circle_is_a_torus_within_the_tolerance():
    m, _ = run("mesh.revolve", curves=[circle(1.0, (3, 0, 0))], tolerance=1e-3)
    t = assert_solid(m)
    assert m.euler_characteristic == 0
    assert m.volume == pytest.approx(2 * math.pi**2 * 3 * 1, rel=2e-3)  # chords inside
    assert t.bounds[1, 2] == pytest.approx(1.0, abs=1e-12)


def test_a_region_with_a_hole_revolves_into_a_hollow_ring():
    rect = square(2, (3, 0))
    hole = square(1, (3, 0))
    m, _ = run("mesh.revolve", curves=[rect, hole], angle=180, segments=12)
    assert_solid(m)
    assert m.volume == pytest.approx(12 * math.sin(math.pi / 12) * 3 * 3, rel=1e-13)


# ------------------------------------------------------------------ extrude -> slice


@st.composite
def star_regions(draw):
    n = draw(st.integers(3, 24))
    radii = draw(st.lists(st.floats(2.0, 10.0), min_size=n, max_size=n))
    turn = draw(st.floats(0, 2 * math.pi))
    a = turn + 2 * math.pi * np.arange(n) / n
    outer = np.column_stack([np.cos(a), np.sin(a)]) * np.array(radii)[:, None]
    rings = [outer]
    if draw(st.booleans()):
        k = draw(st.integers(3, 8))
        b = 2 * math.pi * np.arange(k) / k
        rings.append(np.column_stack([np.cos(b), np.sin(b)]) * draw(st.floats(0.2, 1.5)))
    return rings


@settings(max_examples=40, deadline=None)
@given(star_regions(), st.floats(0.5, 20.0))
def test_the_section_of_an_extruded_region_at_mid_height_is_the_region(rings, height):
    curves = [fg.NurbsCurve.polyline(r, closed=True) for r in rings]
    g = fg.Graph()
    g.add("e", "mesh.extrude", curves=curves, height=height)
    g.add("s", "mesh.slice", mesh="@e", height=height / 2)
    solid = g.evaluate("e")
    assert is_closed_oriented(solid.face_indices, solid.face_offsets, solid.n_vertices)
    loops = g.evaluate("s")
    region = shapely.Polygon(rings[0], rings[1:])
    got = shapely.Polygon()  # the loops' region by the even-odd rule
    for c in loops:
        assert np.all(c.control_points[:, 2] == height / 2)
        got = got.symmetric_difference(shapely.Polygon(c.control_points[:, :2]))
    assert got.symmetric_difference(region).area <= 1e-12 * region.area
    # outer loops counter-clockwise, holes clockwise
    signs = sorted(shapely.LinearRing(c.control_points[:, :2]).is_ccw for c in loops)
    assert signs == sorted([True] + [False] * (len(rings) - 1))
