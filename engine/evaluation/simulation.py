"""Evaluating simulated nodes: a node with ``simulate: {state, from, steps}`` runs
``steps`` times, each step's output the next step's ``state`` input.

Each step has its own cache key, a chain: step 0's key is the identity of ``from``, and
step k's is ``key({"node": base, "state": key of step k - 1})``, where ``base`` hashes the
node's other inputs as a repeated node's does (an input that reads ``step`` enters as its
text and the params it reads). So raising ``steps`` runs only the new steps (the last
cached step is the state to go on from), lowering it runs none, and a changed input starts
again from step 1. The node's own key names its last step.

``@node`` is the last step's output, and all a run keeps; ``@node.frames`` (the list of
every step's output) is gathered from the caches when a wire asks for it, a step the
caches lost recomputed from the one before.

Every step sees the state the simulation started from (``from``) as ``ctx.start``: what
stays put while the state moves (``mesh.relax`` takes its springs' rest lengths from it).

The budget counts each step as a node run (:data:`~.items.ITEM_ELEMENTS` elements) before
anything runs, and the steps times the elements of the state before the first step runs.

:class:`SimulationRun` is a mixin of the evaluation run (:mod:`formgraph.evaluation.run`),
sharing its item keys, lookups and the stats of repeated nodes.
"""

from __future__ import annotations

import time
from typing import Any

from ..core.errors import BudgetError, GraphError, NodeError, Problem
from ..core.registry import NodeSpec
from ..core.types import TypeMismatch
from ..geometry import Mesh, NurbsCurve, Points
from ..language.model import STEP, Input, Items, NodeDef, Wire
from ..language.simulation import steps_problem
from . import cache as _cache
from .items import ITEM_ELEMENTS, file_stamp, reads_loop
from .stats import NodeStat

__all__ = ["SimulationRun", "elements_of"]


def elements_of(value: Any) -> int:
    """The elements a step's state holds, for the budget: vertices and faces of a mesh,
    control points of a curve, points; the sum over a list; 1 for anything else."""
    if isinstance(value, Mesh):
        return value.n_vertices + value.n_faces
    if isinstance(value, NurbsCurve):
        return len(value.control_points)
    if isinstance(value, Points):
        return len(value)
    if isinstance(value, (list, tuple)):
        return sum(elements_of(v) for v in value)
    return 1


class SimulationRun:
    """Simulated nodes, for the evaluation run (``self`` is a ``_Run``)."""

    g: Any
    values: dict[str, Any]
    keys: dict[str, str]
    item_keys: dict[str, list[str]]
    stats: dict[str, Any]
    results: dict[str, Any]
    scale: int = 1

    # ------------------------------------------------------------------------- keys

    def step_count(self, name: str) -> int:
        """The node's ``steps``, checked and budgeted as node runs (memoized)."""
        counts = self.__dict__.setdefault("_step_counts", {})
        if name in counts:
            return counts[name]
        sim = self.g._nodes[name].simulate
        where = self.where(name, "simulate")
        value = self.resolve(name, "simulate", sim.steps)
        problem = steps_problem(value)
        if problem:
            raise GraphError([Problem(where, problem)])
        count = int(value)
        total = count * self.scale
        if total * ITEM_ELEMENTS > self.g.budget:
            raise BudgetError(
                [
                    Problem(
                        where,
                        f"simulate would run {total:,} steps, over the budget of "
                        f"{self.g.budget:,} (each step is a node run and counts as "
                        f"{ITEM_ELEMENTS:,} elements, so at most "
                        f"{self.g.budget // ITEM_ELEMENTS:,} steps; raise it with budget= or "
                        "--budget if you mean it)",
                    )
                ]
            )
        counts[name] = count
        return count

    def step_keys(self, name: str, parts: dict[str, Any]) -> str:
        """The node's key, its steps' keys in :attr:`item_keys` (a chain from ``from``)."""
        sim = self.g._nodes[name].simulate
        base = _cache.key_of(parts)
        prev = _cache.key_of({"from": self.source_part(name, sim.source)})
        keys = []
        for _ in range(self.step_count(name)):
            prev = _cache.key_of({"node": base, "state": prev})
            keys.append(prev)
        self.item_keys[name] = keys
        self.keys[name] = _cache.key_of({"simulate": prev, "steps": len(keys)})
        return self.keys[name]

    def source_part(self, name: str, src: Input) -> Any:
        if isinstance(src, Wire):
            return {"wire": self.identity(src.node), "output": src.output}
        if isinstance(src, Items):
            return [self.source_part(name, i) for i in src.items]
        return _cache.canonical(self.resolve(name, "simulate", src))

    # ----------------------------------------------------------------------- values

    def lookup_steps(self, name: str, spec: NodeSpec) -> tuple[bool, Any, str]:
        """The last step's value when a cache holds it."""
        keys = self.item_keys[name]
        if not keys:
            return False, None, ""
        hit, value, source = self.lookup(keys[-1], spec)
        if hit:
            self.g._identity.setdefault(self.keys[name], self.keys[name])
        return hit, value, source

    def compute_steps(self, name: str, nd: NodeDef, spec: NodeSpec) -> Any:
        """Run the steps after the last one a cache holds; the last step's value."""
        keys = self.item_keys[name]
        state, start = None, 0
        for k in range(len(keys), 0, -1):  # the latest step a cache holds
            hit, value, _ = self.lookup(keys[k - 1], spec)
            if hit:
                state, start = value, k
                break
        if start == 0:
            state = self.start_value(name, nd, spec)
        self.check_state_budget(name, len(keys) - start, state)
        stepper = _Stepper(self, name, nd, spec)
        for k in range(start + 1, len(keys) + 1):
            state = stepper.step(k, state)
        key = self.keys[name]
        self.g._identity[key] = key
        self.g._last[name] = (key, key)
        self.stats[name] = NodeStat(
            "computed",
            stepper.seconds,
            _cache.sizeof(state),
            stepper.warnings,
            items=len(keys),
            computed_items=stepper.computed,
            unit="steps",
        )
        return state

    def frames_of(self, name: str) -> list[Any]:
        """Every step's output, in order (from the caches; a lost step recomputed)."""
        frames = self.__dict__.setdefault("_frames", {})
        if name in frames:
            return frames[name]
        nd = self.g._nodes[name]
        spec = self.registry[nd.type]
        stepper = _Stepper(self, name, nd, spec)
        out: list[Any] = []
        state = None
        for k, key in enumerate(self.item_keys[name], start=1):
            hit, value, _ = self.lookup(key, spec)
            if not hit:
                if state is None:
                    for u in dict.fromkeys(nd.upstream()):
                        self.fetch(u)
                    state = self.start_value(name, nd, spec)
                value = stepper.step(k, state)
            out.append(value)
            state = value
        st = self.stats.get(name)
        if st is not None and stepper.computed:
            st.computed_items += stepper.computed
            st.seconds += stepper.seconds
        frames[name] = out
        return out

    def start_value(self, name: str, nd: NodeDef, spec: NodeSpec) -> Any:
        """Step 0: ``from``, as the state input takes it."""
        sim = nd.simulate
        raw = self.resolve(name, "simulate", sim.source)
        try:
            return spec.inputs[sim.state].type.coerce(raw)
        except (TypeMismatch, ValueError) as exc:
            raise GraphError([Problem(self.where(name, "simulate"), f"from: {exc}")]) from None

    def check_state_budget(self, name: str, steps: int, state: Any) -> None:
        n = elements_of(state)
        if steps * n > self.g.budget:
            raise BudgetError(
                [
                    Problem(
                        self.where(name, "simulate"),
                        f"simulate would run {steps:,} steps on a state of {n:,} elements "
                        f"({steps * n:,} in all), over the budget of {self.g.budget:,} (raise "
                        "it with budget= or --budget if you mean it)",
                    )
                ]
            )


class _Stepper:
    """Runs single steps of one simulated node: the inputs that do not read ``step`` are
    resolved once, the others per step; each step is cached under its key."""

    def __init__(self, run: Any, name: str, nd: NodeDef, spec: NodeSpec):
        self.run, self.name, self.nd, self.spec = run, name, nd, spec
        state = nd.simulate.state
        self.varying = {
            port
            for port, v in nd.inputs.items()
            if port != state and reads_loop(v, STEP, spec.inputs[port].type)
        }
        self.base: dict[str, Any] | None = None  # resolved at the first step that runs
        self.start: Any = None  # ``from``, the state at step 0 (ctx.start of every step)
        self.seconds = 0.0
        self.warnings: list[str] = []
        self.computed = 0

    def step(self, k: int, state: Any) -> Any:
        run, name, nd, spec = self.run, self.name, self.nd, self.spec
        if self.base is None:
            for u in dict.fromkeys(nd.upstream()):  # a frame recomputed late needs them
                run.fetch(u)
            self.base = run.inputs(name, nd, spec, None, skip=self.varying | {nd.simulate.state})
            self.start = run.start_value(name, nd, spec)
        env = dict(run.values)
        env[STEP] = k
        kwargs = dict(self.base)
        if self.varying:
            kwargs.update(run.inputs(name, nd, spec, env, only=self.varying))
        kwargs[nd.simulate.state] = state
        t0 = time.perf_counter()
        try:
            value, _, w = run.call(name, nd, spec, kwargs, env, start=self.start)
        except NodeError as exc:
            message = str(exc)[len(f"{exc.where.prefix()} ({exc.node_type}): ") :]
            raise NodeError(exc.where, exc.node_type, f"step {k}: {message}") from exc.__cause__
        value = run.check_output(name, nd, spec, value)
        self.seconds += time.perf_counter() - t0
        self.warnings.extend(f"step {k}: {m}" for m in w)
        key = run.item_keys[name][k - 1]
        size = _cache.sizeof(value)
        run.g.memory.put(key, value, size)
        if run.g.disk is not None:
            run.g.disk.put(key, value, key)
        run.g._identity[key] = key
        if spec.is_export:
            run.g._written[key] = file_stamp(value)
        self.computed += 1
        return value
