"""Running a sweep's variants as one Dask graph whose task keys are the nodes' cache keys.

Every variant is planned on the client (:meth:`formgraph.Graph.plan`): each node it needs,
keyed as a cold evaluation keys it. Variants that share a node (a profile the varied param
never reaches) share its key, hence its task, so shared work runs once in the whole sweep.
A node the client sees in the disk cache becomes a task that loads it (and, on a worker
without that entry, evaluates it there), so a rerun does not even schedule its ancestors.

Workers receive the graph once, as its YAML text (a task of its own, ``graph-<token>``),
never a file path: nothing here assumes a shared filesystem. Node outputs travel between
workers as Dask data; measured values, exported files (their bytes) and rendered cells come
back to the client in one small result per variant (``row-<hash>``), which the client writes.

A node that fails makes an :class:`Outcome` with its one-line error instead of raising, so
its dependents finish at once with the same error and the sweep goes on. A worker that dies
is Dask's business: the scheduler reruns its tasks elsewhere (``distributed``'s
``allowed-failures``), and a variant is reported once, when its row task finishes.
"""

from __future__ import annotations

import contextlib
import importlib
import logging
import os
import tempfile
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .cache import DiskCache, default_cache_dir, key_of
from .errors import FormgraphError
from .graph import Graph, Step

__all__ = ["Outcome", "RowResult", "Targets", "Totals", "run"]

BLAS_ENV = {
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "VECLIB_MAXIMUM_THREADS": "1",
    "NUMEXPR_NUM_THREADS": "1",
}


class SweepError(FormgraphError):
    """A sweep that cannot run: no cluster to reach, a graph workers cannot rebuild."""


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


@dataclass
class Outcome:
    """One task's result: a value or a one-line error, and the nodes spent on it.

    ``costs`` maps the cache key of every node this value needed to (seconds, status), so a
    variant's seconds count each of its nodes once however the wires fan in.
    """

    value: Any = None
    error: str | None = None
    costs: dict[str, tuple[float, str]] = field(default_factory=dict)


@dataclass(frozen=True)
class Targets:
    """What each variant brings back: measured outputs, exports, a rendered node."""

    measures: tuple[tuple[str, str | None, str], ...] = ()  # (node, output, column)
    exports: tuple[str, ...] = ()  # export node names
    render: str | None = None
    size: tuple[int, int] = (256, 192)
    build: tuple[str, ...] = ()  # nodes only built (nothing measured, exported or drawn)

    @property
    def nodes(self) -> list[str]:
        names = [m[0] for m in self.measures] + list(self.exports) + list(self.build)
        if self.render:
            names.append(self.render)
        return list(dict.fromkeys(names))


@dataclass
class RowResult:
    """One variant as it comes back to the client."""

    error: str | None
    seconds: float
    values: dict[str, Any]
    exports: dict[str, tuple[str, dict[str, bytes]]]  # node -> (main file, {file: bytes})
    image: bytes | None
    costs: dict[str, tuple[float, str]]


@dataclass
class Totals:
    """How much work the sweep's graph held and did."""

    variants: int = 0
    naive: int = 0  # node evaluations of a plain loop without any cache: variants x nodes
    needed: int = 0  # distinct node tasks in the sweep's graph
    computed: int = 0
    cached: int = 0


# --------------------------------------------------------------------- worker side

_GRAPHS: dict[str, Graph] = {}


def _graph(bp: Blueprint) -> Graph:
    """The worker's graph for a blueprint, built once per process."""
    g = _GRAPHS.get(bp.token)
    if g is None:
        for module in bp.modules:
            importlib.import_module(module)
        cache_dir = str(default_cache_dir()) if bp.worker_cache else bp.cache_dir
        g = Graph.from_text(
            bp.text,
            file=bp.file,
            cache_dir=cache_dir,
            budget=bp.budget,
            memory_bytes=0,  # Dask holds the values; a second copy would only cost memory
            out_dir=tempfile.gettempdir(),
        )
        g.set(**bp.params)
        if len(_GRAPHS) >= 4:
            _GRAPHS.clear()
        _GRAPHS[bp.token] = g
    return g


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


def run_export(bp: Blueprint, job: Job, *inputs: Outcome) -> Outcome:
    """Task: an export node written into a scratch folder; its files come back as bytes."""
    costs, error = _merged(inputs)
    if error is not None:
        return Outcome(None, error, costs)
    values = {u: o.value for u, o in zip(job.step.upstream, inputs, strict=True)}
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="formgraph-sweep-") as tmp:
        root = Path(tmp).resolve()
        try:
            path, stat = _graph(bp).compute_step(job.step, values, out_dir=root, **job.params)
            files = {
                p.relative_to(root).as_posix(): p.read_bytes()
                for p in sorted(root.rglob("*"))
                if p.is_file() and not p.name.startswith(".")
            }
            main = Path(path).resolve().relative_to(root).as_posix()
        except Exception as exc:
            costs[job.step.key] = (time.perf_counter() - t0, "failed")
            return Outcome(None, one_line(exc), costs)
    costs[job.step.key] = (stat.seconds, "computed")
    return Outcome((main, files), None, costs)


def run_render(size: tuple[int, int], node: Outcome) -> Outcome:
    """Task: an off-screen picture (PNG bytes) of a node's output."""
    if node.error is not None:
        return node
    try:
        from formgraph.viewer.sheet import render_cell

        png = render_cell(node.value, size)
    except Exception as exc:
        return Outcome(None, f"render: {one_line(exc)}", node.costs)
    return Outcome(png, None, node.costs)


@dataclass(frozen=True)
class RowJob:
    """The literal part of a row task: how its inputs map to columns."""

    measures: tuple[tuple[str, str | None, str], ...]
    nodes: tuple[str, ...]  # the measured nodes, in the order of the first inputs
    exports: tuple[str, ...]
    render: bool
    build: int  # trailing inputs only built


def make_row(job: RowJob, *inputs: Outcome) -> RowResult:
    """Task: a variant's row from its targets' outcomes."""
    costs, error = _merged(inputs)
    n = len(job.nodes)
    values: dict[str, Any] = {}
    exports: dict[str, tuple[str, dict[str, bytes]]] = {}
    image = None
    if error is None:
        by_node = dict(zip(job.nodes, inputs[:n], strict=True))
        for node, output, column in job.measures:
            v = by_node[node].value
            v = getattr(v, output) if output else v
            values[column] = v.item() if hasattr(v, "item") else v
        for name, o in zip(job.exports, inputs[n : n + len(job.exports)], strict=True):
            exports[name] = o.value
        if job.render:
            image = inputs[n + len(job.exports)].value
    seconds = sum(s for s, _ in costs.values())
    return RowResult(error, seconds, values, exports, image, costs)


# --------------------------------------------------------------------- client side


def blueprint(g: Graph, cache_dir: str | None, worker_cache: bool) -> Blueprint:
    """The graph as workers will rebuild it.

    Raises
    ------
    SweepError
        When a node type is defined where workers cannot import it (``__main__``), or the
        graph holds Python objects that do not write to YAML.
    """
    from .registry import node_types

    registry = node_types()
    modules = set()
    for name, type_name in g.nodes.items():
        module = registry[type_name].func.__module__
        if module == "__main__":
            raise SweepError(
                f"{g.file_label}: node '{name}': its type '{type_name}' is defined in the "
                f"script being run (__main__), which Dask workers cannot import; define it "
                f"in a module"
            )
        if not module.startswith("formgraph."):
            modules.add(module)
    try:
        text = g.to_yaml()
    except Exception as exc:  # yaml's RepresenterError for a geometry typed in as an input
        raise SweepError(
            f"{g.file_label}: the graph cannot be sent to Dask workers as YAML ({exc}); pass "
            f"geometry through a typed param instead of a node input"
        ) from None
    return Blueprint(
        uuid.uuid4().hex,
        text,
        g.file_label,
        g.params,
        tuple(sorted(modules)),
        g.budget,
        None if cache_dir is None else str(cache_dir),
        worker_cache,
    )


def build(
    g: Graph,
    bp_key: str,
    variants: Sequence[tuple[int, dict[str, Any]]],
    targets: Targets,
    visible: DiskCache | None,
) -> tuple[dict[str, Any], dict[str, list[int]], Totals]:
    """The Dask graph of every variant, the variants of each row key, and the totals."""
    dsk: dict[str, Any] = {}
    rows: dict[str, list[int]] = {}
    totals = Totals(variants=len(variants))
    names = targets.nodes
    measured = tuple(dict.fromkeys(m[0] for m in targets.measures))
    job = RowJob(targets.measures, measured, targets.exports, targets.render is not None, 0)
    for index, params in variants:
        steps = g.plan(names, **params)
        totals.naive += len(steps)
        by_name = {s.name: s for s in steps}
        needed = set(names)
        for s in reversed(steps):  # from the targets up: a cached node needs no ancestors
            if s.name not in needed or s.key in dsk:
                continue
            ups = [by_name[u].key for u in s.upstream]
            if s.export:
                dsk[s.key] = (run_export, bp_key, Job(s, params), *ups)
            elif visible is not None and visible.has(s.key):
                dsk[s.key] = (cached_step, bp_key, Job(s, params))
                continue
            else:
                dsk[s.key] = (run_step, bp_key, Job(s, params), *ups)
            needed.update(s.upstream)
        refs = [by_name[n].key for n in measured] + [by_name[n].key for n in targets.exports]
        if targets.render is not None:
            node_key = by_name[targets.render].key
            render_key = "render-" + key_of([node_key, list(targets.size)])
            dsk.setdefault(render_key, (run_render, targets.size, node_key))
            refs.append(render_key)
        refs += [by_name[n].key for n in targets.build]
        row_key = "row-" + key_of(refs)
        if row_key not in dsk:
            dsk[row_key] = (make_row, job, *refs)
        rows.setdefault(row_key, []).append(index)
    totals.needed = sum(1 for k in dsk if not k.startswith(("row-", "render-")))
    return dsk, rows, totals


@contextlib.contextmanager
def connect(client: Any, workers: int | None) -> Iterator[Any]:
    """A Dask client: the one given, one for a scheduler address, or an embedded cluster.

    The embedded :class:`distributed.LocalCluster` has one single-threaded worker process per
    core (BLAS threads pinned to 1), listens on the loopback only, and is closed on the way
    out, whatever happened.
    """
    from distributed import Client, LocalCluster

    if client is not None and not isinstance(client, str):
        yield client
        return
    if isinstance(client, str):
        try:
            c = Client(client, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise SweepError(f"cannot reach the Dask scheduler at {client}: {exc}") from None
        try:
            yield c
        finally:
            c.close()
        return
    n = workers or os.cpu_count() or 1
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=logging.ERROR,
        env=BLAS_ENV,
    )
    try:
        c = Client(cluster)
        try:
            yield c
        finally:
            c.close()
    finally:
        cluster.close()


def run(
    g: Graph,
    variants: Sequence[tuple[int, dict[str, Any]]],
    targets: Targets,
    on_row: Callable[[int, RowResult], None],
    *,
    client: Any = None,
    workers: int | None = None,
    cache_dir: str | os.PathLike[str] | None = None,
    worker_cache: bool = False,
) -> Totals:
    """Run ``variants`` (index, params) and call ``on_row`` on the client as each finishes."""
    from distributed import as_completed

    bp = blueprint(g, None if cache_dir is None else str(cache_dir), worker_cache)
    bp_key = f"graph-{bp.token}"
    embedded = client is None
    visible = None
    if embedded and (cache_dir is not None or worker_cache):  # the workers' disk is ours
        visible = DiskCache(default_cache_dir() if worker_cache else cache_dir)
    dsk, rows, totals = build(g, bp_key, variants, targets, visible)
    if not rows:
        return totals
    dsk[bp_key] = bp
    seen: dict[str, tuple[float, str]] = {}
    with connect(client, workers) as c:
        futures = c.get(dsk, list(rows), sync=False, optimize_graph=False)
        pending = as_completed(futures)
        resubmitted: dict[str, int] = {}
        try:
            for fut in pending:
                if fut.cancelled() and resubmitted.get(fut.key, 0) < 3:
                    # the same keys of an interrupted sweep, still being cancelled on a shared
                    # scheduler, cancel ours too: ask again (we never cancel while running)
                    resubmitted[fut.key] = resubmitted.get(fut.key, 0) + 1
                    time.sleep(0.1 * resubmitted[fut.key])
                    (again,) = c.get(dsk, [fut.key], sync=False, optimize_graph=False)
                    futures.append(again)
                    pending.add(again)
                    continue
                result = _row_result(fut)
                fut.release()
                seen.update(result.costs)
                for index in rows[fut.key]:
                    on_row(index, result)
        finally:
            c.cancel(futures)
    totals.computed = sum(1 for _, st in seen.values() if st == "computed")
    totals.cached = sum(1 for _, st in seen.values() if st == "cached")
    return totals


def _row_result(fut: Any) -> RowResult:
    try:
        return fut.result()
    except Exception as exc:  # KilledWorker after too many deaths, or a bug of ours
        name = type(exc).__name__
        if name == "KilledWorker":
            msg = "the Dask workers running this variant kept dying (out of memory?)"
        else:
            msg = one_line(exc)
        return RowResult(msg, 0.0, {}, {}, None, {})
