"""What callers of the Python API hand a :class:`~formgraph.Graph` in, checked before it is
kept: node names, budgets, and values given as the YAML they save to (tuples and arrays as
lists, nested no deeper than a graph file may be)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from ..core.errors import GraphError
from ..core.types import describe
from ..language.yamlio import MAX_DEPTH

__all__ = ["check_budgets", "nesting", "node_names", "plain"]


def node_names(nodes: Any) -> list[str]:
    """The names asked for by ``evaluate(nodes)``: one name or an iterable of names."""
    if isinstance(nodes, str):
        return [nodes]
    names = None
    if isinstance(nodes, Iterable) and not isinstance(nodes, (bytes, dict)):
        names = list(nodes)
    if names is None or not all(isinstance(n, str) for n in names):
        raise GraphError(
            f"evaluate() takes a node name or a list of node names, got {describe(nodes)}"
        )
    return names


def check_budgets(budget: Any, memory_bytes: Any) -> None:
    for what, value, least in (("budget", budget, 1), ("memory_bytes", memory_bytes, 0)):
        if isinstance(value, bool) or not isinstance(value, int) or value < least:
            raise GraphError(
                f"{what} must be a whole number of {'elements' if what == 'budget' else 'bytes'}"
                f" (at least {least}), got {describe(value)}"
            )


def nesting(value: Any) -> int:
    """How deeply lists, tuples and dicts nest in ``value``, without recursion."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, (list, tuple, dict)):
            if d + 1 > MAX_DEPTH:
                return d + 1  # deep enough to refuse: no need to walk the rest
            deepest = max(deepest, d + 1)
            stack.extend((c, d + 1) for c in (v.values() if isinstance(v, dict) else v))
        elif isinstance(v, np.ndarray):
            deepest = max(deepest, d + v.ndim)
    return deepest


def plain(value: Any, what: str = "a value", depth: int = 0) -> Any:
    """Inputs given from Python as the YAML they save to: tuples and arrays become lists,
    numpy numbers Python numbers (geometry objects stay as they are).

    Raises
    ------
    GraphError
        For a value nested deeper than a graph file may be.
    """
    if depth > MAX_DEPTH:
        raise GraphError(f"{what} is nested more than {MAX_DEPTH} levels deep")
    if isinstance(value, np.ndarray):
        if value.ndim > MAX_DEPTH:
            raise GraphError(f"{what} is nested more than {MAX_DEPTH} levels deep")
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [plain(v, what, depth + 1) for v in value]
    if isinstance(value, dict):
        return {k: plain(v, what, depth + 1) for k, v in value.items()}
    return value
