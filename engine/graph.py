"""The graph: params and nodes, checked whole, evaluated on demand through the caches.

Evaluation is pull-based: asking for a node evaluates only its ancestors. Each node's cache
key hashes its type, implementation version, resolved literal inputs and the identities of
its wired inputs. A node's identity is its key, except that a node recomputed to an output
identical to its previous one keeps its previous identity (early cutoff: its descendants stay
cached). Outputs are hashed only for that comparison, never on a cold run.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import cache as _cache
from .check import Outline, check_graph, check_param_value
from .errors import (
    BudgetError,
    CycleError,
    ExpressionError,
    GraphError,
    InputError,
    NodeError,
    ParamError,
    Problem,
    Where,
)
from .model import Expr, Input, Items, Literal, NodeDef, ParamDef, Wire, parse_input
from .registry import DEFAULT_BUDGET, Context, NodeSpec, node_types
from .types import TypeMismatch, type_by_name
from .yamlio import MAX_BYTES, dump, parse

__all__ = ["Graph", "NodeStat", "Step", "load"]


@dataclass
class NodeStat:
    """What happened to one node in the last evaluation."""

    status: str  # 'computed' or 'cached'
    seconds: float = 0.0
    nbytes: int = 0
    warnings: list[str] = field(default_factory=list)
    source: str = ""  # where a cached value came from: 'memory' or 'disk'


@dataclass(frozen=True)
class Step:
    """One node of an evaluation plan (see :meth:`Graph.plan`)."""

    name: str
    key: str  # the node's cache key for the planned params
    upstream: tuple[str, ...]  # the nodes whose outputs it reads, each once
    export: bool  # an export node (writes a file into the output directory)


Progress = Callable[[str, int, int], None]


def load(
    path: str | os.PathLike[str],
    *,
    out_dir: str | os.PathLike[str] = "out",
    cache_dir: str | os.PathLike[str] | None = None,
    budget: int = DEFAULT_BUDGET,
    memory_bytes: int = 1 << 30,
) -> Graph:
    """Read and check a graph file.

    Raises
    ------
    GraphError
        With every problem found, each naming file, line, node and input.
    """
    path = Path(path)
    try:
        with open(path, "rb") as fh:  # never read more than the format allows
            data = fh.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            raise GraphError(
                Problem(
                    Where(str(path)), f"the file is larger than {MAX_BYTES // (1024 * 1024)} MiB"
                )
            )
        text = data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise GraphError(Problem(Where(str(path)), f"cannot read the graph file: {exc}")) from None
    return Graph.from_text(
        text,
        file=str(path),
        out_dir=out_dir,
        cache_dir=cache_dir,
        budget=budget,
        memory_bytes=memory_bytes,
    )


class Graph:
    """A formgraph graph. Build it in code with :meth:`add` or read one with :func:`load`.

    Example
    -------
    >>> g = Graph()
    >>> g.add("pts", "points.circle", count=8, radius=2)
    >>> len(g.evaluate("pts"))
    8
    """

    def __init__(
        self,
        *,
        out_dir: str | os.PathLike[str] = "out",
        cache_dir: str | os.PathLike[str] | None = None,
        budget: int = DEFAULT_BUDGET,
        memory_bytes: int = 1 << 30,
        description: str = "",
        file: str | None = None,
    ):
        self.file = file
        self.description = description
        self.out_dir = Path(out_dir)
        self.budget = budget
        self.memory = _cache.MemoryCache(memory_bytes)
        self.disk = _cache.DiskCache(cache_dir) if cache_dir is not None else None
        self._params: dict[str, ParamDef] = {}
        self._values: dict[str, Any] = {}
        self._nodes: dict[str, NodeDef] = {}
        self._identity: dict[str, str] = {}  # cache key -> identity seen downstream
        self._last: dict[str, tuple[str, str]] = {}  # node -> (key, identity) of its last output
        self._digests: dict[str, str | None] = {}  # cache key -> content digest, when computed
        self._written: dict[str, tuple[int, int] | None] = {}  # export key -> file stamp
        self._parse_problems: list[Problem] = []
        self._checked = False
        self.stats: dict[str, NodeStat] = {}
        self.progress: Progress | None = None

    # ----------------------------------------------------------------------- building

    @classmethod
    def from_text(
        cls, text: str, *, file: str | None = None, check: bool = True, **kwargs: Any
    ) -> Graph:
        doc = parse(text, file or "<graph>")
        g = cls(file=file, description=doc.description, **kwargs)
        g._params = doc.params
        g._values = {n: p.default for n, p in doc.params.items()}
        g._nodes = doc.nodes
        g._parse_problems = doc.problems
        if check:
            g.check()
        return g

    @property
    def file_label(self) -> str:
        return self.file if self.file else "<graph>"

    def _outline(self) -> Outline:
        return Outline(self.file_label, self._params, self._nodes)

    def add_param(
        self,
        name: str,
        default: Any = None,
        *,
        min: float | None = None,
        max: float | None = None,
        doc: str = "",
        type: str | None = None,
    ) -> None:
        """Declare a graph param (``type`` names a geometry type for a Python input slot)."""
        long_form = any(x is not None for x in (min, max, type)) or bool(doc)
        default = _plain(default)
        p = ParamDef(name, default, None, type, min, max, doc, None, long_form)
        if type is not None:
            p.type = type_by_name(type)
        self._params[name] = p
        self._values[name] = default
        self._checked = False

    def add(self, name: str, type: str, **inputs: Any) -> None:
        """Add (or replace) node ``name`` of node type ``type`` with its inputs."""
        self._nodes[name] = NodeDef.make(name, type, {k: _plain(v) for k, v in inputs.items()})
        self._checked = False

    def remove(self, name: str) -> None:
        del self._nodes[name]
        self._checked = False

    @property
    def nodes(self) -> dict[str, str]:
        """Node name -> node type, in author order."""
        return {n: nd.type for n, nd in self._nodes.items()}

    def node_inputs(self, name: str) -> dict[str, Any]:
        """The inputs of node ``name`` as authored."""
        return dict(self._nodes[name].raw)

    def set_input(self, node: str, port: str, value: Any) -> None:
        """Change one input of a node as authored (a literal, wire or expression)."""
        nd = self._nodes[node]
        value = _plain(value)
        nd.raw[port] = value
        nd.parse_errors.pop(port, None)
        try:
            nd.inputs[port] = parse_input(value)
        except ExpressionError as exc:
            nd.parse_errors[port] = exc.problems[0].message
        self._checked = False

    # ------------------------------------------------------------------------- params

    @property
    def params(self) -> dict[str, Any]:
        """The current param values."""
        return dict(self._values)

    @property
    def param_defs(self) -> dict[str, ParamDef]:
        return dict(self._params)

    def set(self, **params: Any) -> None:
        """Change param values for later evaluations."""
        self._values.update(self._checked_params(params))

    def _checked_params(self, params: dict[str, Any]) -> dict[str, Any]:
        problems = []
        out = {}
        for name, value in params.items():
            p = self._params.get(name)
            if p is None:
                from .check import suggest

                problems.append(
                    Problem(
                        Where(self.file_label),
                        f"unknown param '{name}'"
                        f"{suggest(name, self._params)}; params are "
                        f"{', '.join(self._params) or 'none'}",
                    )
                )
                continue
            try:
                out[name] = check_param_value(p, value)
            except TypeMismatch as exc:
                problems.append(Problem(Where(self.file_label, p.line), f"param '{name}': {exc}"))
        if problems:
            raise ParamError(problems)
        return out

    # -------------------------------------------------------------------------- check

    def check(self) -> None:
        """Check the whole graph; raise one GraphError listing every problem."""
        problems = check_graph(self._outline(), self._parse_problems)
        if problems:
            cycles = all(p.message.startswith("cycle: ") for p in problems)
            raise (CycleError if cycles else GraphError)(problems)
        self._checked = True

    def problems(self) -> list[Problem]:
        return check_graph(self._outline(), self._parse_problems)

    # ----------------------------------------------------------------------- evaluate

    def evaluate(self, nodes: str | Iterable[str], **params: Any) -> Any:
        """Evaluate one node (returns its output) or several (returns a dict by name).

        Keyword arguments override params for this call only.
        """
        if not self._checked:
            self.check()
        values = dict(self._values)
        values.update(self._checked_params(params))
        names = [nodes] if isinstance(nodes, str) else list(nodes)
        for n in names:
            if n not in self._nodes:
                from .check import suggest

                raise GraphError(f"{self.file_label}: no node '{n}'{suggest(n, self._nodes)}")
        run = _Run(self, values)
        self.stats = run.stats
        run.run(names)
        outs = {n: run.results[n] for n in names}
        return outs[names[0]] if isinstance(nodes, str) else outs

    def sinks(self) -> list[str]:
        """Nodes nothing else reads from (exports, usually), in author order."""
        used = {up for nd in self._nodes.values() for up in nd.upstream()}
        return [n for n in self._nodes if n not in used]

    def evaluate_all(self, **params: Any) -> dict[str, Any]:
        """Evaluate every sink (so every export writes its file)."""
        return self.evaluate(self.sinks(), **params)

    def plan(self, targets: str | Iterable[str], **params: Any) -> list[Step]:
        """The nodes that ``targets`` need, in evaluation order, each with its cache key.

        Keys are those of a cold evaluation with these params: they depend only on what goes
        into each node (no early cutoff, which needs earlier outputs), so a sweep can key
        every variant's nodes before anything runs and share the nodes whose keys agree.
        Nothing is evaluated.
        """
        if not self._checked:
            self.check()
        values = dict(self._values)
        values.update(self._checked_params(params))
        run = _Run(self, values, pure=True)
        names = [targets] if isinstance(targets, str) else list(targets)
        return [
            Step(
                n,
                run.key(n),
                tuple(dict.fromkeys(self._nodes[n].upstream())),
                run.registry[self._nodes[n].type].is_export,
            )
            for n in self._order(names)
        ]

    def compute_step(
        self,
        step: Step,
        inputs: dict[str, Any],
        *,
        out_dir: str | os.PathLike[str] | None = None,
        **params: Any,
    ) -> tuple[Any, NodeStat]:
        """Node ``step.name``'s output from its inputs' outputs, through the caches.

        ``step`` comes from :meth:`plan` with the same params; ``inputs`` maps each of
        ``step.upstream`` to its output. A value cached under ``step.key`` is returned as it
        is; a computed one is cached under it. Exports always run, writing into ``out_dir``
        (default :attr:`out_dir`).

        Raises
        ------
        NodeError, GraphError
            As :meth:`evaluate` does for the node.
        """
        values = dict(self._values)
        values.update(self._checked_params(params))
        run = _Run(self, values, pure=True)
        if out_dir is not None:
            run.out_path = Path(out_dir).resolve()
            run.out_dir = str(run.out_path)
        run.keys[step.name] = step.key
        run.results.update(inputs)
        nd = self._nodes[step.name]
        spec = run.registry[nd.type]
        if not spec.is_export:
            t0 = time.perf_counter()
            hit, value, source = run.lookup(step.key, spec)
            if hit:
                return value, NodeStat("cached", time.perf_counter() - t0, source=source)
        value = run.compute(step.name, nd, spec)
        return value, run.stats[step.name]

    def cached(self, step: Step) -> tuple[bool, Any]:
        """(True, output) when a cache holds planned ``step``'s output, else (False, None).

        Exports are never answered from the cache (their file may be gone).
        """
        spec = node_types()[self._nodes[step.name].type]
        if spec.is_export:
            return False, None
        hit, value, _ = _Run(self, dict(self._values), pure=True).lookup(step.key, spec)
        return hit, value

    def upstream(self, name: str) -> list[str]:
        """All ancestors of ``name`` and itself, in evaluation order."""
        return self._order([name])

    def _order(self, targets: list[str]) -> list[str]:
        """Ancestors of ``targets`` (and themselves) in topological order, without recursion
        (a chain of thousands of nodes is fine)."""
        order: list[str] = []
        seen: set[str] = set()
        for target in targets:
            stack = [(target, False)]
            while stack:
                n, finished = stack.pop()
                if finished:
                    order.append(n)
                    continue
                if n in seen or n not in self._nodes:
                    continue
                seen.add(n)
                stack.append((n, True))
                stack.extend(
                    (u, False) for u in reversed(self._nodes[n].upstream()) if u not in seen
                )
        return order

    # ------------------------------------------------------------------------ saving

    def to_yaml(self) -> str:
        return dump(self.description, self._params, self._nodes)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the graph as YAML (author order kept); ``load`` reads back an equal graph."""
        text = self.to_yaml()
        Path(path).write_text(text, encoding="utf-8")

    def _as_data(self) -> Any:
        return (
            self.description,
            {n: p.to_yaml() for n, p in self._params.items()},
            [(n, nd.to_yaml()) for n, nd in self._nodes.items()],
        )

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Graph) and self._as_data() == other._as_data()

    def __repr__(self) -> str:
        return f"Graph({self.file_label!r}, {len(self._nodes)} nodes, params={self._values})"


def _plain(value: Any) -> Any:
    """Inputs given from Python as the YAML they save to: tuples and arrays become lists,
    numpy numbers Python numbers (geometry objects stay as they are)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _file_stamp(path: Any) -> tuple[int, int] | None:
    """(size, mtime in ns) of a written file, or None when it is gone."""
    try:
        st = os.stat(path)
    except (OSError, TypeError, ValueError):
        return None
    return st.st_size, st.st_mtime_ns


class _Run:
    """One evaluation call: memoized keys, identities and values, and the run record."""

    def __init__(self, g: Graph, values: dict[str, Any], pure: bool = False):
        self.g = g
        self.values = values
        self.pure = pure  # identities are keys: no early cutoff (for plans)
        self.registry = node_types()
        self.keys: dict[str, str] = {}
        self.results: dict[str, Any] = {}
        self.stats: dict[str, NodeStat] = {}
        self.out_path = g.out_dir.resolve()
        self.out_dir = str(self.out_path)
        self.total = 0
        self.done = 0

    def where(self, name: str, port: str | None = None) -> Where:
        nd = self.g._nodes[name]
        line = nd.input_lines.get(port, nd.line) if port else nd.line
        return Where(self.g.file_label, line, name, port)

    def run(self, targets: list[str]) -> None:
        """Key every ancestor in topological order, then fetch the targets' values.

        A node whose key already has an identity (from an earlier run) is not even fetched
        unless a node that must compute needs its value.
        """
        order = self.g._order(targets)
        self.total = len(order)
        for n in order:
            key = self.key(n)
            if key in self.g._identity and not self.registry[self.g._nodes[n].type].is_export:
                self.stats.setdefault(n, NodeStat("cached", 0.0, source="identity"))
            else:
                self.fetch(n)
        for t in targets:
            self.fetch(t)

    def identity(self, name: str) -> str:
        # identity of the value that flows out of a node: its key, or an earlier identical
        # output's (early cutoff); known for every upstream node by the time it is asked
        if self.pure:
            return self.key(name)
        return self.g._identity[self.keys[name]]

    def key(self, name: str) -> str:
        if name in self.keys:
            return self.keys[name]
        nd = self.g._nodes[name]
        spec = self.registry[nd.type]
        parts: dict[str, Any] = {"type": nd.type, "version": spec.version, "inputs": {}}
        for port, value in nd.inputs.items():
            parts["inputs"][port] = self.key_part(name, port, spec, value)
        if spec.is_export:
            parts["out_dir"] = self.out_dir
        self.keys[name] = _cache.key_of(parts)
        return self.keys[name]

    def key_part(self, name: str, port: str, spec: NodeSpec, value: Input) -> Any:
        if isinstance(value, Wire):
            return {"wire": self.identity(value.node), "output": value.output}
        if isinstance(value, Items):
            return [self.key_part(name, port, spec, i) for i in value.items]
        pt = spec.inputs[port].type
        if pt.is_expression:  # the text, and the values of the params the text reads
            from .expr import compile_expression

            text = self.resolve(name, port, value)
            try:
                names = compile_expression(text).names & set(self.values)
            except ExpressionError as exc:
                raise GraphError(
                    [Problem(self.where(name, port), exc.problems[0].message)]
                ) from None
            return {"expr": text, "params": {n: self.values[n] for n in sorted(names)}}
        return self.resolve(name, port, value)

    def resolve(self, name: str, port: str, value: Input) -> Any:
        if isinstance(value, Literal):
            return value.value
        if isinstance(value, Wire):
            out = self.results[value.node]
            return getattr(out, value.output) if value.output else out
        if isinstance(value, Expr):
            missing = [n for n in value.compiled.names if self.values.get(n) is None]
            if missing:
                raise GraphError(
                    [
                        Problem(
                            self.where(name, port),
                            f"param '{missing[0]}' has no value; pass it as "
                            f"evaluate(..., {missing[0]}=...)",
                        )
                    ]
                )
            try:
                return value.value(self.values)
            except (ValueError, TypeError, ZeroDivisionError, ExpressionError) as exc:
                raise GraphError([Problem(self.where(name, port), str(exc))]) from None
        out: list[Any] = []
        for item in value.items:
            v = self.resolve(name, port, item)
            if isinstance(item, Wire) and isinstance(v, list):
                out.extend(v)  # a list from a wire joins the list (checked at load)
            else:
                out.append(v)
        return out

    def fetch(self, target: str) -> Any:
        """The value of ``target``: from a cache, or computed after its inputs (no recursion)."""
        stack = [target]
        missed: set[str] = set()
        while stack:
            n = stack[-1]
            if n in self.results:
                stack.pop()
                continue
            nd = self.g._nodes[n]
            spec = self.registry[nd.type]
            if n not in missed:
                t0 = time.perf_counter()
                hit, value, source = self.lookup(self.keys[n], spec)
                if hit:
                    self.results[n] = value
                    self.stats[n] = NodeStat(
                        "cached", time.perf_counter() - t0, _cache.sizeof(value), source=source
                    )
                    stack.pop()
                    continue
                missed.add(n)
            pending = [u for u in dict.fromkeys(nd.upstream()) if u not in self.results]
            if pending:
                stack.extend(pending)
                continue
            self.results[n] = self.compute(n, nd, spec)
            stack.pop()
        return self.results[target]

    def lookup(self, key: str, spec: NodeSpec) -> tuple[bool, Any, str]:
        hit, value = self.g.memory.get(key)
        identity = None
        source = "memory"
        if not hit and self.g.disk is not None:
            hit, value, identity = self.g.disk.get_entry(key)
            source = "disk"
            if hit:
                self.g.memory.put(key, value)
        if hit and spec.is_export and self.g._written.get(key) != _file_stamp(value):
            hit = False  # the file is gone or holds something else now: write it again
        if hit and spec.multi_output and not isinstance(value, spec.output_class):
            value = spec.output_class(*value)  # the disk cache stores the outputs as a list
        if hit and key not in self.g._identity:
            self.g._identity[key] = identity or key
        return hit, value, source

    def compute(self, name: str, nd: NodeDef, spec: NodeSpec) -> Any:
        kwargs: dict[str, Any] = {}
        for port, p in spec.inputs.items():
            if port not in nd.inputs:  # defaults reach the node typed like any input
                if p.type.is_expression and p.default is not None:
                    kwargs[port] = self.bind_expression(name, port, p.type, p.default)
                else:
                    kwargs[port] = p.type.coerce(p.default)
                continue
            raw = self.resolve(name, port, nd.inputs[port])
            if p.type.is_expression:
                kwargs[port] = self.bind_expression(name, port, p.type, raw)
                continue
            try:
                kwargs[port] = p.type.coerce(raw)
            except (TypeMismatch, ValueError) as exc:
                raise GraphError([Problem(self.where(name, port), str(exc))]) from None
        warnings: list[str] = []
        if spec.wants_context:
            kwargs["ctx"] = Context(name, self.out_path, self.g.budget, warnings)
        if self.g.progress is not None:
            computed = sum(1 for s in self.stats.values() if s.status == "computed")
            self.g.progress(name, computed, self.total)
        t0 = time.perf_counter()
        try:
            value = spec.func(**kwargs)
        except BudgetError as exc:
            raise BudgetError(
                [Problem(self.where(name), p.message) for p in exc.problems]
            ) from None
        except GraphError as exc:
            raise type(exc)(
                [
                    Problem(self.where(name, getattr(exc, "port", None)), p.message)
                    for p in exc.problems
                ]
            ) from None
        except InputError as exc:
            raise NodeError(self.where(name, exc.port), nd.type, str(exc)) from exc
        except (ValueError, ZeroDivisionError) as exc:
            raise NodeError(self.where(name), nd.type, str(exc)) from exc
        except Exception as exc:
            raise NodeError(self.where(name), nd.type, f"{type(exc).__name__}: {exc}") from exc
        seconds = time.perf_counter() - t0
        value = self.check_output(name, nd, spec, value)
        key = self.key(name)
        identity = key if self.pure else self.cutoff_identity(name, key, value)
        size = _cache.sizeof(value)
        self.g.memory.put(key, value, size)
        if self.g.disk is not None:
            self.g.disk.put(key, value, identity)
        if len(self.g._identity) > 1_000_000:  # bounded: forgetting only costs cache hits
            self.g._identity.clear()
            self.g._digests.clear()
        self.g._identity[key] = identity
        if not self.pure:
            self.g._last[name] = (key, identity)
        if spec.is_export:
            self.g._written[key] = _file_stamp(value)
        self.stats[name] = NodeStat("computed", seconds, size, warnings)
        return value

    def cutoff_identity(self, name: str, key: str, value: Any) -> str:
        """The identity of a freshly computed output: the previous one when identical."""
        prev = self.g._last.get(name)
        if prev is None or prev[0] == key:
            return key
        hit, prev_value = self.g.memory.get(prev[0])
        if not hit:
            return key
        new = self.digest(key, value)
        return prev[1] if new is not None and new == self.digest(prev[0], prev_value) else key

    def digest(self, key: str, value: Any) -> str | None:
        if key not in self.g._digests:
            self.g._digests[key] = _cache.digest(value)
        return self.g._digests[key]

    def bind_expression(self, name: str, port: str, pt: Any, text: Any) -> Any:
        from .expr import Bound, compile_expression

        allowed = set(self.values) | set(pt.variables)
        try:
            compiled = compile_expression(text, allowed)
        except ExpressionError as exc:
            raise GraphError([Problem(self.where(name, port), exc.problems[0].message)]) from None
        params = {n: self.values[n] for n in compiled.names if n in self.values}
        return Bound(compiled, params)

    def check_output(self, name: str, nd: NodeDef, spec: NodeSpec, value: Any) -> Any:
        if spec.multi_output:
            return value
        out_type = spec.outputs["out"]
        try:
            return out_type.coerce(value)
        except (TypeMismatch, ValueError) as exc:
            raise NodeError(
                self.where(name),
                nd.type,
                f"returned a value that does not fit its output {out_type.name}: {exc}",
            ) from None
