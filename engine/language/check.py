"""Checking a graph whole, before anything runs.

Every problem is collected (unknown types with a suggestion, unknown and missing inputs,
wires to missing nodes or outputs, type mismatches, expressions outside the language or
naming unknown params, values out of range, output paths that escape, cycles) so a user
fixes a graph in one pass.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from ..core import safety
from ..core.errors import ExpressionError, Problem, Where
from ..core.registry import NodeSpec, node_types
from ..core.types import (
    Kind,
    PortType,
    TypeMismatch,
    Vec3,
    as_list,
    describe,
    loop_item_problem,
)
from .elements import reads_elements
from .expr import compile_expression
from .inference import expression_ports_take_text, infer_fed
from .model import FRAMES, STEP, Expr, Input, Items, Literal, NodeDef, ParamDef, Wire
from .order import cycle_problems, kahn_order
from .params import check_param_value, suggest
from .simulation import is_state_placeholder, steps_problem


@dataclass(frozen=True)
class Outline:
    """What the checker reads of a graph: where it came from, its params and its nodes.

    The checker needs nothing else (no caches, no evaluation), so it depends on this
    narrow view instead of on :class:`formgraph.Graph`. ``subgraphs`` holds the node types
    of the graph files its nodes name (type string -> spec), ``outputs`` the graph's own
    ``outputs:`` mapping (name -> wire text), for use as a subgraph.
    """

    file_label: str
    params: Mapping[str, ParamDef]
    nodes: Mapping[str, NodeDef]
    subgraphs: Mapping[str, NodeSpec] = field(default_factory=dict)
    outputs: Mapping[str, Any] = field(default_factory=dict)
    output_lines: Mapping[str, int] = field(default_factory=dict)
    # output types found so far, (node, output) -> type: each is worked out once
    types: dict[tuple[str, str | None], PortType | None] = field(
        default_factory=dict, compare=False, repr=False
    )


@dataclass(frozen=True)
class _Loop:
    """A repeated node's loop name, and the type of its items when known before running."""

    name: str
    item: PortType | None = None


def check_graph(g: Outline, extra: list[Problem] | None = None) -> list[Problem]:
    """Every problem of graph ``g`` (an empty list when it can run)."""
    problems = list(extra or [])
    file = g.file_label
    registry = {**node_types(), **g.subgraphs}

    infer_fed(g, registry)
    problems.extend(param_problems(g))
    output_types(g, registry)

    for nd in g.nodes.values():
        spec = registry.get(nd.type)
        if spec is not None:
            expression_ports_take_text(g, nd, spec)
        if spec is None:
            if nd.type.endswith((".yaml", ".yml")):
                continue  # a graph file: its problems come from reading it
            if nd.type:
                # the SPEC's form: file:line, then the type (the node is named after it)
                problems.append(
                    Problem(
                        Where(file, nd.input_lines.get("type", nd.line)),
                        f"unknown node type '{nd.type}'{suggest(nd.type, registry)}"
                        f" in node '{nd.name}'",
                    )
                )
            continue
        problems.extend(_check_node(g, nd, spec, registry))

    problems.extend(_check_outputs(g, registry))
    problems.extend(cycle_problems(g.nodes, g.file_label))
    return problems


def param_problems(g: Outline) -> list[Problem]:
    """The problems of ``g``'s params: their names, and their defaults and choices against
    their types (after :func:`~.inference.infer_fed`, which a whole-number param's kind
    follows)."""
    from .expr import CONSTANTS, FUNCTIONS

    problems: list[Problem] = []
    file = g.file_label
    for p in g.params.values():
        if not p.name.isidentifier() or p.name.startswith("_"):
            problems.append(
                Problem(
                    Where(file, p.line),
                    f"param '{p.name}': a param name is "
                    f"letters, digits and '_', not starting with a digit or '_'",
                )
            )
        elif p.name in CONSTANTS or p.name in FUNCTIONS:
            problems.append(
                Problem(
                    Where(file, p.line),
                    f"param '{p.name}' would hide the "
                    f"expression {'constant' if p.name in CONSTANTS else 'function'}"
                    f" '{p.name}'; choose another name",
                )
            )
        try:
            check_param_value(p, p.default)
        except TypeMismatch as exc:
            problems.append(Problem(Where(file, p.line), f"param '{p.name}': default {exc}"))
        for c in p.choices or ():
            try:
                check_param_value(p, c)
            except TypeMismatch as exc:
                problems.append(Problem(Where(file, p.line), f"param '{p.name}': choice {exc}"))
    return problems


def _check_outputs(g: Outline, registry: dict[str, NodeSpec]) -> list[Problem]:
    from .model import parse_input

    out = []
    for name, text in g.outputs.items():
        where = Where(g.file_label, g.output_lines.get(name))
        try:
            wire = parse_input(text)
        except ExpressionError as exc:
            out.append(Problem(where, f"output '{name}': {exc.problems[0].message}"))
            continue
        if not str(name).isidentifier() or not isinstance(wire, Wire):
            out.append(
                Problem(
                    where, f"output '{name}': an output is a name and a wire, e.g. mesh: '@tess'"
                )
            )
            continue
        msgs = _check_wire(g, PortType((Kind(Any),)), wire, registry)
        out.extend(Problem(where, f"output '{name}': {m}") for m in msgs)
        target = g.nodes.get(wire.node)
        spec = registry.get(target.type) if target is not None else None
        if spec is not None and spec.is_export:
            out.append(
                Problem(
                    where,
                    f"output '{name}': '{wire}' is an export; a subgraph's exports "
                    f"do not run when it is used as a node",
                )
            )
    return out


def output_types(
    g: Outline, registry: Mapping[str, NodeSpec] | None = None
) -> dict[tuple[str, str | None], PortType | None]:
    """The type each node output carries, ``(node, output) -> type`` (``output`` None for a
    node of one output; the type None where unknown), as :func:`output_type` finds it: a
    repeated node's a list, a ``SameAs`` output the type it follows (a repeated
    ``geometry.transform`` of a mesh gives ``list[Mesh]``). Asked upstream first, so each
    is one step."""
    registry = {**node_types(), **g.subgraphs} if registry is None else registry
    for name in kahn_order(g.nodes):
        spec = registry.get(g.nodes[name].type)
        if spec is not None:
            for out in spec.outputs if spec.multi_output else [None]:
                output_type(g, Wire(name, out), registry)
    return dict(g.types)


def output_type(
    g: Outline, wire: Wire, registry: Mapping[str, NodeSpec], seen: frozenset[str] = frozenset()
) -> PortType | None:
    """The type a (valid) wire carries: a repeated node gives a list, and an output typed
    like one of its node's inputs (``SameAs``) is followed upstream. None when unknown.

    Memoized in ``g.types``; :func:`check_graph` asks for the nodes in dependency order
    first, so a long chain of ``SameAs`` nodes is followed one step at a time, not by a
    recursion as deep as the chain."""
    key = (wire.node, wire.output)
    if key in g.types:
        return g.types[key]
    t = _output_type(g, wire, registry, seen)
    if not seen:  # a type found along a path (seen) may be cut short by a cycle
        g.types[key] = t
    return t


def _output_type(
    g: Outline, wire: Wire, registry: Mapping[str, NodeSpec], seen: frozenset[str]
) -> PortType | None:
    nd = g.nodes.get(wire.node)
    spec = registry.get(nd.type) if nd is not None else None
    if spec is None or wire.node in seen:
        return None
    if wire.output == FRAMES and nd.simulate is not None and FRAMES not in spec.outputs:
        return as_list(spec.output_type(None))  # every step's output
    if (wire.output is not None and wire.output not in spec.outputs) or (
        wire.output is None and spec.multi_output
    ):
        return None
    t = spec.output_type(wire.output)
    if t.same_as is not None:
        value = nd.inputs.get(t.same_as)
        follows = _input_type(g, value, registry, seen | {wire.node})
        r = nd.repeat
        if r is not None and isinstance(value, Expr) and value.text.strip() == r.name:
            loop = _check_repeat(g, nd, registry, seen | {wire.node})[1]  # the loop's item
            follows = loop.item if loop is not None else None
        t = follows if follows is not None else PortType(t.kinds, t.optional)
    return as_list(t) if nd.repeat is not None else t


def _input_type(
    g: Outline, value: Input | None, registry: Mapping[str, NodeSpec], seen: frozenset[str]
) -> PortType | None:
    if isinstance(value, Wire):
        return output_type(g, value, registry, seen)
    if isinstance(value, Expr) and value.compiled.is_bare_name:
        p = g.params.get(value.text.strip())
        return p.type if p is not None else None
    if isinstance(value, Items):
        types = [_input_type(g, i, registry, seen) for i in value.items]
        if any(t is None for t in types):
            return None
        bases = [k.base for t in types for k in t.kinds if t is not None]
        from ..core.types import _common_base

        return PortType((Kind(_common_base(bases), True),))
    return None


def _item_type(value: Any) -> PortType | None:
    """The type of the items of a literal list, when they share one."""
    if not isinstance(value, list) or not value:
        return None
    if all(isinstance(v, int) and not isinstance(v, bool) for v in value):
        return PortType((Kind(int),))
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        return PortType((Kind(float),))
    try:
        for v in value:
            PortType((Kind(Vec3),)).coerce(v)
    except TypeMismatch:
        return None
    return PortType((Kind(Vec3),))


def _check_repeat(
    g: Outline,
    nd: NodeDef,
    registry: Mapping[str, NodeSpec],
    seen: frozenset[str] = frozenset(),
) -> tuple[list[str], _Loop | None]:
    """Problems of a node's ``repeat:``, and its loop."""
    from .expr import CONSTANTS, FUNCTIONS

    r = nd.repeat
    if r is None:
        return [], None
    name = r.name
    if not name.isidentifier() or name.startswith("_"):
        return [
            f"loop name '{name}' must be letters, digits and '_', not starting with a digit or '_'"
        ], None
    if name in g.params or name in CONSTANTS or name in FUNCTIONS:
        what = "a param" if name in g.params else "an expression name"
        return [f"loop name '{name}' would hide {what}; choose another"], None
    src = r.source
    how = "a count (int), a list, or a wire to a list or to Points"
    if isinstance(src, Wire):
        msgs = _check_wire(g, PortType((Kind(Any),)), src, registry)
        if msgs:
            return msgs, _Loop(name)
        t = output_type(g, src, registry, seen)
        if t is None:
            return [], _Loop(name)
        if all(k.is_list for k in t.kinds):
            return [], _Loop(name, PortType(tuple(Kind(k.base) for k in t.kinds)))
        if all(getattr(k.base, "__name__", "") == "Points" for k in t.kinds):
            return [], _Loop(name, PortType((Kind(Vec3),)))
        return [f"repeat '{name}' runs over {how}; '{src}' gives {t.name}"], _Loop(name)
    if isinstance(src, Items):
        msgs = [m for i in src.items if isinstance(i, Expr) for m in [_expr_names_problem(g, i)]]
        return [m for m in msgs if m], _Loop(name)
    if isinstance(src, Expr):
        msg = _expr_names_problem(g, src)
        if msg:
            return [msg], _Loop(name)
        try:
            value = _static_value(g, src)
        except _Unknown:
            return [], _Loop(name)
        except (ExpressionError, ValueError, TypeError, ZeroDivisionError) as exc:
            return [f"expression '={src.text}' fails with the param defaults: {exc}"], _Loop(name)
    else:
        value = src.value
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, int) and not isinstance(value, bool):
        if value < 0:
            return [f"repeat '{name}': a count must be >= 0, got {value}"], _Loop(name)
        return [], _Loop(name, PortType((Kind(int),)))
    if isinstance(value, list):
        problem = loop_item_problem(value)
        if problem:
            return [f"repeat '{name}': {problem}"], _Loop(name)
        return [], _Loop(name, _item_type(value))
    return [f"repeat '{name}' runs over {how}, got {describe(value)}"], _Loop(name)


def _check_node(
    g: Outline, nd: NodeDef, spec: NodeSpec, registry: dict[str, NodeSpec]
) -> list[Problem]:
    out: list[Problem] = []
    file = g.file_label

    def add(message: str, port: str | None) -> None:
        line = nd.input_lines.get(port, nd.line) if port else nd.line
        out.append(Problem(Where(file, line, nd.name, port), message))

    for port, message in nd.parse_errors.items():
        add(message, port)
    missing = spec.missing()
    if missing:  # an optional dependency that is not installed: said before anything runs
        out.append(Problem(Where(file, nd.input_lines.get("type", nd.line), nd.name), missing))
    repeat_problems, loop = _check_repeat(g, nd, registry)
    for message in repeat_problems:
        add(message, "repeat")

    simulate_problems, step = _check_simulate(g, nd, spec, registry)
    for message, port in simulate_problems:
        add(message, port)
    loop = loop or step
    for port in nd.raw:
        if port not in spec.inputs and nd.raw[port] is None and " " in str(port):
            add(
                f"the text {port!r} became an input of its own, because inside {{...}} a "
                "', ' ends a value: put text that holds ', ' in quotes",
                port,
            )
        elif port not in spec.inputs:
            add(
                f"'{nd.type}' has no input '{port}'{suggest(port, spec.inputs)}; its inputs are "
                f"{', '.join(spec.inputs) or 'none'}",
                port,
            )
    for port, p in spec.inputs.items():
        if is_state_placeholder(nd, port):
            continue  # each step's input is the previous step's output
        if port not in nd.raw:
            if p.required:
                add(f"missing required input ({p.type.name})", port)
            continue
        if port in nd.parse_errors:
            continue
        for message in _check_input(g, nd, p.type, nd.inputs[port], registry, loop):
            add(message, port)
    return out


def _check_input(
    g: Outline,
    nd: NodeDef,
    pt: PortType,
    value: Input,
    registry: dict[str, NodeSpec],
    loop: _Loop | None = None,
) -> list[str]:
    if isinstance(value, Wire):
        return _check_wire(g, pt, value, registry)
    if pt.per_element and reads_elements(value, set(g.params) | ({loop.name} if loop else set())):
        return []  # evaluated per element: its names are known when the geometry is
    if isinstance(value, Literal):
        return _check_literal(g, pt, value.value, loop)
    if isinstance(value, Expr):
        return _check_expr(g, pt, value, loop)
    # Items: a list holding wires and/or expressions
    wires = [i for i in value.items if isinstance(i, Wire)]
    if not wires:
        try:
            resolved = [_static_value(g, i, loop) for i in value.items]
        except _Unknown as exc:
            return [str(exc)] if str(exc) else []
        except (ExpressionError, ValueError, TypeError, ZeroDivisionError) as exc:
            return [f"an expression fails with the param defaults: {exc}"]
        return _coerce_problems(pt, resolved)
    list_kinds = [k for k in pt.kinds if k.is_list]
    if not list_kinds:
        return [f"expected {pt.name}, got a list of wires"]
    item_type = PortType(tuple(Kind(k.base) for k in list_kinds), range=pt.range)
    list_type = PortType(tuple(list_kinds), range=pt.range)
    problems: list[str] = []
    for item in value.items:
        # a wire carrying a list joins the list (flattened): ["@paths", "@outline"]
        as_item = _check_input(g, nd, item_type, item, registry, loop)
        if as_item and isinstance(item, Wire) and not _check_wire(g, list_type, item, registry):
            continue
        problems.extend(as_item)
    return problems


def _check_wire(g: Outline, pt: PortType, wire: Wire, registry: dict[str, NodeSpec]) -> list[str]:
    target = g.nodes.get(wire.node)
    if target is None:
        if wire.node in g.params:
            return [
                f"'@{wire.node}' wires to a node, but '{wire.node}' is a param: write "
                f"'={wire.node}'"
            ]
        return [f"wire to missing node '@{wire.node}'{suggest(wire.node, g.nodes)}"]
    spec = registry.get(target.type)
    if spec is None:
        return []  # reported on the target itself
    if wire.output == FRAMES and target.simulate is not None and not spec.multi_output:
        produced = output_type(g, wire, registry) or as_list(spec.output_type(None))
        return (
            []
            if pt.accepts(produced)
            else [f"expected {pt.name}, got {produced.name} from '{wire}'"]
        )
    if wire.output is not None and wire.output not in spec.outputs:
        if not spec.multi_output:
            return [f"'{target.type}' has a single output: write '@{wire.node}', not '{wire}'"]
        return [
            f"'{target.type}' has no output '{wire.output}'; its outputs are "
            f"{', '.join(spec.outputs)}"
        ]
    if wire.output is None and spec.multi_output:
        return [
            f"'{target.type}' has several outputs; pick one: "
            f"{', '.join('@' + wire.node + '.' + o for o in spec.outputs)}"
        ]
    produced = output_type(g, wire, registry) or spec.output_type(wire.output)
    if not pt.accepts(produced):
        why = ""
        item = PortType(tuple(Kind(k.base) for k in produced.kinds))
        if target.repeat is not None and pt.accepts(item):
            why = (
                f" ('{wire.node}' is repeated over '{target.repeat.name}': it gives a list, "
                f"one item per {target.repeat.name})"
            )
        return [f"expected {pt.name}, got {produced.name} from '{wire}'{why}"]
    return []


def _check_literal(g: Outline, pt: PortType, value: Any, loop: _Loop | None = None) -> list[str]:
    if pt.is_expression:
        if not isinstance(value, str):
            return [f"expected an expression (text), got {describe(value)}"]
        allowed = set(g.params) | set(pt.variables) | ({loop.name} if loop else set())
        try:
            compile_expression(value, allowed)
        except ExpressionError as exc:
            return [exc.problems[0].message]
        return []
    problems = _coerce_problems(pt, value)
    if not problems and pt.is_output_path and isinstance(value, str):
        why = safety.path_problem(value)
        if why:
            problems.append(why)
    if not problems and pt.is_input_path and isinstance(value, str):
        why = safety.path_problem(value, "input path", "the inputs folder", output=False)
        if why:
            problems.append(why)
    return problems


def _coerce_problems(pt: PortType, value: Any) -> list[str]:
    try:
        pt.coerce(value)
    except TypeMismatch as exc:
        return [str(exc)]
    except ValueError as exc:
        return [str(exc)]
    return []


class _Unknown(Exception):
    """A value that cannot be known before running (a geometry param with no default)."""


def _static_value(g: Outline, item: Input, loop: _Loop | None = None) -> Any:
    if isinstance(item, Literal):
        return item.value
    if isinstance(item, Items):
        return [_static_value(g, i, loop) for i in item.items]
    if isinstance(item, Expr):
        msg = _expr_names_problem(g, item, loop)
        if msg:
            raise _Unknown(msg)
        if loop is not None and loop.name in item.compiled.names:
            raise _Unknown("")  # known item by item, when it runs
        if any(g.params[n].default is None for n in item.compiled.names):
            raise _Unknown("")
        return item.value({n: p.default for n, p in g.params.items()})
    raise _Unknown("")


def _expr_names_problem(g: Outline, e: Expr, loop: _Loop | None = None) -> str | None:
    unknown = sorted(e.compiled.names - set(g.params) - ({loop.name} if loop else set()))
    if unknown:
        known = [*g.params, *([loop.name] if loop else [])]
        return (
            f"expression '={e.text}' names unknown param '{unknown[0]}'"
            f"{suggest(unknown[0], known)}; params are {', '.join(g.params) or 'none'}"
            + (f" (and the loop name '{loop.name}')" if loop else "")
        )
    return None


def _check_expr(g: Outline, pt: PortType, e: Expr, loop: _Loop | None = None) -> list[str]:
    msg = _expr_names_problem(g, e, loop)
    if msg:
        return [msg]
    if loop is not None and e.compiled.is_bare_name and e.text.strip() == loop.name:
        if loop.item is not None and not (pt.accepts(loop.item) or _coercible(pt, loop.item)):
            return [f"expected {pt.name}, got {loop.item.name} from the loop name '{loop.name}'"]
        return []
    if e.compiled.is_bare_name:
        p = g.params[e.text.strip()]
        if p.type is not None:
            if not pt.accepts(p.type):
                return [f"expected {pt.name}, got {p.type.name} from param '{p.name}'"]
            return []
    try:
        value = _static_value(g, e, loop)
    except _Unknown as exc:
        return [str(exc)] if str(exc) else []
    except (ExpressionError, ValueError, TypeError, ZeroDivisionError) as exc:
        return [f"expression '={e.text}' fails with the param defaults: {exc}"]
    if pt.is_expression:
        return (
            []
            if isinstance(value, str)
            else [f"expected an expression (text), got {describe(value)}"]
        )
    return [f"{m} (from '={e.text}')" for m in _coerce_problems(pt, value)]


def _coercible(pt: PortType, item: PortType) -> bool:
    """Whether literal values of type ``item`` (int, float, Vec3) fit port ``pt``."""
    sample = {int: 1, float: 1.5, Vec3: [0.0, 0.0, 0.0]}.get(item.kinds[0].base)
    return sample is not None and not _coerce_problems(pt, sample)


def _check_simulate(
    g: Any, nd: NodeDef, spec: NodeSpec, registry: Mapping[str, NodeSpec]
) -> tuple[list[tuple[str, str]], Any]:
    """Problems of a node's ``simulate:`` as (message, port), and the loop its inputs see
    (the step index, an int), or None without a simulation."""
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
