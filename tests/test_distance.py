"""attr.distance and attr.transfer (nodes/attr/distance.py) against independent references:
scipy's cKDTree, closed forms, trimesh's signed distance, brute force over every primitive."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

import formgraph as fg
from formgraph.geometry import Field, Mesh, NurbsCurve, Points
from formgraph.kernels.geometry import meshdist

KINDS = {Mesh: "Mesh", Points: "Points", Field: "Field"}


def kind(value) -> str:
    if isinstance(value, list):
        return "list[Curve]"
    return (
        next(name for cls, name in KINDS.items() if isinstance(value, cls))
        if not isinstance(value, NurbsCurve)
        else "Curve"
    )


def ask(node_type: str, geometry, other, port: str = "to", **inputs):
    """``node_type`` applied to ``geometry`` with ``port`` = ``other``."""
    g = fg.Graph()
    g.add_param("a_", type=kind(geometry))
    g.add_param("b_", type=kind(other))
    g.add("n", node_type, geometry="=a_", **{port: "=b_"}, **inputs)
    return g.evaluate("n", a_=geometry, b_=other)


def as_mesh(tm: trimesh.Trimesh, **point_data) -> Mesh:
    f = np.asarray(tm.faces)
    return Mesh(tm.vertices, f.reshape(-1), np.arange(0, f.size + 1, 3), point_data or None)


def cloud(n: int, scale: float = 2.0, seed: int = 0) -> Points:
    return Points(np.random.default_rng(seed).uniform(-scale, scale, (n, 3)))


def test_distance_to_points_is_the_k_d_trees_nearest_exactly():
    q, src = cloud(2000, seed=1), cloud(500, seed=2)
    out = ask("attr.distance", q, src)
    d, i = cKDTree(src.xyz).query(q.xyz)
    np.testing.assert_array_equal(out.point_data["distance"], d)
    np.testing.assert_array_equal(out.point_data["closest"], src.xyz[i])
    np.testing.assert_array_equal(out.xyz, q.xyz)


def test_distance_to_a_mesh_is_the_brute_force_minimum_and_the_closest_point_is_on_it():
    tm = trimesh.creation.torus(1.0, 0.35, 48, 16)
    q = cloud(600, 1.6, seed=3)
    out = ask("attr.distance", q, as_mesh(tm), name="gap")
    t = tm.triangles
    brute = meshdist.point_triangle_distance(
        q.xyz[:, None], t[None, :, 0], t[None, :, 1], t[None, :, 2]
    )
    np.testing.assert_allclose(out.point_data["gap"], brute.min(axis=1), rtol=0, atol=1e-12)
    c = out.point_data["closest"]
    np.testing.assert_allclose(np.linalg.norm(c - q.xyz, axis=1), out.point_data["gap"], atol=1e-12)
    # the closest point lies on the surface: trimesh finds it at distance 0
    assert trimesh.proximity.closest_point(tm, c)[1].max() < 1e-9


def test_signed_distance_to_a_sphere_mesh_matches_the_closed_form_and_trimesh():
    tm = trimesh.creation.icosphere(subdivisions=5, radius=2.0)
    q = cloud(1500, 3.0, seed=4)
    out = ask("attr.distance", q, as_mesh(tm), signed=True)
    d = out.point_data["distance"]
    r = np.linalg.norm(q.xyz, axis=1)
    # the mesh lies between the sphere and the sphere less its sag: the least distance
    # from the centre to a face's plane (the foot is the face's circumcentre, inside it)
    sag = 2.0 - np.abs(np.einsum("ij,ij->i", tm.face_normals, tm.triangles[:, 0])).min()
    assert np.abs(d - (r - 2.0)).max() <= sag
    np.testing.assert_array_equal(d < 0, r < 2.0 - sag)  # well inside: negative
    theirs = trimesh.proximity.signed_distance(tm, q.xyz)  # positive inside
    np.testing.assert_allclose(d, -theirs, rtol=0, atol=1e-9)


def test_signed_distance_to_an_open_mesh_warns_and_signs_by_winding_number():
    tm = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    keep = np.ones(len(tm.faces), bool)
    keep[:3] = False  # a small hole
    open_ = as_mesh(trimesh.Trimesh(tm.vertices, tm.faces[keep], process=False))
    q = Points([[0, 0, 0], [0.2, 0.1, -0.3], [3, 0, 0]])
    with pytest.warns(fg.FormgraphWarning, match="open.*winding number"):
        out = ask("attr.distance", q, open_, signed=True)
    d = out.point_data["distance"]
    assert d[0] < 0 and d[1] < 0 and d[2] > 0


def test_distance_to_curves_exact_polylines_and_circles_within_the_tolerance():
    square = NurbsCurve.polyline([[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], closed=True)
    circle = fg.Graph()
    circle.add("c", "nurbs.circle", radius=3.0, center=[10, 0, 0])
    ring = circle.evaluate("c")
    q = Points(np.random.default_rng(5).uniform([-2, -2, -1], [14, 6, 1], (800, 3)))
    out = ask("attr.distance", q, [square, ring], tolerance=1e-6)
    x, y, z = q.xyz.T
    to_ring = np.hypot(np.hypot(x - 10, y) - 3.0, z)
    corners = np.asarray(square.control_points)
    to_square = np.min(
        [
            meshdist.point_segment_distance(q.xyz, a, b)
            for a, b in zip(corners[:-1], corners[1:], strict=True)
        ],
        axis=0,
    )
    np.testing.assert_allclose(
        out.point_data["distance"], np.minimum(to_ring, to_square), atol=2e-6
    )


def test_distance_to_a_field_is_its_value_and_the_closest_point_lies_on_its_surface():
    f = Field.sphere(1.5, (1, 0, 0))
    q = cloud(400, 3.0, seed=6)
    out = ask("attr.distance", q, f, signed=True)
    r = np.linalg.norm(q.xyz - [1, 0, 0], axis=1)
    np.testing.assert_allclose(out.point_data["distance"], r - 1.5, atol=1e-12)
    c = out.point_data["closest"]
    np.testing.assert_allclose(np.linalg.norm(c - [1, 0, 0], axis=1), 1.5, atol=1e-6)
    unsigned = ask("attr.distance", q, f)
    np.testing.assert_allclose(unsigned.point_data["distance"], np.abs(r - 1.5), atol=1e-12)


def test_distance_keeps_a_meshs_own_data_and_adds_both_attributes():
    tm = trimesh.creation.box()
    m = as_mesh(tm, h=np.arange(8.0))
    out = ask("attr.distance", m, Points([[5, 0, 0]]))
    assert set(out.point_data) == {"h", "distance", "closest"}
    assert out.n_faces == m.n_faces
    np.testing.assert_allclose(
        out.point_data["distance"], np.linalg.norm(m.vertices - [5, 0, 0], axis=1)
    )


def test_transfer_from_a_mesh_reproduces_a_linear_attribute_exactly():
    tm = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    # linear over space, so linear over every triangle: its barycentric interpolation at
    # the closest point equals the function there
    v = tm.vertices
    src = as_mesh(tm, h=2 * v[:, 0] - 3 * v[:, 1] + 0.5 * v[:, 2] + 1, rgb=(v + 1) / 2)
    q = cloud(700, 1.5, seed=7)
    out = ask("attr.transfer", q, src, port="source", names=["h", "rgb"])
    c, _, _ = trimesh.proximity.closest_point(tm, q.xyz)
    np.testing.assert_allclose(
        out.point_data["h"], 2 * c[:, 0] - 3 * c[:, 1] + 0.5 * c[:, 2] + 1, atol=1e-9
    )
    np.testing.assert_allclose(out.point_data["rgb"], (c + 1) / 2, atol=1e-9)
    # the query points' own coordinates did not move
    np.testing.assert_array_equal(out.xyz, q.xyz)


def test_transfer_from_points_copies_the_nearest_points_values():
    src = cloud(300, seed=8)
    src = src.with_point_data(
        {"id": np.arange(300.0), "v": np.random.default_rng(0).normal(size=(300, 3))}
    )
    q = cloud(900, seed=9)
    out = ask("attr.transfer", q, src, port="source", names="id")
    _, i = cKDTree(src.xyz).query(q.xyz)
    np.testing.assert_array_equal(out.point_data["id"], i.astype(float))
    assert set(out.point_data) == {"id"}


def test_transfer_names_an_attribute_the_source_lacks_and_lists_what_it_has():
    src = Points([[0, 0, 0]], {"height": [1.0], "color": [[1.0, 0, 0]]})
    with pytest.raises(
        fg.NodeError, match=r"no point attribute 'heigth' \(its point attributes: color, height\)"
    ):
        ask("attr.transfer", cloud(3), src, port="source", names=["heigth"])
