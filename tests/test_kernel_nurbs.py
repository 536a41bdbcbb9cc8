"""Tests of the NURBS kernel (formgraph.kernels.nurbs) against geomdl, closed forms and
invariants (shape unchanged by knot insertion, refinement and degree elevation)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from formgraph.kernels import nurbs as K
from formgraph.kernels.nurbs_construct import _reflection_steps
from geomdl import NURBS, BSpline, fitting, helpers, operations
from hypothesis import given, settings
from hypothesis import strategies as st

T = np.linspace(0.0, 1.0, 101)


def random_curve(rng, degree, n=None, rational=True, unclamped=False):
    n = n if n is not None else degree + 1 + int(rng.integers(0, 6))
    cp = rng.normal(size=(n, 3))
    w = rng.uniform(0.3, 3.0, n) if rational else None
    if unclamped:
        knots = np.sort(rng.uniform(-1, 2, n + degree + 1))
        knots = K.reparametrize(knots, 0.0, 1.0, degree)
    else:
        inner = np.sort(rng.uniform(0.0, 1.0, n - degree - 1))
        knots = np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])
    return cp, degree, knots, w


def geomdl_curve(cp, degree, knots, w):
    c = NURBS.Curve() if w is not None else BSpline.Curve()
    c.degree = degree
    c.ctrlpts = cp.tolist()
    if w is not None:
        c.weights = w.tolist()
    c.knotvector = knots.tolist()
    return c


def geomdl_surface(cp, pu, pv, ku, kv, w):
    s = NURBS.Surface()
    s.degree_u, s.degree_v = pu, pv
    s.ctrlpts_size_u, s.ctrlpts_size_v = cp.shape[:2]
    s.ctrlpts = cp.reshape(-1, 3).tolist()
    s.weights = (np.ones(cp.shape[:2]) if w is None else w).reshape(-1).tolist()
    s.knotvector_u, s.knotvector_v = ku.tolist(), kv.tolist()
    return s


def shape_error(a, b, t=T):
    return float(np.abs(K.curve_evaluate(*a, t) - K.curve_evaluate(*b, t)).max())


# ------------------------------------------------------------------------- basis, spans


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_spans_and_basis_match_geomdl(degree):
    rng = np.random.default_rng(degree)
    cp, p, knots, _ = random_curve(rng, degree, n=degree + 6)
    t = np.concatenate([rng.uniform(0, 1, 40), knots[p:-p]])
    spans = K.find_spans(p, knots, t)
    ref_spans = [helpers.find_span_linear(p, knots.tolist(), len(cp), x) for x in t]
    assert spans.tolist() == ref_spans
    N = K.basis_functions(p, knots, spans, t)
    ref = np.array(
        [helpers.basis_function(p, knots.tolist(), s, x) for s, x in zip(spans, t, strict=True)]
    )
    np.testing.assert_allclose(N, ref, atol=1e-12)
    np.testing.assert_allclose(N.sum(axis=1), 1.0, atol=1e-13)
    D = K.basis_function_derivatives(p, knots, spans, t, 3)
    top = min(3, p)  # geomdl stops at the degree
    ref_d = np.array(
        [
            helpers.basis_function_ders(p, knots.tolist(), s, x, top)
            for s, x in zip(spans, t, strict=True)
        ]
    )
    np.testing.assert_allclose(
        D[: top + 1], ref_d.transpose(1, 0, 2), atol=1e-9 * np.abs(ref_d).max()
    )
    assert np.all(D[top + 1 :] == 0)


def test_end_of_domain_belongs_to_last_span_and_repeated_knots_are_skipped():
    knots = np.array([0, 0, 0, 0.5, 0.5, 1, 1, 1.0])
    assert K.find_spans(2, knots, np.array([0.0, 0.5, 1.0])).tolist() == [2, 4, 4]


# ------------------------------------------------------------------- curves vs geomdl


@pytest.mark.parametrize("rational", [True, False])
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_curve_points_and_derivatives_match_geomdl(degree, rational):
    rng = np.random.default_rng(10 + degree)
    curve = random_curve(rng, degree, rational=rational)
    ref = geomdl_curve(*curve)
    pts = K.curve_evaluate(*curve, T)
    np.testing.assert_allclose(pts, np.array(ref.evaluate_list(T.tolist())), atol=1e-9)
    ders = K.curve_derivatives(*curve, T, 2)
    ref_d = np.array([ref.derivatives(x, order=2) for x in T]).transpose(1, 0, 2)
    np.testing.assert_allclose(ders, ref_d, atol=1e-9 * max(1.0, np.abs(ref_d).max()))


def test_curve_evaluate_shapes():
    curve = random_curve(np.random.default_rng(0), 3)
    assert K.curve_evaluate(*curve, 0.5).shape == (3,)
    assert K.curve_evaluate(*curve, np.zeros((4, 5))).shape == (4, 5, 3)
    assert K.curve_derivatives(*curve, T, 2).shape == (3, len(T), 3)


def test_curve_evaluation_over_many_blocks_matches_pointwise():
    # more parameters than one cache block, unsorted
    rng = np.random.default_rng(1)
    curve = random_curve(rng, 3, n=40)
    t = rng.uniform(0, 1, 10_000)
    whole = K.curve_evaluate(*curve, t)
    some = np.array([K.curve_evaluate(*curve, x) for x in t[::997]])
    np.testing.assert_allclose(whole[::997], some, atol=1e-14)


def test_curve_derivative_is_the_derivative():
    curve = random_curve(np.random.default_rng(2), 4)
    t = np.linspace(0.05, 0.95, 37)
    h = 1e-6
    fd = (K.curve_evaluate(*curve, t + h) - K.curve_evaluate(*curve, t - h)) / (2 * h)
    d1 = K.curve_derivatives(*curve, t, 1)[1]
    np.testing.assert_allclose(d1, fd, atol=1e-5 * np.abs(d1).max())


# ------------------------------------------------------------------ surfaces vs geomdl


@pytest.mark.parametrize("pu,pv", [(1, 1), (1, 3), (2, 2), (3, 3), (4, 2), (5, 5)])
@pytest.mark.parametrize("rational", [True, False])
def test_surface_points_and_partials_match_geomdl(pu, pv, rational):
    rng = np.random.default_rng(100 * pu + pv)
    nu, nv = pu + 3, pv + 2
    cp = rng.normal(size=(nu, nv, 3))
    w = rng.uniform(0.3, 3.0, (nu, nv)) if rational else None
    ku = random_curve(rng, pu, n=nu)[2]
    kv = random_curve(rng, pv, n=nv)[2]
    ref = geomdl_surface(cp, pu, pv, ku, kv, w)
    u, v = rng.uniform(0, 1, 25), rng.uniform(0, 1, 25)
    u[:2], v[:2] = [0.0, 1.0], [1.0, 0.0]
    ref_pts = np.array(ref.evaluate_list(list(zip(u.tolist(), v.tolist(), strict=True))))
    np.testing.assert_allclose(K.surface_evaluate(cp, pu, pv, ku, kv, w, u, v), ref_pts, atol=1e-9)
    grid = K.surface_evaluate_grid(cp, pu, pv, ku, kv, w, u, v)
    assert grid.shape == (25, 25, 3)
    np.testing.assert_allclose(grid[np.arange(25), np.arange(25)], ref_pts, atol=1e-9)
    ref_d = np.array([ref.derivatives(a, b, order=1) for a, b in zip(u, v, strict=True)])
    S, Su, Sv = K.surface_derivatives(cp, pu, pv, ku, kv, w, u, v)
    scale = max(1.0, np.abs(ref_d).max())
    np.testing.assert_allclose(S, ref_pts, atol=1e-9)
    np.testing.assert_allclose(Su, ref_d[:, 1, 0], atol=1e-9 * scale)
    np.testing.assert_allclose(Sv, ref_d[:, 0, 1], atol=1e-9 * scale)
    n = K.surface_normals(cp, pu, pv, ku, kv, w, u, v)
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-12)
    assert np.abs(np.sum(n * Su, axis=-1)).max() < 1e-9 * scale


def test_surface_evaluate_broadcasts():
    rng = np.random.default_rng(5)
    cp = rng.normal(size=(4, 5, 3))
    args = (cp, 2, 3, K.clamped_uniform_knots(4, 2), K.clamped_uniform_knots(5, 3), None)
    u = np.linspace(0, 1, 6)[:, None]
    v = np.linspace(0, 1, 7)[None, :]
    np.testing.assert_allclose(
        K.surface_evaluate(*args, u, v), K.surface_evaluate_grid(*args, u[:, 0], v[0]), atol=1e-14
    )
    assert K.surface_evaluate(*args, 0.5, 0.5).shape == (3,)


def test_normals_at_a_pole_are_finite_and_point_along_the_axis():
    # a hemisphere-like cap: the profile starts on the axis
    prof = K.arc(1.0, 90.0, 0.0, normal=(0, -1, 0))  # from the top (0,0,1) down to (1,0,0)
    surf = K.revolve(prof)
    n = K.surface_normals(*surf, np.array([0.0, 0.0]), np.array([0.0, 0.6]))
    assert np.all(np.isfinite(n))
    np.testing.assert_allclose(np.abs(n[:, 2]), 1.0, atol=1e-6)


# ---------------------------------------------------------------- knot operations


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_insert_knot_matches_geomdl_and_keeps_shape(degree):
    rng = np.random.default_rng(20 + degree)
    curve = random_curve(rng, degree, n=degree + 4)
    cp, p, knots, w = curve
    cp_before = cp.copy()
    times = min(degree, 2)
    new = K.insert_knot(*curve, 0.4321, times)
    assert len(new[0]) == len(cp) + times and len(new[2]) == len(knots) + times
    assert np.count_nonzero(new[2] == 0.4321) == times
    assert shape_error(curve, new) < 1e-12
    np.testing.assert_array_equal(cp, cp_before)  # inputs untouched
    ref = geomdl_curve(*curve)
    operations.insert_knot(ref, [0.4321], [times])
    np.testing.assert_allclose(new[0], np.array(ref.ctrlpts), atol=1e-12)
    np.testing.assert_allclose(new[3], np.array(ref.weights), atol=1e-12)


def test_insert_knot_up_to_the_degree_puts_a_point_on_the_curve():
    curve = random_curve(np.random.default_rng(3), 3, n=7)
    new = K.insert_knot(*curve, 0.3, 3)
    pt = K.curve_evaluate(*curve, 0.3)
    assert np.min(np.linalg.norm(new[0] - pt, axis=1)) < 1e-12


def test_insert_knot_on_unclamped_curves_keeps_shape():
    cp, knots, _ = K.periodic_curve(np.random.default_rng(4).normal(size=(6, 3)), 3)
    curve = (cp, 3, knots, None)
    for t in (0.0, 0.25, 0.5, 1.0):
        assert shape_error(curve, K.insert_knot(*curve, t, 2)) < 1e-12


@settings(max_examples=25, deadline=None)
@given(
    degree=st.integers(1, 5),
    seed=st.integers(0, 10_000),
    count=st.integers(1, 12),
    rational=st.booleans(),
)
def test_refinement_keeps_shape(degree, seed, count, rational):
    rng = np.random.default_rng(seed)
    curve = random_curve(rng, degree, rational=rational)
    new = rng.uniform(0, 1, count)
    new = np.concatenate([new, new[:1]]) if degree > 1 else new  # a repeated new knot
    refined = K.refine_knots(*curve, new)
    assert len(refined[0]) == len(curve[0]) + len(new)
    assert shape_error(curve, refined) < 1e-12


def test_refinement_matches_geomdl():
    curve = random_curve(np.random.default_rng(6), 3, n=8, rational=False)
    ref = geomdl_curve(*curve)
    operations.refine_knotvector(ref, [1])  # midpoints and old knots, up to multiplicity p
    target = np.array(ref.knotvector)
    values, counts = np.unique(target, return_counts=True)
    old = np.array([np.count_nonzero(curve[2] == v) for v in values])
    ours = K.refine_knots(*curve, np.repeat(values, counts - old))
    np.testing.assert_allclose(ours[2], ref.knotvector, atol=1e-15)
    np.testing.assert_allclose(ours[0], np.array(ref.ctrlpts), atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(
    degree=st.integers(1, 5),
    times=st.integers(1, 3),
    seed=st.integers(0, 10_000),
    rational=st.booleans(),
)
def test_degree_elevation_keeps_shape_and_continuity(degree, times, seed, rational):
    curve = random_curve(np.random.default_rng(seed), degree, rational=rational)
    cp, q, knots, w = K.elevate_degree(*curve, times)
    assert q == degree + times
    values, counts = np.unique(curve[2], return_counts=True)
    new_values, new_counts = np.unique(knots, return_counts=True)
    np.testing.assert_array_equal(new_values, values)
    np.testing.assert_array_equal(new_counts, counts + times)
    K.validate_curve(cp, q, knots, w)
    assert shape_error(curve, (cp, q, knots, w)) < 1e-10


def test_degree_elevation_of_a_circle_stays_a_circle():
    cp, q, knots, w = K.elevate_degree(*K.circle(2.0), 2)
    pts = K.curve_evaluate(cp, q, knots, w, np.linspace(0, 1, 333))
    np.testing.assert_allclose(np.linalg.norm(pts, axis=1), 2.0, atol=1e-12)


@pytest.mark.parametrize("rational", [True, False])
def test_bezier_decomposition_matches_geomdl_and_bernstein(rational):
    curve = random_curve(np.random.default_rng(7), 3, n=7, rational=rational)
    segs, sw = K.decompose_bezier(*curve)
    inner = np.unique(curve[2])
    assert segs.shape == (len(inner) - 1, 4, 3)
    ref = operations.decompose_curve(geomdl_curve(*curve))
    for seg, r in zip(segs, ref, strict=True):
        np.testing.assert_allclose(seg, np.array(r.ctrlpts), atol=1e-12)
    # each piece, evaluated as a rational Bezier (Bernstein form), is the curve on its span
    s = np.linspace(0, 1, 11)
    bern = np.stack([math.comb(3, k) * s**k * (1 - s) ** (3 - k) for k in range(4)], axis=1)
    w = np.ones(segs.shape[:2]) if sw is None else sw
    for i, (a, b) in enumerate(zip(inner[:-1], inner[1:], strict=True)):
        num = bern @ (segs[i] * w[i][:, None])
        den = bern @ w[i]
        np.testing.assert_allclose(
            num / den[:, None], K.curve_evaluate(*curve, a + s * (b - a)), atol=1e-12
        )


def test_reparametrize_maps_the_domain():
    knots = np.array([0, 0, 0, 2, 5, 5, 5.0])
    np.testing.assert_allclose(K.reparametrize(knots, 0, 1), [0, 0, 0, 0.4, 1, 1, 1])
    periodic = K.periodic_curve(np.eye(3) * [1, 2, 3], 2)[1]
    out = K.reparametrize(periodic * 3 + 1, -1, 1, degree=2)
    assert out[2] == -1 and out[len(out) - 3] == 1


def test_make_compatible_gives_one_basis_and_keeps_shapes():
    rng = np.random.default_rng(8)
    curves = [
        random_curve(rng, 1, n=4, rational=False),
        random_curve(rng, 3, n=9),
        K.circle(1.0),
        (
            K.periodic_curve(rng.normal(size=(5, 3)), 2)[0],
            2,
            K.periodic_curve(rng.normal(size=(5, 3)), 2)[1],
            None,
        ),
    ]
    out = K.make_compatible(curves)
    assert len({len(c[0]) for c in out}) == 1
    assert {c[1] for c in out} == {3}
    for a, b in zip(curves, out, strict=True):
        np.testing.assert_array_equal(b[2], out[0][2])
        assert b[3] is not None  # one rational curve makes all rational
        ta = K.reparametrize(a[2], 0, 1, a[1])
        assert shape_error((a[0], a[1], ta, a[3]), b) < 1e-10


# ------------------------------------------------------------------ circles and arcs


normals = st.tuples(*[st.floats(-1, 1) for _ in range(3)]).filter(
    lambda n: np.linalg.norm(n) > 1e-3
)


@settings(max_examples=40, deadline=None)
@given(
    normal=normals,
    radius=st.floats(0.01, 100),
    center=st.tuples(*[st.floats(-50, 50) for _ in range(3)]),
)
def test_circle_radius_is_exact_in_any_plane(normal, radius, center):
    cp, p, knots, w = K.circle(radius, center, normal)
    assert cp.shape == (9, 3) and p == 2
    pts = K.curve_evaluate(cp, p, knots, w, np.linspace(0, 1, 257))
    rel = pts - np.asarray(center)
    np.testing.assert_allclose(np.linalg.norm(rel, axis=1), radius, rtol=1e-12, atol=1e-12 * 50)
    n = np.asarray(normal) / np.linalg.norm(normal)
    assert np.abs(rel @ n).max() < 1e-12 * (radius + 50)
    np.testing.assert_allclose(pts[0], pts[-1], atol=0)


def test_circle_starts_at_plus_x_and_runs_counter_clockwise():
    cp, p, knots, w = K.circle(2.0, (1, 1, 0))
    np.testing.assert_allclose(K.curve_evaluate(cp, p, knots, w, 0.0), [3, 1, 0])
    np.testing.assert_allclose(K.curve_evaluate(cp, p, knots, w, 0.25), [1, 3, 0], atol=1e-15)
    d = K.curve_derivatives(cp, p, knots, w, np.array([0.0]), 1)[1, 0]
    assert d[1] > 0  # heading +y at +x: counter-clockwise around +z


@pytest.mark.parametrize(
    "start,end,pieces", [(0, 90, 1), (30, 200, 2), (-45, 240, 4), (10, -100, 2), (0, 360, 4)]
)
def test_arc_ends_pieces_and_radius(start, end, pieces):
    cp, p, knots, w = K.arc(1.5, start, end, (0, 0, 1), (0, 0, 1))
    assert len(cp) == 2 * pieces + 1
    ends = K.curve_evaluate(cp, p, knots, w, np.array([0.0, 1.0]))
    for pt, ang in zip(ends, (start, end), strict=True):
        a = math.radians(ang)
        np.testing.assert_allclose(pt, [1.5 * math.cos(a), 1.5 * math.sin(a), 1], atol=1e-14)
    pts = K.curve_evaluate(cp, p, knots, w, np.linspace(0, 1, 100))
    np.testing.assert_allclose(np.linalg.norm(pts[:, :2], axis=1), 1.5, rtol=1e-13)


def test_plane_frame_is_the_dxf_arbitrary_axis():
    np.testing.assert_allclose(K.plane_frame([0, 0, 1]), np.eye(3))
    f = K.plane_frame([0, 0, -1])
    np.testing.assert_allclose(f[0], [-1, 0, 0])
    f = K.plane_frame([1, 2, 3])
    np.testing.assert_allclose(f @ f.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(f) > 0


# --------------------------------------------------------------------- interpolation


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("parametrization", ["chord", "centripetal", "uniform"])
def test_interpolation_passes_through_its_points(closed, degree, parametrization):
    pts = np.random.default_rng(degree).normal(size=(9, 3))
    cp, p, knots, w = K.interpolate(pts, degree, closed, parametrization)
    K.validate_curve(cp, p, knots, w)
    u = K.interpolation_parameters(pts, closed, parametrization)
    np.testing.assert_allclose(K.curve_evaluate(cp, p, knots, w, u), pts, atol=1e-12)
    t0, t1 = knots[p], knots[len(cp)]
    assert (t0, t1) == (0.0, 1.0)  # open or closed, even or odd: starts at the first point
    ders = K.curve_derivatives(cp, p, knots, w, np.array([t0, t1]), min(p - 1, 2))
    if closed:  # closes with the continuity of the degree
        np.testing.assert_allclose(ders[:, 0], ders[:, 1], atol=1e-9 * np.abs(ders).max())
    else:
        np.testing.assert_allclose(ders[0], pts[[0, -1]], atol=1e-12)


@pytest.mark.parametrize("centripetal", [False, True])
def test_interpolation_matches_geomdl(centripetal):
    pts = np.random.default_rng(9).normal(size=(11, 3))
    ref = fitting.interpolate_curve(pts.tolist(), 3, centripetal=centripetal)
    cp, p, knots, _ = K.interpolate(
        pts, 3, parametrization="centripetal" if centripetal else "chord"
    )
    np.testing.assert_allclose(knots, ref.knotvector, atol=1e-14)
    np.testing.assert_allclose(cp, np.array(ref.ctrlpts), atol=1e-12)


def test_interpolation_degree_is_capped_by_the_count():
    pts = np.array([[0, 0, 0], [1, 1, 0.0]])
    cp, p, knots, _ = K.interpolate(pts, 3)
    assert p == 1
    assert K.interpolate(np.eye(3), 5, closed=True)[1] == 2
    assert K.interpolate(np.eye(3), 5)[1] == 2


def test_closed_interpolation_drops_a_repeated_first_point():
    pts = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [1, 0, 0.0]])
    a = K.interpolate(pts, 3, closed=True)
    b = K.interpolate(pts[:-1], 3, closed=True)
    np.testing.assert_allclose(a[0], b[0])


def test_periodic_curve_is_closed_and_smooth():
    poly = np.random.default_rng(11).normal(size=(7, 3))
    for p in (1, 2, 3, 4):
        cp, knots, w = K.periodic_curve(poly, p)
        K.validate_curve(cp, p, knots, w)
        assert knots[p] == 0 and knots[len(cp)] == 1
        d = K.curve_derivatives(cp, p, knots, w, np.array([0.0, 1.0]), p - 1)
        np.testing.assert_allclose(d[:, 0], d[:, 1], atol=1e-10 * np.abs(d).max())


# --------------------------------------------------------------------------- surfaces


def test_loft_passes_through_curves_of_different_degree_and_knots():
    rng = np.random.default_rng(12)
    curves = [
        K.circle(1.0),
        K.interpolate(rng.normal(size=(6, 3)) * 0.3 + [0, 0, 1], 3),
        (
            np.array([[1, 0, 2], [0, 1, 2], [-1, 0, 2], [0, -1, 2.0]]),
            1,
            np.array([0, 0, 1 / 3, 2 / 3, 1, 1.0]),
            None,
        ),
        K.arc(2.0, 0, 270, (0, 0, 3)),
        random_curve(rng, 5, n=8),
    ]
    surf = K.loft(curves)
    cp, pu, pv, ku, kv, w = surf
    K.validate_surface(*surf)
    assert pv == 3 and cp.shape[1] == len(curves)
    compat = K.make_compatible(curves)
    v = K.interpolation_parameters(np.stack([c[0] for c in compat]))
    for curve, vk in zip(curves, v, strict=True):
        np.testing.assert_allclose(
            K.surface_evaluate(*surf, T, vk), K.curve_evaluate(*curve, T), atol=1e-12
        )


def test_loft_of_two_curves_is_ruled_and_closed_loft_wraps():
    a, b = K.circle(1.0), K.circle(2.0, (0, 0, 1))
    surf = K.loft([a, b])
    assert surf[2] == 1
    mid = K.surface_evaluate(*surf, T, 0.5)
    np.testing.assert_allclose(
        mid, 0.5 * (K.curve_evaluate(*a, T) + K.curve_evaluate(*b, T)), atol=1e-12
    )
    rings = [
        K.circle(1.0, (3 * math.cos(x), 3 * math.sin(x), 0), (-math.sin(x), math.cos(x), 0))
        for x in np.linspace(0, 2 * np.pi, 6, endpoint=False)
    ]
    v = np.linspace(0, 1, 6, endpoint=False)  # equal spacing: the rings are congruent
    for degree_v in (2, 3, 4):
        torus = K.loft(rings, degree_v=degree_v, closed=True)
        cp, pu, pv, ku, kv, w = torus
        assert pv == degree_v and (kv[pv], kv[cp.shape[1]]) == (0.0, 1.0)
        np.testing.assert_allclose(
            K.surface_evaluate(*torus, T, 0.0), K.surface_evaluate(*torus, T, 1.0), atol=1e-12
        )
        for ring, vk in zip(rings, v, strict=True):
            np.testing.assert_allclose(
                K.surface_evaluate(*torus, T, vk), K.curve_evaluate(*ring, T), atol=1e-12
            )


def test_extrude_is_a_ruled_surface():
    curve = random_curve(np.random.default_rng(13), 3, n=6)
    surf = K.extrude(curve, (1, 2, 3))
    for v in (0.0, 0.3, 1.0):
        np.testing.assert_allclose(
            K.surface_evaluate(*surf, T, v),
            K.curve_evaluate(*curve, T) + v * np.array([1, 2, 3]),
            atol=1e-12,
        )


@pytest.mark.parametrize("angle", [360.0, 135.0, -90.0])
def test_revolve_keeps_the_profile_radii(angle):
    rng = np.random.default_rng(14)
    axis_point, axis = np.array([1.0, -2.0, 0.5]), np.array([1.0, 1.0, 2.0])
    profile = random_curve(rng, 3, n=6)
    surf = K.revolve(profile, axis_point, axis, angle)
    a = axis / np.linalg.norm(axis)
    prof = K.curve_evaluate(*profile, T) - axis_point
    pts = K.surface_evaluate(*surf, T[:, None], np.linspace(0, 1, 31)[None, :]) - axis_point
    height = prof @ a
    radius = np.linalg.norm(prof - height[:, None] * a, axis=1)
    h = pts @ a
    r = np.linalg.norm(pts - h[..., None] * a, axis=-1)
    np.testing.assert_allclose(h, np.broadcast_to(height[:, None], h.shape), atol=1e-12)
    np.testing.assert_allclose(r, np.broadcast_to(radius[:, None], r.shape), atol=1e-12)
    np.testing.assert_allclose(K.surface_evaluate(*surf, T, 0.0), prof + axis_point, atol=1e-12)
    # the far end is the profile turned by the angle (right-hand rule about the axis)
    end = K.surface_evaluate(*surf, T, 1.0) - axis_point
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    turned = prof * c + np.cross(a, prof) * s + np.outer(prof @ a, a) * (1 - c)
    np.testing.assert_allclose(end, turned, atol=1e-12)


def helix(turns=3.0, m=200, radius=2.0, pitch=1.0):
    s = np.linspace(0, 2 * np.pi * turns, m)
    x = np.stack([radius * np.cos(s), radius * np.sin(s), pitch * s / (2 * np.pi)], -1)
    t = np.stack(
        [-radius * np.sin(s), radius * np.cos(s), np.full_like(s, pitch / (2 * np.pi))], -1
    )
    return x, t


def s_bend(m=150):
    s = np.linspace(-3, 3, m)
    x = np.stack([s, np.tanh(2 * s) * 2, 0.2 * s**2], -1)
    t = np.stack([np.ones_like(s), 4 / np.cosh(2 * s) ** 2, 0.4 * s], -1)
    return x, t


@pytest.mark.parametrize("path", [helix, s_bend])
def test_rotation_minimizing_frames_do_not_flip_or_twist(path):
    x, t = path()
    f = K.rotation_minimizing_frames(x, t)
    np.testing.assert_allclose(
        np.einsum("mij,mkj->mik", f, f), np.broadcast_to(np.eye(3), f.shape), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(f), 1.0, atol=1e-12)
    # no flips: consecutive normals stay close
    assert np.min(np.sum(f[1:, 0] * f[:-1, 0], axis=1)) > 0.99
    # rotation-minimizing: the normal turns about the tangent as little as possible, so
    # its change has (almost) no component along the binormal
    dr = f[1:, 0] - f[:-1, 0]
    twist = np.abs(np.sum(dr * 0.5 * (f[1:, 1] + f[:-1, 1]), axis=1))
    assert twist.max() < 1e-3


def test_rotation_minimizing_frame_of_a_planar_curve_keeps_the_plane_normal():
    s = np.linspace(0, 4, 90)
    x = np.stack([s, np.sin(s), 0 * s], -1)
    t = np.stack([np.ones_like(s), np.cos(s), 0 * s], -1)
    f = K.rotation_minimizing_frames(x, t, initial=(0, 0, 1))
    np.testing.assert_allclose(f[:, 0], np.broadcast_to([0, 0, 1.0], (90, 3)), atol=1e-12)


def test_closed_path_frames_close_up():
    s = np.linspace(0, 2 * np.pi, 80, endpoint=False)
    # a closed curve off any plane: the transport alone would not come back to itself
    x = np.stack([np.cos(s), np.sin(s), 0.5 * np.sin(2 * s)], -1)
    t = np.stack([-np.sin(s), np.cos(s), np.cos(2 * s)], -1)
    f = K.rotation_minimizing_frames(x, t, closed=True)
    # one more step of transport from the last station returns to the first frame
    steps = _reflection_steps(
        x[-1:], t[-1:] / np.linalg.norm(t[-1]), x[:1], t[:1] / np.linalg.norm(t[0])
    )
    r_back = steps[0] @ f[-1, 0]
    # the distributed correction turns the last step by 1/80 of the holonomy only
    assert float(r_back @ f[0, 0]) > math.cos(2 * np.pi / 80)
    assert np.min(np.sum(f[1:, 0] * f[:-1, 0], axis=1)) > 0.99


@pytest.mark.parametrize("path", [helix, s_bend])
def test_sweep_keeps_the_profile_at_its_distance_from_the_path(path):
    x, t = path()
    surf = K.sweep(K.circle(0.3), x, t)
    v = K.interpolation_parameters(x)
    pts = K.surface_evaluate(*surf, np.linspace(0, 1, 40)[:, None], v[None, :])
    np.testing.assert_allclose(np.linalg.norm(pts - x[None], axis=-1), 0.3, atol=1e-12)
    # the profile's plane is normal to the path
    tn = t / np.linalg.norm(t, axis=1)[:, None]
    assert np.abs(np.einsum("umd,md->um", pts - x[None], tn)).max() < 1e-12
    # and between stations it stays close
    mid = 0.5 * (v[1:] + v[:-1])
    between = K.surface_evaluate(*surf, np.linspace(0, 1, 40)[:, None], mid[None, :])
    centre = 0.5 * (x[1:] + x[:-1])
    assert np.abs(np.linalg.norm(between - centre[None], axis=-1) - 0.3).max() < 0.01


def test_sweep_along_a_closed_path_is_periodic():
    s = np.linspace(0, 2 * np.pi, 65)
    x = np.stack([3 * np.cos(s), 3 * np.sin(s), 0.5 * np.sin(3 * s)], -1)
    t = np.stack([-3 * np.sin(s), 3 * np.cos(s), 1.5 * np.cos(3 * s)], -1)
    cp, pu, pv, ku, kv, w = surf = K.sweep(K.circle(0.5), x, t)
    a = K.surface_evaluate(*surf, T, kv[pv])
    b = K.surface_evaluate(*surf, T, kv[cp.shape[1]])
    np.testing.assert_allclose(a, b, atol=1e-12)


def test_sweep_places_the_profile_xy_plane_normal_to_the_path():
    # path straight up +z: the frame is the world's, so the profile keeps its coordinates
    x = np.stack([np.zeros(5), np.zeros(5), np.linspace(0, 4, 5)], -1)
    t = np.tile([0, 0, 1.0], (5, 1))
    profile = K.circle(1.0, (0.5, 0, 0))
    surf = K.sweep(profile, x, t)
    np.testing.assert_allclose(
        K.surface_evaluate(*surf, T, 0.0), K.curve_evaluate(*profile, T), atol=1e-12
    )


# ------------------------------------------------------------------------ bad inputs


GOOD = (np.zeros((4, 3)), 3, np.array([0, 0, 0, 0, 1, 1, 1, 1.0]), None)


@pytest.mark.parametrize(
    "args,match",
    [
        ((np.zeros((3, 3)), 3, GOOD[2][:-1], None), "degree 3 needs at least 4 control points"),
        ((GOOD[0], 0, GOOD[2], None), "degree must be at least 1"),
        ((GOOD[0], 2.5, GOOD[2], None), "degree must be an integer"),
        ((GOOD[0], 3, GOOD[2][:-1], None), "need 8 knots .* got 7"),
        ((GOOD[0], 3, np.array([0, 0, 0, 1, 0.5, 1, 1, 1.0]), None), "non-decreasing"),
        ((GOOD[0], 3, np.array([0, 0, 0, 0, 0, 0, 0, 0.0]), None), "empty domain"),
        ((GOOD[0], 3, np.array([0, 0, 0, 0, np.nan, 1, 1, 1.0]), None), "finite"),
        (
            (np.zeros((5, 3)), 1, np.array([0, 0.5, 0.5, 0.5, 1, 1, 1.0]), None),
            "repeats 3 times; a knot may repeat at most degree \\+ 1 = 2",
        ),
        ((GOOD[0], 3, GOOD[2], np.array([1, 1, 0, 1.0])), "weights must be positive"),
        ((GOOD[0], 3, GOOD[2], np.array([1, 1, 1.0])), "one value per control point"),
        ((GOOD[0], 3, GOOD[2], np.array([1, 1, np.inf, 1.0])), "weights must be finite"),
        ((np.zeros((4, 2)), 3, GOOD[2], None), "\\(n, 3\\) array"),
        ((np.full((4, 3), np.nan), 3, GOOD[2], None), "control points must be finite"),
    ],
)
def test_validate_curve_errors(args, match):
    with pytest.raises(ValueError, match=match):
        K.validate_curve(*args)


def test_validate_surface_errors():
    cp = np.zeros((4, 3, 3))
    ku, kv = K.clamped_uniform_knots(4, 3), K.clamped_uniform_knots(3, 2)
    K.validate_surface(cp, 3, 2, ku, kv, None)
    with pytest.raises(ValueError, match="v: degree 3 needs at least 4 control points, got 3"):
        K.validate_surface(cp, 3, 3, ku, K.clamped_uniform_knots(4, 3), None)
    with pytest.raises(ValueError, match="u: knots: 4 control points of degree 3 need 8"):
        K.validate_surface(cp, 3, 2, ku[:-1], kv, None)
    with pytest.raises(ValueError, match="shape \\(4, 3\\), got shape \\(3, 4\\)"):
        K.validate_surface(cp, 3, 2, ku, kv, np.ones((3, 4)))
    with pytest.raises(ValueError, match="\\(nu, nv, 3\\) array"):
        K.validate_surface(np.zeros((4, 3)), 3, 2, ku, kv, None)


def test_knot_operation_errors():
    curve = random_curve(np.random.default_rng(15), 3, n=6)
    with pytest.raises(
        ValueError,
        match="multiplicity 0; inserting it 4 more time\\(s\\) would exceed the degree 3",
    ):
        K.insert_knot(*curve, 0.5, 4)
    twice = K.insert_knot(*curve, 0.5, 2)
    with pytest.raises(ValueError, match="knot 0.5 has multiplicity 2"):
        K.insert_knot(*twice, 0.5, 2)
    with pytest.raises(ValueError, match="knot 1.5 is outside the curve's domain \\[0, 1\\]"):
        K.insert_knot(*curve, 1.5)
    with pytest.raises(ValueError, match="times must be a whole number >= 0"):
        K.insert_knot(*curve, 0.5, -1)
    with pytest.raises(ValueError, match="knot 0 has multiplicity 4"):
        K.refine_knots(*curve, [0.0])
    with pytest.raises(ValueError, match="times must be a whole number"):
        K.elevate_degree(*curve, 1.5)
    with pytest.raises(ValueError, match="t0 < t1"):
        K.reparametrize(curve[2], 1, 0)
    with pytest.raises(ValueError, match="at least one curve"):
        K.make_compatible([])


def test_construction_errors():
    with pytest.raises(ValueError, match="radius must be a positive number, got -1"):
        K.circle(-1)
    with pytest.raises(ValueError, match="normal must be a non-zero vector"):
        K.circle(1, normal=(0, 0, 0))
    with pytest.raises(ValueError, match="more than 0 and at most 360 degrees, got 10 to 10"):
        K.arc(1, 10, 10)
    with pytest.raises(ValueError, match="more than 0 and at most 360 degrees, got 0 to 400"):
        K.arc(1, 0, 400)
    with pytest.raises(ValueError, match="center must be a finite"):
        K.arc(1, 0, 90, center=(0, np.nan, 0))
    with pytest.raises(ValueError, match="points 1 and 2 coincide"):
        K.interpolate(np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0.0]]))
    with pytest.raises(ValueError, match="an open interpolating curve needs at least 2 points"):
        K.interpolate(np.zeros((1, 3)))
    with pytest.raises(ValueError, match="a closed interpolating curve needs at least 3 points"):
        K.interpolate(np.eye(3)[:2], closed=True)
    with pytest.raises(
        ValueError, match="parametrization must be one of chord, centripetal, uniform, got 'arc'"
    ):
        K.interpolate(np.eye(3), parametrization="arc")
    with pytest.raises(ValueError, match="a loft needs at least 2 curves, got 1"):
        K.loft([K.circle()])
    with pytest.raises(ValueError, match="a closed loft needs at least 3 curves, got 2"):
        K.loft([K.circle(), K.circle(2.0)], closed=True)
    with pytest.raises(ValueError, match="two consecutive curves of the loft coincide"):
        K.loft([K.circle(), K.circle(), K.circle(2.0)])
    with pytest.raises(ValueError, match="direction must be a non-zero vector"):
        K.extrude(K.circle(), (0, 0, 0))
    with pytest.raises(ValueError, match="axis must be a non-zero vector"):
        K.revolve(K.circle(), axis=(0, 0, 0))
    with pytest.raises(ValueError, match="angle must be more than 0 and at most 360"):
        K.revolve(K.circle(), angle_deg=0)
    with pytest.raises(ValueError, match="a sweep path needs at least 2 points"):
        K.sweep(K.circle(), np.zeros((1, 3)), np.ones((1, 3)))
    with pytest.raises(ValueError, match="tangents must be finite and non-zero"):
        K.sweep(K.circle(), np.eye(3), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="consecutive sweep path points coincide"):
        K.sweep(K.circle(), np.array([[0, 0, 0], [0, 0, 0], [0, 0, 1.0]]), np.ones((3, 3)))
