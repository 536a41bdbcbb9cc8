"""The graph: params and nodes, checked whole, evaluated on demand through the caches
(one evaluation call is a run of :mod:`formgraph.evaluation.run`).

Evaluation is pull-based: asking for a node evaluates only its ancestors. Each node's cache
key hashes its type, implementation version, resolved literal inputs and the identities of
its wired inputs. A node's identity is its key, except that a node recomputed to an output
identical to its previous one keeps its previous identity (early cutoff: its descendants stay
cached). Outputs are compared (to the previous output, content for content) only for that,
never on a cold run.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

from ..core import safety
from ..core.errors import (
    CycleError,
    ExpressionError,
    GraphError,
    ParamError,
    Problem,
    Where,
)
from ..core.registry import DEFAULT_BUDGET, NodeSpec, node_types
from ..core.types import TypeMismatch, describe, type_by_name
from ..language.check import Outline, check_graph
from ..language.model import NodeDef, ParamDef, parse_input
from ..language.params import check_param_value
from ..language.subgraph import Includes, SubgraphSpec, is_graph_type
from ..language.yamlio import MAX_BYTES, MAX_DEPTH, Document, dump, parse, read_choices
from . import cache as _cache
from .arguments import check_budgets, nesting, node_names, plain
from .plans import Plans
from .run import NodeStat, Step, _Run

__all__ = ["Graph", "NodeStat", "Step", "load"]


Progress = Callable[[str, int, int], None]


def load(
    path: str | os.PathLike[str],
    *,
    out_dir: str | os.PathLike[str] = "out",
    cache_dir: str | os.PathLike[str] | None = None,
    budget: int = DEFAULT_BUDGET,
    memory_bytes: int = 1 << 30,
    inputs_dir: str | os.PathLike[str] | None = None,
) -> Graph:
    """Read and check a graph file.

    The files its ``read.*`` nodes name are relative to the graph file's folder and may not
    leave it; ``inputs_dir`` names another folder to read them from (and confine them to).

    Raises
    ------
    GraphError
        With every problem found, each naming file, line, node and input.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise GraphError(f"load() takes the path of a graph file, got {describe(path)}")
    check_budgets(budget, memory_bytes)
    path = Path(path)
    try:
        text = safety.read_regular(path, max_bytes=MAX_BYTES).decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise GraphError(Problem(Where(str(path)), f"cannot read the graph file: {why}")) from None
    return Graph.from_text(
        text,
        file=str(path),
        out_dir=out_dir,
        cache_dir=cache_dir,
        budget=budget,
        memory_bytes=memory_bytes,
        inputs_dir=inputs_dir,
    )


class Graph(Plans):
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
        inputs_dir: str | os.PathLike[str] | None = None,
    ):
        check_budgets(budget, memory_bytes)
        self.file = file
        self.description = description
        self.out_dir = Path(out_dir)
        self.inputs_dir = Path(inputs_dir) if inputs_dir is not None else None
        self._input_root: Path | None = None  # a subgraph's: its top graph's folder
        self.budget = budget
        self.memory = _cache.MemoryCache(memory_bytes)
        self.disk = _cache.DiskCache(cache_dir) if cache_dir is not None else None
        self._params: dict[str, ParamDef] = {}
        self._values: dict[str, Any] = {}
        self._nodes: dict[str, NodeDef] = {}
        self._identity: dict[str, str] = {}  # cache key -> identity seen downstream
        self._last: dict[str, tuple[str, str]] = {}  # node -> (key, identity) of its last output
        self._written: dict[str, tuple[int, int] | None] = {}  # export key -> file stamp
        self._input_digests: dict[str, tuple[tuple[int, ...], str]] = {}  # input -> (stamp, hash)
        self._parse_problems: list[Problem] = []
        self.outputs: dict[str, Any] = {}  # the `outputs:` mapping, for use as a subgraph
        # where the canvas drew each node (the file's `layout:`): the drawing's, no key's
        self.layout: dict[str, tuple[float, float]] = {}
        self._output_lines: dict[str, int] = {}
        self._subgraphs: dict[str, SubgraphSpec] = {}  # graph-file node types -> specs
        self._includes: Includes | None = None
        self._children: dict[Any, Graph] = {}  # subgraph path -> its graph, caches shared
        self._replay: dict[tuple[str, ...], Any] = {}  # targets -> last run's keys (run.py)
        self._pure_root: tuple[str, Path] | None = None  # out_dir -> its root, for plans
        self._step_params: tuple[str, dict[str, Any]] | None = None  # compute_step's last
        self._sinks: list[str] | None = None  # sinks(), kept until the graph changes
        self._checked = False
        # from_text: (the text read, its description and outputs); forgotten on any change
        self._source: tuple[str, str, dict[str, Any]] | None = None
        self._read: Document | None = None  # the document read from it (from_text)
        self._clean: Outline | None = None  # the outline of a check that found nothing
        # from_edit: (the graph before's clean outline, the node edited), for check()
        self._edited: tuple[Outline, str] | None = None
        self.stats: dict[str, NodeStat] = {}
        self.progress: Progress | None = None

    @property
    def _checked(self) -> bool:
        """Whether the graph as it stands was checked. Every change sets it False, which
        also forgets the keys kept from the last runs (they were of the graph before)."""
        return self.__checked

    @_checked.setter
    def _checked(self, value: bool) -> None:
        self.__checked = value
        if not value:
            self._replay.clear()
            self._step_params = None
            self._sinks = None
            self._source = self._read = self._clean = self._edited = None

    # ----------------------------------------------------------------------- building

    @classmethod
    def from_text(
        cls, text: str, *, file: str | None = None, check: bool = True, **kwargs: Any
    ) -> Graph:
        return cls._from_document(parse(text, file or "<graph>"), text, file, check, **kwargs)

    @classmethod
    def from_edit(
        cls, before: Graph, text: str, node: str, *, file: str | None = None, check: bool = True,
        **kwargs: Any,
    ) -> Graph:  # fmt: skip
        """:meth:`from_text` of ``text``, which is the text ``before`` was read from (and
        checked clean) with node ``node``'s lines edited: that node is read again, and the
        check looks at what it reaches (:mod:`formgraph.language.incremental`). Where that
        cannot be proved the same as reading and checking the whole text, the whole text is
        read and checked; either way the graph and its problems are the same."""
        from ..language.incremental import reparse

        src, doc = before._source, None
        if before._read is not None and before._clean is not None and src is not None:
            doc = reparse(before._read, src[0], text, node, file or "<graph>")
        if doc is None:
            return cls.from_text(text, file=file, check=check, **kwargs)
        g = cls._from_document(doc, text, file, False, **kwargs)
        g._edited = (before._clean, node)
        if check:
            g._check_read()
        return g

    @classmethod
    def _from_document(
        cls, doc: Document, text: str, file: str | None, check: bool, **kwargs: Any
    ) -> Graph:
        g = cls(file=file, description=doc.description, **kwargs)
        g._params = doc.params
        g._values = {n: p.default for n, p in doc.params.items()}
        g._nodes = doc.nodes
        g._parse_problems = doc.problems
        g.outputs = doc.outputs
        g._output_lines = doc.output_lines
        g.layout = doc.layout
        g._source = (text, g.description, dict(g.outputs))
        g._read = doc
        if check:
            g._check_read()
        return g

    def _check_read(self) -> None:
        try:
            self.check()
        except GraphError as exc:
            exc.files = self.files  # type: ignore[attr-defined]  (what watch must watch)
            raise

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
    def input_base(self) -> Path:
        """The folder that input paths are relative to: the inputs folder when one is named,
        else the graph file's folder (the working directory for a graph built in code)."""
        if self.inputs_dir is not None:
            return self.inputs_dir
        return Path(self.file).resolve().parent if self.file else Path.cwd()

    @property
    def input_root(self) -> Path:
        """The folder no input path may leave (a subgraph's is its top graph's)."""
        return self._input_root if self._input_root is not None else self.input_base

    @property
    def files(self) -> list[Path]:
        """The graph's file and every subgraph file it reads (what a sweep sends along)."""
        own = [Path(self.file)] if self.file else []
        return own + (list(self._includes.files) if self._includes is not None else [])

    @property
    def input_files(self) -> list[Path]:
        """The files its read nodes name, resolved (a literal path, or a path from a param's
        current value); ``watch`` watches them with :attr:`files`."""
        return self._input_files()

    def _input_files(self) -> list[Path]:
        from ..core import safety
        from ..language.model import Expr, Literal

        found: list[Path] = []
        types = node_types()
        for nd in self._nodes.values():
            spec = types.get(nd.type)
            for port in spec.input_paths if spec is not None else ():
                value = nd.inputs.get(port)
                try:
                    if isinstance(value, Literal):
                        text = value.value
                    elif isinstance(value, Expr):  # a path from a param: its current value
                        text = value.value(self._values)
                    else:
                        continue
                    if isinstance(text, str):
                        found.append(safety.resolve_input(self.input_root, text, self.input_base))
                except (GraphError, KeyError, ValueError, TypeError, ZeroDivisionError):
                    continue  # a loop's or a missing param's: the check or the run says why
        return list(dict.fromkeys(found))

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
            child = type(self)(
                file=spec.label,
                description=doc.description,
                out_dir=self.out_dir,
                inputs_dir=self.inputs_dir,
            )
            child._input_root = self.input_root  # its inputs beside its file, inside the root
            child.budget = self.budget
            child.memory, child.disk = self.memory, self.disk
            child._identity, child._written = self._identity, self._written
            child._input_digests = self._input_digests
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
        choices: Sequence[Any] | None = None,
    ) -> None:
        """Declare a graph param (``type`` names a geometry type for a Python input slot;
        ``choices`` the only values it takes)."""
        if not isinstance(name, str):
            raise ParamError(f"add_param() takes a param name (a string), got {describe(name)}")
        for bound, b in (("min", min), ("max", max)):
            if b is not None and (isinstance(b, bool) or not isinstance(b, (int, float))):
                raise ParamError(f"param '{name}': {bound} must be a number, got {describe(b)}")
        long_form = any(x is not None for x in (min, max, type, choices)) or bool(doc)
        default = plain(default, f"param '{name}'")
        if choices is not None:

            def refuse(message: str, _line: Any) -> None:
                raise ParamError(message)

            choices = read_choices(name, plain(list(choices), f"param '{name}'"), refuse, None)
        p = ParamDef(name, default, None, type, min, max, doc, None, long_form, choices)
        if type is not None:
            if not isinstance(type, str):
                raise ParamError(f"param '{name}': type must be a name such as 'Mesh'")
            try:
                p.type = type_by_name(type)
            except TypeMismatch as exc:
                raise ParamError(f"param '{name}': {exc}") from None
        self._params[name] = p
        self._values[name] = default
        self._checked = False

    def add(self, name: str, type: str, /, **inputs: Any) -> None:
        """Add (or replace) node ``name`` of node type ``type`` with its inputs."""
        if not isinstance(name, str) or not isinstance(type, str):
            what = "node name" if not isinstance(name, str) else "node type"
            bad = name if not isinstance(name, str) else type
            raise GraphError(f"add() takes a {what} (a string), got {describe(bad)}")
        self._nodes[name] = NodeDef.make(
            name, type, {k: plain(v, f"input '{k}' of '{name}'") for k, v in inputs.items()}
        )
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
        """The inputs of node ``name`` as authored (a copy: changing it changes nothing;
        ``set_input`` does)."""
        return plain(dict(self._nodes[name].raw))

    def set_input(self, node: str, port: str, value: Any) -> None:
        """Change one input of a node as authored (a literal, wire or expression)."""
        nd = self._nodes[node] = self._nodes[node].moved()  # (its own: see NodeDef.moved)
        value = plain(value, f"input '{port}' of '{node}'")
        if port == "repeat":  # not an input: the node's loop
            nd.set_repeat(value)
            self._checked = False
            return
        if port == "simulate":  # not an input: the node's steps
            nd.set_simulate(value)
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
        self._step_params = None

    def _checked_params(self, params: dict[str, Any]) -> dict[str, Any]:
        problems = []
        out = {}
        for name, value in params.items():
            p = self._params.get(name)
            if p is None:
                from ..language.params import suggest

                problems.append(
                    Problem(
                        Where(self.file_label),
                        f"unknown param '{name}'"
                        f"{suggest(name, self._params)}; params are "
                        f"{', '.join(self._params) or 'none'}",
                    )
                )
                continue
            if nesting(value) > MAX_DEPTH:
                problems.append(
                    Problem(
                        Where(self.file_label, p.line),
                        f"param '{name}': the value is nested more than {MAX_DEPTH} levels deep",
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
        from ..language.incremental import recheck

        edited, self._edited = self._edited, None
        if edited is not None and not self._parse_problems:
            outline = Outline(
                self.file_label, self._params, self._nodes, {}, self.outputs, self._output_lines
            )
            if recheck(edited[0], outline, edited[1]):  # (no subgraph: nothing to include)
                self._subgraphs, self._include_problems = {}, []
                self._checked, self._clean = True, outline
                return
        outline = self._outline()
        problems = check_graph(outline, self._parse_problems + self._include_problems)
        if problems:
            cycles = all(p.message.startswith("cycle: ") for p in problems)
            raise (CycleError if cycles else GraphError)(problems)
        self._checked, self._clean = True, outline

    def problems(self) -> list[Problem]:
        outline = self._outline()
        return check_graph(outline, self._parse_problems + self._include_problems)

    # ----------------------------------------------------------------------- evaluate

    def evaluate(self, nodes: str | Iterable[str], **params: Any) -> Any:
        """Evaluate one node (returns its output) or several (returns a dict by name).

        A name may pick one output of a node with several, ``"a.ring"``, as the wire
        ``@a.ring`` does. Keyword arguments override params for this call only.
        """
        if not self._checked:
            self.check()
        values = dict(self._values)
        values.update(self._checked_params(params))
        names = node_names(nodes)
        picks = {n: self._output_of(n) for n in names}
        run = _Run(self, values)
        self.stats = run.stats
        run.run(list(dict.fromkeys(node for node, _ in picks.values())))
        outs = {
            n: run.results[node] if output is None else getattr(run.results[node], output)
            for n, (node, output) in picks.items()
        }
        return outs[names[0]] if isinstance(nodes, str) else outs

    def _output_of(self, name: str) -> tuple[str, str | None]:
        """(node, output) of ``name``: a node, or ``node.output`` as a wire spells it."""
        if name in self._nodes:
            return name, None
        from ..language.params import suggest

        node, _, output = name.rpartition(".")
        if node in self._nodes:
            spec = self.node_types().get(self._nodes[node].type)
            if spec is not None and spec.multi_output and output in spec.outputs:
                return node, output
            if spec is not None:
                outs = ", ".join(f"{node}.{o}" for o in spec.outputs) if spec.multi_output else ""
                raise GraphError(
                    f"{self.file_label}: node '{node}' ({spec.name}) has no output '{output}'"
                    + (f"; its outputs are {outs}" if outs else "; it has one output")
                )
        raise GraphError(f"{self.file_label}: no node '{name}'{suggest(name, self._nodes)}")

    def frames(self, node: str, **params: Any) -> list[Any]:
        """Every step's output of simulated node ``node``, in order (``@node.frames``)."""
        nd = self._nodes.get(node)
        if nd is None or nd.simulate is None:
            raise GraphError(f"{self.file_label}: '{node}' is not a simulated node (simulate:)")
        if not self._checked:
            self.check()
        run = _Run(self, {**self._values, **self._checked_params(params)})
        self.stats = run.stats
        run.run([node])
        return run.frames_of(node)

    def sinks(self) -> list[str]:
        """Nodes nothing else reads from (exports, usually), in author order."""
        if self._sinks is None:
            used = {up for nd in self._nodes.values() for up in nd.upstream()}
            self._sinks = [n for n in self._nodes if n not in used]
        return list(self._sinks)

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

    def source_text(self) -> str:
        """Text that rebuilds this graph: the text it was read from while nothing has
        changed since (so its line numbers stay the file's), else :meth:`to_yaml`."""
        src = self._source
        if src is not None and (src[1], src[2]) == (self.description, self.outputs):
            return src[0]  # (description and outputs are attributes, set without a trace)
        return self.to_yaml()

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
