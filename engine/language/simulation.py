"""What the check (:mod:`.check`) and the run need to know of a node's ``simulate: {state,
from, steps}`` (see :class:`.model.Simulate`).

A simulated node runs ``steps`` times, each step's output the next step's ``state`` input:
so the node has one output, and that output must fit the state input; ``from`` (step 0)
must fit it too; ``steps`` is a count known before anything runs (an int, or an expression
over the params), so that the budget can count it. Its expressions see ``step``.
"""

from __future__ import annotations

from typing import Any

from ..core.types import describe
from .model import Expr, NodeDef

__all__ = ["is_state_placeholder", "steps_problem"]


def is_state_placeholder(nd: NodeDef, port: str) -> bool:
    """Whether ``port`` of a simulated node is its state, written as ``"=<state>"`` (the
    SPEC's way of saying "the previous step's output") or left out."""
    sim = nd.simulate
    if sim is None or port != sim.state:
        return False
    value = nd.inputs.get(port)
    return value is None or (
        isinstance(value, Expr) and value.compiled.is_bare_name and value.text.strip() == port
    )


def steps_problem(value: Any) -> str | None:
    """Why ``value`` is not a step count, or None."""
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if not isinstance(value, int) or isinstance(value, bool):
        return f"steps is a count (an int >= 0), got {describe(value)}"
    if value < 0:
        return f"steps must be >= 0, got {value}"
    return None
