"""geometry.filter (nodes/geometry/filter.py, kernels/mesh/select.py): one mask per test, the
kept elements and their attributes against numpy written directly, trimesh and shapely."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.geometry import Mesh, NurbsCurve, Points


def kept(geometry, keep, **inputs):
    g = fg.Graph()
    kind = "Points" if isinstance(geometry, Points) else "Mesh"
    kind = kind if not isinstance(geometry, list) else "list[Curve]"
    g.add_param("g_", type=kind)
    g.add_param("t", 0.25)
    g.add("f", "geometry.filter", geometry="=g_", keep=keep, **inputs)
    return g.evaluate("f", g_=geometry)


def sphere(**point_data) -> Mesh:
    tm = trimesh.creation.icosphere(subdivisions=2)
    f = tm.faces
    m = Mesh(tm.vertices, f.reshape(-1), np.arange(0, f.size + 1, 3))
    v = m.vertices
    return m.with_data(
        {"h": v[:, 2] * 10, "c": v + 1, **point_data}, {"id": np.arange(m.n_faces, dtype=float)}
    )


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 400), st.floats(-1.5, 1.5), st.integers(0, 10**6))
def test_points_are_the_numpy_mask_with_their_attributes(n, t, seed):
    xyz = np.random.default_rng(seed).normal(size=(n, 3))
    p = Points(xyz, {"w": np.arange(n, dtype=float), "v": xyz * 2})
    out = kept(p, f"=z > {t!r} or x < -1")
    mask = (xyz[:, 2] > t) | (xyz[:, 0] < -1)
    np.testing.assert_array_equal(out.xyz, xyz[mask])
    np.testing.assert_array_equal(out.point_data["w"], np.flatnonzero(mask).astype(float))
    np.testing.assert_array_equal(out.point_data["v"], xyz[mask] * 2)


def test_a_mesh_by_point_keeps_the_faces_whose_corners_all_pass_and_drops_unused_points():
    m = sphere()
    out = kept(m, "=z > t")
    v, f = m.vertices, np.asarray(m.face_indices).reshape(-1, 3)
    faces = (v[f, 2] > 0.25).all(axis=1)
    ref = trimesh.Trimesh(v, f, process=False).submesh([np.flatnonzero(faces)], append=True)
    assert out.n_faces == faces.sum() == len(ref.faces)
    np.testing.assert_allclose(out.vertices, ref.vertices)  # the same vertices, same order
    np.testing.assert_array_equal(np.asarray(out.face_indices).reshape(-1, 3), ref.faces)
    assert np.all(out.vertices[:, 2] > 0.25)
    # point attributes follow their vertices, face attributes their faces
    np.testing.assert_allclose(out.point_data["h"], out.vertices[:, 2] * 10)
    np.testing.assert_allclose(out.point_data["c"], out.vertices + 1)
    np.testing.assert_array_equal(out.face_data["id"], np.flatnonzero(faces).astype(float))


def test_a_mesh_by_face_tests_the_face_centres_and_normals():
    m = sphere()
    out = kept(m, "=nz > 0.5 and id >= 10", domain="face")
    v, f = m.vertices, np.asarray(m.face_indices).reshape(-1, 3)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    faces = (n[:, 2] > 0.5) & (np.arange(len(f)) >= 10)
    np.testing.assert_array_equal(out.face_data["id"], np.flatnonzero(faces).astype(float))
    used = np.unique(f[faces])
    assert out.n_vertices == len(used)
    np.testing.assert_array_equal(out.vertices, v[used])


def test_true_and_false_keep_all_or_nothing():
    m = sphere()
    assert kept(m, True) == kept(m, "=i >= 0")
    assert kept(m, True).n_faces == m.n_faces
    none = kept(m, False)
    assert none.n_faces == 0 and none.n_vertices == 0 and set(none.point_data) == {"h", "c"}


def test_curves_are_kept_whole_by_length_area_closure_and_centroid():
    square = NurbsCurve.polyline([[0, 0], [2, 0], [2, 2], [0, 2]], closed=True)  # ccw, 4
    clockwise = NurbsCurve.polyline([[5, 0], [5, 3], [8, 3], [8, 0]], closed=True)  # cw, -9
    line = NurbsCurve.polyline([[0, 5], [10, 5]])  # open, length 10
    g = fg.Graph()
    g.add("circle", "nurbs.circle", radius=1.0, center=[20, 0, 0])
    circle = g.evaluate("circle")  # ccw, pi
    curves = [square, clockwise, line, circle]
    assert kept(curves, "=area > 0") == [square, circle]
    assert kept(curves, "=area < 0") == [clockwise]
    assert kept(curves, "=closed < 0.5") == [line]
    assert kept(curves, "=length > 9") == [clockwise, line]  # 12 and 10
    assert kept(curves, "=x > 10") == [circle]  # centroid (20, 0)
    assert kept(curves, "=i == count - 1") == [circle]
    # the signed areas against shapely's (counter-clockwise positive)
    for c, s in [(square, 4.0), (clockwise, -9.0)]:
        ring = shapely.LinearRing(np.asarray(c.control_points)[:, :2])
        assert shapely.Polygon(ring).area == abs(s) and ring.is_ccw == (s > 0)
    assert kept(curves, "=abs(area - pi) < 1e-9") == [circle]


def test_a_test_that_gives_numbers_is_refused_with_what_to_write():
    with pytest.raises(
        fg.NodeError, match=r"input 'keep'.*'=z \+ 1' gives numbers, not true or false"
    ):
        kept(sphere(), "=z + 1")


def test_an_unknown_name_lists_the_attributes_that_exist():
    with pytest.raises(
        fg.NodeError,
        match=r"names 'heigth', which is not a param, a variable .* \(attributes: c, h\)",
    ):
        kept(sphere(), "=heigth > 2")
    with pytest.raises(
        fg.NodeError, match=r"attribute of the curves \(attributes: area, closed, length\)"
    ):
        kept([NurbsCurve.polyline([[0, 0], [1, 0]])], "=lenght > 2")


def test_a_point_set_has_no_faces():
    with pytest.raises(fg.NodeError, match="a point set has no faces"):
        kept(Points([[0, 0, 0]]), "=z > 0", domain="face")
