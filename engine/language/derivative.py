"""Exact derivatives of expressions: forward-mode differentiation of the expression's syntax
tree, to second order (truncated Taylor arithmetic).

Every whitelisted operation of :mod:`formgraph.language.expr` carries its value and its first
and second derivatives with respect to one variable (``t`` of a parametric curve, ``u`` or
``v`` of a surface) through the tree, so ``derivative(0.3)`` of ``cos(100 t)`` is
``-100 sin(30)`` to rounding, where a central difference loses digits with frequency times
range. Comparisons, ``floor``, ``ceil`` and ``rand`` are piecewise constant (derivative 0);
``where``, ``min``, ``max``, ``clip`` and ``a if c else b`` differentiate the branch taken.
``noise`` has no closed-form derivative here: :func:`taylor` raises :class:`NotDifferentiable`
and the caller falls back to differences.

The tree is the one :func:`~formgraph.language.expr.compile_expression` already checked, so
nothing outside the language can reach here; this module only reads it again.
"""

from __future__ import annotations

import ast
import functools
import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from .expr import CONSTANTS

__all__ = ["NotDifferentiable", "taylor"]

Jet = tuple[Any, Any, Any]  # value, first and second derivative
Env = Mapping[str, Any]


class NotDifferentiable(ValueError):
    """An expression uses a function without a derivative here (``noise``)."""


def taylor(text: str, variable: str, env: Env) -> Jet:
    """Value, first and second derivative of expression ``text`` in ``variable`` over ``env``.

    Parameters
    ----------
    text : str
        An expression of the language (already checked by ``compile_expression``).
    variable : str
        The name to differentiate in; every other name is held constant.
    env : mapping
        Values of the names (arrays broadcast).

    Returns
    -------
    value, first, second : arrays broadcast to the variable's shape

    Raises
    ------
    NotDifferentiable
        For ``noise``.
    """
    fn = _compiled(text.strip(), variable)
    with np.errstate(all="ignore"):
        v, d1, d2 = fn(env)
    shape = np.shape(env[variable]) if variable in env else np.shape(v)
    return tuple(np.broadcast_to(np.asarray(x, np.float64), shape) for x in (v, d1, d2))  # type: ignore[return-value]


@functools.lru_cache(maxsize=256)
def _compiled(text: str, variable: str) -> Callable[[Env], Jet]:
    return _Jets(variable).visit(ast.parse(text, mode="eval").body)


def _const(v: Any) -> Jet:
    return v, 0.0, 0.0


def _chain(f0: Any, f1: Any, f2: Any, a: Jet) -> Jet:
    """f(a) from f, f', f'' at a's value: (f a)' = f' a', (f a)'' = f'' a'^2 + f' a''."""
    _, a1, a2 = a
    return f0, f1 * a1, f2 * a1 * a1 + f1 * a2


def _sin(a: Jet) -> Jet:
    s, c = np.sin(a[0]), np.cos(a[0])
    return _chain(s, c, -s, a)


def _cos(a: Jet) -> Jet:
    s, c = np.sin(a[0]), np.cos(a[0])
    return _chain(c, -s, -c, a)


def _tan(a: Jet) -> Jet:
    t = np.tan(a[0])
    return _chain(t, 1 + t * t, 2 * t * (1 + t * t), a)


def _asin(a: Jet) -> Jet:
    x = a[0]
    r = 1 - x * x
    return _chain(np.arcsin(x), 1 / np.sqrt(r), x / r**1.5, a)


def _acos(a: Jet) -> Jet:
    x = a[0]
    r = 1 - x * x
    return _chain(np.arccos(x), -1 / np.sqrt(r), -x / r**1.5, a)


def _atan(a: Jet) -> Jet:
    x = a[0]
    r = 1 + x * x
    return _chain(np.arctan(x), 1 / r, -2 * x / (r * r), a)


def _sinh(a: Jet) -> Jet:
    s, c = np.sinh(a[0]), np.cosh(a[0])
    return _chain(s, c, s, a)


def _cosh(a: Jet) -> Jet:
    s, c = np.sinh(a[0]), np.cosh(a[0])
    return _chain(c, s, c, a)


def _tanh(a: Jet) -> Jet:
    t = np.tanh(a[0])
    return _chain(t, 1 - t * t, -2 * t * (1 - t * t), a)


def _exp(a: Jet) -> Jet:
    e = np.exp(a[0])
    return _chain(e, e, e, a)


def _log(a: Jet) -> Jet:
    x = a[0]
    return _chain(np.log(x), 1 / x, -1 / (x * x), a)


def _log10(a: Jet) -> Jet:
    x, k = a[0], 1 / math.log(10)
    return _chain(np.log10(x), k / x, -k / (x * x), a)


def _sqrt(a: Jet) -> Jet:
    s = np.sqrt(a[0])
    return _chain(s, 0.5 / s, -0.25 / (s * s * s), a)


def _abs(a: Jet) -> Jet:
    sign = np.sign(a[0])
    return np.abs(a[0]), sign * a[1], sign * a[2]


def _step(f: Callable[[Any], Any]) -> Callable[[Jet], Jet]:
    return lambda a: _const(f(a[0]))


def _select(c: Any, a: Jet, b: Jet) -> Jet:
    return tuple(np.where(c, x, y) for x, y in zip(a, b, strict=True))  # type: ignore[return-value]


def _minimum(*args: Jet) -> Jet:
    out = args[0]
    for b in args[1:]:
        out = _select(out[0] <= b[0], out, b)
    return out


def _maximum(*args: Jet) -> Jet:
    out = args[0]
    for b in args[1:]:
        out = _select(out[0] >= b[0], out, b)
    return out


def _clip(x: Jet, lo: Jet, hi: Jet) -> Jet:
    return _select(x[0] < lo[0], lo, _select(x[0] > hi[0], hi, x))


def _where(c: Jet, a: Jet, b: Jet) -> Jet:
    return _select(c[0], a, b)


def _atan2(y: Jet, x: Jet) -> Jet:
    # theta' = N / D with N = x y' - y x', D = x^2 + y^2; theta'' = (N' D - N D') / D^2
    n = x[0] * y[1] - y[0] * x[1]
    d = x[0] * x[0] + y[0] * y[0]
    n1 = x[0] * y[2] - y[0] * x[2]
    d1 = 2 * (x[0] * x[1] + y[0] * y[1])
    return np.arctan2(y[0], x[0]), n / d, (n1 * d - n * d1) / (d * d)


def _rand(*args: Jet) -> Jet:
    from .expr import FUNCTIONS

    return _const(FUNCTIONS["rand"][0](*(a[0] for a in args)))


_FUNCTIONS: dict[str, Callable[..., Jet]] = {
    "sin": _sin,
    "cos": _cos,
    "tan": _tan,
    "asin": _asin,
    "acos": _acos,
    "atan": _atan,
    "atan2": _atan2,
    "sinh": _sinh,
    "cosh": _cosh,
    "tanh": _tanh,
    "exp": _exp,
    "log": _log,
    "log10": _log10,
    "sqrt": _sqrt,
    "abs": _abs,
    "floor": _step(np.floor),
    "ceil": _step(np.ceil),
    "min": _minimum,
    "max": _maximum,
    "clip": _clip,
    "where": _where,
    "rand": _rand,
}


def _add(a: Jet, b: Jet) -> Jet:
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]


def _sub(a: Jet, b: Jet) -> Jet:
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


def _mul(a: Jet, b: Jet) -> Jet:
    return a[0] * b[0], a[1] * b[0] + a[0] * b[1], a[2] * b[0] + 2 * a[1] * b[1] + a[0] * b[2]


def _div(a: Jet, b: Jet) -> Jet:
    q = a[0] / b[0]
    q1 = (a[1] - q * b[1]) / b[0]
    return q, q1, (a[2] - 2 * q1 * b[1] - q * b[2]) / b[0]


def _pow(a: Jet, b: Jet) -> Jet:
    x, y = a[0], b[0]
    p = x**y
    # a constant exponent (the usual t**2): b x^(b-1), exact at x = 0 and for x < 0
    c1 = y * x ** (y - 1) * a[1]
    c2 = y * (y - 1) * x ** (y - 2) * a[1] * a[1] + y * x ** (y - 1) * a[2]
    c1 = np.where(a[1] == 0, 0.0, c1)  # 0 * inf at x = 0 for y < 1 means no change in x
    c2 = np.where((a[1] == 0) & (a[2] == 0), 0.0, c2)
    # a varying exponent: p = exp(L), L = y log x
    lg = np.log(x)
    l1 = b[1] * lg + y * a[1] / x
    l2 = b[2] * lg + 2 * b[1] * a[1] / x + y * (a[2] / x - a[1] * a[1] / (x * x))
    fixed = (np.asarray(b[1]) == 0) & (np.asarray(b[2]) == 0)
    return p, np.where(fixed, c1, p * l1), np.where(fixed, c2, p * (l2 + l1 * l1))


def _mod(a: Jet, b: Jet) -> Jet:
    k = np.floor(a[0] / b[0])
    return a[0] % b[0], a[1] - k * b[1], a[2] - k * b[2]


_BINARY: dict[type, Callable[[Jet, Jet], Jet]] = {
    ast.Add: _add,
    ast.Sub: _sub,
    ast.Mult: _mul,
    ast.Div: _div,
    ast.Pow: _pow,
    ast.Mod: _mod,
}


class _Jets:
    """The syntax tree as closures env -> (value, first, second derivative)."""

    def __init__(self, variable: str):
        self.variable = variable

    def visit(self, node: ast.AST) -> Callable[[Env], Jet]:
        method = getattr(self, "visit_" + type(node).__name__, None)
        if method is not None:
            return method(node)
        return self.value_only(node)  # comparisons and logic: piecewise constant

    def value_only(self, node: ast.AST) -> Callable[[Env], Jet]:
        from .expr import compile_expression

        fn = compile_expression(ast.unparse(node))
        return lambda env: _const(fn(env))

    def visit_Constant(self, node: ast.Constant) -> Callable[[Env], Jet]:
        v = np.float64(node.value)
        return lambda env: _const(v)

    def visit_Name(self, node: ast.Name) -> Callable[[Env], Jet]:
        name = node.id
        if name in CONSTANTS:
            c = np.float64(CONSTANTS[name])
            return lambda env: _const(c)
        if name == self.variable:
            return lambda env: (np.asarray(env[name], np.float64), 1.0, 0.0)
        return lambda env: _const(np.asarray(env[name], np.float64))

    def visit_BinOp(self, node: ast.BinOp) -> Callable[[Env], Jet]:
        op = _BINARY[type(node.op)]
        a, b = self.visit(node.left), self.visit(node.right)
        return lambda env: op(a(env), b(env))

    def visit_UnaryOp(self, node: ast.UnaryOp) -> Callable[[Env], Jet]:
        if isinstance(node.op, ast.Not):
            return self.value_only(node)
        a = self.visit(node.operand)
        if isinstance(node.op, ast.USub):
            return lambda env: tuple(-x for x in a(env))  # type: ignore[return-value]
        return a

    def visit_IfExp(self, node: ast.IfExp) -> Callable[[Env], Jet]:
        c, a, b = self.value_only(node.test), self.visit(node.body), self.visit(node.orelse)
        return lambda env: _select(c(env)[0], a(env), b(env))

    def visit_Call(self, node: ast.Call) -> Callable[[Env], Jet]:
        assert isinstance(node.func, ast.Name)  # checked by compile_expression
        if node.func.id == "noise":
            raise NotDifferentiable("noise() has no derivative here")
        fn = _FUNCTIONS[node.func.id]
        if node.func.id == "where":
            c = self.value_only(node.args[0])
            a, b = self.visit(node.args[1]), self.visit(node.args[2])
            return lambda env: _where(c(env), a(env), b(env))
        args = [self.visit(a) for a in node.args]
        return lambda env: fn(*(a(env) for a in args))
