"""Subgraphs: a node whose ``type`` is a path to a graph file runs that graph as one node.

The file is read relative to the file that names it and must stay inside the top graph's
folder. Its params become the node's inputs (same names, types and defaults; a param with
a geometry ``type:`` takes a wire) and its ``outputs:`` mapping the node's outputs. Every
file of the tree is read once, checked with its own file name and lines, and each problem
carries the chain of nodes that led to it; include cycles are errors. A spec's ``digest``
hashes the file and everything it includes, so an edit invalidates exactly its users.
"""

from __future__ import annotations

import collections
import hashlib
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..core import safety
from ..core.errors import Problem, Where
from ..core.registry import REQUIRED, NodeSpec, Port, node_types
from ..core.types import Kind, PortType, Range
from .check import Outline, check_graph, output_type
from .model import NodeDef, ParamDef, Wire, parse_input
from .params import param_kind
from .yamlio import MAX_BYTES, Document, parse

__all__ = ["Includes", "SubgraphSpec", "is_graph_type"]


def is_graph_type(type_: str) -> bool:
    """Whether a node type names a graph file (``parts/ring.yaml``) rather than a node."""
    return isinstance(type_, str) and type_.endswith((".yaml", ".yml"))


@dataclass(frozen=True, eq=False)
class SubgraphSpec(NodeSpec):
    """The node type of a graph file: its params as inputs, its ``outputs:`` as outputs."""

    path: Path | None = None
    label: str = ""
    digest: str = ""
    document: Document | None = None
    subgraphs: Mapping[str, SubgraphSpec] = field(default_factory=dict)
    output_wires: Mapping[str, Wire] = field(default_factory=dict)


def _run_elsewhere(**kwargs: Any) -> Any:  # pragma: no cover - the graph runs subgraphs
    raise RuntimeError("a subgraph runs through its graph, not as a function")


def _param_port(p: ParamDef) -> Port:
    rng = Range(p.min, p.max) if (p.min is not None or p.max is not None) else None
    if p.type is not None:
        t = PortType(p.type.kinds, range=rng)  # the default fills it: not None-able
        return Port(p.name, t, REQUIRED if p.default is None else p.default, p.doc)
    base: Any = param_kind(p) or Any  # an int only when written whole throughout
    return Port(p.name, PortType((Kind(base),), range=rng), p.default, p.doc)


MAX_NESTING = 50
"""How deep graph files may use graph files (a part of a part of ...): far beyond any design,
and shallow enough that checking and evaluating them never meets Python's recursion limit."""


def _chain_text(chain: list[tuple[str, str]]) -> str:
    """' (in the subgraph used by node 'a' of x.yaml, used by node 'b' of top.yaml)'."""
    if not chain:
        return ""
    links = ", used by ".join(f"node '{node}' of {file}" for node, file in reversed(chain))
    return f" (in the subgraph used by {links})"


class Includes:
    """Reads the graph files that a graph's nodes name as types, once each.

    Parameters
    ----------
    root : Path
        The top graph's folder: no subgraph file may lie outside it.
    top : Path, optional
        The top graph's own file (an include of it is a cycle).
    """

    def __init__(self, root: Path, top: Path | None = None):
        self.root = root.resolve()
        self.top = top.resolve() if top is not None else None
        self.loaded: dict[Path, tuple[SubgraphSpec | None, list[Problem]]] = {}
        self.files: list[Path] = []

    def resolve_all(
        self,
        nodes: Mapping[str, NodeDef],
        file_label: str,
        base_dir: Path,
        chain: list[tuple[str, str]] = (),  # type: ignore[assignment]
        stack: tuple[Path, ...] = (),
    ) -> tuple[dict[str, SubgraphSpec], list[Problem]]:
        """The specs of the graph files named by ``nodes`` (type -> spec), and problems."""
        specs: dict[str, SubgraphSpec] = {}
        problems: list[Problem] = []
        stack = stack or ((self.top,) if self.top is not None else ())
        for nd in nodes.values():
            if not is_graph_type(nd.type) or nd.type in specs:
                continue
            spec, found = self.load(nd, file_label, base_dir, list(chain), stack)
            problems.extend(p for p in found if p not in problems)
            if spec is not None:
                specs[nd.type] = spec
        return specs, problems

    def load(
        self,
        nd: NodeDef,
        file_label: str,
        base_dir: Path,
        chain: list[tuple[str, str]],
        stack: tuple[Path, ...],
    ) -> tuple[SubgraphSpec | None, list[Problem]]:
        where = Where(file_label, nd.line, nd.name)
        suffix = _chain_text(chain)
        text = nd.type
        if (
            os.path.isabs(text)
            or text.startswith(("/", "\\"))
            or (len(text) > 1 and text[1] == ":")
        ):
            return None, [
                Problem(
                    where,
                    f"subgraph path '{text}' is absolute; write it relative to {file_label}"
                    f"{suffix}",
                )
            ]
        try:
            if "\0" in text:
                raise ValueError("it contains a NUL character")
            path = (base_dir / text).resolve()
        except (OSError, RuntimeError, ValueError) as exc:  # NUL, a symlink loop, too long
            return None, [Problem(where, f"cannot use the subgraph path {text!r}: {exc}{suffix}")]
        if not path.is_relative_to(self.root):
            return None, [
                Problem(
                    where,
                    f"subgraph path '{text}' leaves the graph's folder ({self.root}); a graph "
                    f"may only use graph files inside it{suffix}",
                )
            ]
        label = os.path.normpath(os.path.join(os.path.dirname(file_label), text))
        if path in stack:
            names = [*(str(p.name) for p in stack[stack.index(path) :]), path.name]
            return None, [Problem(where, f"include cycle: {' -> '.join(names)}{suffix}")]
        if len(stack) > MAX_NESTING:
            names = [p.name for p in stack]
            shown = [*names[:2], "...", *names[-2:]] if len(names) > 5 else names
            return None, [
                Problem(
                    where,
                    f"subgraph '{text}' would nest graph files more than {MAX_NESTING} deep "
                    f"({' -> '.join(shown)} -> {path.name}); flatten some of the parts",
                )
            ]
        if path in self.loaded:
            return self.loaded[path]
        try:
            data = safety.read_regular(path, max_bytes=MAX_BYTES)
            source = data.decode("utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            return None, [Problem(where, f"cannot read the subgraph file '{text}': {why}{suffix}")]
        self.files.append(path)
        doc = parse(source, label)
        inner_chain = [*chain, (nd.name, file_label)] if file_label != label else list(chain)
        subs, problems = self.resolve_all(
            doc.nodes, label, path.parent, inner_chain, (*stack, path)
        )
        outline = Outline(label, doc.params, doc.nodes, subs, doc.outputs, doc.output_lines)
        own = check_graph(outline, doc.problems)
        # a file that could not be read, or whose outputs: is malformed, already says so
        malformed = any("'outputs' must be" in p.message for p in doc.problems)
        if doc.top_keys is not None and not doc.outputs and not malformed:
            own.append(
                Problem(
                    Where(label, 1),
                    "a graph used as a node needs 'outputs:' (e.g. outputs: {mesh: '@tess'})",
                )
            )
        inner = _chain_text(inner_chain)
        problems = [*problems, *(Problem(p.where, p.message + inner) for p in own)]
        spec = None if problems else self._spec(text, path, label, doc, subs, data)
        self.loaded[path] = (spec, problems)
        return spec, problems

    def _spec(
        self,
        name: str,
        path: Path,
        label: str,
        doc: Document,
        subs: dict[str, SubgraphSpec],
        data: bytes,
    ) -> SubgraphSpec:
        registry = {**node_types(), **subs}
        # the file, the files it uses, and the versions of the node types it runs: a new
        # implementation of a node inside invalidates the subgraph's cached outputs too
        h = hashlib.blake2b(_without_layout(data, doc), digest_size=20)
        for t in sorted(subs):
            h.update(f"\0{t}\0{subs[t].digest}".encode())
        for t in sorted({nd.type for nd in doc.nodes.values()} - set(subs)):
            h.update(f"\0{t}\0{registry[t].version}".encode())
        outline = Outline(label, doc.params, doc.nodes, subs, doc.outputs, doc.output_lines)
        wires: dict[str, Wire] = {}
        outputs: dict[str, PortType] = {}
        for out, text in doc.outputs.items():
            wire = parse_input(text)
            assert isinstance(wire, Wire)  # checked
            wires[out] = wire
            outputs[out] = output_type(outline, wire, registry) or PortType((Kind(Any),))
        multi = len(outputs) > 1
        output_class = collections.namedtuple("Outputs", list(outputs)) if multi else None  # type: ignore[misc]
        inputs = {p.name: _param_port(p) for p in doc.params.values()}
        summary = doc.description.split("\n\n", 1)[0].replace("\n", " ").strip()
        return SubgraphSpec(
            name=name,
            func=_run_elsewhere,
            version=1,
            inputs=inputs,
            outputs=outputs,
            summary=summary or f"the graph {label}",
            doc=doc.description,
            wants_context=False,
            multi_output=multi,
            output_class=output_class,
            path=path,
            label=label,
            digest=h.hexdigest(),
            document=doc,
            subgraphs=subs,
            output_wires=wires,
        )


def _without_layout(data: bytes, doc: Document) -> bytes:
    """A graph file's bytes without its ``layout:`` section (the canvas's positions, which
    must not change the key of what the file computes)."""
    if doc.top_keys is None or "layout" not in doc.top_keys:
        return data
    import re

    import yaml

    from . import yamlread

    text = data.decode("utf-8")
    root = yaml.compose(text, Loader=yamlread.Loader)  # (parsed already: it composes)
    starts = [0, *(m.end() for m in re.finditer("\n", text))]
    for k, v in root.value:
        if isinstance(k, yaml.ScalarNode) and k.value == "layout":
            a = starts[k.start_mark.line] + k.start_mark.column
            end = v.end_mark
            b = starts[end.line] + end.column if end.line < len(starts) else len(text)
            return (text[:a] + text[b:]).encode("utf-8")
    return data
