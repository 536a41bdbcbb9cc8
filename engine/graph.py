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
from .geometry import Points
from .model import Expr, Input, Items, Literal, NodeDef, ParamDef, Wire, parse_input, wires_of
from .registry import DEFAULT_BUDGET, Context, NodeSpec, node_types
from .subgraph import Includes, SubgraphSpec, is_graph_type
from .types import TypeMismatch, type_by_name
from .yamlio import MAX_BYTES, dump, parse

__all__ = ["Graph", "NodeStat", "load"]


@dataclass
class NodeStat:
    """What happened to one node in the last evaluation."""

    status: str  # 'computed' or 'cached'
    seconds: float = 0.0
    nbytes: int = 0
    warnings: list[str] = field(default_factory=list)
    source: str = ""  # where a cached value came from: 'memory' or 'disk'
    items: int | None = None  # a repeated node: how many items it has
    computed_items: int = 0  # ... and how many of them were computed (not cached)
    inner: dict[str, NodeStat] | None = None  # a subgraph node: its own nodes' stats


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
        self.outputs: dict[str, Any] = {}  # the `outputs:` mapping, for use as a subgraph
        self._output_lines: dict[str, int] = {}
        self._subgraphs: dict[str, SubgraphSpec] = {}  # graph-file node types -> specs
        self._includes: Includes | None = None
        self._children: dict[Any, Graph] = {}  # subgraph path -> its graph, caches shared
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
        g.outputs = doc.outputs
        g._output_lines = doc.output_lines
        if check:
            try:
                g.check()
            except GraphError as exc:
                exc.files = g.files  # type: ignore[attr-defined]  (what watch must watch)
                raise
        return g

    @property
    def file_label(self) -> str:
        return self.file if self.file else "<graph>"

    def _outline(self) -> Outline:
        self._subgraphs, problems = self._resolve_includes()
        self._include_problems = problems
        return Outline(
            self.file_label,
            self._params,
            self._nodes,
            self._subgraphs,
            self.outputs,
            self._output_lines,
        )

    def _resolve_includes(self) -> tuple[dict[str, SubgraphSpec], list[Problem]]:
        if not any(is_graph_type(nd.type) for nd in self._nodes.values()):
            return {}, []
        if self._includes is None:
            top = Path(self.file) if self.file else None
            root = top.resolve().parent if top is not None else Path.cwd()
            self._includes = Includes(root, top)
        base = Path(self.file).resolve().parent if self.file else Path.cwd()
        return self._includes.resolve_all(self._nodes, self.file_label, base)

    @property
    def files(self) -> list[Path]:
        """The graph's file and every subgraph file it reads (what ``watch`` watches)."""
        own = [Path(self.file)] if self.file else []
        return own + (list(self._includes.files) if self._includes is not None else [])

    def as_node_spec(self) -> SubgraphSpec:
        """This graph as a node type, as another graph using its file sees it (its params
        as inputs, its ``outputs:`` as outputs): what ``formgraph nodes part.yaml`` prints."""
        if not self.file:
            raise GraphError("only a graph read from a file can be used as a node")
        path = Path(self.file)
        nd = NodeDef.make(path.name, path.name, {})
        spec, problems = Includes(path.resolve().parent).load(
            nd, str(path), path.resolve().parent, [], ()
        )
        if spec is None:
            raise GraphError(problems)
        return spec

    def _child(self, spec: SubgraphSpec) -> Graph:
        """The graph of a subgraph file, sharing this graph's caches and settings."""
        child = self._children.get(spec.path)
        if child is None:
            doc = spec.document
            assert doc is not None
            child = Graph(file=spec.label, description=doc.description, out_dir=self.out_dir)
            child.budget = self.budget
            child.memory, child.disk = self.memory, self.disk
            child._identity, child._digests, child._written = (
                self._identity,
                self._digests,
                self._written,
            )
            child._params, child._nodes, child.outputs = doc.params, doc.nodes, doc.outputs
            child._values = {n: p.default for n, p in doc.params.items()}
            child._subgraphs = dict(spec.subgraphs)
            child._checked = True  # checked with this graph
            self._children[spec.path] = child
        return child

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

    def node_types(self) -> dict[str, NodeSpec]:
        """The node types this graph can use: the registry, and the graph files it names."""
        if not self._checked:
            self._outline()  # reads the subgraph files
        return {**node_types(), **self._subgraphs}

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
        if port == "repeat":  # not an input: the node's loop
            nd.set_repeat(value)
            self._checked = False
            return
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
        outline = self._outline()
        problems = check_graph(outline, self._parse_problems + self._include_problems)
        if problems:
            cycles = all(p.message.startswith("cycle: ") for p in problems)
            raise (CycleError if cycles else GraphError)(problems)
        self._checked = True

    def problems(self) -> list[Problem]:
        outline = self._outline()
        return check_graph(outline, self._parse_problems + self._include_problems)

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
        return dump(self.description, self._params, self._nodes, self.outputs)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the graph as YAML (author order kept); ``load`` reads back an equal graph."""
        text = self.to_yaml()
        Path(path).write_text(text, encoding="utf-8")

    def _as_data(self) -> Any:
        return (
            self.description,
            {n: p.to_yaml() for n, p in self._params.items()},
            [(n, nd.to_yaml()) for n, nd in self._nodes.items()],
            dict(self.outputs),
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


def _names(value: Input, pt: Any) -> set[str]:
    """The names an input's expressions read (an expression port's text too)."""
    if isinstance(value, Expr):
        return set(value.compiled.names)
    if isinstance(value, Items):
        return {n for i in value.items for n in _names(i, pt)}
    if isinstance(value, Literal) and pt.is_expression and isinstance(value.value, str):
        from .expr import compile_expression

        try:
            return set(compile_expression(value.value).names)
        except ExpressionError:
            return set()
    return set()


def _reads(value: Input, loop: str, pt: Any) -> bool:
    """Whether an input reads the loop name (and so differs item by item)."""
    return loop in _names(value, pt)


def _file_stamp(path: Any) -> tuple[int, int] | None:
    """(size, mtime in ns) of a written file, or None when it is gone."""
    try:
        st = os.stat(path)
    except (OSError, TypeError, ValueError):
        return None
    return st.st_size, st.st_mtime_ns


class _Run:
    """One evaluation call: memoized keys, identities and values, and the run record."""

    def __init__(self, g: Graph, values: dict[str, Any], tokens: dict[str, Any] | None = None):
        self.g = g
        self.values = values
        self.tokens = tokens or {}  # key stand-ins of params that hold wired values
        self.registry = {**node_types(), **g._subgraphs}
        self.keys: dict[str, str] = {}
        self.item_keys: dict[str, list[str]] = {}  # repeated node -> its items' keys
        self.items: dict[str, tuple[list[Any], list[Any]]] = {}  # -> (items, key tokens)
        self.item_values: dict[str, dict[int, Any]] = {}  # -> items found or computed
        self.inner: dict[str, dict[str, NodeStat]] = {}  # subgraph node -> its run's stats
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
        for n in order:  # the budget applies to every count known before anything runs
            r = self.g._nodes[n].repeat
            if r is not None and not wires_of(r.source):
                self.repeat_items(n)
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
        return self.g._identity[self.keys[name]]

    def key(self, name: str) -> str:
        if name in self.keys:
            return self.keys[name]
        nd = self.g._nodes[name]
        spec = self.registry[nd.type]
        parts: dict[str, Any] = {"type": nd.type, "version": spec.version, "inputs": {}}
        digest = getattr(spec, "digest", None)
        if digest is not None:  # a subgraph: its file tree's content
            parts["file"] = digest
        loop = nd.repeat.name if nd.repeat is not None else None
        for port, value in nd.inputs.items():
            if loop is not None and _reads(value, loop, spec.inputs[port].type):
                # known item by item: the authored text and the params it reads here, the
                # item's own token in the item's key
                names = sorted(_names(value, spec.inputs[port].type) & set(self.values))
                parts["inputs"][port] = {
                    "loop": nd.raw[port],
                    "params": {n: self.tokens.get(n, self.values[n]) for n in names},
                }
                continue
            parts["inputs"][port] = self.key_part(name, port, spec, value)
        if spec.is_export:
            parts["out_dir"] = self.out_dir
        if nd.repeat is None:
            self.keys[name] = _cache.key_of(parts)
            return self.keys[name]
        base = _cache.key_of(parts)
        _, tokens = self.repeat_items(name)
        items = [_cache.key_of({"node": base, "item": t}) for t in tokens]
        self.item_keys[name] = items
        self.keys[name] = _cache.key_of({"repeat": items})
        return self.keys[name]

    def repeat_items(self, name: str) -> tuple[list[Any], list[Any]]:
        """The items of a repeated node and their key tokens (memoized; budget checked)."""
        if name in self.items:
            return self.items[name]
        r = self.g._nodes[name].repeat
        assert r is not None
        src = r.source
        where = self.where(name, "repeat")
        if isinstance(src, Wire):
            self.fetch(src.node)
            value = self.resolve(name, "repeat", src)
            token: Any = {"wire": self.identity(src.node), "output": src.output}
        else:
            value = self.resolve(name, "repeat", src)
            token = None if isinstance(src, (Literal, Expr)) else self.key_part_items(name, src)
        if isinstance(value, Points):
            value = value.xyz.tolist()
        elif isinstance(value, float) and value.is_integer():
            value = int(value)
        if isinstance(value, int) and not isinstance(value, bool):
            if value < 0:
                raise GraphError([Problem(where, f"a repeat count must be >= 0, got {value}")])
            count = value
        elif isinstance(value, (list, tuple)):
            count = len(value)
        else:
            raise GraphError(
                [
                    Problem(
                        where,
                        f"repeat '{r.name}' runs over a count, a list or Points, got "
                        f"{type(value).__name__}",
                    )
                ]
            )
        if count > self.g.budget:
            raise BudgetError(
                [
                    Problem(
                        where,
                        f"repeat '{r.name}' would run {count:,} items, over the budget of "
                        f"{self.g.budget:,} (raise it with budget= or --budget if you mean it)",
                    )
                ]
            )
        values = list(range(count)) if isinstance(value, int) else list(value)
        if token is None:
            tokens = values
        else:
            tokens = [{"source": token, "index": k} for k in range(count)]
        self.items[name] = (values, tokens)
        return self.items[name]

    def key_part_items(self, name: str, src: Input) -> Any:
        if isinstance(src, Wire):
            return {"wire": self.identity(src.node), "output": src.output}
        if isinstance(src, Items):
            return [self.key_part_items(name, i) for i in src.items]
        return _cache.canonical(self.resolve(name, "repeat", src))

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
        return self.resolve(name, port, value)

    def resolve(self, name: str, port: str, value: Input, env: dict[str, Any] | None = None) -> Any:
        if isinstance(value, Literal):
            return value.value
        if isinstance(value, Wire):
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
        for item in value.items:
            v = self.resolve(name, port, item, env)
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
                if nd.repeat is not None:
                    hit, value, source = self.lookup_items(n, spec)
                else:
                    hit, value, source = self.lookup(self.keys[n], spec)
                if hit:
                    self.results[n] = value
                    self.stats[n] = NodeStat(
                        "cached", time.perf_counter() - t0, _cache.sizeof(value), source=source
                    )
                    if nd.repeat is not None:
                        self.stats[n].items = len(self.item_keys[n])
                    stack.pop()
                    continue
                missed.add(n)
            pending = [u for u in dict.fromkeys(nd.upstream()) if u not in self.results]
            if pending:
                stack.extend(pending)
                continue
            if nd.repeat is not None:
                self.results[n] = self.compute_items(n, nd, spec)
            else:
                self.results[n] = self.compute(n, nd, spec)
            stack.pop()
        return self.results[target]

    def lookup_items(self, name: str, spec: NodeSpec) -> tuple[bool, Any, str]:
        """A repeated node's value when every item is cached (the hits are remembered)."""
        found = self.item_values.setdefault(name, {})
        source = "memory"
        for k, key in enumerate(self.item_keys[name]):
            if k in found:
                continue
            hit, value, src = self.lookup(key, spec)
            if hit:
                found[k] = value
                source = src if src == "disk" else source
        if len(found) < len(self.item_keys[name]):
            return False, None, ""
        value = self.assemble(spec, [found[k] for k in range(len(found))])
        self.g._identity.setdefault(self.keys[name], self.keys[name])
        return True, value, source

    def assemble(self, spec: NodeSpec, values: list[Any]) -> Any:
        """The items' outputs as the node's list (items that are lists are joined)."""

        def join(column: list[Any], t: Any) -> list[Any]:
            listed = all(k.is_list for k in t.kinds)
            out: list[Any] = []
            for v in column:
                if isinstance(v, list) or (listed and isinstance(v, np.ndarray)):
                    out.extend(v)
                else:
                    out.append(v)
            return out

        if spec.multi_output:
            return spec.output_class(
                *(join([v[i] for v in values], t) for i, t in enumerate(spec.outputs.values()))
            )
        return join(values, spec.output_type(None))

    def compute_items(self, name: str, nd: NodeDef, spec: NodeSpec) -> Any:
        """Compute the items of a repeated node that no cache holds, each under its own key."""
        assert nd.repeat is not None
        loop = nd.repeat.name
        items, _ = self.repeat_items(name)
        found = self.item_values.setdefault(name, {})
        keys = self.item_keys[name]
        static = {
            port: v for port, v in nd.inputs.items() if not _reads(v, loop, spec.inputs[port].type)
        }
        base = self.inputs(name, nd, spec, None, skip=set(nd.inputs) - set(static))
        seconds = 0.0
        size = 0
        warnings: list[str] = []
        computed = 0
        for k, item in enumerate(items):
            if k in found:
                continue
            env = dict(self.values)
            env[loop] = item
            kwargs = dict(base)
            kwargs.update(self.inputs(name, nd, spec, env, only=set(nd.inputs) - set(static)))
            value, dt, w = self.call(name, nd, spec, kwargs, env)
            value = self.check_output(name, nd, spec, value)
            seconds += dt
            warnings.extend(f"item {k}: {m}" for m in w)
            n = _cache.sizeof(value)
            size += n
            self.g.memory.put(keys[k], value, n)
            if self.g.disk is not None:
                self.g.disk.put(keys[k], value, keys[k])
            self.g._identity[keys[k]] = keys[k]
            if spec.is_export:
                self.g._written[keys[k]] = _file_stamp(value)
            found[k] = value
            computed += 1
        key = self.keys[name]
        self.g._identity[key] = key
        self.g._last[name] = (key, key)
        self.stats[name] = NodeStat(
            "computed", seconds, size, warnings, items=len(items), computed_items=computed
        )
        return self.assemble(spec, [found[k] for k in range(len(items))])

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
            raw = self.resolve(name, port, nd.inputs[port], env)
            if p.type.is_expression:
                kwargs[port] = self.bind_expression(name, port, p.type, raw, env)
                continue
            try:
                kwargs[port] = p.type.coerce(raw)
            except (TypeMismatch, ValueError) as exc:
                raise GraphError([Problem(self.where(name, port), str(exc))]) from None
        return kwargs

    def call(
        self,
        name: str,
        nd: NodeDef,
        spec: NodeSpec,
        kwargs: dict[str, Any],
        env: dict[str, Any] | None = None,
    ) -> tuple[Any, float, list[str]]:
        """Run the node function (or the subgraph) on ``kwargs``: (value, seconds, warnings)."""
        warnings: list[str] = []
        if spec.wants_context:
            kwargs["ctx"] = Context(name, self.out_path, self.g.budget, warnings)
        if self.g.progress is not None:
            computed = sum(1 for s in self.stats.values() if s.status == "computed")
            self.g.progress(name, computed, self.total)
        t0 = time.perf_counter()
        try:
            if isinstance(spec, SubgraphSpec):
                value = self.run_subgraph(name, nd, spec, kwargs, env)
            else:
                value = spec.func(**kwargs)
        except BudgetError as exc:
            raise BudgetError(
                [Problem(self.where(name), p.message) for p in exc.problems]
            ) from None
        except (NodeError, GraphError) as exc:
            if isinstance(spec, SubgraphSpec):
                raise  # already names the subgraph's file, line and node
            if isinstance(exc, NodeError):
                raise
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
        return value, time.perf_counter() - t0, warnings

    def run_subgraph(
        self,
        name: str,
        nd: NodeDef,
        spec: SubgraphSpec,
        kwargs: dict[str, Any],
        env: dict[str, Any] | None,
    ) -> Any:
        """Evaluate a subgraph's outputs with the node's inputs as its params.

        A wired input enters the subgraph's keys as the wire's identity, never hashed.
        """
        child = self.g._child(spec)
        values = dict(child._values)
        values.update(kwargs)
        tokens = {
            port: self.key_part(name, port, spec, v)
            for port, v in nd.inputs.items()
            if wires_of(v)
            and not (nd.repeat is not None and _reads(v, nd.repeat.name, spec.inputs[port].type))
        }
        run = _Run(child, values, tokens)
        targets = list(dict.fromkeys(w.node for w in spec.output_wires.values()))
        chain = f" (in the subgraph '{name}' of {self.g.file_label})"
        try:
            run.run(targets)
        except NodeError as exc:
            raise NodeError(
                exc.where, exc.node_type, str(exc).split(": ", 1)[-1] + chain
            ) from exc.__cause__
        except GraphError as exc:
            raise type(exc)([Problem(p.where, p.message + chain) for p in exc.problems]) from None
        self.inner[name] = run.stats
        outs = []
        for wire in spec.output_wires.values():
            outs.append(run.resolve(targets[0], "outputs", wire))
        return spec.output_class(*outs) if spec.multi_output else outs[0]

    def compute(self, name: str, nd: NodeDef, spec: NodeSpec) -> Any:
        kwargs = self.inputs(name, nd, spec, None)
        value, seconds, warnings = self.call(name, nd, spec, kwargs)
        value = self.check_output(name, nd, spec, value)
        key = self.key(name)
        identity = self.cutoff_identity(name, key, value)
        size = _cache.sizeof(value)
        self.g.memory.put(key, value, size)
        if self.g.disk is not None:
            self.g.disk.put(key, value, identity)
        if len(self.g._identity) > 1_000_000:  # bounded: forgetting only costs cache hits
            self.g._identity.clear()
            self.g._digests.clear()
        self.g._identity[key] = identity
        self.g._last[name] = (key, identity)
        if spec.is_export:
            self.g._written[key] = _file_stamp(value)
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
        new = self.digest(key, value)
        return prev[1] if new is not None and new == self.digest(prev[0], prev_value) else key

    def digest(self, key: str, value: Any) -> str | None:
        if key not in self.g._digests:
            self.g._digests[key] = _cache.digest(value)
        return self.g._digests[key]

    def bind_expression(
        self, name: str, port: str, pt: Any, text: Any, env: dict[str, Any] | None = None
    ) -> Any:
        from .expr import Bound, compile_expression

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
