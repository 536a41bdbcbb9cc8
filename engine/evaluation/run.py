"""One evaluation call: cache keys in topological order, then values fetched or computed.

Pull-based: only the targets' ancestors are keyed. A node whose key already has an
identity from an earlier run is not even fetched unless a node that must compute needs its
value. Each node's cache key hashes its type, implementation version, resolved literal
inputs and the identities of its wired inputs; a node recomputed to an output identical to
its previous one keeps its previous identity (early cutoff). Repeated and subgraph nodes
are evaluated by the :class:`formgraph.evaluation.items.LanguageRun` mixin.
"""

from __future__ import annotations

import contextlib
import functools
import os
import sys
import time
import warnings as _warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from ..core import memory, safety
from ..core.errors import (
    BudgetError,
    ExpressionError,
    FormgraphWarning,
    GraphError,
    InputError,
    NodeError,
    PathError,
    Problem,
    Where,
)
from ..core.registry import Context, Estimate, NodeSpec, RunTally, node_types
from ..core.types import Entries, TypeMismatch
from ..language.elements import bind_elements, reads_elements
from ..language.expr import FUNCTIONS_VERSION
from ..language.model import FRAMES, STEP, Expr, Input, Items, Literal, NodeDef, Wire, wires_of
from ..language.subgraph import SubgraphSpec
from . import cache as _cache
from .cutoff import same_content
from .items import LanguageRun, file_stamp, input_names, reads_loop
from .keys import InputKeys
from .replay import Replay
from .simulation import SimulationRun
from .stats import NodeStat, Step

__all__ = ["GraphView", "NodeStat", "Step"]  # the records are in .stats


class GraphView(Protocol):
    """What a run sees of its graph (a :class:`formgraph.Graph` is one): its nodes, the
    caches and identity tables it shares with its subgraphs, and its settings. The run
    depends on this narrow view, not on the Graph class, as the check does on ``Outline``."""

    file_label: str
    out_dir: Any
    budget: int
    progress: Callable[[str, int, int], None] | None
    memory: Any  # the bounded memory cache (formgraph.evaluation.cache)
    disk: Any  # the disk cache, or None
    _nodes: dict[str, NodeDef]
    _subgraphs: dict[str, SubgraphSpec]
    _identity: dict[str, str]  # key -> identity of the value it holds
    _written: dict[str, Any]  # key of an export -> (size, mtime) of the file it wrote
    _last: dict[str, tuple[str, str]]  # node -> (key, identity) of its last value
    _replay: dict[tuple[str, ...], Any]  # targets -> the keys of the last run (_Run.replay)

    def _order(self, targets: Any) -> list[str]: ...

    def _child(self, spec: SubgraphSpec) -> GraphView: ...


class _Run(LanguageRun, SimulationRun, Replay, InputKeys):
    """One evaluation call: memoized keys, identities and values, and the run record."""

    def __init__(
        self,
        g: GraphView,
        values: dict[str, Any],
        tokens: dict[str, Any] | None = None,
        pure: bool = False,
    ):
        self.g = g
        self.values = values
        self.pure = pure  # identities are keys: no early cutoff (for plans)
        self.tokens = tokens or {}  # key stand-ins of params that hold wired values
        self.registry = {**node_types(), **g._subgraphs}
        self.keys: dict[str, str] = {}
        self.item_keys: dict[str, list[str]] = {}  # repeated node -> its items' keys
        self.items: dict[str, tuple[list[Any], list[Any]]] = {}  # -> (items, key tokens)
        self.item_values: dict[str, dict[int, Any]] = {}  # -> items found or computed
        self.inner: dict[str, dict[str, NodeStat]] = {}  # subgraph node -> its run's stats
        self.results: dict[str, Any] = {}
        self.stats: dict[str, NodeStat] = {}
        self.total = 0
        self.tally = RunTally(g.budget)  # what this run's nodes hold together
        self.started: set[str] = set()  # nodes that began computing, for the progress line
        self.quiet = False  # inside run(): numpy's warnings are silenced once, not per node
        # node -> input path -> (file, bytes): read once when keyed, handed to the node
        self.input_files: dict[str, dict[str, tuple[Path, bytes]]] = {}

    @functools.cached_property
    def out_path(self) -> Path:
        """The output folder, resolved when a run first needs it (an export's key or a
        node's context), not by every run (a slider's step of a graph without exports
        never looks at the file system)."""
        g = self.g
        memo = getattr(g, "_pure_root", None) if self.pure else None
        if memo is not None and memo[0] == str(g.out_dir):
            # A plan or a step keys with the folder's name only (a sweep plans every variant
            # and runs every step through one: one look at the file system, not thousands);
            # an export still checks where it writes.
            return memo[1]
        try:
            path = safety.output_root(g.out_dir)
        except PathError:  # only an export needs it: each says why, at its own line
            path = Path(os.path.abspath(g.out_dir))
        if self.pure:
            g._pure_root = (str(g.out_dir), path)
        return path

    @functools.cached_property
    def out_dir(self) -> str:
        return str(self.out_path)

    def where(self, name: str, port: str | None = None) -> Where:
        nd = self.g._nodes[name]
        line = nd.input_lines.get(port, nd.line) if port else nd.line
        return Where(self.g.file_label, line, name, port)

    def run(self, targets: list[str]) -> None:
        """Key every ancestor in topological order, then fetch the targets' values.

        A node whose key already has an identity (from an earlier run) is not even fetched
        unless a node that must compute needs its value.
        """
        if self.quiet:
            return self._run(targets)
        with _quiet_numpy():  # entered once per run, not per node (~3 us each)
            self.quiet = True
            try:
                return self._run(targets)
            finally:
                self.quiet = False

    def _run(self, targets: list[str]) -> None:
        replayed = self.replay(targets)
        order = self.g._order(targets) if replayed is None else replayed
        self.total = len(order)
        for n in order:  # the budget applies to every count known before anything runs
            r = self.g._nodes[n].repeat
            if r is not None and not wires_of(r.source):
                self.repeat_items(n)
                self.precheck_nested(n)
            elif r is not None:  # over a wire: what its source would make, before it runs
                for w in wires_of(r.source):
                    self.precheck_source(n, r.name, w.node, self.where(n, "repeat"))
            if self.g._nodes[n].simulate is not None:
                self.step_count(n)
        for n in order:
            key = self.key(n)
            if key in self.g._identity and not self.registry[self.g._nodes[n].type].is_export:
                st = self.stats.setdefault(n, NodeStat("cached", 0.0, source="identity"))
                if n in self.item_keys:
                    st.items = len(self.item_keys[n])
                    st.unit = "steps" if self.g._nodes[n].simulate is not None else st.unit
            else:
                self.fetch(n)
        for t in targets:
            self.fetch(t)
        self.input_files.clear()  # the bytes of inputs whose nodes came from a cache
        if replayed is None:
            self.remember(targets, order)

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
        parts = self.key_parts(name, nd, spec)
        if nd.simulate is not None:
            return self.step_keys(name, parts)
        if nd.repeat is None:
            self.keys[name] = _cache.key_of(parts)
            return self.keys[name]
        base = _cache.key_of(parts)
        _, tokens = self.repeat_items(name)
        items = [_cache.key_of({"node": base, "item": t}) for t in tokens]
        self.item_keys[name] = items
        self.keys[name] = _cache.key_of({"repeat": items})
        return self.keys[name]

    def key_parts(
        self, name: str, nd: NodeDef, spec: NodeSpec, slots: dict[str, Any] | None = None
    ) -> dict[str, Any]:
        """What a node's key hashes; ``slots`` stands in for some ports' parts (a sweep's
        plans splice each variant's parts of the ports that vary into one text)."""
        parts: dict[str, Any] = {
            "type": nd.type,
            "version": spec.version,
            "functions": FUNCTIONS_VERSION,  # what rand returns: a new hash, new keys
            "inputs": {},
        }
        digest = getattr(spec, "digest", None)
        if digest is not None:  # a subgraph: its file tree's content
            parts["file"] = digest
        loop = nd.repeat.name if nd.repeat is not None else None
        sim = nd.simulate
        if sim is not None:
            loop = STEP
        for port, value in nd.inputs.items():
            if sim is not None and port == sim.state:
                continue  # the previous step's key stands for it
            if loop is not None and reads_loop(value, loop, spec.inputs[port].type):
                # known item by item: the authored text and the params it reads here, the
                # item's own token in the item's key
                names = sorted(input_names(value, spec.inputs[port].type) & set(self.values))
                parts["inputs"][port] = {
                    "loop": nd.raw[port],
                    "params": {n: self.tokens.get(n, self.values[n]) for n in names},
                    "wires": [self.key_part(name, port, spec, w) for w in wires_of(value)],
                }
                if port in spec.input_paths:  # a file per item, read when the item runs:
                    parts["inputs"][port]["unkeyed"] = os.urandom(8).hex()  # never trusted
                continue
            if slots is not None and port in slots:
                parts["inputs"][port] = slots[port]
                continue
            parts["inputs"][port] = self.port_part(name, port, spec, value)
        if spec.is_export:
            parts["out_dir"] = self.out_dir
        return parts

    def port_part(self, name: str, port: str, spec: NodeSpec, value: Input) -> Any:
        """One port's part of a node's key (a file's the hash of its bytes)."""
        part = self.key_part(name, port, spec, value)
        if port not in spec.input_paths:
            return part
        if wires_of(value):  # a path known only when its wire runs: never trusted
            return {"wired": part, "unkeyed": os.urandom(8).hex()}
        return self.input_file(name, port, part)

    def read_input(self, name: str, relpath: str) -> tuple[Path, bytes]:
        """What a node's ``ctx.read`` returns: the bytes keyed, else the file read now (a
        path that came down a wire)."""
        held = self.input_files.get(name, {}).pop(relpath, None)
        if held is not None:  # handed over: the node holds the only reference (it may let
            return held  # go of a large file's bytes once parsed, before the run ends)
        path = safety.resolve_input(self.g.input_root, relpath, self.g.input_base)
        return path, safety.read_input(path)

    def key_part(self, name: str, port: str, spec: NodeSpec, value: Input) -> Any:
        if isinstance(value, Wire):
            return {"wire": self.identity(value.node), "output": value.output}
        if isinstance(value, Items):
            return [self.key_part(name, port, spec, i) for i in value.items]
        pt = spec.inputs[port].type
        if pt.per_element and reads_elements(value, self.values):
            element = bind_elements(value, self.values)  # per element: text and params
            names = sorted(element.names & set(self.values))
            return {
                "per_element": element.text,
                "params": {n: self.tokens.get(n, self.values[n]) for n in names},
            }
        if pt.is_expression:  # the text, and the values of the params the text reads
            from ..language.expr import compile_expression

            text = self.resolve(name, port, value)
            try:
                names = compile_expression(text).names & set(self.values)
            except ExpressionError as exc:
                raise GraphError(
                    [Problem(self.where(name, port), exc.problems[0].message)]
                ) from None
            return {
                "expr": text,
                "params": {n: self.tokens.get(n, self.values[n]) for n in sorted(names)},
            }
        if isinstance(value, Expr) and value.compiled.names & self.tokens.keys():
            names = sorted(value.compiled.names)  # reads a wired subgraph param: its identity
            return {
                "expr": value.text,
                "params": {n: self.tokens.get(n, self.values[n]) for n in names},
            }
        if isinstance(value, Literal) and type(value.value) in (list, dict):
            # a literal list's key text, written once and kept with it (the same text)
            kept = value.__dict__.get("_keyed")
            if kept is None:
                kept = _cache.Keyed(value.value)
                object.__setattr__(value, "_keyed", kept)
            return kept
        return self.resolve(name, port, value)

    def resolve(self, name: str, port: str, value: Input, env: dict[str, Any] | None = None) -> Any:
        if isinstance(value, Literal):
            return value.value
        if isinstance(value, Wire):
            if value.output == FRAMES and self.g._nodes[value.node].simulate is not None:
                return self.frames_of(value.node)
            out = self.results[value.node]
            if value.output and self.registry[self.g._nodes[value.node].type].multi_output:
                return getattr(out, value.output)
            return out
        values = self.values if env is None else env
        if isinstance(value, Expr):
            missing = [n for n in value.compiled.names if values.get(n) is None]
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
                return value.value(values)
            except (ValueError, TypeError, ZeroDivisionError, ExpressionError) as exc:
                raise GraphError([Problem(self.where(name, port), str(exc))]) from None
        out: list[Any] = []
        entries: list[int] = []
        for k, item in enumerate(value.items):
            v = self.resolve(name, port, item, env)
            if isinstance(item, Wire) and isinstance(v, list):
                out.extend(v)  # a list from a wire joins the list (checked at load)
                entries.extend([k] * len(v))
            else:
                out.append(v)
                entries.append(k)
        return Entries(out, entries)  # which entry each item came on (types.entries_of)

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
                if nd.repeat is not None:
                    hit, value, source = self.lookup_items(n, spec)
                elif nd.simulate is not None:
                    hit, value, source = self.lookup_steps(n, spec)
                else:
                    hit, value, source = self.lookup(self.keys[n], spec)
                if hit:
                    self.results[n] = value
                    size = self.g.memory.size(self.keys.get(n, ""), value)  # or sizeof
                    self.tally.held += size
                    seconds = time.perf_counter() - t0
                    self.stats[n] = NodeStat("cached", seconds, size, source=source)
                    if nd.repeat is not None:
                        self.stats[n].items = len(self.item_keys[n])
                    elif nd.simulate is not None:
                        self.stats[n].items = len(self.item_keys[n])
                        self.stats[n].unit = "steps"
                    stack.pop()
                    continue
                missed.add(n)
            pending = [u for u in dict.fromkeys(nd.upstream()) if u not in self.results]
            if pending:
                stack.extend(pending)
                continue
            if nd.repeat is not None:
                self.results[n] = self.compute_items(n, nd, spec)
            elif nd.simulate is not None:
                self.results[n] = self.compute_steps(n, nd, spec)
            else:
                self.results[n] = self.compute(n, nd, spec)
            st = self.stats.get(n)
            self.tally.held += st.nbytes if st is not None and st.nbytes else 0
            stack.pop()
        return self.results[target]

    def lookup(self, key: str, spec: NodeSpec) -> tuple[bool, Any, str]:
        hit, value = self.g.memory.get(key)
        identity = None
        source = "memory"
        if not hit and self.g.disk is not None:
            hit, value, identity = self.g.disk.get_entry(key)
            source = "disk"
            if hit and not _holds(spec, value):
                hit = False  # a well-formed entry of another type (a foreign or forged file)
            if hit:
                self.g.memory.put(key, value)
        if hit and spec.is_export:
            # trusted only when this graph wrote the file and it is still what was written; a
            # fresh process has no record, so it writes again (an identical file stays untouched)
            stamp = file_stamp(value)
            if stamp is None or self.g._written.get(key) != stamp:
                hit = False
        if hit and spec.multi_output and not isinstance(value, spec.output_class):
            value = spec.output_class(*value)  # the disk cache stores the outputs as a list
        if hit and key not in self.g._identity:
            self.g._identity[key] = identity or key
        return hit, value, source

    def inputs(
        self,
        name: str,
        nd: NodeDef,
        spec: NodeSpec,
        env: dict[str, Any] | None,
        *,
        only: set[str] | None = None,
        skip: set[str] = frozenset(),  # type: ignore[assignment]
    ) -> dict[str, Any]:
        """The node function's keyword arguments (``env``: the values expressions see)."""
        kwargs: dict[str, Any] = {}
        for port, p in spec.inputs.items():
            if (only is not None and port not in only) or port in skip:
                continue
            if port not in nd.inputs:  # defaults reach the node typed like any input
                if p.type.is_expression and p.default is not None:
                    kwargs[port] = self.bind_expression(name, port, p.type, p.default, env)
                else:
                    kwargs[port] = p.type.coerce(p.default)
                continue
            values = self.values if env is None else env
            if p.type.per_element and reads_elements(nd.inputs[port], values):
                kwargs[port] = bind_elements(nd.inputs[port], values)
                continue
            raw = self.resolve(name, port, nd.inputs[port], env)
            if isinstance(nd.inputs[port], Wire) and isinstance(raw, list):
                raw = Entries(raw, [0] * len(raw))  # one wire: one entry, however many items
            if p.type.is_expression:
                kwargs[port] = self.bind_expression(name, port, p.type, raw, env)
                continue
            try:
                kwargs[port] = p.type.coerce(raw)
            except (TypeMismatch, ValueError) as exc:
                raise GraphError([Problem(self.where(name, port), str(exc))]) from None
        return kwargs

    def estimate(self, name: str, spec: NodeSpec, kwargs: dict[str, Any]) -> float | None:
        """What node ``name`` would make on ``kwargs``, by running it only to its first
        budget check (``Context.guard``); None when it makes no such check."""
        if not spec.wants_context or isinstance(spec, SubgraphSpec):
            return None
        ctx = Context(name, self.out_path, self.g.budget, [], probe=True)
        try:
            with contextlib.nullcontext() if self.quiet else _quiet_numpy():
                spec.func(**{**kwargs, "ctx": ctx})
        except Estimate as est:
            return float(est.elements)
        except Exception:  # the real call reports it, located
            return None
        return None

    def call(
        self,
        name: str,
        nd: NodeDef,
        spec: NodeSpec,
        kwargs: dict[str, Any],
        env: dict[str, Any] | None = None,
        start: Any = None,
    ) -> tuple[Any, float, list[str]]:
        """Run the node function (or the subgraph) on ``kwargs``: (value, seconds, warnings);
        ``start``: a simulation's first state, for a step (:attr:`Context.start`)."""
        warnings: list[str] = []
        if spec.wants_context:
            kwargs["ctx"] = Context(
                name,
                # resolved for an export (its key holds it); any other node that writes
                # resolves it then (ctx.write goes through safety.resolve_output)
                self.out_path if spec.is_export else Path(self.g.out_dir),
                self.g.budget,
                warnings,
                inputs=lambda relpath: self.read_input(name, relpath),
                tally=self.tally,
                start=start,
            )
        if self.g.progress is not None:  # counted as it goes: linear in the graph's size
            self.g.progress(name, len(self.started) - (name in self.started), self.total)
        self.started.add(name)
        t0 = time.perf_counter()
        try:
            with contextlib.nullcontext() if self.quiet else _quiet_numpy():
                if isinstance(spec, SubgraphSpec):
                    value = self.run_subgraph(name, nd, spec, kwargs, env)
                else:
                    value = spec.func(**kwargs)
        except BudgetError as exc:
            if isinstance(spec, SubgraphSpec):
                raise  # already names the subgraph's file, line and node
            here = self.where(name, exc.port)
            raise BudgetError([Problem(here, p.message) for p in exc.problems]) from None
        except (NodeError, GraphError) as exc:
            if isinstance(spec, SubgraphSpec):
                raise  # already names the subgraph's file, line and node
            if isinstance(exc, NodeError):
                raise
            port = getattr(exc, "port", None)
            if port is None and getattr(exc, "path", None) is not None:  # its path input
                paths = (p for p, t in spec.inputs.items() if t.type.is_output_path)
                port = next(paths, spec.input_paths[0] if spec.input_paths else None)
            raise type(exc)(
                [Problem(self.where(name, port), p.message) for p in exc.problems]
            ) from None
        except InputError as exc:
            raise NodeError(self.where(name, exc.port), nd.type, str(exc)) from exc
        except (ValueError, ZeroDivisionError) as exc:
            raise NodeError(self.where(name), nd.type, str(exc)) from exc
        except MemoryError as exc:  # a node that does not say what it will make (guard)
            raise NodeError(self.where(name), nd.type, memory.ran_out(exc)) from None
        except Exception as exc:
            raise NodeError(self.where(name), nd.type, f"{type(exc).__name__}: {exc}") from exc
        finally:
            self.input_files.pop(name, None)
        for w in warnings:
            _warn(f"{self.where(name).prefix()}: {w}")
        return value, time.perf_counter() - t0, warnings

    def compute(self, name: str, nd: NodeDef, spec: NodeSpec) -> Any:
        kwargs = self.inputs(name, nd, spec, None)
        value, seconds, warnings = self.call(name, nd, spec, kwargs)
        value = self.check_output(name, nd, spec, value)
        key = self.key(name)
        identity = key if self.pure else self.cutoff_identity(name, key, value)
        size = _cache.sizeof(value)
        self.g.memory.put(key, value, size)
        if self.g.disk is not None:
            self.g.disk.put(key, value, identity)
        if len(self.g._identity) > 1_000_000:  # bounded: forgetting only costs cache hits
            self.g._identity.clear()
        self.g._identity[key] = identity
        if not self.pure:
            self.g._last[name] = (key, identity)
        if spec.is_export:
            self.g._written[key] = file_stamp(value)
        self.stats[name] = NodeStat("computed", seconds, size, warnings)
        self.stats[name].inner = self.inner.pop(name, None)
        return value

    def cutoff_identity(self, name: str, key: str, value: Any) -> str:
        """The identity of a freshly computed output: the previous one when identical."""
        prev = self.g._last.get(name)
        if prev is None or prev[0] == key:
            return key
        hit, prev_value = self.g.memory.get(prev[0])
        if not hit:
            return key
        return prev[1] if same_content(value, prev_value) else key

    def bind_expression(
        self, name: str, port: str, pt: Any, text: Any, env: dict[str, Any] | None = None
    ) -> Any:
        from ..language.bound import Bound
        from ..language.expr import compile_expression

        values = self.values if env is None else env
        allowed = set(values) | set(pt.variables)
        try:
            compiled = compile_expression(text, allowed)
        except ExpressionError as exc:
            raise GraphError([Problem(self.where(name, port), exc.problems[0].message)]) from None
        params = {n: values[n] for n in compiled.names if n in values}
        return Bound(compiled, params)

    def check_output(self, name: str, nd: NodeDef, spec: NodeSpec, value: Any) -> Any:
        if spec.multi_output:
            for field_name, v in zip(spec.outputs, value, strict=False):
                if isinstance(v, float) and not np.isfinite(v):
                    raise NodeError(
                        self.where(name),
                        nd.type,
                        f"output '{field_name}' is not finite ({v}): an input is too extreme",
                    )
            return value
        out_type = spec.output_type(None)
        try:
            return out_type.coerce(value)
        except (TypeMismatch, ValueError) as exc:
            raise NodeError(
                self.where(name),
                nd.type,
                f"returned a value that does not fit its output {out_type.name}: {exc}",
            ) from None


@contextlib.contextmanager
def _quiet_numpy() -> Iterator[None]:
    """numpy's overflow/invalid-value chatter never reaches a user: a result that is not
    finite is refused (check_output, the geometry types), located."""
    with np.errstate(all="ignore"), _warnings.catch_warnings():
        _warnings.simplefilter("ignore", RuntimeWarning)
        yield


_PACKAGE = os.path.dirname(os.path.abspath(__file__))


def _warn(message: str) -> None:
    """Emit a :class:`FormgraphWarning` attributed to the first caller outside formgraph."""
    frame, level = sys._getframe(0), 1
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    _warnings.warn(message, FormgraphWarning, stacklevel=level)


def _holds(spec: NodeSpec, value: Any) -> bool:
    """Whether a value read from the disk cache has the shape of ``spec``'s output(s)."""
    if not spec.multi_output:
        return spec.output_type(None).holds(value)
    if not isinstance(value, (list, tuple)) or len(value) != len(spec.outputs):
        return False
    return all(t.holds(v) for t, v in zip(spec.outputs.values(), value, strict=True))
