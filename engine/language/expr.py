"""A small, whitelisting expression language, compiled to closures (never ``eval``).

The language: numbers, ``+ - * / ** %``, unary minus, comparisons, ``and``/``or``/``not``,
a conditional ``a if c else b``, names of graph params and of the node's own variables
(``t``, ``u``, ``v``), the constants ``pi``, ``e``, ``tau`` and the functions listed in
:data:`FUNCTIONS`. Everything is vectorized over numpy arrays. Numbers are float64, so a
power overflows to ``inf`` at once instead of building a huge Python integer
(``9**9**9**9`` costs microseconds), and the caller decides what a non-finite value means.

Python's own parser reads the text (``ast.parse(mode="eval")``); we walk the tree and turn
each whitelisted node into a closure, refusing attributes, subscripts, lambdas,
comprehensions, dunder names and calls of anything not in the table.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.errors import ExpressionError
from ..kernels.attributes.noise import noise as _noise
from ..kernels.attributes.random import VERSION as _RAND_VERSION
from ..kernels.attributes.random import rand as _rand

# What the built-in functions return is part of every node's cache key: a kernel whose
# values change bumps its VERSION, so no result cached with the old numbers is used again.
FUNCTIONS_VERSION = f"rand{_RAND_VERSION}"
MAX_LENGTH = 4000
MAX_NODES = 2000
MAX_DEPTH = 64


def _depth(tree: ast.AST) -> int:
    """Nesting depth of a syntax tree, measured without recursion."""
    deepest = 0
    stack = [(tree, 1)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend((child, d + 1) for child in ast.iter_child_nodes(node))
    return deepest


CONSTANTS: dict[str, float] = {"pi": math.pi, "e": math.e, "tau": math.tau}


def _reduce(ufunc: np.ufunc) -> Callable[..., Any]:
    def f(*args: Any) -> Any:
        if not args:
            raise ValueError(f"{ufunc.__name__} needs at least one argument")
        out = args[0]
        for a in args[1:]:
            out = ufunc(out, a)
        return out

    return f


FUNCTIONS: dict[str, tuple[Callable[..., Any], int | tuple[int, int | None]]] = {
    "sin": (np.sin, 1),
    "cos": (np.cos, 1),
    "tan": (np.tan, 1),
    "asin": (np.arcsin, 1),
    "acos": (np.arccos, 1),
    "atan": (np.arctan, 1),
    "atan2": (np.arctan2, 2),
    "sinh": (np.sinh, 1),
    "cosh": (np.cosh, 1),
    "tanh": (np.tanh, 1),
    "exp": (np.exp, 1),
    "log": (np.log, 1),
    "log10": (np.log10, 1),
    "sqrt": (np.sqrt, 1),
    "abs": (np.abs, 1),
    "floor": (np.floor, 1),
    "ceil": (np.ceil, 1),
    "min": (_reduce(np.minimum), (1, None)),
    "max": (_reduce(np.maximum), (1, None)),
    "clip": (np.clip, 3),
    "where": (np.where, 3),
    # per-element variation: a pure hash to [0, 1) and 0.96 x Perlin's noise, in [-1, 1]
    "rand": (_rand, (1, 2)),
    "noise": (_noise, (1, 3)),
}

_BINARY: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Pow: operator.pow,
    ast.Mod: operator.mod,
}
_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
}

Env = Mapping[str, Any]


@dataclass(frozen=True)
class Compiled:
    """A compiled expression: call it with the values of its names.

    Attributes
    ----------
    text : str
        The source text.
    names : frozenset[str]
        The params and variables it reads (constants and functions excluded).
    """

    text: str
    names: frozenset[str]
    _fn: Callable[[Env], Any]

    def __call__(self, env: Env | None = None, /, **values: Any) -> Any:
        scope = dict(env or {})
        scope.update(values)
        missing = self.names - scope.keys()
        if missing:
            raise ExpressionError(
                f"expression {self.text!r} needs a value for {', '.join(sorted(missing))}"
            )
        with np.errstate(all="ignore"):
            try:
                return self._fn(scope)
            except OverflowError:  # a Python int too large for a float64, e.g. a param
                raise ValueError(
                    f"{_glimpse(self.text)}: a number is too large (numbers in expressions "
                    f"are floats, up to about 1.8e308)"
                ) from None

    @property
    def is_bare_name(self) -> bool:
        return self.text.strip().isidentifier() and self.text.strip() not in CONSTANTS


def compile_expression(text: str, allowed: set[str] | frozenset[str] | None = None) -> Compiled:
    """Compile ``text`` into a :class:`Compiled` closure tree.

    Parameters
    ----------
    text : str
        The expression, without the leading ``=``.
    allowed : set of str, optional
        The names it may read (params and the node's variables); None allows any name
        (checked later, when the values come).

    Raises
    ------
    ExpressionError
        For syntax errors and anything outside the language, naming the offending text.
    """
    if not isinstance(text, str):
        raise ExpressionError(f"an expression must be a string, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(
            f"expression is {len(text)} characters long; the limit is {MAX_LENGTH}"
        )
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"expression {text!r} is not valid: {exc.msg}") from None
    except (RecursionError, MemoryError):
        raise ExpressionError(f"expression {text[:40]!r}... is nested too deeply") from None
    count = sum(1 for _ in ast.walk(tree))
    if count > MAX_NODES:
        raise ExpressionError(
            f"expression {text!r} is too large ({count} parts; limit {MAX_NODES})"
        )
    depth = _depth(tree.body)
    if depth > MAX_DEPTH:
        raise ExpressionError(
            f"expression {text[:40]!r}{'...' if len(text) > 40 else ''} is nested too deeply "
            f"({depth} levels; limit {MAX_DEPTH})"
        )
    names: set[str] = set()
    fn = _Compiler(text, allowed, names).visit(tree.body)
    return Compiled(text, frozenset(names), fn)


def _glimpse(text: str) -> str:
    return repr(text) if len(text) <= 40 else repr(text[:37]) + "..."


class _Compiler:
    def __init__(self, text: str, allowed: set[str] | frozenset[str] | None, names: set[str]):
        self.text = text
        self.allowed = allowed
        self.names = names

    def refuse(self, node: ast.AST, what: str) -> ExpressionError:
        snippet = ast.get_source_segment(self.text.strip(), node) or what
        return ExpressionError(f"{what} is not allowed in expressions: {snippet!r}")

    def visit(self, node: ast.AST) -> Callable[[Env], Any]:
        method = getattr(self, "visit_" + type(node).__name__, None)
        if method is None:
            raise self.refuse(node, type(node).__name__.lower())
        return method(node)

    def visit_Constant(self, node: ast.Constant) -> Callable[[Env], Any]:
        value = node.value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.refuse(node, "a literal of this kind")
        try:
            v = np.float64(value)
        except OverflowError:
            raise ExpressionError(
                f"a number in {_glimpse(self.text)} is too large "
                f"(numbers in expressions are floats, up to about 1.8e308)"
            ) from None
        return lambda env: v

    def visit_Name(self, node: ast.Name) -> Callable[[Env], Any]:
        name = node.id
        if name.startswith("_"):
            raise self.refuse(node, "a name starting with '_'")
        if name in CONSTANTS:
            c = np.float64(CONSTANTS[name])
            return lambda env: c
        if name in FUNCTIONS:
            raise ExpressionError(f"function '{name}' must be called, as in {name}(...)")
        if self.allowed is not None and name not in self.allowed:
            known = ", ".join(sorted(self.allowed)) or "none"
            raise ExpressionError(f"unknown name '{name}' in {self.text!r} (known: {known})")
        self.names.add(name)
        return lambda env: env[name]

    def visit_BinOp(self, node: ast.BinOp) -> Callable[[Env], Any]:
        op = _BINARY.get(type(node.op))
        if op is None:
            raise self.refuse(node, f"operator {type(node.op).__name__}")
        a, b = self.visit(node.left), self.visit(node.right)
        return lambda env: op(a(env), b(env))

    def visit_UnaryOp(self, node: ast.UnaryOp) -> Callable[[Env], Any]:
        a = self.visit(node.operand)
        if isinstance(node.op, ast.USub):
            return lambda env: -a(env)
        if isinstance(node.op, ast.UAdd):
            return a
        if isinstance(node.op, ast.Not):
            return lambda env: np.logical_not(a(env))
        raise self.refuse(node, f"operator {type(node.op).__name__}")

    def visit_BoolOp(self, node: ast.BoolOp) -> Callable[[Env], Any]:
        parts = [self.visit(v) for v in node.values]
        combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or

        def f(env: Env) -> Any:
            out = parts[0](env)
            for p in parts[1:]:
                out = combine(out, p(env))
            return out

        return f

    def visit_Compare(self, node: ast.Compare) -> Callable[[Env], Any]:
        ops = []
        for op in node.ops:
            fn = _COMPARE.get(type(op))
            if fn is None:
                raise self.refuse(node, f"comparison {type(op).__name__}")
            ops.append(fn)
        terms = [self.visit(node.left)] + [self.visit(c) for c in node.comparators]

        def f(env: Env) -> Any:
            values = [t(env) for t in terms]
            out = ops[0](values[0], values[1])
            for i, op in enumerate(ops[1:], start=1):
                out = np.logical_and(out, op(values[i], values[i + 1]))
            return out

        return f

    def visit_IfExp(self, node: ast.IfExp) -> Callable[[Env], Any]:
        c, a, b = self.visit(node.test), self.visit(node.body), self.visit(node.orelse)
        return lambda env: np.where(c(env), a(env), b(env))

    def visit_Call(self, node: ast.Call) -> Callable[[Env], Any]:
        if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
            what = (
                f"calling '{node.func.id}'" if isinstance(node.func, ast.Name) else "calling this"
            )
            raise self.refuse(node, what)
        if node.keywords:
            raise self.refuse(node, "a keyword argument")
        fn, arity = FUNCTIONS[node.func.id]
        n = len(node.args)
        lo, hi = (arity, arity) if isinstance(arity, int) else arity
        if n < lo or (hi is not None and n > hi):
            want = str(lo) if lo == hi else f"at least {lo}"
            raise ExpressionError(
                f"{node.func.id}() takes {want} argument{'s' if lo != 1 else ''}, got {n}"
                f" in {self.text!r}"
            )
        args = [self.visit(a) for a in node.args]
        return lambda env: fn(*(a(env) for a in args))
