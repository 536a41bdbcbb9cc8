"""What an optimisation study asks for: objectives, constraints, the search space, the front.

Objectives name scalar number outputs (``size.volume``); constraints are ``EXPR <= NUMBER``
or ``EXPR >= NUMBER`` over params and measured outputs, compiled by the graph's own
expression language (:mod:`formgraph.language.expr`, never ``eval``). All of it is checked
against the graph before any trial runs, every problem at once, each naming the file and
the line of the node or param it is about.

A constraint's violation follows optuna's convention (Deb et al., "A fast and elitist
multiobjective genetic algorithm: NSGA-II", IEEE TEVC 6(2), 2002, the constrained
domination used there): a number ``<= 0`` when it holds, the amount it misses by otherwise.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.errors import ExpressionError, Problem, Where
from ..evaluation.graph import Graph
from ..language.expr import Compiled, compile_expression
from ..language.params import suggest
from .sampling import Domain

__all__ = [
    "Constraint",
    "Objective",
    "constraints_of",
    "non_dominated",
    "objectives_of",
    "space_of",
]

_DOTTED = re.compile(r"(?<![\w.])([A-Za-z_]\w*)\.([A-Za-z_]\w*)")
_SEP = "__dot__"  # node.output inside an expression: a plain name for the compiler


@dataclass(frozen=True)
class Objective:
    """One objective: a measured column and its direction."""

    column: str  # node.output (or node, for a node with one output)
    node: str
    maximize: bool

    @property
    def direction(self) -> str:
        return "maximize" if self.maximize else "minimize"


@dataclass(frozen=True)
class Constraint:
    """``expr <= bound`` or ``expr >= bound``; :meth:`violation` <= 0 when it holds."""

    text: str
    expr: Compiled
    upper: bool  # True for <=
    bound: float
    columns: tuple[str, ...]  # the measured outputs it reads (node.output)
    params: tuple[str, ...]  # the params it reads

    def violation(self, values: Mapping[str, Any]) -> float:
        """How far ``values`` (params and columns by name) miss it; inf when not a number."""
        env = {n: values[n] for n in self.params}
        env.update({c.replace(".", _SEP): values[c] for c in self.columns})
        try:
            v = float(self.expr(env))
        except (TypeError, ValueError, ExpressionError, ZeroDivisionError):
            return math.inf
        if not math.isfinite(v):
            return math.inf
        return v - self.bound if self.upper else self.bound - v


def _where(g: Graph, node: str | None = None) -> Where:
    nd = g._nodes.get(node) if node else None  # the node's line in the file, when known
    return Where(g.file_label, getattr(nd, "line", None), node)


def _number_outputs(g: Graph, node: str) -> dict[str | None, str]:
    """The outputs of ``node``: name (None for a single output) -> its type's name."""
    spec = g.node_types()[g.nodes[node]]
    outs = spec.outputs if spec.multi_output else {None: spec.output_type(None)}
    return {o: t.name for o, t in outs.items()}


def _is_number(g: Graph, node: str, output: str | None) -> bool:
    spec = g.node_types()[g.nodes[node]]
    pt = spec.outputs[output] if spec.multi_output else spec.output_type(None)
    k = pt.kinds[0]
    return len(pt.kinds) == 1 and not k.is_list and k.base in (int, float)


def _column(g: Graph, item: str, role: str) -> tuple[str | None, Problem | None]:
    """The column of ``NODE.OUTPUT`` (or ``NODE`` with one output), or the problem with it."""
    node, _, output = item.partition(".")
    here = Where(g.file_label)
    if node not in g.nodes:
        return None, Problem(here, f"{role} '{item}': no node '{node}'{suggest(node, g.nodes)}")
    spec = g.node_types()[g.nodes[node]]
    if spec.is_export:
        return None, Problem(_where(g, node), f"{role} '{item}': '{node}' is an export")
    outs = _number_outputs(g, node)
    if output and output not in outs:
        listed = ", ".join(f"{node}.{o}" for o in outs if o) or node
        return None, Problem(_where(g, node), f"{role} '{item}': no such output; use {listed}")
    if not output and len(outs) > 1:
        listed = ", ".join(f"{node}.{o}" for o in outs if o)
        return None, Problem(_where(g, node), f"{role} '{item}': name one output: {listed}")
    key = output or next(iter(outs))
    if not _is_number(g, node, key):
        return None, Problem(
            _where(g, node),
            f"{role} '{item}' gives {outs[key]}, not a number; name a number output "
            f"(mesh.measure's volume, curves.measure's length)",
        )
    return (f"{node}.{key}" if key else node), None


def objectives_of(
    g: Graph, minimize: Sequence[str], maximize: Sequence[str]
) -> tuple[list[Objective], list[Problem]]:
    """The objectives, in the order given (minimised ones first), and their problems."""
    out: list[Objective] = []
    problems: list[Problem] = []
    for items, up in ((minimize, False), (maximize, True)):
        for item in items:
            column, problem = _column(g, item, "maximize" if up else "minimize")
            if problem is not None:
                problems.append(problem)
            elif any(o.column == column for o in out):
                problems.append(Problem(_where(g, column.split(".")[0]), f"'{item}' given twice"))
            else:
                out.append(Objective(column, column.split(".")[0], up))
    if not out and not problems:
        problems.append(Problem(Where(g.file_label), "give at least one --minimize or --maximize"))
    return out, problems


_BOUND = re.compile(r"^(?P<expr>.+?)\s*(?P<op><=|>=)\s*(?P<bound>[^<>=]+)$", re.S)


def constraints_of(g: Graph, texts: Sequence[str]) -> tuple[list[Constraint], list[Problem]]:
    """The constraints, parsed and checked against the graph's params and outputs."""
    out: list[Constraint] = []
    problems: list[Problem] = []
    here = Where(g.file_label)
    for text in texts:
        m = _BOUND.match(text.strip())
        if m is None:
            problems.append(
                Problem(here, f"constraint {text!r}: write EXPR <= NUMBER or EXPR >= NUMBER")
            )
            continue
        try:
            bound = float(m["bound"])
        except ValueError:
            bound = math.nan
        if not math.isfinite(bound):
            problems.append(
                Problem(here, f"constraint {text!r}: {m['bound'].strip()!r} is not a number")
            )
            continue
        source, columns, bad = _rewrite(g, text, m["expr"])
        if bad:
            problems += bad
            continue
        try:
            expr = compile_expression(source)
        except ExpressionError as exc:
            problems.append(Problem(here, f"constraint {text!r}: {_plain(str(exc))}"))
            continue
        params, unknown = [], []
        for name in sorted(expr.names):
            if _SEP in name:
                continue
            if name in g.params:
                params.append(name)
            elif name in g.nodes:  # a node with one number output, named bare
                column, problem = _column(g, name, f"constraint {text!r}:")
                if problem is not None:
                    problems.append(problem)
                    continue
                columns.append(column)
            else:
                unknown.append(name)
        if unknown:
            name = unknown[0]
            problems.append(
                Problem(
                    here,
                    f"constraint {text!r}: '{name}' is neither a param nor a node output"
                    f"{suggest(name, [*g.params, *g.nodes])}",
                )
            )
            continue
        out.append(
            Constraint(
                text, expr, m["op"] == "<=", bound, tuple(dict.fromkeys(columns)), tuple(params)
            )
        )
    return out, problems


def _rewrite(g: Graph, text: str, expr: str) -> tuple[str, list[str], list[Problem]]:
    """``expr`` with each ``node.output`` made a plain name; the columns; their problems."""
    columns: list[str] = []
    bad: list[Problem] = []

    def dotted(match: re.Match[str]) -> str:
        column, problem = _column(g, match.group(0), f"constraint {text!r}:")
        if problem is not None:
            bad.append(problem)
            return match.group(1)
        columns.append(column)
        return column.replace(".", _SEP)

    return _DOTTED.sub(dotted, expr), columns, bad


def _plain(message: str) -> str:
    """An expression error about our rewritten text, said about the user's."""
    return re.sub(r"(\w+)" + _SEP + r"(\w+)", r"\1.\2", message)


def space_of(domains: Sequence[Domain], ints: Mapping[str, bool]) -> dict[str, Any]:
    """optuna distributions of the varied params.

    An interval is a float range; an int param's ``FROM:TO`` (consecutive whole numbers) an
    int range; any other list a choice.
    """
    from optuna.distributions import (
        CategoricalDistribution,
        FloatDistribution,
        IntDistribution,
    )

    space: dict[str, Any] = {}
    for d in domains:
        if d.values is None:
            space[d.name] = FloatDistribution(d.low, d.high)
            continue
        vals = d.values
        consecutive = (
            ints.get(d.name, False)
            and len(vals) > 1
            and all(isinstance(v, int) for v in vals)
            and list(vals) == list(range(vals[0], vals[0] + len(vals)))
        )
        if consecutive:
            space[d.name] = IntDistribution(vals[0], vals[-1])
        else:
            space[d.name] = CategoricalDistribution(vals)
    return space


def non_dominated(values: np.ndarray) -> np.ndarray:
    """Which rows of ``values`` (n, k), all to be minimised, no other row dominates.

    Row a dominates row b when it is no worse in every column and better in one (Pareto);
    equal rows do not dominate each other. One column: the rows equal to the least. Two:
    Kung, Luccio and Preparata's sweep ("On finding the maxima of a set of vectors", JACM
    22(4), 1975), O(n log n): sorted by the first column then the second, a row is kept
    when it is the least second value among rows of its first value and below every second
    value of a smaller first value. More: pairwise and vectorized, O(n^2 k) in memory
    blocks of 256 rows.

    Returns
    -------
    numpy.ndarray of bool, shape (n,)
    """
    v = np.asarray(values, dtype=np.float64)
    n = len(v)
    if n == 0:
        return np.zeros(0, dtype=bool)
    if v.shape[1] == 1:
        return v[:, 0] == v[:, 0].min()
    if v.shape[1] == 2:
        order = np.lexsort((v[:, 1], v[:, 0]))
        a, b = v[order, 0], v[order, 1]
        starts = np.flatnonzero(np.r_[True, a[1:] != a[:-1]])  # first row of each a value
        group = np.repeat(starts, np.diff(np.r_[starts, n]))  # each row's group start
        lowest = np.minimum.accumulate(b)  # least b among rows up to here
        before = np.where(group > 0, lowest[np.maximum(group - 1, 0)], np.inf)
        keep = np.empty(n, dtype=bool)
        keep[order] = (b == b[group]) & (b < before)
        return keep
    keep = np.ones(n, dtype=bool)
    for start in range(0, n, 256):
        b = v[start : start + 256]  # (m, k): is any row of v dominating each of these?
        no_worse = (v[None, :, :] <= b[:, None, :]).all(axis=2)
        better = (v[None, :, :] < b[:, None, :]).any(axis=2)
        keep[start : start + 256] = ~(no_worse & better).any(axis=1)
    return keep
