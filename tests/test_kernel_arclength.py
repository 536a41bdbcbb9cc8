"""Tests of formgraph.kernels.curves.arclength: the length against closed forms (the
perimeter of an ellipse by scipy's complete elliptic integral, a helix), even division
checked by scipy's adaptive quadrature between consecutive parameters, and the table's
inverse against a hypothesis range of curves."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.special import ellipe

from formgraph.kernels.curves import (
    arc_length_table,
    even_arc_parameters,
    even_lengths,
    parameters_at_lengths,
)


def ellipse_derivative(a: float, b: float):
    def d(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        return np.stack([-a * np.sin(t), b * np.cos(t), np.zeros_like(t)], axis=-1)

    return d


def quad_length(d, t0: float, t1: float) -> float:
    return quad(lambda t: float(np.linalg.norm(d(np.array([t]))[0])), t0, t1, epsabs=1e-13)[0]


def test_even_lengths_open_has_both_ends_closed_no_repeat():
    np.testing.assert_allclose(even_lengths(6.0, 4, closed=False), [0, 2, 4, 6])
    np.testing.assert_allclose(even_lengths(6.0, 4, closed=True), [0, 1.5, 3, 4.5])


@pytest.mark.parametrize("closed", [False, True])
def test_ellipse_divided_into_equal_arcs_of_the_exact_perimeter(closed):
    a, b = 3.0, 1.0
    d = ellipse_derivative(a, b)
    perimeter = 4 * a * ellipe(1 - (b / a) ** 2)
    seen = []

    def divisions(length: float) -> int:
        seen.append(length)
        return 9

    breaks = np.linspace(0, 2 * np.pi, 5)  # the quarter points, as a NURBS circle's spans
    t = even_arc_parameters(d, breaks, divisions, closed)
    assert seen == [pytest.approx(perimeter, rel=1e-12)] and len(t) == 9
    assert t[0] == 0.0 and np.all(np.diff(t) > 0)
    ends = np.append(t, 2 * np.pi) if closed else t
    gaps = [quad_length(d, lo, hi) for lo, hi in zip(ends[:-1], ends[1:], strict=True)]
    np.testing.assert_allclose(gaps, perimeter / (9 if closed else 8), rtol=1e-10)
    if not closed:
        assert t[-1] == pytest.approx(2 * np.pi, abs=1e-12)


def test_helix_parameters_are_linear_in_length():
    """A helix has constant speed sqrt(r^2 + c^2): equal lengths are equal parameters."""
    r, c = 2.0, 0.5

    def d(t):
        t = np.asarray(t, dtype=float)
        return np.stack([-r * np.sin(t), r * np.cos(t), np.full_like(t, c)], axis=-1)

    t = even_arc_parameters(d, [0.0, 10.0], lambda length: 21, closed=False, pieces=4)
    np.testing.assert_allclose(t, np.linspace(0, 10, 21), atol=1e-12)


def test_divisions_is_asked_before_anything_of_its_size_is_made():
    class Refused(Exception):
        pass

    def refuse(length: float) -> int:
        raise Refused(length)

    with pytest.raises(Refused):
        even_arc_parameters(ellipse_derivative(1, 1), [0, 1], refuse, closed=False)


@settings(max_examples=40, deadline=None)
@given(
    a=st.floats(0.2, 5.0),
    b=st.floats(0.2, 5.0),
    frac=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=8),
)
def test_table_inverse_lands_on_the_asked_lengths(a, b, frac):
    d = ellipse_derivative(a, b)

    def speed(t):
        return np.linalg.norm(d(t), axis=-1)

    edges, cum = arc_length_table(speed, np.linspace(0, math.pi, 3), pieces=8)
    s = np.sort(np.array(frac)) * cum[-1]
    t = parameters_at_lengths(speed, edges, cum, s)
    back = [quad_length(d, 0.0, ti) for ti in t]
    np.testing.assert_allclose(back, s, atol=1e-10 * cum[-1])


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), count=st.integers(2, 400), closed=st.booleans())
def test_the_interpolant_inverse_lands_where_newton_alone_does(seed, count, closed):
    """even_arc_parameters inverts the table through each piece's Gauss-node polynomial and
    runs Newton only where that polynomial is not exact; random-walk cubics (some with a
    near-cusp, where it is not) land where Newton from the linear guess lands."""
    from formgraph.kernels import nurbs

    rng = np.random.default_rng(seed)
    cp = np.cumsum(rng.normal(size=(12, 3)), axis=0)
    knots = nurbs.clamped_uniform_knots(12, 3)

    def d(t):
        return nurbs.curve_derivatives(cp, 3, knots, None, t, 1)[1]

    def speed(t):
        return np.linalg.norm(d(t), axis=-1)

    breaks = np.unique(knots)
    t = even_arc_parameters(d, breaks, lambda length: count, closed)
    edges, cum = arc_length_table(speed, breaks)
    s = even_lengths(cum[-1], count, closed)
    newton = parameters_at_lengths(speed, edges, cum, s, iterations=12)
    np.testing.assert_allclose(t, newton, atol=1e-12)


def test_a_kink_inside_a_piece_is_found_and_solved_by_newton():
    """A speed with a kink (|t - 0.3| + 0.05) inside a piece: no polynomial is exact there,
    the piece is checked, found out, and its points placed by Newton on the curve itself:
    where Newton alone places them. (The table's own quadrature is not exact across a kink:
    kinks belong at breaks, as a NURBS's knots are.)"""
    from formgraph.kernels.curves import arclength

    def d(t):
        t = np.asarray(t, dtype=float)
        return np.stack([np.abs(t - 0.3) + 0.05, np.zeros_like(t), np.zeros_like(t)], axis=-1)

    def speed(t):
        return np.linalg.norm(d(t), axis=-1)

    edges, cum, at_nodes = arclength._table(speed, np.array([0.0, 1.0]), 4)
    c, scale = arclength._monomial(at_nodes), np.abs(at_nodes).mean(axis=1)
    trusted = arclength._interpolant_exact(speed, edges, np.arange(4), c, scale)
    assert trusted.tolist() == [True, False, True, True]  # the kink is in [0.25, 0.5]
    t = even_arc_parameters(d, [0.0, 1.0], lambda length: 41, closed=False, pieces=4)
    s = even_lengths(cum[-1], 41, False)
    newton = parameters_at_lengths(speed, edges, cum, s, iterations=12)
    np.testing.assert_allclose(t, newton, atol=1e-13)
    # and the interpolant alone would have been off there
    interpolant_only = parameters_at_lengths(speed, edges, cum, s, iterations=0, at_nodes=at_nodes)
    inside = (t > 0.25) & (t < 0.5)
    assert np.abs(interpolant_only - t)[inside].max() > 1e-6
