"""The worker side of a sweep: the tasks Dask runs, and what they hand back.

A worker rebuilds the graph once per sweep from its text (:class:`Blueprint`), then runs
node tasks (:func:`run_step`, :func:`cached_step`, :func:`run_export`) for the nodes that
variants share and row tasks (:func:`run_rows`) for each few variants' own nodes. A node
that fails makes an :class:`Outcome` with its one-line error instead of raising, so its
dependents finish at once with the same error and the sweep goes on.
"""

from __future__ import annotations

import importlib
import pickle
import sys
import tempfile
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..core.errors import FormgraphError, FormgraphWarning
from ..evaluation.cache import default_cache_dir, key_of
from ..evaluation.graph import Graph, Step

__all__ = ["Blueprint", "Outcome", "RowResult", "RowResults", "run_rows", "run_step"]


@dataclass(frozen=True)
class Blueprint:
    """What a worker needs to rebuild the graph: its text, never its file."""

    token: str
    text: str
    file: str
    params: dict[str, Any]
    modules: tuple[str, ...]  # modules registering node types outside formgraph
    budget: int
    cache_dir: str | None  # a path on the worker, or None: no disk cache
    worker_cache: bool  # each worker's own default cache folder instead of cache_dir
    files: dict[str, str] = field(default_factory=dict)  # subgraph files, by path from
    # the graph's folder: a worker without them (another machine) writes them out
    path: str = ""  # the graph file's absolute path on the client
    inputs: str = ""  # the folder its read nodes read, absolute on the client (same machine,
    # or the same path on every worker)

    def __dask_tokenize__(self) -> str:  # Dask names the graph by hashing it: keep it cheap
        return self.token


@dataclass
class Outcome:
    """One task's result: a value or a one-line error, and the nodes spent on it.

    ``costs`` maps the cache key of every node this value needed to (seconds, status), so a
    variant's seconds count each of its nodes once however the wires fan in.
    """

    value: Any = None
    error: str | None = None
    costs: dict[str, tuple[float, str]] = field(default_factory=dict)


@dataclass
class RowResult:
    """One variant as it comes back to the client."""

    error: str | None
    seconds: float
    values: dict[str, Any]
    exports: dict[str, tuple[str, dict[str, bytes]]]  # node -> (main file, {file: bytes})
    image: bytes | None
    costs: dict[str, tuple[float, str]]

    def __reduce__(self) -> Any:  # a plain tuple: a dataclass's state dict costs more
        return RowResult, (
            self.error,
            self.seconds,
            self.values,
            self.exports,
            self.image,
            self.costs,
        )


@dataclass
class RowResults:
    """What a row task hands back: (row key, result) for each of its variants.

    One object, not a list: Dask serialises a list element by element (a header and a
    pickle frame each), which cost more than the light variants themselves.
    """

    rows: list[tuple[str, RowResult]]


_GRAPHS: dict[str, Graph] = {}


def _one_line_warnings() -> None:
    """In a Dask worker, print our warnings as one line each, as the command line does.

    Python's default shows a warning as ``file:line: Category: message`` plus the source
    line, and the file is Dask's (``dask/_task_spec.py``, the frame that called the node),
    so a sweep's terminal filled with Dask internals. Other warnings keep their format.
    """
    if getattr(warnings.showwarning, "_formgraph", False):
        return
    try:
        from distributed import get_worker

        get_worker()
    except (ImportError, ValueError):
        return  # not in a worker: the caller's own warning display stays
    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):  # type: ignore[no-untyped-def]
        if issubclass(category, FormgraphWarning):
            print(f"formgraph: warning: {message}", file=file or sys.stderr)
            return
        shown(message, category, filename, lineno, file, line)

    show._formgraph = True  # type: ignore[attr-defined]
    warnings.showwarning = show


def _graph(bp: Blueprint) -> Graph:
    """The worker's graph for a blueprint, built once per process."""
    _one_line_warnings()
    g = _GRAPHS.get(bp.token)
    if g is None:
        for module in bp.modules:
            importlib.import_module(module)
        cache_dir = str(default_cache_dir()) if bp.worker_cache else bp.cache_dir
        g = Graph.from_text(
            bp.text,
            file=_graph_file(bp),
            cache_dir=cache_dir,
            budget=bp.budget,
            memory_bytes=0,  # Dask holds the values; a second copy would only cost memory
            out_dir=tempfile.gettempdir(),
            inputs_dir=bp.inputs or None,
        )
        g.set(**bp.params)
        if len(_GRAPHS) >= 4:
            _GRAPHS.clear()
        _GRAPHS[bp.token] = g
    return g


def _graph_file(bp: Blueprint) -> str:
    """The graph's own file when this machine has it and its subgraphs as they were sent,
    else the same tree written to a scratch folder (kept while the process lives)."""
    if not bp.files:
        return bp.file  # only a label: the text is all there is to read
    root = Path(bp.path).parent
    try:
        if all((root / rel).read_text(encoding="utf-8") == text for rel, text in bp.files.items()):
            return bp.path
    except (OSError, UnicodeDecodeError):
        pass
    from ..core.safety import path_problem

    scratch = Path(tempfile.mkdtemp(prefix="formgraph-graph-"))
    for rel, text in bp.files.items():
        if path_problem(rel):  # a subgraph never leaves the graph's folder
            raise FormgraphError(f"{bp.file}: cannot place the subgraph file {rel!r}")
        target = scratch / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    return str(scratch / Path(bp.file).name)


def one_line(exc: BaseException) -> str:
    """An error as one line of at most 400 characters (for a CSV cell)."""
    text = str(exc) if isinstance(exc, FormgraphError) else f"{type(exc).__name__}: {exc}"
    text = "; ".join(part.strip() for part in text.splitlines() if part.strip())
    return text if len(text) <= 400 else text[:397] + "..."


@dataclass(frozen=True)
class Job:
    """The literal part of a node task: which step, for which params."""

    step: Step
    params: dict[str, Any]

    def __dask_tokenize__(self) -> str:
        return self.step.key


def _merged(inputs: Sequence[Outcome]) -> tuple[dict[str, tuple[float, str]], str | None]:
    costs: dict[str, tuple[float, str]] = {}
    error = None
    for o in inputs:
        costs.update(o.costs)
        if o.error is not None and error is None:
            error = o.error
    return costs, error


def run_step(bp: Blueprint, job: Job, *inputs: Outcome) -> Outcome:
    """Task: one node from its inputs' outcomes (or their first error)."""
    costs, error = _merged(inputs)
    if error is not None:
        return Outcome(None, error, costs)
    values = {u: o.value for u, o in zip(job.step.upstream, inputs, strict=True)}
    t0 = time.perf_counter()
    try:
        value, stat = _graph(bp).compute_step(job.step, values, **job.params)
    except Exception as exc:  # recorded as the variant's error, never lost
        costs[job.step.key] = (time.perf_counter() - t0, "failed")
        return Outcome(None, one_line(exc), costs)
    costs[job.step.key] = (stat.seconds, stat.status)
    return Outcome(value, None, costs)


def cached_step(bp: Blueprint, job: Job) -> Outcome:
    """Task: a node the client saw in the disk cache; evaluated here if this worker lacks it."""
    g = _graph(bp)
    t0 = time.perf_counter()
    try:
        hit, value = g.cached(job.step)
        if not hit:
            value = g.evaluate(job.step.name, **job.params)
    except Exception as exc:
        return Outcome(None, one_line(exc), {job.step.key: (time.perf_counter() - t0, "failed")})
    status = "cached" if hit else "computed"
    return Outcome(value, None, {job.step.key: (time.perf_counter() - t0, status)})


def _export(g: Graph, step: Step, inputs: dict[str, Any], params: dict[str, Any]) -> Any:
    """An export node written into a scratch folder: (main file, {file: bytes}), and stat."""
    with tempfile.TemporaryDirectory(prefix="formgraph-sweep-") as tmp:
        root = Path(tmp).resolve()
        path, stat = g.compute_step(step, inputs, out_dir=root, **params)
        files = {
            p.relative_to(root).as_posix(): p.read_bytes()
            for p in sorted(root.rglob("*"))
            if p.is_file() and not p.name.startswith(".")
        }
        return (Path(path).resolve().relative_to(root).as_posix(), files), stat


def run_export(bp: Blueprint, job: Job, *inputs: Outcome) -> Outcome:
    """Task: an export that several variants share; its files come back as bytes."""
    costs, error = _merged(inputs)
    if error is not None:
        return Outcome(None, error, costs)
    values = {u: o.value for u, o in zip(job.step.upstream, inputs, strict=True)}
    t0 = time.perf_counter()
    try:
        value, stat = _export(_graph(bp), job.step, values, job.params)
    except Exception as exc:
        costs[job.step.key] = (time.perf_counter() - t0, "failed")
        return Outcome(None, one_line(exc), costs)
    costs[job.step.key] = (stat.seconds, "computed")
    return Outcome(value, None, costs)


@dataclass(frozen=True)
class RowJob:
    """What a variant's row holds: how its targets map to columns (the same for all rows)."""

    measures: tuple[tuple[str, str | None, str], ...]
    exports: tuple[str, ...]
    render: str | None
    size: tuple[int, int]
    camera: tuple[Any, Any, Any] | None = None

    def __dask_tokenize__(self) -> str:
        return key_of(
            [list(m) for m in self.measures]
            + [list(self.exports), self.render, list(self.camera or ())]
        )


@dataclass(frozen=True)
class RowPlan:
    """One variant's own nodes (no other variant needs them), computed in its row task."""

    steps: tuple[Step, ...]  # in evaluation order
    shared: tuple[tuple[str, str], ...]  # (name, key) of the shared nodes it reads
    params: dict[str, Any]
    key: str

    def __dask_tokenize__(self) -> str:
        return self.key


@dataclass(frozen=True)
class RowChunk:
    """The literal part of a row task: its variants' plans and the shared keys it reads
    (a dataclass: Dask would take a bare tuple of keys for references to their values)."""

    plans: tuple[RowPlan, ...]
    keys: tuple[str, ...]

    def __dask_tokenize__(self) -> str:
        return key_of([p.key for p in self.plans])

    def __reduce__(self) -> Any:
        """Pickled as each distinct shape of plan once (its nodes' names, wires and kinds,
        the shared nodes' names) and per variant only its keys and params: a chunk is
        pickled and unpickled twice on its way to a worker (client, scheduler, worker)."""
        shapes: dict[Any, int] = {}
        rows = []
        for p in self.plans:
            shape = (
                tuple((s.name, s.upstream, s.export) for s in p.steps),
                tuple(n for n, _ in p.shared),
            )
            rows.append(
                (
                    shapes.setdefault(shape, len(shapes)),
                    tuple(s.key for s in p.steps),
                    tuple(s.upstream_keys for s in p.steps),
                    tuple(k for _, k in p.shared),
                    p.params,
                    p.key,
                )
            )
        return _chunk, (tuple(shapes), tuple(rows), self.keys)


@dataclass(frozen=True)
class Packed:
    """A row task's :class:`RowChunk`, pickled once on the client: the scheduler receives
    and forwards its bytes as they are, and only the worker that runs it unpacks it."""

    data: bytes
    token: str

    @classmethod
    def of(cls, chunk: RowChunk) -> Packed:
        return cls(pickle.dumps(chunk, protocol=pickle.HIGHEST_PROTOCOL), chunk.__dask_tokenize__())

    def unpack(self) -> RowChunk:
        return pickle.loads(self.data)

    def __dask_tokenize__(self) -> str:
        return self.token

    def __reduce__(self) -> Any:
        return Packed, (self.data, self.token)


def _chunk(shapes: Any, rows: Any, keys: tuple[str, ...]) -> RowChunk:
    """A :class:`RowChunk` from its pickled form (:meth:`RowChunk.__reduce__`)."""
    plans = []
    for shape, step_keys, upstream_keys, shared_keys, params, key in rows:
        steps, shared = shapes[shape]
        plan_steps = tuple(
            Step(name, k, up, export, ups)
            for (name, up, export), k, ups in zip(steps, step_keys, upstream_keys, strict=True)
        )
        plans.append(RowPlan(plan_steps, tuple(zip(shared, shared_keys, strict=True)), params, key))
    return RowChunk(tuple(plans), keys)


def run_rows(bp: Blueprint, job: RowJob, packed: Packed, *shared: Outcome) -> RowResults:
    """Task: a few variants' rows, each from its own nodes and the shared ones' outcomes.

    Fusing variants' private chains into one task is Dask's own linear fusion, keyed by what
    the variants need: the per-task overhead is paid once per few variants, while every node
    that variants share stays a task of its own under its cache key.
    """
    chunk = packed.unpack()
    by_key = dict(zip(chunk.keys, shared, strict=True))
    return RowResults([(plan.key, run_row(bp, job, plan, by_key)) for plan in chunk.plans])


def run_row(bp: Blueprint, job: RowJob, plan: RowPlan, shared: dict[str, Outcome]) -> RowResult:
    """One variant's own nodes from the shared ones' outcomes, then its row."""
    costs, error = _merged([shared[k] for _, k in plan.shared])
    values = {n: shared[k].value for n, k in plan.shared}
    if error is None:
        g = _graph(bp)
        for step in plan.steps:
            t0 = time.perf_counter()
            try:
                if any(u not in values for u in step.upstream):  # seen cached by the client
                    hit, value = g.cached(step)
                    if not hit:  # not on this worker's disk: evaluate it here
                        value = g.evaluate(step.name, **plan.params)
                    stat_of = (time.perf_counter() - t0, "cached" if hit else "computed")
                else:
                    inputs = {u: values[u] for u in step.upstream}
                    if step.export:
                        value, stat = _export(g, step, inputs, plan.params)
                    else:
                        value, stat = g.compute_step(step, inputs, **plan.params)
                    stat_of = (stat.seconds, stat.status)
            except Exception as exc:  # recorded as the variant's error, never lost
                costs[step.key] = (time.perf_counter() - t0, "failed")
                error = one_line(exc)
                break
            values[step.name] = value
            costs[step.key] = stat_of
    seconds = sum(s for s, _ in costs.values())
    measured: dict[str, Any] = {}
    image = None
    if error is None:
        for node, output, column in job.measures:
            v = getattr(values[node], output) if output else values[node]
            measured[column] = v.item() if hasattr(v, "item") else v
        if job.render is not None:
            try:
                from formgraph.viewer.sheet import render_cell

                image = render_cell(values[job.render], job.size, job.camera)
            except Exception as exc:
                error = f"render: {one_line(exc)}"
    exports = {n: values[n] for n in job.exports} if error is None else {}
    return RowResult(error, seconds, measured, exports, image, costs)
