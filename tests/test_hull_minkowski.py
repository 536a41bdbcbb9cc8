"""mesh.hull, curves.hull (nodes/mesh/hull.py, nodes/curves/hull.py) against scipy's
ConvexHull and shapely's convex_hull, and mesh.minkowski (nodes/mesh/minkowski.py) against
the closed form of a box summed with a convex polytope."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

import formgraph as fg
from formgraph.kernels.mesh import minkowski as km


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n"), g.stats["n"].warnings


def solid(m: fg.Mesh) -> trimesh.Trimesh:
    t = trimesh.Trimesh(m.vertices, m.face_indices.reshape(-1, 3), process=False)
    assert m.is_watertight and t.is_watertight and t.is_winding_consistent and t.volume > 0
    return t


# --------------------------------------------------------------------------------- hulls


@settings(max_examples=30, deadline=None)
@given(st.integers(4, 400), st.integers(0, 2**31))
def test_mesh_hull_volume_is_scipys_to_1e_9(n, seed):
    p = np.random.default_rng(seed).normal(size=(n, 3)) * [3, 1, 2]
    m, _ = run("mesh.hull", geometry=fg.Points(p))
    solid(m)
    ref = ConvexHull(p)
    assert m.volume == pytest.approx(ref.volume, rel=1e-9)
    assert sorted(map(tuple, m.vertices)) == sorted(map(tuple, p[ref.vertices]))


def test_mesh_hull_keeps_the_point_attributes_of_its_vertices():
    p = np.random.default_rng(1).normal(size=(200, 3))
    pts = fg.Points(p, point_data={"i": np.arange(200.0)})
    m, _ = run("mesh.hull", geometry=pts)
    for k, v in enumerate(m.vertices):
        assert np.array_equal(p[int(m.point_data["i"][k])], v)


def test_mesh_hull_of_curves_and_meshes_together():
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=2)
    g.add("s", "mesh.sphere", radius=0.5, center=[0, 0, 3], segments=32)
    g.add("h", "mesh.hull", geometry=["@c", "@s"], tolerance=1e-4)
    m = g.evaluate("h")
    solid(m)
    assert m.bounds.ravel() == pytest.approx([-2, -2, 0, 2, 2, 3.5], abs=1e-3)
    r = np.hypot(m.vertices[:, 0], m.vertices[:, 1])
    low = m.vertices[:, 2] == 0
    assert np.allclose(r[low], 2.0, atol=1e-12)  # the circle's points are on the circle


def test_curves_hull_agrees_with_shapely_and_runs_counter_clockwise():
    rng = np.random.default_rng(7)
    p = rng.uniform(-5, 5, (300, 2))
    c, _ = run("curves.hull", geometry=fg.Points(p))
    assert c.closed and c.degree == 1 and np.all(c.control_points[:, 2] == 0)
    ring = shapely.LinearRing(c.control_points[:, :2])
    assert ring.is_ccw
    ref = shapely.MultiPoint(p).convex_hull
    assert shapely.Polygon(ring).symmetric_difference(ref).area <= 1e-12 * ref.area
    assert len(c.control_points) - 1 == len(ref.exterior.coords) - 1


def test_curves_hull_of_text_and_circles():
    g = fg.Graph()
    g.add("t", "curves.text", text="hull", size=10)
    g.add("c", "nurbs.circle", radius=3, center=[-5, 2, 0])
    g.add("h", "curves.hull", geometry=["@t", "@c"], tolerance=1e-3)
    hull = shapely.Polygon(g.evaluate("h").control_points[:, :2])
    for c in g.evaluate("t"):
        pts = c.evaluate(np.linspace(*c.domain, 400))[:, :2]
        assert hull.buffer(1e-9).contains(shapely.MultiPoint(pts))
    far = shapely.Point(-8, 2)  # the circle's leftmost point is a corner, within 1e-3
    assert hull.exterior.distance(far) <= 1e-3


# ---------------------------------------------------------------------------- minkowski


def _box_plus_polytope_volume(a: float, b: float, c: float, q: np.ndarray) -> float:
    """V(box + K) = abc + sum of edge * projected area + sum of face * width + V(K): the
    mixed volumes of a sum of segments and a convex body (projections by scipy)."""
    vol = ConvexHull(q).volume
    proj = [ConvexHull(np.delete(q, i, axis=1)).volume for i in range(3)]  # areas
    width = np.ptp(q, axis=0)
    edges = (a, b, c)
    faces = (b * c, c * a, a * b)  # the face across axis i
    return (
        a * b * c
        + sum(edges[i] * proj[i] for i in range(3))
        + sum(faces[i] * width[i] for i in range(3))
        + vol
    )


def test_a_box_summed_with_a_ball_is_the_rounded_box_of_the_closed_form():
    g = fg.Graph()
    g.add("b", "mesh.box", size=[4, 3, 2])
    g.add("s", "mesh.sphere", radius=0.5, segments=24)
    g.add("m", "mesh.minkowski", a="@b", b="@s")
    m = g.evaluate("m")
    solid(m)
    ball = g.evaluate("s").vertices
    assert m.volume == pytest.approx(_box_plus_polytope_volume(4, 3, 2, ball), rel=1e-9)
    # as the ball gets rounder: abc + 2r(ab + bc + ca) + pi r^2 (a + b + c) + 4/3 pi r^3
    r = 0.5
    smooth = 24 + 2 * r * 26 + math.pi * r * r * 9 + 4 / 3 * math.pi * r**3
    assert m.volume == pytest.approx(smooth, rel=5e-3)
    assert m.bounds.ravel() == pytest.approx([-2.5, -2, -1.5, 2.5, 2, 1.5], abs=1e-9)


def test_a_non_convex_solid_summed_with_a_small_cube():
    g = fg.Graph()
    g.add("a", "mesh.box", size=[4, 4, 1])
    g.add("c", "mesh.box", size=[2, 2, 3])
    g.add("l", "mesh.boolean", a="@a", b="@c", operation="difference")  # a square ring
    g.add("k", "mesh.box", size=[0.5, 0.5, 0.5])
    g.add("m", "mesh.minkowski", a="@l", b="@k")
    ring, k = g.evaluate("l"), g.evaluate("k")
    assert not km.is_convex(*ring.arrays) and km.is_convex(*k.arrays)
    m = g.evaluate("m")
    solid(m)
    # the ring grows by 0.25 on every side: outer 4.5, hole 1.5, height 1.5
    assert m.volume == pytest.approx((4.5**2 - 1.5**2) * 1.5, rel=1e-9)


def test_minkowski_cost_is_counted_from_the_sizes():
    g = fg.Graph()
    g.add("s", "mesh.sphere", radius=1, segments=16)
    g.add("t", "mesh.torus", major=2, minor=0.5)
    s, t = g.evaluate("s"), g.evaluate("t")
    assert km.is_convex(*s.arrays) and not km.is_convex(*t.arrays)
    assert km.cost(s.arrays, s.arrays) == s.n_vertices**2
    tri = 2 * t.n_faces  # its quads as triangles
    assert km.cost(t.arrays, s.arrays) == 6 * tri * s.n_vertices
    assert km.cost(t.arrays, t.arrays) == 14 * tri * tri
