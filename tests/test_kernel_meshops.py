"""Mesh operation kernels: box, merge, transform, reverse, triangulate, face lists."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mesh_shapes import cube, flat, prism, tetrahedron

from formgraph.kernels.mesh import build_halfedges
from formgraph.kernels.mesh.meshops import (
    box,
    dihedral_angles,
    face_normals,
    faces_from_lists,
    merge,
    reverse_faces,
    transform,
    triangulate,
    validate_faces,
)
from formgraph.kernels.mesh.subdivision import catmull_clark, doo_sabin


def signed_volume(v, fi, fo):
    _, tf, _ = triangulate(v, fi, fo)
    t = v[tf.reshape(-1, 3)]
    return np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0


# --------------------------------------------------------------------------------------


def test_box_is_closed_outward_and_sized():
    v, fi, fo = box([2.0, 3.0, 4.0], [1.0, -1.0, 0.5])
    he = build_halfedges(fi, fo, 8)
    assert he.is_closed and he.euler_characteristic == 2
    np.testing.assert_allclose(signed_volume(v, fi, fo), 24.0)
    np.testing.assert_allclose(v.min(axis=0), [0.0, -2.5, -1.5])
    np.testing.assert_allclose(v.max(axis=0), [2.0, 0.5, 2.5])
    with pytest.raises(
        ValueError, match=r"box size must be > 0 along every axis, got \[1.0, 0.0, 1.0\]"
    ):
        box([1, 0, 1])


def test_merge():
    a, b = box(1.0), box(2.0, [5, 0, 0])
    v, fi, fo = merge([a, b, tetrahedron()])
    he = build_halfedges(fi, fo, len(v))
    assert len(v) == 20 and he.n_faces == 16 and he.euler_characteristic == 6
    np.testing.assert_array_equal(fi[24:48], b[1] + 8)
    assert merge([])[2].tolist() == [0]


@given(
    st.lists(st.floats(-360, 360), min_size=3, max_size=3),
    st.lists(st.floats(0.1, 3), min_size=3, max_size=3),
)
@settings(max_examples=30, deadline=None)
def test_transform_matches_scipy(angles, scale):
    from scipy.spatial.transform import Rotation

    p = np.random.default_rng(6).normal(size=(10, 3))
    got = transform(p, [1, 2, 3], angles, scale)
    expect = Rotation.from_euler("xyz", angles, degrees=True).apply(p * scale) + [1, 2, 3]
    np.testing.assert_allclose(got, expect, atol=1e-12)


def test_transform_order_and_errors():
    p = np.array([[1.0, 0, 0]])
    # scale x by 2, turn 90 about z, then move: (1,0,0) -> (2,0,0) -> (0,2,0) -> (0,2,1)
    np.testing.assert_allclose(
        transform(p, [0, 0, 1], [0, 0, 90], [2, 1, 1]), [[0, 2, 1]], atol=1e-15
    )
    # 90 about x first, then 90 about y: (0,1,0) -> (0,0,1) -> (1,0,0)
    np.testing.assert_allclose(
        transform([[0, 1.0, 0]], rotate_deg_xyz=[90, 90, 0]), [[1, 0, 0]], atol=1e-15
    )
    with pytest.raises(ValueError, match=r"scale factors must be non-zero, got \[1.0, 0.0, 1.0\]"):
        transform(p, scale=[1, 0, 1])
    with pytest.raises(ValueError, match="rotate must be a number or 3 finite numbers"):
        transform(p, rotate_deg_xyz=[1, 2, 3, 4])


def test_reverse_faces():
    fi, fo = flat([[0, 1, 2, 3], [4, 5, 6]])
    assert reverse_faces(fi, fo).tolist() == [0, 3, 2, 1, 4, 6, 5]
    v, bfi, bfo = box()
    assert signed_volume(v, reverse_faces(bfi, bfo), bfo) == pytest.approx(-1.0)


def test_triangulate_convex_keeps_orientation_and_order():
    v, fi, fo = prism(6)
    tv, tfi, tfo = triangulate(v, fi, fo)
    assert tfo.size - 1 == (np.diff(fo) - 2).sum() == 4 + 4 + 12
    build_halfedges(tfi, tfo, len(v))  # still consistently oriented
    np.testing.assert_allclose(signed_volume(v, tfi, tfo), signed_volume(v, fi, fo))
    assert tfi[:3].tolist() == [5, 4, 3]  # a fan from the first corner, face 0 first


@st.composite
def star_polygons(draw):
    k = draw(st.integers(4, 14))
    radii = draw(st.lists(st.floats(0.2, 1.0), min_size=k, max_size=k))
    jitter = draw(st.lists(st.floats(-0.3, 0.3), min_size=k, max_size=k))
    angles = draw(st.lists(st.floats(-180, 180), min_size=3, max_size=3))
    return k, np.array(radii), np.array(jitter), angles


@given(star_polygons())
@settings(max_examples=40, deadline=None)
def test_triangulate_concave_polygons_against_shapely(poly):
    shapely = pytest.importorskip("shapely")
    k, radii, jitter, angles = poly
    a = 2 * np.pi * (np.arange(k) + jitter) / k  # star-shaped about the origin: simple
    xy = np.stack([radii * np.cos(a), radii * np.sin(a)], axis=1)
    v = transform(np.c_[xy, np.zeros(k)], [0.5, -1, 2], angles)
    fi, fo = np.arange(k), np.array([0, k])
    tv, tfi, tfo = triangulate(v, fi, fo)
    tri = tv[tfi.reshape(-1, 3)]
    normal = transform(np.array([[0, 0, 1.0]]), rotate_deg_xyz=angles)[0]
    areas = np.einsum("ij,j->i", np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), normal) / 2
    assert len(areas) == k - 2
    assert (areas > -1e-12).all()  # all triangles keep the polygon's orientation
    np.testing.assert_allclose(areas.sum(), shapely.Polygon(xy).area, rtol=1e-9, atol=1e-12)


def test_faces_from_lists_and_validate():
    fi, fo = faces_from_lists([[0, 1, 2], [0, 2, 3, 4]])
    assert fi.tolist() == [0, 1, 2, 0, 2, 3, 4] and fo.tolist() == [0, 3, 7]
    with pytest.raises(
        ValueError, match=r"face 1 must be a list of vertex indices, got \[0, 1.5, 2\]"
    ):
        faces_from_lists([[0, 1, 2], [0, 1.5, 2]])
    v, vfi, vfo = validate_faces(np.zeros((5, 3)), fi, fo)
    assert v.dtype == np.float64 and vfi.dtype == np.int64


def test_kernels_never_modify_inputs():
    v, fi, fo = cube()
    for a in (v, fi, fo):
        a.flags.writeable = False
    for kernel in (catmull_clark, doo_sabin, triangulate, validate_faces):
        kernel(v, fi, fo)
    build_halfedges(fi, fo, 8)
    merge([(v, fi, fo), (v, fi, fo)])


def test_face_normals_and_dihedral_angles():
    v, fi, fo = box(2.0)
    n = face_normals(v, fi, fo)
    np.testing.assert_allclose(
        n, [[0, 0, -1], [0, 0, 1], [0, -1, 0], [0, 1, 0], [-1, 0, 0], [1, 0, 0]]
    )
    he = build_halfedges(fi, fo, 8)
    np.testing.assert_allclose(dihedral_angles(v, he), 90.0)
    gv = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 1], [2, 1, 1]], dtype=float)
    gfi, gfo = flat([[0, 1, 2, 3], [1, 4, 5, 2]])
    angles = dihedral_angles(gv, build_halfedges(gfi, gfo, 6))
    assert sorted(angles.round(9).tolist()) == [0.0] * 6 + [45.0]  # boundary edges count 0
