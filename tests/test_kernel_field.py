"""Field kernels (engine/kernels/field): SDFs, blends, TPMS, mesh distances, the mesher."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import example, given, settings
from hypothesis import strategies as st

from formgraph.kernels.field import mesher, roots, sdf
from formgraph.kernels.geometry import meshdist

O = np.zeros(3)


def solid(v: np.ndarray, t: np.ndarray) -> trimesh.Trimesh:
    m = trimesh.Trimesh(v, t, process=False)
    assert m.is_watertight and m.is_winding_consistent
    # welded by construction: no two vertices share a grid edge, none unused
    assert len(np.unique(t)) == len(v)
    return m


def test_sphere_is_closed_outward_genus_zero_and_on_the_surface():
    cell = 0.08
    f = lambda p: sdf.sphere(p, 1.0, O)  # noqa: E731
    v, t = mesher.mesh_field(f, [-1, -1, -1], [1, 1, 1], cell)
    m = solid(v, t)
    assert m.euler_number == 2
    assert m.volume == pytest.approx(4 / 3 * np.pi, rel=0.01)
    assert np.abs(f(v)).max() < 1e-3 * cell  # root-found, not only interpolated


def test_root_finding_beats_linear_interpolation_on_a_curved_field():
    # |p|^2 - 1 is not a distance: linear interpolation alone misses the root
    f = lambda p: (p * p).sum(axis=1) - 1.0  # noqa: E731
    lin, _ = mesher.mesh_field(f, [-1] * 3, [1] * 3, 0.2, lipschitz=3.0, root_steps=0)
    exact, _ = mesher.mesh_field(f, [-1] * 3, [1] * 3, 0.2, lipschitz=3.0)
    assert np.median(np.abs(f(exact))) < 1e-3 * np.median(np.abs(f(lin)))
    # at worst a vertex is held END_GAP of its edge off a corner that is on the surface
    assert np.abs(f(exact)).max() <= 3.0 * roots.END_GAP * 0.2 * 1.001


def test_rounded_box_volume_closed_form():
    a, b, c, r = 2.0, 1.5, 1.0, 0.3
    v, t = mesher.mesh_field(
        lambda p: sdf.box(p, np.array([a, b, c]), O, r), [-1, -0.75, -0.5], [1, 0.75, 0.5], 0.03
    )
    x, y, z = a - 2 * r, b - 2 * r, c - 2 * r
    exact = x * y * z + 2 * r * (x * y + y * z + x * z) + np.pi * r * r * (x + y + z)
    exact += 4 / 3 * np.pi * r**3
    assert solid(v, t).volume == pytest.approx(exact, rel=0.01)


def test_box_offset_is_the_minkowski_sum_with_a_ball():
    a, d = 2.0, 0.4
    f = lambda p: sdf.box(p, np.array([a, a, a]), O) - d  # noqa: E731
    v, t = mesher.mesh_field(f, [-1.4] * 3, [1.4] * 3, 0.04)
    exact = a**3 + 6 * a * a * d + 3 * np.pi * a * d * d + 4 / 3 * np.pi * d**3
    assert solid(v, t).volume == pytest.approx(exact, rel=0.005)


def test_lens_of_two_spheres():
    r, d = 1.0, 1.2
    c2 = np.array([d, 0, 0])
    f = lambda p: sdf.smooth_max(sdf.sphere(p, r, O), sdf.sphere(p, r, c2), 0.0)  # noqa: E731
    v, t = mesher.mesh_field(f, [d - r, -1, -1], [r, 1, 1], 0.025)
    exact = np.pi * (4 * r + d) * (2 * r - d) ** 2 / 12
    assert solid(v, t).volume == pytest.approx(exact, rel=0.01)


def test_torus_as_a_tube_round_a_circle_has_genus_one():
    R, r = 1.0, 0.3
    s = np.linspace(0, 2 * np.pi, 129)
    ring = np.stack([R * np.cos(s), R * np.sin(s), 0 * s], axis=1)
    tubes = meshdist.Nearest(np.stack([ring[:-1], ring[1:]], axis=1))
    v, t = mesher.mesh_field(
        lambda p: tubes.distance(p) - r, [-1.3, -1.3, -0.3], [1.3, 1.3, 0.3], 0.04
    )
    m = solid(v, t)
    assert m.euler_number == 0
    assert m.volume == pytest.approx(2 * np.pi**2 * R * r * r, rel=0.01)
    exact = sdf.torus(v, R, r, O)
    assert np.abs(exact).max() < 2e-3  # the 128-gon's sag: R (1 - cos(pi / 128)) = 3e-4


def test_smooth_min_is_at_most_a_quarter_blend_below_min_and_lipschitz():
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(2, 1000))
    k = 0.5
    s = sdf.smooth_min(a, b, k)
    assert (s <= np.minimum(a, b) + 1e-15).all()
    assert (s >= np.minimum(a, b) - k / 4 - 1e-15).all()
    # along a line through two spheres, the blend changes no faster than the distance
    p = np.stack([np.linspace(-3, 3, 2001), np.zeros(2001), np.zeros(2001)], axis=1)
    blend = sdf.smooth_min(sdf.sphere(p, 1, O - [1, 0, 0]), sdf.sphere(p, 1, O + [1.2, 0, 0]), 1.0)
    assert np.abs(np.diff(blend)).max() <= (p[1, 0] - p[0, 0]) * (1 + 1e-9)


@pytest.mark.parametrize("kind", sdf.TPMS_KINDS)
def test_tpms_wall_has_its_thickness(kind):
    period, thick = 10.0, 1.0
    rng = np.random.default_rng(1)
    p = rng.uniform(0, period, (4000, 3))
    f, g = sdf._tpms_value_gradient(kind, p, period)
    # points on the surface (a Newton projection), then along the normal by +- t/2
    for _ in range(30):
        f, g = sdf._tpms_value_gradient(kind, p, period)
        p = p - (f / (g * g).sum(axis=1))[:, None] * g
    f, g = sdf._tpms_value_gradient(kind, p, period)
    n = g / np.linalg.norm(g, axis=1, keepdims=True)
    ok = np.abs(f) < 1e-9
    for side in (1, -1):
        q = p[ok] + side * n[ok] * thick / 2
        # even to first order: within a few per cent of the wall at a tenth of the period
        assert np.median(np.abs(sdf.tpms(q, kind, period, thick))) < 0.04 * thick


def test_gyroid_volume_fraction_is_thickness_times_area_density():
    # the gyroid has 3.0917 a^2 of area per cubic cell of side a (Schoen); a thin sheet
    # of thickness t fills t * 3.0917 / a of space, up to O((t / a)^2) (2.4 % at t / a = 0.06)
    a, t = 10.0, 0.5
    f = lambda p: np.maximum(  # noqa: E731
        sdf.tpms(p, "gyroid", a, t), sdf.box(p, np.array([20.0] * 3), O)
    )
    v, tri = mesher.mesh_field(f, [-10] * 3, [10] * 3, 0.25, lipschitz=2.0)
    m = solid(v, tri)
    assert m.volume / 20**3 == pytest.approx(t * 3.0917 / a, rel=0.03)


def test_culling_keeps_every_cell_dense_marching_would_use():
    def f(p):
        box = sdf.box(p, np.array([1.0, 0.4, 2]), O + 0.5, 0.1)
        return sdf.smooth_min(sdf.sphere(p, 0.7, O), box, 0.3)

    v, t = mesher.mesh_field(f, [-1] * 3, [1.5] * 3, 0.05)
    # the dense count of sign-changing cells equals the adaptive mesher's
    origin, levels, blocks = mesher.plan_grid([-1] * 3, [1.5] * 3, 0.05)
    n = blocks * (1 << levels)
    axes = [origin[k] + np.arange(n[k] + 1) * 0.05 for k in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    ins = (f(grid) < 0).reshape(*(n + 1))
    corners = [
        ins[i : i + n[0], j : j + n[1], k : k + n[2]]
        for i in (0, 1)
        for j in (0, 1)
        for k in (0, 1)
    ]
    s = np.sum(corners, axis=0)
    cells = mesher.crossing_cells(f, [-1] * 3, [1.5] * 3, 0.05)
    ijk = np.stack(np.nonzero((s > 0) & (s < 8)), 1)
    # exactly the cells dense marching would use: none missing, none made up
    assert len(ijk) > 0
    assert {tuple(c) for c in cells.tolist()} == {tuple(c) for c in ijk.tolist()}
    solid(v, t)


def test_budget_is_counted_before_cells_are_made():
    with pytest.raises(mesher.BudgetExceeded) as exc:
        mesher.mesh_field(lambda p: sdf.sphere(p, 1, O), [-1] * 3, [1] * 3, 1e-4, max_cells=10**6)
    assert exc.value.count > 10**6


def test_a_field_that_is_not_finite_is_refused():
    with pytest.raises(ValueError, match="not finite"):
        mesher.mesh_field(lambda p: np.full(len(p), np.nan), [-1] * 3, [1] * 3, 0.5)


@settings(max_examples=12, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1), st.floats(0.25, 0.8)),
        min_size=1,
        max_size=4,
    ),
    st.floats(0, 0.6),
)
@example(spheres=[(0.0, 0.0, 0.0, 0.5), (0.0, 0.0, 0.75, 0.5)], k=0.0)  # a kink on edges
def test_random_smooth_blends_are_closed_outward_and_even_euler(spheres, k):
    def f(p):
        out = None
        for x, y, z, r in spheres:
            d = sdf.sphere(p, r, np.array([x, y, z]))
            out = d if out is None else sdf.smooth_min(out, d, k)
        return out

    v, t = mesher.mesh_field(f, [-2] * 3, [2] * 3, 0.1)
    m = solid(v, t)
    assert m.volume > 0
    assert m.euler_number % 2 == 0
    biggest = max(4 / 3 * np.pi * r**3 for *_, r in spheres)
    assert m.volume > 0.9 * biggest
    assert np.abs(f(v)).max() < 1e-3 * 0.1


# ------------------------------------------------------------------------------ distances


def test_point_triangle_distance_matches_trimesh_closest_point():
    rng = np.random.default_rng(5)
    tri = rng.normal(size=(500, 3, 3))
    tri[:20, 2] = tri[:20, 0] + 2 * (tri[:20, 1] - tri[:20, 0])  # collinear corners
    tri[20:25, 1:] = tri[20:25, :1]  # a point
    p = rng.normal(size=(500, 3)) * 2
    d = meshdist.point_triangle_distance(p, tri[:, 0], tri[:, 1], tri[:, 2])
    ref = np.linalg.norm(trimesh.triangles.closest_point(tri[25:], p[25:]) - p[25:], axis=1)
    assert np.allclose(d[25:], ref, atol=1e-9)
    brute = np.minimum(
        meshdist.point_segment_distance(p[:25], tri[:25, 0], tri[:25, 1]),
        meshdist.point_segment_distance(p[:25], tri[:25, 1], tri[:25, 2]),
    )
    brute = np.minimum(brute, meshdist.point_segment_distance(p[:25], tri[:25, 2], tri[:25, 0]))
    assert np.allclose(d[:25], brute)


def test_nearest_is_exact_against_brute_force_and_varied_triangle_sizes():
    m = trimesh.creation.icosphere(3)
    tri = m.triangles.copy()
    tri = np.concatenate([tri, [[[3, 0, 0], [-3, 4, 0], [0, -3, 5]]]])  # one huge triangle
    rng = np.random.default_rng(2)
    p = rng.uniform(-3, 3, (700, 3))
    d = meshdist.Nearest(tri).distance(p)
    brute = np.stack(
        [
            meshdist.point_triangle_distance(
                p, *np.broadcast_to(t, (len(p), 3, 3)).transpose(1, 0, 2)
            )
            for t in tri
        ],
        1,
    ).min(axis=1)
    assert np.allclose(d, brute, atol=1e-12)


def test_winding_number_is_one_inside_zero_outside_and_near_exact():
    m = trimesh.creation.annulus(0.4, 1.0, 0.6, sections=48)
    tri = m.triangles
    rng = np.random.default_rng(4)
    p = rng.uniform(-1.2, 1.2, (1500, 3))
    w = meshdist.WindingNumber(tri)(p)
    a, b, c = (tri[None, :, k] - p[:, None] for k in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
    num = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("ijk,ijk->ij", a, b) * lc
    den += np.einsum("ijk,ijk->ij", a, c) * lb + np.einsum("ijk,ijk->ij", b, c) * la
    exact = (2 * np.arctan2(num, den)).sum(axis=1) / (4 * np.pi)
    assert np.abs(w - exact).max() < 0.05
    assert ((w > 0.5) == m.contains(p)).all()


def test_pseudonormal_sign_on_a_closed_mesh_agrees_with_the_winding_number():
    m = trimesh.creation.annulus(0.4, 1.0, 0.6, sections=32)  # concave edges and corners
    rng = np.random.default_rng(6)
    p = np.concatenate(
        [rng.uniform(-1.2, 1.2, (1500, 3)), m.vertices + rng.normal(0, 1e-3, m.vertices.shape)]
    )
    signed = meshdist.SignedDistance(m.vertices, m.faces)
    assert signed.closed
    d = signed(p)
    w = meshdist.WindingNumber(m.triangles)(p)
    assert ((d < 0) == (w > 0.5)).all()
    np.testing.assert_allclose(np.abs(d), meshdist.Nearest(m.triangles).distance(p))
    assert not meshdist.SignedDistance(m.vertices, m.faces[1:]).closed


def _brute_nearest(p, corners):
    if corners.shape[1] == 2:
        d = [meshdist.point_segment_distance(p, s[0], s[1]) for s in corners]
    else:
        d = [meshdist.point_triangle_distance(p, t[0], t[1], t[2]) for t in corners]
    return np.stack(d, 1).min(axis=1)


@pytest.mark.parametrize("k", [2, 3])
def test_nearest_is_exact_on_a_soup_of_all_sizes_near_and_far(k):
    # sizes over six decades (several size classes), degenerate ones, duplicates, and
    # points on, near and far from them: every distance is the brute force's, and the
    # primitive it names is at that distance
    rng = np.random.default_rng(11 + k)
    n = 600
    size = 10.0 ** rng.uniform(-4, 2, n)
    corners = rng.uniform(-5, 5, (n, 1, 3)) + rng.normal(size=(n, k, 3)) * size[:, None, None]
    corners[:10, 1:] = corners[:10, :1]  # points
    corners[10:20, -1] = corners[10:20, 0] + 0.5 * (corners[10:20, 1] - corners[10:20, 0])
    corners[20:30] = corners[30:40]  # duplicates
    p = np.concatenate(
        [
            rng.uniform(-40, 40, (300, 3)),
            corners[rng.integers(0, n, 300), 0] + rng.normal(0, 1e-3, (300, 3)),
            corners[:50].mean(axis=1),
        ]
    )
    near = meshdist.Nearest(corners)
    d, prim = near.nearest(p)
    np.testing.assert_allclose(d, _brute_nearest(p, corners), rtol=1e-12, atol=1e-12)
    # the primitive it names is at that distance, and so is the closest point it gives
    named = corners[prim]
    if k == 2:
        own = meshdist.point_segment_distance(p, named[:, 0], named[:, 1])
    else:
        own = meshdist.point_triangle_distance(p, named[:, 0], named[:, 1], named[:, 2])
    np.testing.assert_allclose(own, d, rtol=1e-12, atol=1e-12)
    closest, _ = near.closest(p)
    np.testing.assert_allclose(np.linalg.norm(closest - p, axis=1), d, rtol=1e-9, atol=1e-12)


def test_nearest_on_a_fine_surface_far_and_near_matches_trimesh():
    # a fine torus (the clusters' cylinders carry the far points) against trimesh
    m = trimesh.creation.torus(1.0, 0.4, major_sections=96, minor_sections=48)
    rng = np.random.default_rng(8)
    i = rng.integers(0, len(m.faces), 400)
    p = np.concatenate(
        [
            rng.uniform(-3, 3, (400, 3)),
            m.triangles_center[i] + m.face_normals[i] * rng.uniform(-0.3, 0.3, (400, 1)),
        ]
    )
    d = meshdist.Nearest(m.triangles).distance(p)
    _, ref, _ = trimesh.proximity.closest_point(m, p)
    np.testing.assert_allclose(d, ref, atol=1e-9)
