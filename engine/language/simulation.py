"""The check of a node's ``simulate: {state, from, steps}`` (see :class:`.model.Simulate`).

A simulated node runs ``steps`` times, each step's output the next step's ``state`` input:
so the node has one output, and that output must fit the state input; ``from`` (step 0)
must fit it too; ``steps`` is a count known before anything runs (an int, or an expression
over the params), so that the budget can count it. Its expressions see ``step``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..core.registry import NodeSpec
from ..core.types import Kind, PortType, describe
from .model import STEP, Expr, Literal, NodeDef, Wire

__all__ = ["check_simulate", "is_state_placeholder"]


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


def check_simulate(
    g: Any, nd: NodeDef, spec: NodeSpec, registry: Mapping[str, NodeSpec]
) -> tuple[list[tuple[str, str]], Any]:
    """Problems of a node's ``simulate:`` as (message, port), and the loop its inputs see
    (the step index, an int), or None without a simulation."""
    from .check import _check_input, _expr_names_problem, _Loop, _static_value, _Unknown

    sim = nd.simulate
    if sim is None:
        return [], None
    out: list[tuple[str, str]] = []
    loop = _Loop(STEP, PortType((Kind(int),)))
    if nd.repeat is not None:
        out.append(
            ("a node cannot both repeat and simulate; simulate a subgraph instead", "simulate")
        )
    if STEP in g.params:
        out.append(
            (
                f"param '{STEP}' would be hidden by the step index of this simulation; rename it",
                "simulate",
            )
        )
    if spec.multi_output:
        out.append(
            (
                f"simulate needs a node with one output (each step's output is the next "
                f"step's state); '{nd.type}' has {', '.join(spec.outputs)}",
                "simulate",
            )
        )
    elif sim.state not in spec.inputs:
        out.append(
            (
                f"'{nd.type}' has no input '{sim.state}' to take the state; its inputs are "
                f"{', '.join(spec.inputs) or 'none'}",
                "simulate",
            )
        )
    else:
        pt = spec.inputs[sim.state].type
        produced = spec.output_type(None)
        if not pt.accepts(produced):
            out.append(
                (
                    f"the state input '{sim.state}' ({pt.name}) cannot take the node's own "
                    f"output ({produced.name}), so no step could follow another",
                    "simulate",
                )
            )
        if sim.state in nd.raw and not is_state_placeholder(nd, sim.state):
            out.append(
                (
                    f"input '{sim.state}' is the simulation's state (the previous step's "
                    f"output): leave it out or write '={sim.state}'; step 0 is 'from'",
                    sim.state,
                )
            )
        for message in _check_input(g, nd, pt, sim.source, dict(registry), None):
            out.append((f"from: {message}", "simulate"))
    steps = sim.steps
    if isinstance(steps, Wire):
        out.append(
            (
                "steps is a count known before anything runs (an int, or an expression over "
                f"the params), not a wire ('{steps}')",
                "simulate",
            )
        )
        return out, loop
    value: Any = None
    if isinstance(steps, Expr):
        msg = _expr_names_problem(g, steps)
        if msg:
            out.append((f"steps: {msg}", "simulate"))
            return out, loop
        try:
            value = _static_value(g, steps)
        except _Unknown:
            return out, loop
        except (ValueError, TypeError, ZeroDivisionError, ArithmeticError) as exc:
            out.append((f"steps '={steps.text}' fails with the param defaults: {exc}", "simulate"))
            return out, loop
    elif isinstance(steps, Literal):
        value = steps.value
    problem = steps_problem(value)
    if problem:
        out.append((problem, "simulate"))
    return out, loop


def steps_problem(value: Any) -> str | None:
    """Why ``value`` is not a step count, or None."""
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if not isinstance(value, int) or isinstance(value, bool):
        return f"steps is a count (an int >= 0), got {describe(value)}"
    if value < 0:
        return f"steps must be >= 0, got {value}"
    return None
