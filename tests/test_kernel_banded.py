"""Banded and cyclic-banded solves (kernels/nurbs/banded.py) and the interpolation built on
them, against dense LAPACK solves and scipy's B-spline interpolation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from formgraph.kernels import nurbs as K
from formgraph.kernels.nurbs import fit
from formgraph.kernels.nurbs.banded import banded_entries, solve_banded_rows
from formgraph.kernels.nurbs.fit import _collocation_rows, _periodic_knots


def _dense(cols, vals, n):
    A = np.zeros((n, n))
    np.add.at(A, (np.repeat(np.arange(n), cols.shape[1]), cols.ravel()), vals.ravel())
    return A


def _random_band(rng, n, lower, upper, cyclic):
    """Diagonally dominant rows with ``lower`` / ``upper`` neighbours (wrapped if cyclic)."""
    offs = np.arange(-lower, upper + 1)
    cols = np.arange(n)[:, None] + offs
    vals = rng.uniform(-1, 1, cols.shape)
    vals[:, lower] = (np.abs(vals).sum(axis=1) + 0.5) * rng.choice([-1, 1], n)
    if cyclic:
        cols %= n
    else:
        keep = (cols >= 0) & (cols < n)
        vals = np.where(keep, vals, 0.0)
        cols = np.clip(cols, 0, n - 1)
    return cols, vals


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(1, 400),
    lower=st.integers(0, 5),
    upper=st.integers(0, 5),
    cyclic=st.booleans(),
    rhs=st.integers(1, 4),
    seed=st.integers(0, 10_000),
)
def test_banded_solve_matches_a_dense_solve(n, lower, upper, cyclic, rhs, seed):
    rng = np.random.default_rng(seed)
    cols, vals = _random_band(rng, n, lower, upper, cyclic)
    b = rng.normal(size=(n, rhs))
    x = solve_banded_rows(cols, vals, b, cyclic=cyclic)
    ref = np.linalg.solve(_dense(cols, vals, n), b)
    np.testing.assert_allclose(x, ref, atol=1e-10 * max(1.0, np.abs(ref).max()))


def test_a_singular_banded_system_is_refused():
    n = 100
    cols = np.stack([np.arange(n), np.minimum(np.arange(n) + 1, n - 1)], axis=1)
    vals = np.ones((n, 2))
    vals[50] = 0.0  # an empty row
    with pytest.raises(ValueError, match="singular"):
        solve_banded_rows(cols, vals, np.ones(n))


@settings(max_examples=40, deadline=None)
@given(
    n=st.integers(8, 300),
    degree=st.integers(1, 7),
    closed=st.booleans(),
    seed=st.integers(0, 10_000),
)
def test_collocation_solve_matches_the_dense_one(n, degree, closed, seed):
    """The interpolation system as the seed solved it (dense), against the banded solve."""
    rng = np.random.default_rng(seed)
    steps = rng.uniform(0.05, 3.0, n)  # uneven chords
    u = np.concatenate([[0.0], np.cumsum(steps)])
    u = (u / u[-1])[:n] if closed else u[:n] / u[n - 1]
    p = min(degree, n - 1)
    data = rng.normal(size=(n, 3))
    cp, knots = K.fit_columns(data, u, p, closed)
    if not closed:
        cols, vals = _collocation_rows(p, knots, u)
        ref = np.linalg.solve(_dense(cols, vals, n), data)
        np.testing.assert_allclose(cp, ref, atol=1e-9 * np.abs(ref).max())
    else:
        kn = _periodic_knots(u, p)
        t = u if p % 2 == 1 else np.where(u < kn[p], u + 1.0, u)
        cols, vals = _collocation_rows(p, kn, t)
        ref = np.linalg.solve(_dense(cols % n, vals, n), data)
        if p % 2 == 1:  # odd degrees keep the periodic knots as they are
            np.testing.assert_allclose(cp[:n], ref, atol=1e-9 * np.abs(ref).max())
    np.testing.assert_allclose(K.curve_evaluate(cp, p, knots, None, u), data, atol=1e-9)


def test_open_interpolation_matches_scipy():
    interpolate = pytest.importorskip("scipy.interpolate")
    rng = np.random.default_rng(3)
    pts = np.cumsum(rng.normal(size=(2000, 3)), axis=0)
    cp, p, knots, _ = K.interpolate(pts, 3)
    u = K.interpolation_parameters(pts)
    ref = interpolate.make_interp_spline(u, pts, k=3, t=knots)
    np.testing.assert_allclose(cp, ref.c, atol=1e-9 * np.abs(pts).max())


@pytest.mark.parametrize("closed", [False, True])
def test_a_hundred_thousand_points_interpolate(closed):
    t = np.linspace(0, 40 * np.pi, 100_000, endpoint=not closed)
    pts = np.column_stack([np.cos(t), np.sin(t), np.sin(0.37 * t)])
    cp, p, knots, _ = K.interpolate(pts, 3, closed)
    u = K.interpolation_parameters(pts, closed)
    np.testing.assert_allclose(K.curve_evaluate(cp, p, knots, None, u), pts, atol=1e-9)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("degree", [2, 3, 5, 7])
def test_wildly_uneven_spacing_is_accurate_or_refused(closed, degree):
    """Chords from 1e-8 to 1 (collocation condition numbers up to 1e24): the curve passes
    through its points, or the node is told why not; never a silently wrong curve."""
    rng = np.random.default_rng(degree + 10 * closed)
    steps = 10 ** rng.uniform(-8, 0, 3000)
    x = np.cumsum(steps)
    pts = np.column_stack([x, np.sin(x), np.zeros_like(x)])
    try:
        cp, p, knots, _ = K.interpolate(pts, degree, closed)
    except ValueError as exc:
        assert "ill-conditioned" in str(exc)
        return
    u = K.interpolation_parameters(pts, closed)
    miss = np.abs(K.curve_evaluate(cp, p, knots, None, u) - pts).max()
    assert miss <= 1e-7 * np.abs(pts).max()


@pytest.mark.parametrize("closed", [False, True])
def test_the_charge_covers_what_the_solve_holds(closed):
    # What a node charges against its budget before asking for the fit (numpy's and
    # LAPACK's arrays, traced), for a cubic through 200,000 points in 3 columns.
    import tracemalloc

    n = 200_000
    t = np.linspace(0, 40 * np.pi, n, endpoint=not closed)
    pts = np.column_stack([np.cos(t), np.sin(t), np.sin(0.37 * t)])
    tracemalloc.start()
    try:
        K.interpolate(pts, 3, closed)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak / 8 <= banded_entries(n, 4, 3, closed)


def test_open_fit_falls_back_to_the_rows_solve(monkeypatch):
    # If scipy's solve refuses, the rows' own banded solve gives the same curve.
    import scipy.interpolate

    rng = np.random.default_rng(8)
    pts = np.cumsum(rng.normal(size=(500, 3)), axis=0)
    cp, p, knots, _ = K.interpolate(pts, 3)

    def refuse(*args, **kwargs):
        raise np.linalg.LinAlgError("refused")

    monkeypatch.setattr(scipy.interpolate, "make_interp_spline", refuse)
    cp2, _, knots2, _ = K.interpolate(pts, 3)
    np.testing.assert_array_equal(knots, knots2)
    np.testing.assert_allclose(cp2, cp, atol=1e-9 * np.abs(pts).max())
    u = K.interpolation_parameters(pts)
    cols, vals = fit._collocation_rows(3, knots, u)
    np.testing.assert_allclose(_dense(cols, vals, 500) @ cp2, pts, atol=1e-9 * np.abs(pts).max())


def test_averaged_knots_by_running_sums_match_the_definition():
    # Eq. 9.8: knot j + p is the mean of parameters j .. j + p - 1 (running sums, kept in
    # order against rounding).
    rng = np.random.default_rng(2)
    u = np.concatenate([[0.0], np.sort(rng.uniform(0, 1, 998)), [1.0]])
    for p in (1, 2, 3, 5):
        knots = fit._averaged_knots(u, p)
        inner = [u[j : j + p].mean() for j in range(1, len(u) - p)]
        np.testing.assert_allclose(knots[p + 1 : -p - 1], inner, atol=1e-14)
        assert (np.diff(knots) >= 0).all()


def test_open_fit_without_scipys_private_collocation(monkeypatch):
    # The band comes from scipy's own (not public) collocation routine; without it the
    # public make_interp_spline does the same fit.
    rng = np.random.default_rng(9)
    pts = np.cumsum(rng.normal(size=(400, 3)), axis=0)
    cp, _, knots, _ = K.interpolate(pts, 3)
    monkeypatch.setattr(fit, "_scipy_coloc", lambda: None)
    cp2, _, _, _ = K.interpolate(pts, 3)
    np.testing.assert_allclose(cp2, cp, atol=1e-9 * np.abs(pts).max())
    u = K.interpolation_parameters(pts)
    np.testing.assert_allclose(
        K.curve_evaluate(cp, 3, knots, None, u), pts, atol=1e-9 * np.abs(pts).max()
    )


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from([1, 2, 3, 4, 5]), st.sampled_from([1, 3, 7]))
def test_open_fit_of_many_columns_matches_scipy(seed, degree, columns):
    # The band is at most p - 1 wide on each side with averaged knots (each parameter lies
    # between the means of the p parameters up to and from it; up to rounding, which may
    # leave a tiny entry one further out), and the solve gets only the live diagonals;
    # three columns or fewer share the collocation's own array, more get their own.
    from scipy import interpolate

    rng = np.random.default_rng(seed)
    k = 60 + int(rng.integers(0, 200))
    u = np.concatenate([[0.0], np.sort(rng.uniform(0, 1, k - 2)), [1.0]])
    knots = fit._averaged_knots(u, degree)
    cols, vals = fit._collocation_rows(degree, knots, u)
    # rounding in a span of width h leaves entries of about eps / h (two parameters 8e-7
    # apart gave 4.6e-9 one diagonal out)
    tiny = 1e-9 + 100 * np.finfo(float).eps / np.diff(u).min()
    live = np.abs(vals) > tiny
    offsets = (cols - np.arange(k)[:, None])[live]
    assert np.abs(offsets).max() <= max(degree - 1, 0)
    values = rng.normal(size=(k, columns))
    ctrl, knots2 = fit.fit_columns(values, u, degree)
    np.testing.assert_array_equal(knots2, knots)
    ref = interpolate.make_interp_spline(u, values, k=degree, t=knots)
    np.testing.assert_allclose(ctrl, ref.c, atol=1e-8 * np.abs(values).max())
    np.testing.assert_allclose(ref.__class__(knots, ctrl, degree)(u), values, atol=1e-9)
