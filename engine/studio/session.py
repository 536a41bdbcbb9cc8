"""The studio's engine side: one graph file, its text, its params and its last good result.

A :class:`StudioSession` holds what the page shows and does every evaluation through the one
engine: a :class:`~formgraph.graph.Graph` built from the editor's text (or the file), whose
memory cache is handed on from version to version, so an edit or a slider step recomputes
only what it reaches. It knows nothing of trame or threads; :mod:`.worker` runs it off the
page's event loop and :mod:`.page` shows what it returns.

A broken version (a YAML typo, a bad wire, a node that fails) never replaces the last good
one: :class:`Cooked` then carries the problems, each with its line, and the values shown
stay those of the last version that worked.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from formgraph.core.errors import FormgraphError, GraphError, NodeError, Problem, Where
from formgraph.core.registry import DEFAULT_BUDGET
from formgraph.core.safety import write_atomic
from formgraph.evaluation.graph import Graph
from formgraph.language.yamlio import MAX_BYTES

__all__ = ["Control", "Cooked", "StudioSession", "Superseded", "controls_of", "plain"]


class Superseded(Exception):
    """Raised between two nodes of an evaluation that a newer request has made stale."""


@dataclass(frozen=True)
class Control:
    """One param as the page draws it: a slider, a number field, a toggle or a choice."""

    name: str
    kind: str  # 'slider', 'number', 'toggle', 'choice' or 'text'
    value: Any
    default: Any
    min: float | None = None
    max: float | None = None
    step: float | None = None
    choices: tuple[Any, ...] = ()  # a choice's options: texts, numbers or booleans
    doc: str = ""

    @property
    def digits(self) -> int | None:
        """Decimals that show a value on the step's grid (0.05: 2; 1 or 5: 0); None
        without a step."""
        import math

        if not self.step or not math.isfinite(self.step):
            return None
        return max(0, -math.floor(math.log10(self.step) + 1e-9))

    def snap(self, number: float) -> float:
        """A slider's ``number`` on its grid (min + k step), rounded to the step's decimals:
        the browser's float steps add up to 9.399999999999999, the param gets 9.4."""
        if self.kind != "slider" or not self.step or self.min is None:
            return number
        k = round((number - self.min) / self.step)
        on_grid = self.min + k * self.step
        if self.max is not None:
            on_grid = min(max(on_grid, self.min), self.max)
        return round(on_grid, self.digits or 0)

    def as_dict(self) -> dict[str, Any]:
        """The control as the page's state holds it (JSON: an Enum as its value)."""
        return {
            "name": self.name,
            "kind": self.kind,
            "default": plain(self.default),
            "min": self.min,
            "max": self.max,
            "step": self.step,
            "digits": self.digits,
            "choices": [plain(c) for c in self.choices],
            "doc": self.doc,
        }


def plain(value: Any) -> Any:
    """``value`` as JSON can carry it: an Enum as its value, a tuple as a list, anything
    else that is not a number, string, bool, list or None as its repr."""
    import enum

    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return repr(value)


def controls_of(graph: Graph, values: dict[str, Any]) -> list[Control]:
    """A control per param of ``graph``, chosen from its type, min and max.

    A param declared with ``choices:`` (or whose type is an Enum port type) is a list of its
    options; otherwise a number with both a min and a max is a slider (whole steps for an
    int), any other number a number field, a bool a toggle, and anything else (a vector, a
    list, a string) a text field holding its YAML.
    """
    from formgraph.language.params import param_kind, param_step

    out = []
    current = {**graph.params, **values}
    for name, p in graph.param_defs.items():
        value = current.get(name)
        default = p.default
        enum = p.type.enum if p.type is not None else None
        kind = param_kind(p)
        integer = kind is int or (p.type is not None and p.type.name == "int")
        if p.choices is not None:
            out.append(Control(name, "choice", value, default, choices=p.choices, doc=p.doc))
        elif enum is not None:
            choices = tuple(str(m.value) for m in enum)
            shown = value.value if hasattr(value, "value") else value
            out.append(Control(name, "choice", shown, default, choices=choices, doc=p.doc))
        elif isinstance(value, bool) or isinstance(default, bool):
            out.append(Control(name, "toggle", bool(value), default, doc=p.doc))
        elif isinstance(value, (int, float)) and p.min is not None and p.max is not None:
            lo, hi = float(p.min), float(p.max)
            step = param_step(p) or 1.0
            out.append(Control(name, "slider", value, default, lo, hi, step, doc=p.doc))
        elif isinstance(value, (int, float)):
            step = 1.0 if integer else None
            out.append(Control(name, "number", value, default, p.min, p.max, step, doc=p.doc))
        else:
            out.append(Control(name, "text", value, default, doc=p.doc))
    return out


@dataclass
class Cooked:
    """What one request to the session produced.

    ``ok`` is whether the version asked for evaluated; when it did not, ``problems`` say
    why (each with its line, when known) and ``shown`` is still the last good result.
    """

    ok: bool
    shown: list[tuple[str, Any]]
    stats: dict[str, Any] = field(default_factory=dict)
    seconds: float = 0.0
    problems: list[Problem] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)
    message: str = ""
    new_graph: bool = False  # a new version of the graph (controls and drawing may change)
    warnings: list[Problem] = field(default_factory=list)  # the nodes' warnings, located
    frames: int = 0  # the steps of the shown simulated nodes (0: none is shown)
    frame: int | None = None  # the step shown (a frame request), 1 .. frames

    @property
    def computed(self) -> int:
        return sum(1 for s in self.stats.values() if s.status == "computed")

    @property
    def cached(self) -> int:
        return len(self.stats) - self.computed


class StudioSession:
    """A graph file opened in the studio.

    Parameters
    ----------
    path : str or path
        The graph file; Save writes it (atomically) and nothing else outside ``out_dir``.
    out_dir : str or path
        Where Run writes the exports (through the same path checks as ``formgraph run``).
    sets : sequence of str
        ``NAME=VALUE`` params from the command line, the controls' starting values.
    budget : int
        The element budget per node, as for :func:`formgraph.load`.
    inputs_dir : str or path, optional
        The folder the read nodes read from (default: the graph file's), as ``--inputs``.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        out_dir: str | os.PathLike[str] = "out",
        sets: Sequence[str] = (),
        budget: int = DEFAULT_BUDGET,
        inputs_dir: str | os.PathLike[str] | None = None,
    ):
        self.path = Path(path)
        self.inputs_dir = inputs_dir
        self.out_dir = Path(out_dir)
        self.sets = list(sets)
        self.budget = budget
        self.text = ""  # the text of the version opened last (the editor's or the file's)
        self.disk_text: str | None = None  # the file's text as last read or saved
        self.graph: Graph | None = None  # the last version that checked
        self.values: dict[str, Any] = {}  # params set by the controls (and --set)
        self.shown_names: list[str] | None = None  # None: the graph's results
        self.last: Cooked = Cooked(False, [])
        self.memory: Any = None  # the cache handed on from version to version
        self.progress: Callable[[str, int, int], None] | None = None
        self._files: list[Path] = [self.path]
        self._frames: dict[str, list[Any]] = {}  # simulated node -> its steps (this cook's)

    # ------------------------------------------------------------------------ text

    def read_file(self) -> str:
        """The graph file's text (at most the size a graph file may have)."""
        with open(self.path, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            raise GraphError(
                Problem(Where(str(self.path)), f"the file is larger than {MAX_BYTES >> 20} MiB")
            )
        return data.decode("utf-8", errors="replace")

    def open(self, text: str | None = None) -> Cooked:
        """Take a new version of the graph (the editor's text, or the file's) and cook it.

        The params the controls hold are kept where the new version still has them and
        still accepts their values.
        """
        if text is None:
            try:
                text = self.read_file()
            except (OSError, GraphError) as exc:
                problem = exc.problems[0] if isinstance(exc, GraphError) else None
                problem = problem or Problem(Where(str(self.path)), f"cannot read it: {exc}")
                return self._failed([problem], str(problem))
            self.disk_text = text
        self.text = text
        try:
            graph = Graph.from_text(
                text,
                file=str(self.path),
                out_dir=self.out_dir,
                budget=self.budget,
                inputs_dir=self.inputs_dir,
            )
        except GraphError as exc:
            self._files = list(getattr(exc, "files", None) or [self.path])
            return self._failed(exc.problems, str(exc))
        self._files = [*(graph.files or [self.path]), *graph.input_files]
        if self.memory is not None:
            graph.memory = self.memory  # a new version recomputes only what it reaches
        first = self.graph is None
        values = self._start_values(graph) if first else self._kept_values(graph)
        if isinstance(values, Cooked):
            return values
        # a version that checks becomes the current one even if a node of it fails: the
        # controls then act on it (a param may be what fixes it)
        self.graph, self.values = graph, values
        cooked = self.cook()
        cooked.new_graph = True
        return cooked

    def _start_values(self, graph: Graph) -> dict[str, Any] | Cooked:
        from formgraph.core.errors import UsageError
        from formgraph.language.params import parse_sets

        try:
            return parse_sets(graph, self.sets)
        except (UsageError, GraphError) as exc:
            problems = getattr(exc, "problems", None) or [Problem(Where(), str(exc))]
            return self._failed(problems, str(exc))

    def _kept_values(self, graph: Graph) -> dict[str, Any]:
        from formgraph.core.types import TypeMismatch
        from formgraph.language.params import check_param_value

        kept = {}
        for name, value in self.values.items():
            p = graph.param_defs.get(name)
            if p is None:
                continue
            try:
                check_param_value(p, value)
            except (TypeMismatch, ValueError, TypeError):
                continue
            kept[name] = value
        return kept

    def files(self) -> list[Path]:
        """The files the last version read: its own, its subgraph files and the files its
        read nodes name (what to watch)."""
        return list(self._files)

    # ------------------------------------------------------------------------ cook

    def targets(self) -> list[str]:
        from formgraph.viewer.app import shown_nodes

        assert self.graph is not None
        return shown_nodes(self.graph, self.shown_names)

    def show(self, names: Sequence[str] | None) -> Cooked:
        """Show these nodes (``name`` or ``name.output``), or the graph's results (None)."""
        old = self.shown_names
        self.shown_names = list(names) if names else None
        cooked = self.cook()
        if not cooked.ok:
            self.shown_names = old
        return cooked

    def set_params(self, **values: Any) -> Cooked:
        """Cook with some params changed; a value the param refuses leaves it as it was."""
        old = dict(self.values)
        self.values.update(values)
        cooked = self.cook()
        if not cooked.ok:
            self.values = old
        return cooked

    def reset_params(self, *names: str) -> Cooked:
        """Back to the file's defaults (of ``names``, or of every param)."""
        old = dict(self.values)
        for name in names or list(self.values):
            self.values.pop(name, None)
        cooked = self.cook()
        if not cooked.ok:
            self.values = old
        return cooked

    def cook(self) -> Cooked:
        """Evaluate the shown nodes of the current version with the current params."""
        graph = self.graph
        if graph is None:
            return self._failed(self.last.problems, self.last.message or "nothing loaded")
        try:
            targets = self.targets()
            bases = list(dict.fromkeys(_base(graph, t) for t in targets))
            graph.progress = self.progress
            t0 = time.perf_counter()
            try:
                outs = graph.evaluate(bases, **self.values)
            finally:
                graph.progress = None
            seconds = time.perf_counter() - t0
        except Superseded:
            raise
        except FormgraphError as exc:
            from formgraph.drawgraph.layout import failed_nodes

            problems = exc.problems if isinstance(exc, GraphError) else [_node_problem(exc)]
            cooked = self._failed(problems, str(exc), failed_nodes(exc))
            cooked.stats = dict(graph.stats)
            return cooked
        self.memory = graph.memory
        shown = []
        for t in targets:
            base = _base(graph, t)
            value = outs[base]
            if t != base:
                value = getattr(value, t[len(base) + 1 :])
            shown.append((t, value))
        self._frames = {}
        frames = max((graph.stats[b].items for b in self._simulated(targets)), default=0)
        self.last = Cooked(
            True, shown, dict(graph.stats), seconds, warnings=_warnings(graph), frames=frames
        )
        return self.last

    def _simulated(self, targets: Sequence[str]) -> list[str]:
        """The shown targets that are simulated nodes themselves (not their ``.frames``)."""
        graph = self.graph
        assert graph is not None
        nodes = graph._nodes
        return [t for t in targets if t in nodes and nodes[t].simulate is not None]

    def frame(self, k: int) -> Cooked:
        """The last cook's picture with each shown simulated node at its step ``k`` (1 ..
        steps, clipped), taken from the caches: nothing upstream recooks, and a step the
        memory cache let go is recomputed from the one before."""
        last, graph = self.last, self.graph
        if graph is None or not last.ok or not last.frames:
            return last
        t0 = time.perf_counter()
        k = min(max(int(k), 1), last.frames)
        shown = []
        for label, value in last.shown:
            if label in self._simulated([label]):
                if label not in self._frames:
                    graph.progress = self.progress
                    try:
                        self._frames[label] = graph.frames(label, **self.values)
                    finally:
                        graph.progress = None
                steps = self._frames[label]
                if steps:
                    value = steps[min(k, len(steps)) - 1]
            shown.append((label, value))
        seconds = time.perf_counter() - t0
        return Cooked(
            True, shown, dict(graph.stats), seconds, frames=last.frames, frame=k,
            warnings=last.warnings,
        )  # fmt: skip

    def _failed(self, problems: Sequence[Problem], message: str, failed=()) -> Cooked:
        return Cooked(
            False, self.last.shown, problems=list(problems), failed=list(failed), message=message
        )

    # --------------------------------------------------------------------- writing

    def save(self, text: str) -> Path:
        """Write ``text`` to the graph file, atomically (the only file outside ``out_dir``
        the studio writes)."""
        path = self.path.resolve()
        target = write_atomic(path.parent, path.name, text.encode("utf-8"))
        self.disk_text = text
        return target

    def run(self) -> Cooked:
        """Evaluate every sink of the current version, so each export writes its file into
        the output directory (as ``formgraph run`` does)."""
        graph = self.graph
        if graph is None:
            return self._failed(self.last.problems, "nothing to run: the graph does not load")
        try:
            t0 = time.perf_counter()
            graph.evaluate_all(**self.values)
            seconds = time.perf_counter() - t0
        except FormgraphError as exc:
            from formgraph.drawgraph.layout import failed_nodes

            problems = exc.problems if isinstance(exc, GraphError) else [_node_problem(exc)]
            return self._failed(problems, str(exc), failed_nodes(exc))
        self.memory = graph.memory
        return Cooked(True, self.last.shown, dict(graph.stats), seconds)

    def exports(self) -> list[str]:
        """The files the current version's exports write, relative to the output folder."""
        graph = self.graph
        if graph is None:
            return []
        registry = graph.node_types()
        out = []
        for name, type_name in graph.nodes.items():
            if registry[type_name].is_export:
                path = graph.node_inputs(name).get("path")
                if isinstance(path, str):
                    out.append(path)
        return out


def _warnings(graph: Graph) -> list[Problem]:
    """The last evaluation's node warnings (an open mesh, a value clamped), each at its
    node's line."""
    out = []
    for name, st in graph.stats.items():
        node = graph._nodes.get(name)  # the authored node: its line
        where = Where(graph.file, getattr(node, "line", None), name)
        out.extend(Problem(where, w) for w in st.warnings)
    return out


def _base(graph: Graph, target: str) -> str:
    return target if target in graph.nodes else target.split(".", 1)[0]


def _node_problem(exc: FormgraphError) -> Problem:
    """A failed node as a located problem (the message without the location prefix)."""
    if not isinstance(exc, NodeError):
        return Problem(Where(), str(exc))
    text, prefix = str(exc), exc.where.prefix()
    if text.startswith(prefix):
        text = text[len(prefix) :].lstrip(": ")
    return Problem(exc.where, text)
