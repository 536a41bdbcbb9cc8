"""Parametric curves and surfaces are differentiated exactly (forward mode over the
expression's syntax tree) and measured adaptively: checked against closed forms and scipy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

import formgraph as fg
from formgraph.language.derivative import taylor


def _curve(x, y, z, t=(0.0, 1.0), samples=256):
    g = fg.Graph()
    g.add("c", "curves.parametric", x=x, y=y, z=z, t=list(t), samples=samples)
    g.add("m", "curves.measure", curve="@c")
    return g


@pytest.mark.parametrize("turns", [100, 1000])
def test_helix_length_is_its_closed_form(turns):
    g = _curve("cos(t)", "sin(t)", "t / 10", (0.0, 2 * math.pi * turns))
    exact = 2 * math.pi * turns * math.sqrt(1.01)  # 200 pi sqrt(1.01) for 100 turns
    assert g.evaluate("m.length") == pytest.approx(exact, rel=1e-12)


def test_derivative_of_a_high_frequency_cosine_is_exact():
    c = _curve("cos(100 * t)", "sin(100 * t)", "0").evaluate("c")
    assert np.linalg.norm(c.derivative(0.3)) == pytest.approx(100.0, rel=1e-14)
    np.testing.assert_allclose(c.derivative(0.3, 2), [-1e4 * math.cos(30), -1e4 * math.sin(30), 0])


def test_length_agrees_with_scipy_quad_on_a_wiggly_curve():
    g = _curve("t", "sin(40 * t) * exp(-t)", "t**2 / 3", (0.0, 3.0), samples=8)

    def speed(t):
        dy = 40 * math.cos(40 * t) * math.exp(-t) - math.sin(40 * t) * math.exp(-t)
        return math.sqrt(1 + dy * dy + (2 * t / 3) ** 2)

    ref, _ = quad(speed, 0, 3, limit=5000, epsabs=0, epsrel=1e-13)
    assert g.evaluate("m.length") == pytest.approx(ref, rel=1e-12)


TEXTS = [
    "sin(t) * cos(2 * t) + t**3",
    "exp(-t) / (1 + t**2)",
    "sqrt(1 + t * t) - log(2 + t)",
    "atan2(sin(t), 2 + cos(t))",
    "tanh(t) * sinh(t / 2) + cosh(t / 3)",
    "t**t + 2**t",
    "abs(t - 0.5) + min(t, 0.7) + max(t, 0.2) + clip(t, 0.1, 0.8)",
    "asin(t / 2) + acos(t / 3) + atan(t) + tan(t / 2) + log10(1 + t)",
    "t**2 if t > 0.4 else -t",
    "where(t > 0.3, t**3, t) + floor(3 * t) + t % 0.25",
]


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(TEXTS), st.floats(0.05, 0.95))
def test_taylor_agrees_with_richardson_differences(text, t):
    from formgraph.language.expr import compile_expression

    f = compile_expression(text)
    kinks = [0.1, 0.2, 0.25, 1 / 3, 0.3, 0.4, 0.5, 2 / 3, 0.7, 0.75, 0.8]
    if min(abs(t - k) for k in kinks) < 1e-3:
        return  # a branch or floor changes there: no derivative to compare
    v, d1, d2 = taylor(text, "t", {"t": np.float64(t)})
    assert float(v) == pytest.approx(float(f(t=t)), rel=1e-13, abs=1e-13)
    h = 1e-4  # Richardson extrapolation of central differences: O(h^4)

    def cd1(h):
        return (f(t=t + h) - f(t=t - h)) / (2 * h)

    def cd2(h):
        return (f(t=t + h) - 2 * f(t=t) + f(t=t - h)) / h**2

    assert float(d1) == pytest.approx((4 * cd1(h / 2) - cd1(h)) / 3, rel=1e-7, abs=1e-7)
    assert float(d2) == pytest.approx((4 * cd2(h / 2) - cd2(h)) / 3, rel=1e-4, abs=1e-4)


def test_surface_normals_are_exact():
    g = fg.Graph()
    g.add("s", "surfaces.parametric", x="u", y="v", z="0.5 * sin(20 * u) * cos(20 * v)")
    g.add("p", "geometry.sample_surface", surface="@s", u=9, v=7)
    pts, normals = g.evaluate("p")
    u, v = pts.xyz[:, 0], pts.xyz[:, 1]
    fu, fv = 10 * np.cos(20 * u) * np.cos(20 * v), -10 * np.sin(20 * u) * np.sin(20 * v)
    exact = np.column_stack([-fu, -fv, np.ones_like(u)])
    exact /= np.linalg.norm(exact, axis=1, keepdims=True)
    np.testing.assert_allclose(normals, exact, rtol=0, atol=1e-14)


def test_noise_falls_back_to_differences():
    c = _curve("t", "noise(3 * t, 0, 0)", "0").evaluate("c")
    d = c.derivative(np.array([0.3, 0.6]))
    assert np.all(np.isfinite(d)) and np.allclose(d[:, 0], 1.0)
