"""Mesh kernels: half-edges, Catmull-Clark, Doo-Sabin, mesh operations."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mesh_shapes import (
    antiprism,
    cube,
    flat,
    grid,
    pillow,
    prism,
    quad_and_pentagon,
    split_quads,
    tetrahedron,
    torus,
)
from scipy.interpolate import BSpline
from scipy.spatial import cKDTree

from formgraph.kernels.mesh import MeshTopologyError, build_halfedges
from formgraph.kernels.mesh.halfedge import boundary_loops
from formgraph.kernels.mesh.meshops import (
    reverse_faces,
    triangulate,
    validate_faces,
)
from formgraph.kernels.mesh.subdivision import (
    catmull_clark,
    catmull_clark_counts,
    doo_sabin,
    doo_sabin_counts,
    doo_sabin_weights,
)

CLOSED = {
    "cube": cube(),
    "tetrahedron": tetrahedron(),
    "prism5": prism(5),
    "antiprism7": antiprism(7),
    "torus": torus(),
    "pillow": pillow(),  # valence-2 vertices
    "pentagons": quad_and_pentagon(),
}


def signed_volume(v, fi, fo):
    _, tf, _ = triangulate(v, fi, fo)
    t = v[tf.reshape(-1, 3)]
    return np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0


# --------------------------------------------------------------------------------------
# half-edges
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(CLOSED))
def test_halfedge_invariants(name):
    v, fi, fo = CLOSED[name]
    he = build_halfedges(fi, fo, len(v))
    h = np.arange(he.n_halfedges)
    assert (he.twin[he.twin] == h).all() and (he.twin != h).all()
    assert (he.next[he.prev] == h).all() and (he.prev[he.next] == h).all()
    assert (he.origin[he.next] == he.vertex).all()
    assert (he.origin[he.twin] == he.vertex).all()
    assert (he.face[he.next] == he.face).all()
    assert (he.origin[he.vertex_halfedge] == np.arange(len(v))).all()
    assert (he.face[he.face_halfedge] == np.arange(he.n_faces)).all()
    assert (he.edge[he.twin] == he.edge).all()
    assert he.is_closed and he.boundary_loops() == []
    assert he.euler_characteristic == (0 if name == "torus" else 2)
    assert (he.valence == np.bincount(he.origin)).all()


def test_halfedges_agree_with_trimesh_edges():
    trimesh = pytest.importorskip("trimesh")
    v, fi, fo = antiprism(9)
    _, tf, _ = triangulate(v, fi, fo)
    tm = trimesh.Trimesh(v, tf.reshape(-1, 3), process=False)
    he = build_halfedges(tf, np.arange(0, tf.size + 1, 3), len(v))
    assert he.n_edges == len(tm.edges_unique)
    ours = {tuple(e) for e in he.edge_vertices.tolist()}
    assert ours == {tuple(sorted(e)) for e in tm.edges_unique.tolist()}


def test_faces_around_vertex_are_counter_clockwise():
    v, fi, fo = grid(3, 3)
    he = build_halfedges(fi, fo, len(v))
    offsets, faces = he.faces_around_vertex()
    ring = faces[offsets[4] : offsets[5]]
    centroids = np.add.reduceat(v[fi], fo[:-1])[ring] / 4 - v[4]
    angles = np.unwrap(np.arctan2(centroids[:, 1], centroids[:, 0]))
    assert len(ring) == 4 and (np.diff(angles) > 0).all()
    # a corner lies in one face, an edge vertex in two, from the boundary inward
    assert np.diff(offsets).tolist() == [1, 2, 1, 2, 4, 2, 1, 2, 1]
    assert he.valence.tolist() == [2, 3, 2, 3, 4, 3, 2, 3, 2]


def test_boundary_loops_of_an_annulus():
    # 8 x 3 grid closed in u: an annulus with an outer and an inner loop
    a = 2 * np.pi * np.arange(8) / 8
    r = np.array([1.0, 2.0, 3.0])
    v = np.stack(
        np.broadcast_arrays(np.cos(a)[:, None] * r, np.sin(a)[:, None] * r, 0 * r), -1
    ).reshape(-1, 3)
    from formgraph.kernels.mesh import grid_faces

    fi, fo = grid_faces(8, 3, closed_u=True)
    if signed_area_z(v, fi, fo) < 0:
        fi = reverse_faces(fi, fo)
    he = build_halfedges(fi, fo, len(v))
    loops = he.boundary_loops()
    assert sorted(len(loop) for loop in loops) == [8, 8]
    assert he.euler_characteristic == 0
    for loop in loops:
        p = v[loop]
        area = 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
        radius = np.linalg.norm(p[0])
        # the mesh lies on the left: the outer loop runs counter-clockwise, the inner one not
        assert np.sign(area) == (1 if radius > 2 else -1)


def signed_area_z(v, fi, fo):
    _, tf, _ = triangulate(v, fi, fo)
    t = v[tf.reshape(-1, 3)]
    return np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 2].sum() / 2


def test_bowtie_vertex_has_two_fans():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], dtype=float)
    fi, fo = flat([[0, 1, 2], [0, 3, 4]])
    he = build_halfedges(fi, fo, len(v))
    assert he.is_manifold_vertex.tolist() == [False, True, True, True, True]
    assert (he.fans.vertex == 0).sum() == 2
    assert len(he.boundary_loops()) == 2
    assert [loop.tolist() for loop in boundary_loops(fi, fo, len(v))] == [
        loop.tolist() for loop in he.boundary_loops()
    ]


@pytest.mark.parametrize(
    "faces, n, message",
    [
        ([[0, 1, 2], [0, 1, 3]], 4, r"faces 0 and 1 both run edge 0 -> 1 the same way"),
        ([[0, 1, 2], [1, 0, 3], [0, 1, 4]], 5, r"edge \(0, 1\) is shared by 3 faces \[0, 1, 2\]"),
        ([[0, 1, 2], [2, 1, 7]], 4, r"face 1 refers to vertex 7, but the mesh has 4 vertices"),
        ([[0, 1, 2], [2, -1, 3]], 4, r"face 1 refers to vertex -1"),
        ([[0, 1, 2], [2, 3]], 4, r"face 1 has 2 vertices; a face needs at least 3"),
        ([[0, 1, 2, 1]], 3, r"face 0 visits vertex 1 twice"),
        ([[0, 1, 2], [2, 3, 2]], 4, r"face 1 visits vertex 2 twice"),
    ],
)
def test_bad_topology_is_rejected(faces, n, message):
    fi, fo = flat(faces)
    v = np.zeros((n, 3))
    with pytest.raises(MeshTopologyError, match=message):
        build_halfedges(fi, fo, n)
    with pytest.raises(MeshTopologyError, match=message):
        boundary_loops(fi, fo, n)
    for kernel in (catmull_clark, doo_sabin, validate_faces):
        with pytest.raises(ValueError, match=message):
            kernel(v, fi, fo)


def test_bad_arrays_are_rejected():
    with pytest.raises(MeshTopologyError, match="face_offsets must start at 0 and end at"):
        build_halfedges([0, 1, 2], [0, 4], 3)
    with pytest.raises(MeshTopologyError, match="face_indices must hold integers, got float64"):
        build_halfedges(np.array([0.0, 1, 2]), [0, 3], 3)
    with pytest.raises(ValueError, match=r"vertices must be an \(n, 3\) array, got shape \(3, 2\)"):
        catmull_clark(np.zeros((3, 2)), [0, 1, 2], [0, 3])
    with pytest.raises(ValueError, match=r"vertex 1 is not finite"):
        doo_sabin([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]], [0, 1, 2], [0, 3])
    with pytest.raises(ValueError, match=r"levels must be a whole number >= 0, got -1"):
        catmull_clark(*cube(), levels=-1)


# --------------------------------------------------------------------------------------
# Catmull-Clark
# --------------------------------------------------------------------------------------


def test_catmull_clark_cube_closed_form():
    h = 1.5
    v, fi, fo = catmull_clark(*cube(h))
    assert v.shape == (26, 3) and fo.size - 1 == 24 and (np.diff(fo) == 4).all()
    # original corners (same indices) move to 5/9 of the half-size
    np.testing.assert_allclose(np.abs(v[:8]), 5 / 9 * h, rtol=1e-15)
    # edge points: two coordinates at 3/4, one at 0; face points: the face centres
    ep = np.sort(np.abs(v[8:20]), axis=1)
    np.testing.assert_allclose(ep, np.tile([0, 0.75 * h, 0.75 * h], (12, 1)), atol=1e-15)
    fp = np.sort(np.abs(v[20:]), axis=1)
    np.testing.assert_allclose(fp, np.tile([0, 0, h], (6, 1)), atol=1e-15)
    assert signed_volume(v, fi, fo) > 0  # still outward


@pytest.mark.parametrize("name", sorted(CLOSED))
def test_catmull_clark_keeps_euler_characteristic_and_counts(name):
    v, fi, fo = CLOSED[name]
    he = build_halfedges(fi, fo, len(v))
    counts = catmull_clark_counts(len(v), he.n_edges, he.n_faces, he.n_halfedges, 3)
    for level in (1, 2, 3):
        sv, sfi, sfo = catmull_clark(v, fi, fo, level)
        she = build_halfedges(sfi, sfo, len(sv))
        assert she.euler_characteristic == he.euler_characteristic
        assert (len(sv), she.n_edges, she.n_faces) == counts[level - 1]
        assert she.is_closed and (np.diff(sfo) == 4).all()


@pytest.mark.parametrize("mesh", [tetrahedron(), prism(6), antiprism(5)])
def test_triangles_and_ngons_become_quads(mesh):
    v, fi, fo = mesh
    sv, sfi, sfo = catmull_clark(v, fi, fo)
    assert sfo.size - 1 == fi.size  # F' = sum of face sizes
    assert (np.diff(sfo) == 4).all()
    assert len(sv) == len(v) + build_halfedges(fi, fo, len(v)).n_edges + fo.size - 1


def test_open_grid_keeps_corners_and_straight_sides():
    rng = np.random.default_rng(1)
    z = rng.normal(size=(5, 4))
    z[[0, -1], :] = 0.0
    z[:, [0, -1]] = 0.0
    v, fi, fo = grid(5, 4, z)
    sv, sfi, sfo = catmull_clark(v, fi, fo, 3)
    np.testing.assert_array_equal(sv[[0, 3, 16, 19]], v[[0, 3, 16, 19]])  # corners stay
    he = build_halfedges(sfi, sfo, len(sv))
    loop = sv[he.boundary_loops()[0]]
    on_side = np.isclose(loop[:, 0], 0) | np.isclose(loop[:, 0], 4)
    on_side |= np.isclose(loop[:, 1], 0) | np.isclose(loop[:, 1], 3)
    assert on_side.all() and np.allclose(loop[:, 2], 0)
    # the sides stay evenly refined: 4 levels of midpoints along x of the y = 0 side
    bottom = np.sort(loop[np.isclose(loop[:, 1], 0), 0])
    np.testing.assert_allclose(bottom, np.arange(0, 4.0001, 0.125), atol=1e-12)
    assert len(he.boundary_loops()) == 1 and he.euler_characteristic == 1


def test_open_boundary_follows_cubic_bspline_curve_rule():
    rng = np.random.default_rng(2)
    v, fi, fo = grid(4, 3, rng.normal(size=(4, 3)))
    sv, _, _ = catmull_clark(v, fi, fo)
    he = build_halfedges(fi, fo, len(v))
    loop = he.boundary_loops()[0]
    # boundary vertex 3 (i=1, j=0): neighbours 0 and 6 along the boundary, corner 0 fixed
    np.testing.assert_allclose(sv[3], (v[0] + 6 * v[3] + v[6]) / 8)
    np.testing.assert_allclose(sv[0], v[0])
    assert 3 in loop and 0 in loop


def grid_bspline(z: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Uniform bicubic B-spline with control net (i, j, z[i, j]), evaluated with scipy."""
    nu, nv = z.shape
    tu, tv = np.arange(-2.0, nu + 2), np.arange(-2.0, nv + 2)
    bu = BSpline.design_matrix(x, tu, 3).toarray()
    bv = BSpline.design_matrix(y, tv, 3).toarray()
    return np.einsum("pi,ij,pj->p", bu, z, bv)


def test_limit_is_the_bicubic_bspline_surface():
    """Catmull-Clark on a regular net is uniform bicubic B-spline refinement (Lane-Riesenfeld):
    x, y stay on the dyadic lattice, the limit stencil (16 v + 4 sum e + sum d) / 36 of every
    refined vertex lies exactly on the surface, and the net converges to it as O(4^-level)."""
    rng = np.random.default_rng(3)
    nu, nv = 7, 6
    z = rng.normal(size=(nu, nv))
    v, fi, fo = grid(nu, nv, z)
    errors = []
    for level in (1, 2, 3, 4):
        sv, sfi, sfo = catmull_clark(v, fi, fo, level)
        step = 0.5**level
        np.testing.assert_allclose(sv[:, :2] / step, np.round(sv[:, :2] / step), atol=1e-9)
        inner = np.flatnonzero(
            (sv[:, 0] >= 1 - 1e-9)
            & (sv[:, 0] <= nu - 2 + 1e-9)
            & (sv[:, 1] >= 1 - 1e-9)
            & (sv[:, 1] <= nv - 2 + 1e-9)
        )
        surface = grid_bspline(z, sv[inner, 0], sv[inner, 1])
        # limit stencil from the quads: sum over incident quads of their vertex sums is
        # 4 v + 2 sum(edge neighbours) + sum(diagonal neighbours)
        quads = sfi.reshape(-1, 4)
        n = len(sv)
        qsum = np.zeros(n)
        np.add.at(qsum, quads, sv[quads, 2].sum(axis=1, keepdims=True).repeat(4, axis=1))
        edges = np.unique(
            np.sort(np.stack([quads, np.roll(quads, -1, 1)], -1), -1).reshape(-1, 2), axis=0
        )
        esum = np.zeros(n)
        np.add.at(esum, edges[:, 0], sv[edges[:, 1], 2])
        np.add.at(esum, edges[:, 1], sv[edges[:, 0], 2])
        limit = (qsum + 12 * sv[:, 2] + 2 * esum) / 36
        np.testing.assert_allclose(limit[inner], surface, atol=1e-12)
        errors.append(np.abs(sv[inner, 2] - surface).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert errors[-1] < 0.02 and (ratios > 3.5).all() and (ratios < 4.5).all()


def test_creases_keep_a_cube_a_cube():
    v, fi, fo = cube()
    he = build_halfedges(fi, fo, 8)
    sv, sfi, sfo = catmull_clark(v, fi, fo, 3, creases=he.edge_vertices)
    # every crease edge stays straight and every face flat: all points on the cube's surface
    assert np.allclose(np.abs(sv).max(axis=1), 1.0)
    np.testing.assert_array_equal(sv[:8], v)  # three creases meet: corners
    # a crease loop round the bottom face: its corners follow the curve rule (a + 6v + b) / 8
    loop = np.array([[0, 1], [1, 3], [3, 2], [2, 0]])
    cv, _, _ = catmull_clark(v, fi, fo, 1, creases=loop)
    np.testing.assert_allclose(cv[0], [-0.75, -0.75, -1.0], atol=1e-15)
    np.testing.assert_allclose(cv[:4, 2], -1.0, atol=1e-15)


def test_semi_sharp_creases_blend_to_smooth():
    v, fi, fo = cube()
    he = build_halfedges(fi, fo, 8)
    smooth = catmull_clark(v, fi, fo, 2)[0]
    sharp = catmull_clark(v, fi, fo, 2, creases=he.edge_vertices)[0]
    one = catmull_clark(v, fi, fo, 2, creases=he.edge_vertices, sharpness=1.0)[0]
    zero = catmull_clark(v, fi, fo, 2, creases=he.edge_vertices, sharpness=0.0)[0]
    half = catmull_clark(v, fi, fo, 1, creases=he.edge_vertices, sharpness=0.5)[0]
    np.testing.assert_array_equal(zero, smooth)
    assert not np.allclose(one, sharp) and not np.allclose(one, smooth)
    # sharpness 1: sharp on the first level, smooth on the second
    first = catmull_clark(v, fi, fo, 1, creases=he.edge_vertices)
    again = catmull_clark(*first, 1)[0]  # numbers its edge points in another order
    np.testing.assert_allclose(one[:26], again[:26], atol=1e-15)
    np.testing.assert_allclose(np.unique(one.round(12), axis=0), np.unique(again.round(12), axis=0))
    lo, hi = (
        catmull_clark(v, fi, fo, 1)[0],
        catmull_clark(v, fi, fo, 1, creases=he.edge_vertices)[0],
    )
    np.testing.assert_allclose(half, 0.5 * (lo + hi), atol=1e-15)


def test_crease_meeting_the_boundary_pins_it():
    rng = np.random.default_rng(7)
    v, fi, fo = grid(4, 3, rng.normal(size=(4, 3)))
    # edge 3-4 runs from boundary vertex 3 (i=1, j=0) inward: three sharp edges meet at 3
    for sharpness in (None, 0.5, 2.0):
        sv, _, _ = catmull_clark(v, fi, fo, 1, creases=[[3, 4]], sharpness=sharpness)
        np.testing.assert_array_equal(sv[3], v[3])
        assert np.isfinite(sv).all()


def test_crease_must_be_an_edge():
    with pytest.raises(ValueError, match=r"crease \(0, 3\) is not an edge of the mesh"):
        catmull_clark(*cube(), creases=[[0, 1], [0, 3]])


def _reference(levels, v, fi, fo):
    pytest.importorskip("pyOpenSubdiv")
    from pyOpenSubdiv.pysubdivision import pysubdivide

    faces = [fi[fo[f] : fo[f + 1]].tolist() for f in range(fo.size - 1)]
    r = pysubdivide(levels, v.tolist(), faces, fi.tolist(), np.diff(fo).tolist())
    return np.array(r["vertices"], dtype=np.float64), np.array(r["faces"], dtype=np.int64)


def _canonical(quads: np.ndarray) -> set[tuple[int, ...]]:
    start = quads.argmin(axis=1)
    rolled = quads[np.arange(len(quads))[:, None], (start[:, None] + np.arange(4)) % 4]
    return set(map(tuple, rolled.tolist()))


@pytest.mark.parametrize("name", sorted(CLOSED))
@pytest.mark.parametrize("levels", [1, 2])
def test_catmull_clark_matches_opensubdiv(name, levels):
    v, fi, fo = CLOSED[name]
    v = v + np.random.default_rng(4).normal(scale=0.05, size=v.shape)  # no symmetric ties
    ov, of = _reference(levels, v, fi, fo)
    sv, sfi, sfo = catmull_clark(v, fi, fo, levels)
    assert ov.shape == sv.shape and len(of) == sfo.size - 1
    scale = np.abs(sv).max()
    if name in ("pillow", "pentagons"):
        # both faces share every vertex, so their face points coincide: compare positions
        a, b = np.unique(ov.round(5), axis=0), np.unique(sv.round(5), axis=0)
        assert a.shape == b.shape
        np.testing.assert_allclose(a, b, atol=4e-7 * scale)
        return
    dist, match = cKDTree(sv).query(ov)
    assert dist.max() < 4e-7 * scale  # float32 positions
    assert np.unique(match).size == len(sv)
    assert _canonical(match[of]) == _canonical(sfi.reshape(-1, 4))


# --------------------------------------------------------------------------------------
# Doo-Sabin
# --------------------------------------------------------------------------------------


def test_doo_sabin_weights():
    for k in range(3, 9):
        w = doo_sabin_weights(k)
        np.testing.assert_allclose(w.sum(axis=1), 1.0)
    np.testing.assert_allclose(doo_sabin_weights(4)[0], [9 / 16, 3 / 16, 1 / 16, 3 / 16])
    np.testing.assert_allclose(doo_sabin_weights(3)[0], [2 / 3, 1 / 6, 1 / 6])


def test_doo_sabin_cube():
    v, fi, fo = doo_sabin(*cube())
    sizes = np.diff(fo)
    assert len(v) == 24 and sizes.size == 26
    assert (sizes == 4).sum() == 18 and (sizes == 3).sum() == 8
    # corner points of a face of the [-1, 1] cube sit at (+-1/2, +-1/2) on that face
    np.testing.assert_allclose(np.sort(np.abs(v), axis=1), np.tile([0.5, 0.5, 1.0], (24, 1)))
    he = build_halfedges(fi, fo, len(v))
    assert he.is_closed and he.euler_characteristic == 2
    assert signed_volume(v, fi, fo) > 0
    v2, fi2, fo2 = doo_sabin(*cube(), levels=2)
    he2 = build_halfedges(fi2, fo2, len(v2))
    assert (len(v2), he2.n_edges, he2.n_faces) == (96, 192, 98)
    assert np.bincount(np.diff(fo2)).tolist() == [0, 0, 0, 8, 90]


@pytest.mark.parametrize("name", sorted(CLOSED))
def test_doo_sabin_counts_and_euler(name):
    v, fi, fo = CLOSED[name]
    he = build_halfedges(fi, fo, len(v))
    counts = doo_sabin_counts(he, 3)
    for level in (1, 2, 3):
        sv, sfi, sfo = doo_sabin(v, fi, fo, level)
        she = build_halfedges(sfi, sfo, len(sv))
        assert (len(sv), she.n_edges, she.n_faces) == counts[level - 1]
        assert she.euler_characteristic == he.euler_characteristic and she.is_closed
    if abs(signed_volume(v, fi, fo)) > 1e-9:  # still facing the same way
        assert signed_volume(sv, sfi, sfo) * signed_volume(v, fi, fo) > 0


def test_doo_sabin_pillow_becomes_a_box():
    # valence-2 vertices get no V-face: two quads glued all round -> 2 F-faces + 4 E-faces
    v, fi, fo = doo_sabin(*pillow())
    he = build_halfedges(fi, fo, len(v))
    assert (len(v), he.n_edges, he.n_faces) == (8, 12, 6) and he.is_closed
    assert (he.valence == 3).all()


def test_doo_sabin_open_grid_boundary_is_chaikin():
    rng = np.random.default_rng(5)
    v, fi, fo = grid(4, 3, rng.normal(size=(4, 3)))
    he = build_halfedges(fi, fo, len(v))
    sv, sfi, sfo = doo_sabin(v, fi, fo)
    she = build_halfedges(sfi, sfo, len(sv))
    assert (len(sv), she.n_edges, she.n_faces) == doo_sabin_counts(he, 1)[0]
    assert she.euler_characteristic == 1 and len(she.boundary_loops()) == 1
    # the new boundary polygon: Chaikin points of every old boundary edge, corners kept
    old = v[he.boundary_loops()[0]]
    nxt = np.roll(old, -1, axis=0)
    expect = np.stack([0.75 * old + 0.25 * nxt, 0.25 * old + 0.75 * nxt], 1).reshape(-1, 3)
    got = sv[she.boundary_loops()[0]]
    corners = [tuple(p) for p in v[[0, 2, 9, 11]].tolist()]
    got = np.array([p for p in got.tolist() if tuple(p) not in corners])
    assert len(got) == len(expect)
    shift = np.argmin(np.linalg.norm(got - expect[0], axis=1))
    np.testing.assert_allclose(np.roll(got, -shift, axis=0), expect, atol=1e-14)
    np.testing.assert_array_equal(sv[-4:], v[[0, 2, 9, 11]])


# --------------------------------------------------------------------------------------
# random meshes
# --------------------------------------------------------------------------------------


@st.composite
def random_meshes(draw):
    """Quad grids (open, a cylinder or a torus), some quads split into triangles, some
    faces removed (which may leave non-manifold 'bowtie' vertices), vertices jittered."""
    nu = draw(st.integers(3, 6))
    nv = draw(st.integers(3, 6))
    closed_u, closed_v = draw(st.booleans()), draw(st.booleans())
    from formgraph.kernels.mesh import grid_faces

    fi, fo = grid_faces(nu, nv, closed_u, closed_v)
    n_faces = fo.size - 1
    split = np.array(draw(st.lists(st.booleans(), min_size=n_faces, max_size=n_faces)))
    fi, fo = split_quads(fi, fo, split)
    n_faces = fo.size - 1
    keep = np.array(draw(st.lists(st.booleans(), min_size=n_faces, max_size=n_faces)))
    if draw(st.booleans()):
        keep[:] = True
    keep[0] = True
    faces = [fi[fo[f] : fo[f + 1]] for f in np.flatnonzero(keep)]
    used = np.unique(np.concatenate(faces))
    remap = np.full(nu * nv, -1)
    remap[used] = np.arange(used.size)
    fi, fo = flat([remap[f] for f in faces])
    seed = draw(st.integers(0, 2**32 - 1))
    v = np.random.default_rng(seed).normal(size=(used.size, 3))
    return v, fi, fo


@settings(max_examples=40, deadline=None)
@given(random_meshes())
def test_catmull_clark_random_meshes(mesh):
    v, fi, fo = mesh
    he = build_halfedges(fi, fo, len(v))
    sv, sfi, sfo = catmull_clark(v, fi, fo, 2)
    she = build_halfedges(sfi, sfo, len(sv))  # manifold and consistently oriented
    counts = catmull_clark_counts(len(v), he.n_edges, he.n_faces, he.n_halfedges, 2)
    assert (len(sv), she.n_edges, she.n_faces) == counts[-1]
    assert she.n_faces == 4 * fi.size  # F' = sum of face sizes, twice
    assert she.euler_characteristic == he.euler_characteristic
    assert len(she.boundary_loops()) == len(he.boundary_loops())
    assert np.isfinite(sv).all()


def _reference_catmull_clark(v: np.ndarray, faces: list[list[int]]):
    """One level by the rules as written, element by element (the test's own reading of
    Catmull & Clark 1978 with the B-spline boundary rules), points numbered as the kernel
    numbers them: vertices, edges by sorted end pair, faces."""
    edges: dict[tuple[int, int], list[int]] = {}
    for f, face in enumerate(faces):
        for a, b in zip(face, face[1:] + face[:1], strict=True):
            edges.setdefault((min(a, b), max(a, b)), []).append(f)
    keys = sorted(edges)
    fp = [v[face].mean(axis=0) for face in faces]
    ep = []
    for a, b in keys:
        fs = edges[(a, b)]
        ep.append((v[a] + v[b]) / 2 if len(fs) == 1 else (v[a] + v[b] + fp[fs[0]] + fp[fs[1]]) / 4)
    vp = []
    for i in range(len(v)):
        inc = [k for k in keys if i in k]
        fs = [f for f, face in enumerate(faces) if i in face]
        rim = [k for k in inc if len(edges[k]) == 1]
        if rim and len(rim) == 2 and len(fs) > 1:  # boundary: the cubic B-spline curve
            a, b = (k[0] if k[1] == i else k[1] for k in rim)
            vp.append(v[a] / 8 + 6 * v[i] / 8 + v[b] / 8)
        elif rim or not fs:  # a corner, a vertex of 4+ boundary edges, an unused one
            vp.append(v[i])
        else:
            n = len(inc)
            q = np.mean([fp[f] for f in fs], axis=0)
            r = np.mean([(v[a] + v[b]) / 2 for a, b in inc], axis=0)
            vp.append((q + 2 * r + (n - 3) * v[i]) / n)
    eid = {k: len(v) + j for j, k in enumerate(keys)}
    quads = []
    for f, face in enumerate(faces):
        for j, c in enumerate(face):
            after, before = face[(j + 1) % len(face)], face[j - 1]
            e1, e0 = eid[(min(c, after), max(c, after))], eid[(min(c, before), max(c, before))]
            quads.append([c, e1, len(v) + len(keys) + f, e0])
    return np.array(vp + ep + fp), quads


def _faces(fi, fo):
    return [fi[fo[f] : fo[f + 1]].tolist() for f in range(fo.size - 1)]


OPEN_AND_MIXED = {
    "grid": grid(5, 4),  # boundary vertices, corners (valence 2)
    "grid_triangles": (grid(4, 4)[0], *split_quads(*grid(4, 4)[1:], np.arange(9) % 2 == 0)),
    "prism5": prism(5),  # valence 3, pentagons
    "antiprism5": antiprism(5),  # triangles and pentagons
    "tetrahedron": tetrahedron(),
    "pentagons": quad_and_pentagon(),  # valence 2
}


@pytest.mark.parametrize("name", sorted(OPEN_AND_MIXED))
def test_catmull_clark_follows_the_rules_element_by_element(name):
    v, fi, fo = OPEN_AND_MIXED[name]
    rng = np.random.default_rng(11)
    v = v + rng.normal(scale=0.05, size=v.shape)
    # two attribute columns ride along, by the same rules
    va = np.column_stack([v, rng.normal(size=(len(v), 2))])
    ref, quads = _reference_catmull_clark(va, _faces(fi, fo))
    sv, sfi, sfo = catmull_clark(va, fi, fo, 1)
    np.testing.assert_allclose(sv, ref, rtol=0, atol=1e-13)
    assert sfi.reshape(-1, 4).tolist() == quads
    if name == "pentagons":
        return  # its two faces share every vertex: level-2 points coincide, no matching
    # the second level on all quads (closed form connectivity): the same points, by place
    ref2, quads2 = _reference_catmull_clark(ref, quads)
    sv2, sfi2, sfo2 = catmull_clark(va, fi, fo, 2)
    dist, match = cKDTree(sv2).query(ref2)
    assert dist.max() < 1e-12 and np.unique(match).size == len(sv2)
    np.testing.assert_allclose(sv2[match], ref2, rtol=0, atol=1e-13)
    assert _canonical(match[np.array(quads2)]) == _canonical(sfi2.reshape(-1, 4))


@settings(max_examples=25, deadline=None)
@given(random_meshes())
def test_catmull_clark_random_meshes_follow_the_rules(mesh):
    """Open grids with holes and faces that touch at a corner only (non-manifold
    vertices): two levels against the element-by-element rules."""
    v, fi, fo = mesh
    ref, quads = _reference_catmull_clark(v, _faces(fi, fo))
    ref2, quads2 = _reference_catmull_clark(ref, quads)
    sv2, sfi2, _ = catmull_clark(v, fi, fo, 2)
    dist, match = cKDTree(sv2).query(ref2)
    assert dist.max() < 1e-9
    assert _canonical(match[np.array(quads2)]) == _canonical(sfi2.reshape(-1, 4))


@settings(max_examples=40, deadline=None)
@given(random_meshes())
def test_doo_sabin_random_meshes(mesh):
    v, fi, fo = mesh
    he = build_halfedges(fi, fo, len(v))
    sv, sfi, sfo = doo_sabin(v, fi, fo, 2)
    she = build_halfedges(sfi, sfo, len(sv))
    counts = doo_sabin_counts(he, 2)
    assert (len(sv), she.n_edges, she.n_faces) == counts[-1]
    # sheets that touched at a vertex come apart: each fan counts as a vertex
    assert she.euler_characteristic == he.fans.vertex.size - he.n_edges + he.n_faces
    assert she.is_manifold_vertex.all()
    assert np.isfinite(sv).all()
    # every new point is a convex combination of old ones: inside the bounding box
    assert (sv >= v.min(axis=0) - 1e-12).all() and (sv <= v.max(axis=0) + 1e-12).all()


@settings(max_examples=40, deadline=None)
@given(random_meshes())
def test_halfedges_random_meshes(mesh):
    v, fi, fo = mesh
    he = build_halfedges(fi, fo, len(v))
    h = np.arange(he.n_halfedges)
    inner = he.twin >= 0
    assert (he.twin[he.twin[inner]] == h[inner]).all()
    assert (he.origin[he.twin[inner]] == he.vertex[inner]).all()
    # fans cover each outgoing half-edge once, and step counter-clockwise by twin(prev)
    assert np.sort(he.fans.halfedges).tolist() == h.tolist()
    for i in range(he.fans.vertex.size):
        fan = he.fans.halfedges[he.fans.offsets[i] : he.fans.offsets[i + 1]]
        assert (he.twin[he.prev[fan[:-1]]] == fan[1:]).all()
        assert (he.origin[fan] == he.fans.vertex[i]).all()
    loops = he.boundary_loops()
    assert sum(len(loop) for loop in loops) == he.boundary_halfedges.size
    edges = {tuple(e) for e in he.boundary_edges.tolist()}
    for loop in loops:
        assert all((a, b) in edges for a, b in zip(loop, np.roll(loop, -1), strict=True))


@settings(max_examples=60, deadline=None)
@given(random_meshes())
def test_boundary_loops_from_one_sort_match_the_half_edges(mesh):
    # the same loops, starting at the same vertices, in the same order (pinched 'bowtie'
    # vertices take the fans' way; all others link a boundary edge to the one leaving its
    # end)
    v, fi, fo = mesh
    expect = build_halfedges(fi, fo, len(v)).boundary_loops()
    got = boundary_loops(fi, fo, len(v))
    assert [loop.tolist() for loop in got] == [loop.tolist() for loop in expect]
