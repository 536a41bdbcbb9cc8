"""Solid kernels: primitives, weld, orient, cap, solidify, booleans and measures, checked
against trimesh, scipy, shapely, manifold3d's own status and closed forms."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from mesh_shapes import cube, flat, grid, prism
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from formgraph.kernels.mesh import boolean as kb
from formgraph.kernels.mesh import cells as kc
from formgraph.kernels.mesh import measure as km
from formgraph.kernels.mesh import primitives as kp
from formgraph.kernels.mesh import repair as kr
from formgraph.kernels.mesh import solidify as ks
from formgraph.kernels.mesh.meshops import reverse_faces, triangulate


def tri(mesh):
    """A trimesh of our arrays (triangulated, not processed: it sees the mesh as it is)."""
    v, fi, fo = triangulate(*mesh)
    return trimesh.Trimesh(v, fi.reshape(-1, 3), process=False)


def volume(mesh) -> float:
    return float(km.signed_volume(*mesh).sum())


def area(mesh) -> float:
    return float(km.face_areas(*mesh).sum())


def solid(mesh) -> bool:
    t = tri(mesh)
    return t.is_watertight and t.is_winding_consistent and t.volume > 0


def sinc(x: float) -> float:
    return np.sin(x) / x


# ------------------------------------------------------------------------------ primitives


@pytest.mark.parametrize("n", [3, 8, 64, 257])
def test_cylinder_is_the_inscribed_prism(n):
    r, h = 1.3, 2.1
    m = kp.cylinder(r, h, n)
    assert solid(m) and km.solid_report(m[1], m[2], len(m[0])).is_solid
    exact = n / 2 * r * r * np.sin(2 * np.pi / n) * h
    assert volume(m) == pytest.approx(exact, rel=1e-12)
    assert tri(m).volume == pytest.approx(exact, rel=1e-12)
    side = n * 2 * r * np.sin(np.pi / n) * h
    assert area(m) == pytest.approx(side + 2 * exact / h, rel=1e-12)
    # convergence: 1 - sinc(x) <= x^2 / 6 bounds the relative error of the inscribed prism
    smooth = np.pi * r * r * h
    assert 0 < (smooth - volume(m)) / smooth <= (2 * np.pi / n) ** 2 / 6


def _uv_sphere_volume(r: float, n: int) -> float:
    """Sum of the prismatoid bands between the rings (aligned regular n-gons)."""
    m = max(2, n // 2)
    theta = np.pi * np.arange(m + 1) / m
    a, z = r * np.sin(theta), r * np.cos(theta)
    return float(
        np.sum((z[:-1] - z[1:]) * (a[:-1] ** 2 + a[:-1] * a[1:] + a[1:] ** 2) / 3)
        * n
        / 2
        * np.sin(2 * np.pi / n)
    )


@pytest.mark.parametrize("n", [3, 4, 16, 64, 200])
def test_sphere_volume_and_area(n):
    r = 1.7
    m = kp.sphere(r, n, center=(1, -2, 3))
    assert solid(m)
    assert volume(m) == pytest.approx(_uv_sphere_volume(r, n), rel=1e-12)
    # every face's plane is at least r cos(d) from the centre, d = dtheta + dphi the angular
    # size of a face; the convex mesh lies between that ball and the sphere, so
    # V_ball cos^3(d) <= V <= V_ball and A_sphere cos^2(d) <= A <= A_sphere
    # (no bound from it once d passes 90 degrees)
    d = np.pi / max(2, n // 2) + 2 * np.pi / n
    c = max(0.0, np.cos(d))
    ball, sphere = 4 / 3 * np.pi * r**3, 4 * np.pi * r**2
    assert ball * c**3 <= volume(m) < ball
    assert sphere * c**2 <= area(m) < sphere
    assert tri(m).area == pytest.approx(area(m), rel=1e-12)


@pytest.mark.parametrize("nu,nv", [(3, 3), (16, 8), (64, 32), (128, 100)])
def test_torus_volume_closed_form(nu, nv):
    big, small = 3.0, 0.8
    m = kp.torus(big, small, nu, nv)
    assert solid(m)
    # each sector is the inscribed tube polygon swept between two meridian planes:
    # sin(2 pi / nu) * R * A_polygon (Pappus on the sector)
    polygon = nv / 2 * small**2 * np.sin(2 * np.pi / nv)
    assert volume(m) == pytest.approx(nu * np.sin(2 * np.pi / nu) * big * polygon, rel=1e-12)
    smooth = 2 * np.pi**2 * big * small**2
    bound = ((2 * np.pi / nu) ** 2 + (2 * np.pi / nv) ** 2) / 6  # 1 - ab <= (1-a) + (1-b)
    assert 1 - sinc(2 * np.pi / nu) * sinc(2 * np.pi / nv) == pytest.approx(
        (smooth - volume(m)) / smooth, rel=1e-9
    )
    assert 0 < (smooth - volume(m)) / smooth <= bound


@pytest.mark.parametrize(
    "mesh,chi",
    [
        (kp.sphere(1, 12), 2),
        (kp.cylinder(1, 1, 12), 2),
        (kp.torus(2, 1, 12, 6), 0),
        (kp.plane((1, 1), (3, 4)), 1),
        (kp.cylinder(1, 1, 12, caps=False), 0),
    ],
)
def test_euler_characteristic(mesh, chi):
    v, fi, fo = mesh
    t = km.edge_table(fi, fo, len(v))
    assert len(v) - t.n_edges + (fo.size - 1) == chi == tri(mesh).euler_number


def test_primitives_refuse_bad_sizes():
    with pytest.raises(ValueError, match="radius must be > 0"):
        kp.cylinder(0, 1)
    with pytest.raises(ValueError, match="segments must be a whole number >= 3"):
        kp.sphere(1, 2)
    with pytest.raises(ValueError, match=r"minor \(2\) must be smaller than major \(1\)"):
        kp.torus(1, 2)


# ------------------------------------------------------------------------------ union-find


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 60), st.lists(st.tuples(st.integers(0, 59), st.integers(0, 59))))
def test_union_find_matches_scipy(n, edges):
    edges = [(a % n, b % n) for a, b in edges]
    a = np.array([e[0] for e in edges], dtype=np.int64)
    b = np.array([e[1] for e in edges], dtype=np.int64)
    root, _ = km.union_find(n, a, b)
    graph = coo_matrix((np.ones(a.size), (a, b)), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    # the same partition, and each root is the smallest member of its component
    assert len(set(zip(root.tolist(), labels.tolist(), strict=True))) == labels.max() + 1
    for r in np.unique(root):
        assert r == np.flatnonzero(root == r).min()


# ---------------------------------------------------------------------------------- weld


def soup(mesh):
    """Every triangle with its own three vertices (as an STL file holds them)."""
    v, fi, fo = triangulate(*mesh)
    return v[fi], np.arange(fi.size), fo


def test_weld_a_triangle_soup_back_into_a_solid():
    sphere = kp.sphere(1, 24)
    welded = kr.weld(*soup(sphere))
    assert len(welded[0]) == len(sphere[0])
    assert solid(welded)
    assert volume(welded) == pytest.approx(volume(sphere), rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31), st.floats(0.01, 0.3))
def test_weld_groups_match_a_kd_tree(seed, tol):
    rng = np.random.default_rng(seed)
    pts = rng.random((80, 3))
    pts = np.concatenate([pts, pts[:20] + rng.normal(0, tol / 4, (20, 3))])  # near copies
    # the weld's vertex groups against kd-tree pairs and scipy's components
    i, j = kc.close_pairs(pts, tol)
    root, _ = km.union_find(len(pts), i, j)
    pairs = np.array(sorted(cKDTree(pts).query_pairs(tol)), dtype=np.int64).reshape(-1, 2)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(pts),) * 2)
    _, labels = connected_components(graph, directed=False)
    assert len(set(zip(root.tolist(), labels.tolist(), strict=True))) == labels.max() + 1


def test_weld_merges_within_tolerance_only():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1e-4, 0, 0], [1, 3e-4, 0], [0, 1, 0.0]])
    fi, fo = flat([[0, 1, 2], [3, 4, 5]])
    out_v, out_fi, out_fo = kr.weld(v, fi, fo, 2e-4)
    # 3 merges into 0 and 5 into 2 (exact), 4 stays (3e-4 away from 1)
    assert len(out_v) == 4 and out_fo.tolist() == [0, 3, 6]
    np.testing.assert_array_equal(out_v[out_fi[:3]], v[[0, 1, 2]])
    # a face that collapses is dropped, the others keep their order
    _, fi2, fo2 = kr.weld(v, fi, fo, 1.0)
    assert fo2.tolist() == [0]


def test_weld_is_transitive_and_keeps_first_positions():
    v = np.array([[0, 0, 0], [0.6, 0, 0], [1.2, 0, 0], [0, 5, 0], [0, 0, 5.0]])
    fi, fo = flat([[0, 3, 4], [1, 4, 3], [2, 3, 4]])
    out_v, out_fi, out_fo = kr.weld(v, fi, fo, 0.7)
    assert len(out_v) == 3 and out_fo.tolist() == [0, 3, 6, 9]
    np.testing.assert_array_equal(out_v[0], [0, 0, 0])


def test_weld_default_tolerance_is_relative_to_the_box():
    assert kr.weld_tolerance(np.array([[0, 0, 0], [3, 4, 0.0]])) == pytest.approx(5e-6)
    with pytest.raises(ValueError, match="tolerance must be a finite number >= 0"):
        kr.weld(*cube(), -1.0)


# -------------------------------------------------------------------------------- orient


def mix(mesh, seed):
    v, fi, fo = mesh
    flips = np.random.default_rng(seed).random(fo.size - 1) < 0.5
    return v, np.where(np.repeat(flips, np.diff(fo)), reverse_faces(fi, fo), fi), fo


def test_orient_turns_an_inward_mesh_outward():
    v, fi, fo = kp.sphere(1, 16)
    inward = (v, reverse_faces(fi, fo), fo)
    assert volume(inward) < 0
    out, conflicts = kr.orient(*inward)
    assert conflicts == 0 and volume((v, out, fo)) > 0
    np.testing.assert_array_equal(out, fi)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from(["torus", "sphere", "cylinder", "prism"]))
def test_orient_a_randomly_flipped_mesh(seed, which):
    mesh = {
        "torus": kp.torus(2, 0.7, 12, 7),
        "sphere": kp.sphere(1, 10),
        "cylinder": kp.cylinder(1, 2, 9),
        "prism": prism(5),
    }[which]
    v, fi, fo = mix(mesh, seed)
    out, conflicts = kr.orient(v, fi, fo)
    t = tri((v, out, fo))
    assert conflicts == 0 and t.is_winding_consistent and t.volume > 0
    assert volume((v, out, fo)) == pytest.approx(volume(mesh), rel=1e-12)


def test_orient_each_closed_part_outward():
    a = kp.sphere(1, 8)
    b = kp.cylinder(1, 1, 7, center=(5, 0, 0))
    v, fi, fo = kr.compact(*_merge(a, (b[0], reverse_faces(b[1], b[2]), b[2])))
    out, _ = kr.orient(v, fi, fo)
    vols = km.signed_volume(v, out, fo)
    assert vols[: a[2].size - 1].sum() > 0 and vols[a[2].size - 1 :].sum() > 0


def test_orient_an_open_flat_sheet_keeps_its_majority_side():
    v, fi, fo = grid(5, 4)
    flipped = np.zeros(fo.size - 1, dtype=bool)
    flipped[:3] = True
    mixed = np.where(np.repeat(flipped, np.diff(fo)), reverse_faces(fi, fo), fi)
    out, _ = kr.orient(v, mixed, fo)
    np.testing.assert_array_equal(out, fi)


def test_orient_counts_what_a_moebius_strip_cannot_satisfy():
    n = 24
    t = 2 * np.pi * np.arange(n) / n
    half = t / 2
    centre = np.stack([np.cos(t), np.sin(t), np.zeros(n)], 1)
    width = np.stack([np.cos(half) * np.cos(t), np.cos(half) * np.sin(t), np.sin(half)], 1)
    v = np.concatenate([centre - 0.2 * width, centre + 0.2 * width])
    faces = [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n - 1)]
    faces.append([n - 1, n, 0, 2 * n - 1])  # the half twist: the sides swap
    fi, fo = flat(faces)
    _, conflicts = kr.orient(v, fi, fo)
    assert conflicts == 1


def _merge(*meshes):
    from formgraph.kernels.mesh.meshops import merge

    return merge(list(meshes))


# ----------------------------------------------------------------------------------- cap


def test_cap_closes_an_open_tube():
    n = 40
    tube = kp.cylinder(1.5, 2, n, caps=False)
    capped = kr.cap(*tube)
    assert solid(capped)
    assert volume(capped) == pytest.approx(volume(kp.cylinder(1.5, 2, n)), rel=1e-12)
    assert len(capped[0]) == len(tube[0])  # planar loops: no new vertex


def _open_prism(outline: np.ndarray):
    """Walls and a bottom over a planar outline (counter-clockwise), open at the top."""
    k = len(outline)
    ring = np.column_stack([outline, np.zeros(k)])
    v = np.concatenate([ring, ring + [0, 0, 1]])
    walls = [[i, (i + 1) % k, k + (i + 1) % k, k + i] for i in range(k)]
    fi, fo = flat(walls + [list(range(k - 1, -1, -1))])
    return v, fi, fo


def _check_cap_inside(outline: np.ndarray):
    from shapely.geometry import Polygon
    from shapely.ops import unary_union

    v, fi, fo = _open_prism(outline)
    out_v, out_fi, out_fo = kr.cap(v, fi, fo)
    assert solid((out_v, out_fi, out_fo))
    new = out_fi[fo[-1] :].reshape(-1, 3)
    assert len(new) == len(outline) - 2
    tris = [Polygon(out_v[t, :2]) for t in new]
    poly = Polygon(outline)
    scale = poly.length
    assert all(poly.buffer(1e-9 * scale).contains(t) for t in tris)
    assert sum(t.area for t in tris) == pytest.approx(poly.area, rel=1e-9)
    assert unary_union(tris).symmetric_difference(poly).area < 1e-9 * poly.area


def test_cap_triangulates_a_concave_outline_inside_it():
    pytest.importorskip("shapely")
    _check_cap_inside(np.array([[0, 0], [4, 0], [4, 1], [1, 1], [1, 3], [3, 3], [3, 4], [0, 4.0]]))


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(0.2, 1.0), min_size=3, max_size=24), st.integers(0, 2**31))
def test_cap_of_random_star_outlines_stays_inside(radii, seed):
    pytest.importorskip("shapely")
    k = len(radii)
    gaps = np.random.default_rng(seed).uniform(0.5, 1.5, k)
    angle = 2 * np.pi * np.cumsum(gaps) / gaps.sum()
    r = np.asarray(radii)
    _check_cap_inside(np.column_stack([r * np.cos(angle), r * np.sin(angle)]))


def test_cap_fans_a_non_planar_loop_to_its_centroid():
    v, fi, fo = kp.cylinder(1, 2, 16, caps=False)
    v = v.copy()
    top = v[:, 2] > 0
    v[top, 2] += 0.3 * np.cos(2 * np.arctan2(v[top, 1], v[top, 0]))  # a saddle rim
    out = kr.cap(v, fi, fo)
    assert len(out[0]) == len(v) + 1  # one centroid for the warped rim; the flat one has none
    assert solid(out)


def test_cap_refuses_misoriented_input():
    v, fi, fo = mix(kp.cylinder(1, 1, 8, caps=False), 3)
    with pytest.raises(ValueError, match="inconsistent orientation"):
        kr.cap(v, fi, fo)


# ------------------------------------------------------------------------------ solidify


@pytest.mark.parametrize("offset", [-1.0, 0.0, 0.5, 1.0])
def test_solidify_a_flat_plate_has_area_times_thickness(offset):
    sheet = kp.plane((3, 2), (6, 5))
    shell = ks.solidify(*sheet, 0.25, offset)
    assert solid(shell)
    assert volume(shell) == pytest.approx(area(sheet) * 0.25, rel=1e-12)
    z = shell[0][:, 2]
    assert z.max() == pytest.approx(0.25 * (1 + offset) / 2)
    assert z.min() == pytest.approx(-0.25 * (1 - offset) / 2)


def test_solidify_a_varying_thickness_and_a_closed_surface():
    sheet = kp.plane((2, 2), (4, 4))
    t = 0.1 + 0.05 * sheet[0][:, 0]
    shell = ks.solidify(*sheet, t, -1)
    assert solid(shell)
    # the wall is linear in x over each quad: the volume is the integral of t over the sheet
    assert volume(shell) == pytest.approx(0.1 * 4, rel=1e-12)
    ball = kp.sphere(1, 48)
    hollow = ks.solidify(*ball, 0.1, -1)
    assert solid(hollow) and tri(hollow).body_count == 2
    assert volume(hollow) == pytest.approx(volume(ball) * (1 - 0.9**3), rel=0.02)


def test_solidify_refuses_bad_thickness():
    with pytest.raises(ValueError, match="thickness must be > 0"):
        ks.solidify(*kp.plane(), 0.0)
    with pytest.raises(ValueError, match="offset must be between -1 and 1"):
        ks.solidify(*kp.plane(), 0.1, 2)


def test_vertex_normals_are_angle_weighted():
    # a cube corner: three faces meet at right angles -> the diagonal, however split
    v, fi, fo = cube()
    n = ks.vertex_normals(v, fi, fo)
    np.testing.assert_allclose(n[7], np.ones(3) / np.sqrt(3))
    v2, fi2, fo2 = triangulate(v, fi, fo)
    np.testing.assert_allclose(ks.vertex_normals(v2, fi2, fo2), n, atol=1e-12)


# ------------------------------------------------------------------------------- boolean

PRIMITIVES = st.sampled_from(["sphere", "box", "cylinder", "torus"])
POINT = st.tuples(*[st.floats(-1.0, 1.0)] * 3)


def primitive(kind: str, centre, size: float):
    if kind == "sphere":
        return kp.sphere(size, 20, centre)
    if kind == "cylinder":
        return kp.cylinder(size, 1.5 * size, 17, True, centre)
    if kind == "torus":
        return kp.torus(size, size / 3, 19, 9, centre)
    v, fi, fo = cube(size)
    return v + np.asarray(centre), fi, fo


@settings(max_examples=30, deadline=None)
@given(PRIMITIVES, PRIMITIVES, POINT, POINT, st.floats(0.4, 1.2), st.floats(0.4, 1.2))
def test_random_booleans_are_solid_and_volumes_add_up(ka, kb_, ca, cb, sa, sb):
    import manifold3d

    a, b = primitive(ka, ca, sa), primitive(kb_, cb, sb)
    results = {op: kb.boolean(a, b, op) for op in ("union", "intersection", "difference")}
    for op, m in results.items():
        if m[2].size == 1:  # empty (no overlap for an intersection)
            continue
        t = trimesh.Trimesh(m[0], m[1].reshape(-1, 3), process=False)
        assert t.is_watertight and t.is_winding_consistent, op
        mm = manifold3d.Manifold(
            manifold3d.Mesh64(
                vert_properties=m[0].copy(), tri_verts=m[1].reshape(-1, 3).astype(np.uint64)
            )
        )
        assert mm.status() == manifold3d.Error.NoError
    va, vb = volume(a), volume(b)
    vu, vi, vd = (volume(results[op]) for op in ("union", "intersection", "difference"))
    assert vu == pytest.approx(va + vb - vi, rel=1e-6)
    assert vd == pytest.approx(va - vi, rel=1e-6, abs=1e-9 * va)


def test_boolean_leaves_its_inputs_alone():
    a = tuple(np.array(x) for x in kp.sphere(1, 16))
    b = tuple(np.array(x) for x in kp.sphere(1, 16, (0.5, 0, 0)))
    frozen = [x.copy() for x in (*a, *b)]
    for x in (*a, *b):
        x.flags.writeable = False
    kb.boolean(a, b, "difference")
    for x, y in zip((*a, *b), frozen, strict=True):
        np.testing.assert_array_equal(x, y)


def test_boolean_refuses_open_input_with_a_sentence():
    with pytest.raises(
        kb.NotSolidError,
        match=r"input a is not a closed solid: it has 16 open edges \(e\.g\. edge \d+-\d+ at \(",
    ):
        kb.boolean(kp.cylinder(1, 1, 8, caps=False), kp.sphere(1, 8))


def test_boolean_refuses_non_manifold_and_inside_out_input():
    v, fi, fo = cube()
    fin = np.concatenate([fi, fi[:4]])
    fon = np.concatenate([fo, [fo[-1] + 4]])
    with pytest.raises(
        kb.NotSolidError, match="input b is not a closed solid: it has 4 non-manifold edges"
    ):
        kb.boolean(kp.sphere(1, 8), (v, fin, fon))
    with pytest.raises(
        kb.NotSolidError, match=r"input a is inside out \(its volume is -8\); mesh.orient"
    ):
        kb.boolean((v, reverse_faces(fi, fo), fo), kp.sphere(1, 8))


def test_union_fuses_overlapping_parts_of_one_mesh():
    a, b = cube(1.0), kp.sphere(1, 16, (1, 0, 0))
    both = _merge(a, b)
    fused = kb.union([both])
    pair = kb.boolean(a, b, "union")
    assert volume(fused) == pytest.approx(volume(pair), rel=1e-9)
    assert volume(fused) < volume(a) + volume(b)


# ------------------------------------------------------------------------------- measure


def test_measures_match_trimesh():
    m = kr.cap(*kp.cylinder(0.7, 3, 11, caps=False))
    t = tri(m)
    assert area(m) == pytest.approx(t.area, rel=1e-12)
    assert volume(m) == pytest.approx(t.volume, rel=1e-12)
    report = km.solid_report(m[1], m[2], len(m[0]))
    assert report.is_solid and report.problems() == ""
    opened = kp.cylinder(0.7, 3, 11, caps=False)
    report = km.solid_report(opened[1], opened[2], len(opened[0]))
    assert report.problems() == "22 open edges" and report.example is not None


def test_exact_duplicates_survive_a_hash_collision(monkeypatch):
    pts = np.array([[0, 0, 0], [1, 2, 3], [0, 0, 0], [-0.0, 5, 1], [0, 5, 1.0]])
    first, inverse = kr.exact_duplicates(pts)
    assert first.tolist() == [0, 1, 3] and inverse.tolist() == [0, 1, 0, 2, 2]
    monkeypatch.setattr(kr, "_mix", lambda x: np.zeros_like(x))  # every row collides
    first2, inverse2 = kr.exact_duplicates(pts)
    assert first2.tolist() == [0, 1, 3] and inverse2.tolist() == [0, 1, 0, 2, 2]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from([0, 1 << 63, 0xF << 60, 0xFFF << 52]))
def test_exact_duplicates_split_what_a_weak_hash_joins(seed, mask):
    # A hash of a few (top) bits puts many different rows in one run of the sort, next to
    # runs of rows that agree; each mixed run
    # is split by the rows themselves: the groups are numpy's unique rows, in the order
    # they first appear (-0.0 and 0.0 are one value).
    rng = np.random.default_rng(seed)
    base = rng.integers(-2, 3, (40, 3)).astype(float)
    pts = base[rng.integers(0, 40, 200)]
    pts[rng.random(pts.shape) < 0.1] *= -1.0  # signed zeros among them
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(kr, "_mix", lambda x: x & np.uint64(mask))
        first, inverse = kr.exact_duplicates(pts)
    _, idx, inv = np.unique(pts + 0.0, axis=0, return_index=True, return_inverse=True)
    rank = np.argsort(idx)
    where = np.empty_like(rank)
    where[rank] = np.arange(rank.size)
    np.testing.assert_array_equal(first, idx[rank])
    np.testing.assert_array_equal(inverse, where[inv.reshape(-1)])


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31))
def test_dropping_collapsed_triangles_keeps_the_others_in_order(seed):
    rng = np.random.default_rng(seed)
    fi = rng.integers(0, 6, 3 * 50)
    fo = np.arange(0, fi.size + 1, 3)
    out_fi, out_fo = kr.drop_collapsed(fi, fo, 6)
    kept = [t for t in fi.reshape(-1, 3).tolist() if len(set(t)) == 3]
    assert out_fi.reshape(-1, 3).tolist() == kept
    assert out_fo.tolist() == list(range(0, 3 * len(kept) + 1, 3))
    # the polygon path (a quad appended) drops the same triangles
    poly_fi, poly_fo = kr.drop_collapsed(np.r_[fi, 0, 1, 2, 3], np.r_[fo, fo[-1] + 4], 6)
    assert poly_fi[:-4].tolist() == out_fi.tolist()


def test_triangle_measures_of_orient_match_the_polygon_ones():
    v, fi, fo = triangulate(*kp.torus(2, 0.7, 12, 7))
    v = v + [1e3, -2e3, 5e2]  # far from the origin
    origin = np.random.default_rng(1).normal(size=(fo.size - 1, 3)) + v.mean(axis=0)
    fast = kr._face_measures(v, fi, fo, True)
    slow = kr._face_measures(v, fi, fo, False)
    np.testing.assert_allclose(fast[0](), slow[0](), rtol=1e-9)
    np.testing.assert_allclose(fast[1], slow[1], rtol=1e-12)
    np.testing.assert_allclose(fast[2](origin), slow[2](origin), rtol=1e-9, atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from(["torus", "sphere", "prism"]))
def test_orient_a_randomly_flipped_triangle_soup(seed, which):
    # all triangles, welded from a soup (the triangle paths of weld, orient and cap)
    mesh = {"torus": kp.torus(2, 0.7, 12, 7), "sphere": kp.sphere(1, 10), "prism": prism(5)}
    v, fi, fo = triangulate(*mesh[which])
    welded = kr.weld(*mix(soup((v, fi, fo)), seed))
    out, conflicts = kr.orient(*welded)
    t = tri((welded[0], out, welded[2]))
    assert conflicts == 0 and t.is_winding_consistent and t.volume > 0
    assert t.volume == pytest.approx(volume((v, fi, fo)), rel=1e-12)


def test_weld_refuses_a_tolerance_that_would_compare_everything(monkeypatch):
    monkeypatch.setattr(kc, "MAX_PAIRS", 1000)
    v, fi, fo = kp.sphere(1, 64)
    with pytest.raises(ValueError, match=r"weld tolerance 3 is too coarse for this mesh: [\d,]+ "):
        kr.weld(v, fi, fo, 3.0)
    assert len(kr.weld(v, fi, fo)[0]) == len(v)  # the default tolerance compares few pairs


def test_orient_keeps_a_cavity_facing_inward():
    hollow = ks.solidify(*kp.sphere(1, 32), 0.1, -1)  # outer wall and an inward inner wall
    out, _ = kr.orient(*hollow)
    np.testing.assert_array_equal(out, hollow[1])
    v, fi, fo = hollow
    scrambled = mix(hollow, 7)
    out, _ = kr.orient(*scrambled)
    assert volume((v, out, fo)) == pytest.approx(volume(hollow), rel=1e-12)
    # a ball inside the cavity is a separate solid again: outward
    nested = _merge(hollow, kp.sphere(0.5, 16))
    nv, nfi, nfo = nested
    inward_ball = np.concatenate([nfi[: fi.size], reverse_faces(nfi, nfo)[fi.size :]])
    out, _ = kr.orient(nv, inward_ball, nfo)
    np.testing.assert_array_equal(out, nfi)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from(["sphere", "cube", "open", "soup", "nonmanifold"]))
def test_fast_solid_check_agrees_with_the_report(seed, which):
    rng = np.random.default_rng(seed)
    v, fi, fo = {
        "sphere": kp.sphere(1, 8),
        "cube": cube(),
        "open": kp.cylinder(1, 1, 6, caps=False),
        "soup": (rng.random((6, 3)), rng.integers(0, 6, 30), np.arange(0, 31, 3)),
        "nonmanifold": _merge(cube(), cube()),
    }[which]
    if which == "nonmanifold":
        fi = np.concatenate([fi[:24], fi[:24]])
    if rng.random() < 0.5:  # flip a few faces
        flips = rng.random(fo.size - 1) < 0.2
        fi = np.where(np.repeat(flips, np.diff(fo)), reverse_faces(fi, fo), fi)
    if which == "soup":
        fi, fo = kr.drop_collapsed(fi, fo, 6)
    assert km.is_closed_oriented(fi, fo, len(v)) == km.solid_report(fi, fo, len(v)).is_solid


def test_packed_and_hashed_cell_keys_find_the_same_pairs(monkeypatch):
    # Cell numbers that fit 21 bits an axis take the packed-key path; forcing the hashed
    # one must give the same close pairs (and so the same weld).
    rng = np.random.default_rng(4)
    base = rng.uniform(-1, 1, (3000, 3))
    near = base[rng.integers(0, 3000, 2000)] + rng.normal(scale=3e-4, size=(2000, 3))
    v = np.concatenate([base, near])
    packed = kc.close_pairs(v, 1e-3)
    monkeypatch.setattr(kc, "_PACKED", 0)
    hashed = kc.close_pairs(v, 1e-3)

    def canon(ij):
        i, j = np.minimum(*ij), np.maximum(*ij)
        return sorted(zip(i.tolist(), j.tolist(), strict=True))

    assert canon(packed) == canon(hashed)
    d = np.linalg.norm(v[:, None] - v[None], axis=2)
    brute = np.argwhere(np.triu(d <= 1e-3, k=1))
    assert canon(packed) == sorted(map(tuple, brute.tolist()))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from([1e-3, 0.02]))
def test_coarse_cells_find_every_close_pair(seed, tol):
    # Cells 8 tolerances wide, each point probing only the faces it is near, against all
    # pairs by brute force; points on a few shared planes (as meshes have them) and close
    # copies across cell faces.
    rng = np.random.default_rng(seed)
    pts = rng.uniform(0, 1, (300, 3))
    pts[rng.random(300) < 0.3, 2] = 0.5  # a plane of points
    near = pts[:100] + rng.normal(0, tol / 2, (100, 3))
    v = np.concatenate([pts, near])
    lo = v.min(axis=0)
    side = tol + 8 * np.finfo(np.float64).eps * float(np.abs(v).max())
    got = kc._close_pairs_coarse(v, lo, side, tol)
    assert got is not None
    d = np.linalg.norm(v[:, None] - v[None], axis=2)
    brute = sorted(map(tuple, np.argwhere(np.triu(d <= tol, k=1)).tolist()))
    i, j = np.minimum(*got), np.maximum(*got)
    assert sorted(zip(i.tolist(), j.tolist(), strict=True)) == brute
    # crowded coarse cells are left to the fine ones
    assert kc._close_pairs_coarse(v, lo, 0.1, 0.1) is None


def test_triangle_face_vectors_match_the_polygon_formula():
    from formgraph.kernels.mesh import measure

    rng = np.random.default_rng(6)
    v = rng.normal(size=(50, 3)) + 1e3  # far from the origin
    tri = rng.integers(0, 50, (200, 3))
    fast = measure.face_vectors(v, tri.ravel(), np.arange(0, 601, 3))
    # The same triangles among one quad: the general Newell path.
    fi = np.r_[tri.ravel(), [0, 1, 2, 3]]
    general = measure.face_vectors(v, fi, np.r_[np.arange(0, 601, 3), 604])[:-1]
    np.testing.assert_allclose(fast, general, rtol=1e-9, atol=1e-9)
    a, b, c = v[tri[:, 0]], v[tri[:, 1]], v[tri[:, 2]]
    np.testing.assert_allclose(fast, np.cross(b - a, c - a), rtol=1e-9, atol=1e-9)


def test_triangle_signed_volumes_match_the_fan_formula():
    from formgraph.kernels.mesh import measure

    rng = np.random.default_rng(7)
    v = rng.normal(size=(40, 3))
    tri = rng.integers(0, 40, (100, 3))
    fo = np.arange(0, 301, 3)
    origins = rng.normal(size=(100, 3))
    for origin in (None, origins[0], origins):
        fast = measure.signed_volume(v, tri.ravel(), fo, origin)
        # the general path: the same triangles plus one quad, which is dropped after
        general = measure.signed_volume(
            v,
            np.r_[tri.ravel(), [0, 1, 2, 3]],
            np.r_[fo, 304],
            None
            if origin is None
            else (np.r_[origins, [[0, 0, 0]]] if origin.ndim == 2 else origin),
        )[:-1]
        if origin is None:  # the default origins differ (the quad's corners are in the box)
            assert np.sum(fast) == pytest.approx(np.sum(general), abs=1e-9)
        else:
            np.testing.assert_allclose(fast, general, rtol=1e-9, atol=1e-12)
