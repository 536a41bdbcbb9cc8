"""Tests of the NURBS kernel's evaluation and knot operations (formgraph.kernels.nurbs)
against geomdl, closed forms and invariants (shape unchanged by knot insertion, refinement
and degree elevation), and of its validation errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from geomdl import helpers, operations
from hypothesis import given, settings
from hypothesis import strategies as st
from nurbs_shapes import T, geomdl_curve, geomdl_surface, random_curve, shape_error

from formgraph.kernels import nurbs as K

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


PLANS = [
    ((first, b1), (second, b2))
    for first, second in (("u", "v"), ("v", "u"))
    for b1 in (False, True)
    for b2 in (False, True)
]


@pytest.mark.parametrize("plan", PLANS)
@pytest.mark.parametrize("rational", [True, False])
def test_every_plan_of_a_grid_matches_the_dense_collocation_product(monkeypatch, plan, rational):
    from formgraph.kernels.nurbs import surface

    rng = np.random.default_rng(7 * rational)
    nu, nv, pu, pv = 6, 30, 2, 3
    cp = rng.normal(size=(nu, nv, 3)) * 5.0
    w = rng.uniform(0.3, 3.0, (nu, nv)) if rational else np.ones((nu, nv))
    ku = random_curve(rng, pu, n=nu)[2]
    kv = random_curve(rng, pv, n=nv)[2]
    # the ends, interior knots (where a span starts) and points between
    u = np.r_[0.0, ku[pu + 1 : nu][:3], rng.uniform(0, 1, 30), 1.0]
    v = np.r_[0.0, kv[pv + 1 : nv][:3], rng.uniform(0, 1, 50), 1.0]
    monkeypatch.setattr(surface, "_plan", lambda *_: plan)
    grid = K.surface_evaluate_grid(cp, pu, pv, ku, kv, w if rational else None, u, v)
    bu, bv = K.basis_matrix(pu, ku, u, nu), K.basis_matrix(pv, kv, v, nv)
    num = np.einsum("ai,ijc,bj->abc", bu, cp * w[..., None], bv)
    den = np.einsum("ai,ij,bj->ab", bu, w, bv)
    np.testing.assert_allclose(grid, num / den[..., None], rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize(
    "shape,plan",
    [
        ((20, 20, 300, 300, 3, 3), (("u", False), ("v", False))),  # the plain products
        ((9, 256, 65, 257, 2, 3), (("v", True), ("u", False))),  # a sweep: its band first
    ],
)
def test_the_grid_plan_sums_a_long_direction_over_its_band(shape, plan):
    from formgraph.kernels.nurbs import surface

    assert surface._plan(*shape) == plan


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
