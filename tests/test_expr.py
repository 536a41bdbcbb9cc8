"""The whitelisting expression language: vectorized, bounded, never eval."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from formgraph.core.errors import ExpressionError
from formgraph.language.bound import Bound
from formgraph.language.expr import compile_expression


@pytest.mark.parametrize(
    ("text", "env", "expected"),
    [
        ("2*pi*turns", {"turns": 3}, 6 * np.pi),
        ("-x ** 2", {"x": 3}, -9.0),
        ("7 % 3 + 10 / 4", {}, 3.5),
        ("atan2(1, 1) * 4", {}, np.pi),
        ("min(3, x, 2)", {"x": 1.5}, 1.5),
        ("max(3, 4)", {}, 4.0),
        ("clip(x, 0, 1)", {"x": 5}, 1.0),
        ("where(x > 1, 10, 20)", {"x": 2}, 10.0),
        ("1 if x < 0 else 2", {"x": 1}, 2.0),
        ("0 < x <= 1", {"x": 1}, True),
        ("sqrt(e) ** 2 + tau", {}, np.e + 2 * np.pi),
        ("log10(1000) + log(exp(2)) + floor(2.7) + ceil(2.1) + abs(-1)", {}, 3 + 2 + 2 + 3 + 1),
    ],
)
def test_values(text, env, expected):
    assert compile_expression(text)(env) == pytest.approx(expected)


def test_vectorized_over_arrays():
    t = np.linspace(0, 1, 1001)
    f = compile_expression("r * cos(2*pi*t) + where(t > 0.5, 1, 0)")
    out = f(r=2.0, t=t)
    assert out.shape == (1001,)
    np.testing.assert_allclose(out, 2 * np.cos(2 * np.pi * t) + (t > 0.5))


def test_bound_params_and_names():
    c = compile_expression("radius * sin(t)", {"radius", "t"})
    assert c.names == {"radius", "t"}
    b = Bound(c, {"radius": 2.0})
    assert b(t=np.pi / 2) == pytest.approx(2.0)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("__import__('os').system('ls')", "is not allowed"),
        ("().__class__.__bases__", "attribute is not allowed"),
        ("x[0]", "subscript is not allowed"),
        ("lambda: 1", "lambda is not allowed"),
        ("[i for i in x]", "listcomp is not allowed"),
        ("open('f')", "calling 'open' is not allowed"),
        ("eval('1')", "calling 'eval' is not allowed"),
        ("_x + 1", "name starting with '_' is not allowed"),
        ("'text'", "a literal of this kind is not allowed"),
        ("sin(x=1)", "a keyword argument is not allowed"),
        ("sin(1, 2)", r"sin\(\) takes 1 argument, got 2"),
        ("x if", "is not valid"),
        ("sin", "function 'sin' must be called"),
        ("a := 3", "is not valid"),
        ("x.y", "attribute is not allowed"),
        ("x @ y", "operator MatMult"),
        ("x << 2", "operator LShift"),
    ],
)
def test_refused(text, message):
    with pytest.raises(ExpressionError, match=message):
        compile_expression(text)


def test_unknown_name_is_refused_when_names_are_given():
    with pytest.raises(ExpressionError, match=r"unknown name 'q' in 'q \+ t' \(known: t\)"):
        compile_expression("q + t", {"t"})


def test_huge_power_is_cheap_and_not_finite():
    # cheap because every number is a float64: a power of integers would be a Python int of
    # billions of digits (a hang), a float power overflows to inf at once. The type says
    # which was computed; no clock is read (a busy machine would make a timed bound flaky).
    exact = compile_expression("9**9")()
    assert isinstance(exact, np.floating) and exact == 387420489.0
    value = compile_expression("9**9**9**9")()
    assert isinstance(value, np.floating) and not np.isfinite(value)


def test_size_limits():
    with pytest.raises(ExpressionError, match="characters long"):
        compile_expression("1+" * 3000 + "1")
    with pytest.raises(ExpressionError, match="too large"):
        compile_expression("+".join(["x"] * 1500))


@given(st.floats(-1e6, 1e6), st.floats(-1e6, 1e6))
def test_arithmetic_matches_numpy(a, b):
    f = compile_expression("a * b - a / (abs(b) + 1) + max(a, b)")
    expected = a * b - a / (abs(b) + 1) + max(a, b)
    assert f(a=a, b=b) == pytest.approx(expected, rel=1e-12, abs=1e-9)


def test_a_compiled_expression_is_kept_and_its_names_still_checked():
    # the same text compiled again is the kept (immutable) object; the allowed names are
    # part of what is kept, so a name refused under one set is refused every time
    a = compile_expression("radius * cos(t)")
    assert compile_expression("radius * cos(t)") is a
    assert a(radius=2.0, t=0.0) == 2.0
    assert compile_expression("radius * cos(t)", {"radius", "t"}).names == a.names
    for _ in range(2):
        with pytest.raises(ExpressionError, match="radius"):
            compile_expression("radius * cos(t)", {"t"})
