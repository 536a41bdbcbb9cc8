"""Running a sweep's variants as one Dask graph keyed by the nodes' cache keys.

Every variant is planned on the client (:meth:`formgraph.Graph.plan`): each node it needs,
keyed as a cold evaluation keys it. A node that two or more variants need (a profile the
varied param never reaches) is a task under its cache key, so shared work runs once in the
whole sweep. A variant's own nodes run in its row task, ``row-<hash of its target keys>``
(identical variants share it): Dask's linear fusion, done by what variants share, so the
per-task overhead is paid once per variant. A node the client sees in the disk cache is
loaded instead (evaluated on a worker that lacks it), and its ancestors are not scheduled.

Workers receive the graph once, as its YAML text (a task of its own, ``graph-<token>``),
never a file path: nothing here assumes a shared filesystem. Shared nodes' outputs travel
between workers as Dask data; measured values, exported files (their bytes) and rendered
cells come back to the client in one small result per variant, which the client writes.

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

__all__ = ["Outcome", "RowResult", "SweepError", "Targets", "Totals", "run"]

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
    files: dict[str, str] = field(default_factory=dict)  # subgraph files, by path from
    # the graph's folder: a worker without them (another machine) writes them out
    path: str = ""  # the graph file's absolute path on the client

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
            file=_graph_file(bp),
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
    scratch = Path(tempfile.mkdtemp(prefix="formgraph-graph-"))
    for rel, text in bp.files.items():
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

    def __dask_tokenize__(self) -> str:
        return key_of([list(m) for m in self.measures] + [list(self.exports), self.render])


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


def run_rows(
    bp: Blueprint, job: RowJob, chunk: RowChunk, *shared: Outcome
) -> list[tuple[str, RowResult]]:
    """Task: a few variants' rows, each from its own nodes and the shared ones' outcomes.

    Fusing variants' private chains into one task is Dask's own linear fusion, keyed by what
    the variants need: the per-task overhead is paid once per few variants, while every node
    that variants share stays a task of its own under its cache key.
    """
    by_key = dict(zip(chunk.keys, shared, strict=True))
    return [(plan.key, run_row(bp, job, plan, by_key)) for plan in chunk.plans]


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

                image = render_cell(values[job.render], job.size)
            except Exception as exc:
                error = f"render: {one_line(exc)}"
    exports = {n: values[n] for n in job.exports} if error is None else {}
    return RowResult(error, seconds, measured, exports, image, costs)


# --------------------------------------------------------------------- client side


def blueprint(g: Graph, cache_dir: str | None, worker_cache: bool) -> Blueprint:
    """The graph as workers will rebuild it.

    Raises
    ------
    SweepError
        When a node type is defined where workers cannot import it (``__main__``), or the
        graph holds Python objects that do not write to YAML.
    """
    registry = g.node_types()  # the registry and the graph files it names
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
    files: dict[str, str] = {}
    if g.file and len(g.files) > 1:  # subgraphs: their text travels with the graph
        root = Path(g.file).resolve().parent
        for path in g.files[1:]:
            try:
                rel = Path(path).resolve().relative_to(root).as_posix()
                files[rel] = Path(path).read_text(encoding="utf-8")
            except (OSError, ValueError, UnicodeDecodeError) as exc:
                raise SweepError(
                    f"{g.file_label}: cannot send {path} to Dask workers: {exc}"
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
        files,
        str(Path(g.file).resolve()) if g.file else "",
    )


def build(
    g: Graph,
    bp_key: str,
    variants: Sequence[tuple[int, dict[str, Any]]],
    targets: Targets,
    visible: DiskCache | None,
    chunk: int = 1,
) -> tuple[dict[str, Any], dict[str, list[int]], dict[str, list[str]], Totals]:
    """The Dask graph of every variant, the variants of each row key, the row keys of each
    row task, and the totals.

    A node two or more variants need is a task under its cache key, computed once; a
    variant's own nodes run inside its row task (``row-<hash of its target keys>``, so
    identical variants share a row), ``chunk`` rows to a task. A node the client sees in the
    disk cache is loaded instead of computed, and its ancestors are not needed at all.
    """
    names = targets.nodes
    plans: list[tuple[str, list[Step], dict[str, Any]]] = []
    rows: dict[str, list[int]] = {}
    users: dict[str, int] = {}  # node key -> how many distinct rows need it
    cached: set[str] = set()
    totals = Totals(variants=len(variants))
    for index, params in variants:
        steps = g.plan(names, **params)
        totals.naive += len(steps)
        by_name = {s.name: s for s in steps}
        row_key = "row-" + key_of([by_name[n].key for n in names] + [list(targets.size)])
        if row_key in rows:
            rows[row_key].append(index)
            continue
        rows[row_key] = [index]
        needed = set(names)
        kept = []
        for s in reversed(steps):  # from the targets up: a cached node needs no ancestors
            if s.name not in needed:
                continue
            kept.append(s)
            if not s.export and visible is not None and visible.has(s.key):
                cached.add(s.key)
                continue
            needed.update(s.upstream)
        kept.reverse()
        for s in kept:
            users[s.key] = users.get(s.key, 0) + 1
        plans.append((row_key, kept, params))
    dsk: dict[str, Any] = {}
    job = RowJob(targets.measures, targets.exports, targets.render, targets.size)
    row_plans = []
    for row_key, steps, params in plans:
        by_name = {s.name: s for s in steps}
        own = tuple(s for s in steps if users[s.key] == 1)
        for s in steps:
            if users[s.key] == 1 or s.key in dsk:
                continue
            if s.key in cached:
                dsk[s.key] = (cached_step, bp_key, Job(s, params))
            else:
                ups = [by_name[u].key for u in s.upstream]
                dsk[s.key] = (run_export if s.export else run_step, bp_key, Job(s, params), *ups)
        wanted = [u for s in own if s.key not in cached for u in s.upstream] + names
        shared = tuple(
            (n, by_name[n].key) for n in dict.fromkeys(wanted) if users[by_name[n].key] > 1
        )
        row_plans.append(RowPlan(own, shared, params, row_key))
    chunks: dict[str, list[str]] = {}
    for i in range(0, len(row_plans), chunk):
        group = tuple(row_plans[i : i + chunk])
        keys = tuple(dict.fromkeys(k for p in group for _, k in p.shared))
        task_key = group[0].key if len(group) == 1 else "rows-" + key_of([p.key for p in group])
        dsk[task_key] = (run_rows, bp_key, job, RowChunk(group, keys), *keys)
        chunks[task_key] = [p.key for p in group]
    totals.needed = len(users)
    return dsk, rows, chunks, totals


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
    import dask

    n = workers or os.cpu_count() or 1
    # distributed sets MALLOC_TRIM_THRESHOLD_ in workers to hand memory back early; for
    # numpy kernels whose temporaries are megabytes that costs a page-fault storm (the spiral
    # tube builds 1.4x slower), and a sweep's workers end with the sweep anyway
    with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # its HTTP routes, off 8787
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

    if not variants:  # all done already (a resumed sweep): no cluster needed
        return Totals()
    bp = blueprint(g, None if cache_dir is None else str(cache_dir), worker_cache)
    bp_key = f"graph-{bp.token}"
    embedded = client is None
    visible = None
    if embedded and (cache_dir is not None or worker_cache):  # the workers' disk is ours
        visible = DiskCache(default_cache_dir() if worker_cache else cache_dir)
    seen: dict[str, tuple[float, str]] = {}
    with connect(client, workers) as c:
        threads = sum(w.get("nthreads", 1) for w in c.scheduler_info()["workers"].values())
        # a few variants to a task when there are many per thread: Dask's overhead per task
        # is paid once per few light variants, and the table still grows steadily
        chunk = max(1, min(16, len(variants) // (8 * max(threads, 1))))
        dsk, rows, chunks, totals = build(g, bp_key, variants, targets, visible, chunk)
        if not rows:
            return totals
        dsk[bp_key] = bp
        futures = c.get(dsk, list(chunks), sync=False, optimize_graph=False)
        pending = as_completed(futures)
        resubmitted: dict[str, int] = {}
        try:
            for batch in pending.batches():  # one gather per batch: no round trip per task
                done = [f for f in batch if f.status == "finished"]
                try:
                    results = dict(zip([f.key for f in done], c.gather(done), strict=True))
                except Exception:  # lost meanwhile (a worker died): each on its own below
                    results = {}
                for fut in batch:
                    if fut.cancelled() and resubmitted.get(fut.key, 0) < 8:
                        # the same keys of an interrupted sweep, still being cancelled on a
                        # shared scheduler, cancel ours too: ask again (we never cancel ours)
                        resubmitted[fut.key] = resubmitted.get(fut.key, 0) + 1
                        time.sleep(0.1 * resubmitted[fut.key])
                        (again,) = c.get(dsk, [fut.key], sync=False, optimize_graph=False)
                        futures.append(again)
                        pending.add(again)
                        continue
                    if fut.key in results:
                        finished = results[fut.key]
                    else:
                        finished = _chunk_result(fut, chunks[fut.key])
                    fut.release()
                    for row_key, result in finished:
                        seen.update(result.costs)
                        for index in rows[row_key]:
                            on_row(index, result)
        finally:
            c.cancel(futures)
    totals.computed = sum(1 for _, st in seen.values() if st == "computed")
    totals.cached = sum(1 for _, st in seen.values() if st == "cached")
    return totals


def _chunk_result(fut: Any, row_keys: list[str]) -> list[tuple[str, RowResult]]:
    try:
        return fut.result()
    except Exception as exc:  # KilledWorker after too many deaths, or a bug of ours
        if type(exc).__name__ == "KilledWorker":
            msg = "the Dask workers running this variant kept dying (out of memory?)"
        else:
            msg = one_line(exc)
        return [(k, RowResult(msg, 0.0, {}, {}, None, {})) for k in row_keys]
