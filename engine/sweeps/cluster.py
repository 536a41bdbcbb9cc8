"""Running a sweep's variants as one Dask graph keyed by the nodes' cache keys.

Every variant is planned on the client (:meth:`formgraph.Graph.plan`): each node it needs,
keyed as a cold evaluation keys it. A node that two or more variants need (a profile the
varied param never reaches) is a task under its cache key, so shared work runs once in the
whole sweep. A variant's own nodes run in its row (``row-<hash of its target keys>``, which
identical variants share), a few rows to a task when there are many: Dask's linear fusion,
done by what variants share, so the per-task overhead is paid once per few variants. A node
the client sees in the disk cache is loaded instead (evaluated on a worker that lacks it),
and its ancestors are not scheduled. The tasks themselves are :mod:`formgraph.sweeps.tasks`.

Workers receive the graph once, as its YAML text (a task of its own, ``graph-<token>``),
never a file path: nothing here assumes a shared filesystem. Shared nodes' outputs travel
between workers as Dask data; measured values, exported files (their bytes) and rendered
cells come back to the client in one small result per variant, which the client writes.

A node that fails is an outcome holding its one-line error, never an exception, so its
dependents finish at once with the same error and the sweep goes on. A worker that dies
is Dask's business: the scheduler reruns its tasks elsewhere (``distributed``'s
``allowed-failures``), and a variant is reported once, when its row task finishes.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..core import safety
from ..core.errors import FormgraphError
from ..evaluation.cache import DiskCache, default_cache_dir, key_of, key_text
from ..evaluation.graph import Graph, Step
from ..language.yamlio import MAX_BYTES
from .tasks import (
    Blueprint,
    Job,
    Packed,
    RowChunk,
    RowJob,
    RowPlan,
    RowResult,
    cached_step,
    one_line,
    run_export,
    run_rows,
    run_step,
)

__all__ = ["RowResult", "Running", "SweepError", "Targets", "Totals", "connect", "run", "start"]

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
class Targets:
    """What each variant brings back: measured outputs, exports, a rendered node."""

    measures: tuple[tuple[str, str | None, str], ...] = ()  # (node, output, column)
    exports: tuple[str, ...] = ()  # export node names
    render: str | None = None
    size: tuple[int, int] = (256, 192)
    build: tuple[str, ...] = ()  # nodes only built (nothing measured, exported or drawn)
    camera: tuple[Any, Any, Any] | None = None  # (view, azimuth, elevation) of the cells

    @property
    def nodes(self) -> list[str]:
        names = [m[0] for m in self.measures] + list(self.exports) + list(self.build)
        if self.render:
            names.append(self.render)
        return list(dict.fromkeys(names))


@dataclass
class Totals:
    """How much work the sweep's graph held and did."""

    variants: int = 0
    naive: int = 0  # node evaluations of a plain loop without any cache: variants x nodes
    needed: int = 0  # distinct node tasks in the sweep's graph
    computed: int = 0
    cached: int = 0


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
        text = g.source_text()  # the file's own lines, for workers' messages
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
                files[rel] = safety.read_regular(path, max_bytes=MAX_BYTES).decode("utf-8")
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
        str(Path(g.input_base).resolve()),
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
    planned = g.plans(names, [params for _, params in variants])
    # the row key is key_of([target keys..., size, camera]); its text written directly
    tail = key_text([list(targets.size), list(targets.camera or ())])[1:]
    order = [s.name for s in planned[0]] if planned else []  # the same for every variant
    where = [order.index(n) for n in names]
    for (index, params), steps in zip(variants, planned, strict=True):
        totals.naive += len(steps)
        text = "[" + "".join([key_text(steps[i].key) + "," for i in where]) + tail
        row_key = "row-" + hashlib.blake2b(text.encode(), digest_size=20).hexdigest()
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
    job = RowJob(targets.measures, targets.exports, targets.render, targets.size, targets.camera)
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
        _row_task(dsk, chunks, bp_key, job, tuple(row_plans[i : i + chunk]))
    totals.needed = len(users)
    return dsk, rows, chunks, totals


def _row_task(
    dsk: dict[str, Any],
    chunks: dict[str, list[str]],
    bp_key: str,
    job: RowJob,
    group: tuple[RowPlan, ...],
) -> str:
    """Put the row task of ``group`` (its variants' plans) in ``dsk`` and its rows in
    ``chunks``; its key (a single row's task is keyed by its row key)."""
    keys = tuple(dict.fromkeys(k for p in group for _, k in p.shared))
    task_key = group[0].key if len(group) == 1 else "rows-" + key_of([p.key for p in group])
    dsk[task_key] = (run_rows, bp_key, job, Packed.of(RowChunk(group, keys)), *keys)
    chunks[task_key] = [p.key for p in group]
    return task_key


@contextlib.contextmanager
def _workers_ignore_interrupts() -> Iterator[None]:
    """Start worker processes with Ctrl-C ignored (an ignored signal stays ignored across
    their exec, where a handler or a blocked mask would not).

    A terminal sends Ctrl-C to the whole process group: the workers would each die with a
    ``KeyboardInterrupt`` traceback, mid-import or mid-task, while the client is already
    stopping the sweep and closing the cluster, which ends them in order. Only the client
    hears Ctrl-C; while the workers start (a second or two) it is ignored there too.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


CHUNK_CAP = 128  # variants to a row task at most (Dask's cost per task is ~ms of CPU)
FILES_CHUNK_CAP = 16  # ... when each variant brings files back (exports, a drawn cell): a
# task's results are held whole on the worker and the client until it ends

HANDSHAKE_SECONDS = 10.0
# A gather of finished tasks is a copy of their rows: far under this unless Dask deadlocked
# on a worker that died meanwhile (dask/distributed#3196, seen under a load of 20)
GATHER_SECONDS = 120.0
LOST = "Dask lost this variant with a dying worker and did not run it again"
_HANDSHAKE_BYTES = 1 << 16  # a scheduler's greeting is some 60 bytes


def probe_scheduler(address: str, timeout: float | None = None) -> None:
    """Check that a Dask scheduler listens at ``address`` before a client trusts it.

    A Dask scheduler greets every connection at once with a small handshake (an 8-byte
    length, then msgpack frames holding its Python version and pickle protocol).
    ``distributed`` itself waits for it without a time limit and allocates whatever length
    the peer announces, so a port that accepts and stays silent would hang the sweep and
    one that sends junk could ask for exabytes. Here the greeting must come within
    ``timeout`` seconds (:data:`HANDSHAKE_SECONDS`), be under 64 KiB and read as Dask's.
    Addresses other than TCP (``tls://``, ``inproc://``) are left to ``distributed``.

    Raises
    ------
    SweepError
        No connection, no greeting in time, or a peer that is not a Dask scheduler.
    """
    import socket
    import struct

    import msgpack
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.protocol.utils import unpack_frames

    try:
        scheme, loc = parse_address(address)
        if scheme != "tcp":
            return
        host, port = parse_host_port(loc)
    except (ValueError, TypeError) as exc:
        raise SweepError(f"{address!r} is not a scheduler address ({exc})") from None
    timeout = HANDSHAKE_SECONDS if timeout is None else timeout
    deadline = time.monotonic() + timeout

    def receive(sock: Any, n: int) -> bytes:
        data = bytearray()
        while len(data) < n:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError
            sock.settimeout(left)
            chunk = sock.recv(n - len(data))
            if not chunk:
                raise ConnectionError("it closed the connection")
            data += chunk
        return bytes(data)

    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            (size,) = struct.unpack("<Q", receive(sock, 8))
            if not 0 < size <= _HANDSHAKE_BYTES:
                raise ValueError(f"it announced a first message of {size:,} bytes")
            frames = unpack_frames(receive(sock, size))
            info = msgpack.loads(frames[0], raw=False) if frames else None
            if not (isinstance(info, dict) and "python" in info and "pickle-protocol" in info):
                raise ValueError("its first message is not Dask's handshake")
    except TimeoutError:
        raise SweepError(
            f"the peer at {address} accepted the connection but sent no Dask handshake "
            f"within {timeout:g} s: it is not a Dask scheduler, or not answering"
        ) from None
    except OSError as exc:
        raise SweepError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
    except ValueError as exc:  # ours above, and msgpack's on junk
        raise SweepError(f"the peer at {address} is not a Dask scheduler ({exc})") from None
    except Exception as exc:  # junk: struct, msgpack or frame errors of any kind
        raise SweepError(
            f"the peer at {address} is not a Dask scheduler ({one_line(exc)})"
        ) from None


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
        probe_scheduler(client)
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
    # tube builds 1.4x slower), and a sweep's workers end with the sweep anyway. Dask's own
    # profiler (a thread reading each worker's stacks every 10 ms, for a dashboard that is
    # off here) is off too. So are most of the timers an idle cluster runs (the event
    # loops' 20 ms tick, kept only to warn of a blocked loop; the 500 ms system monitor,
    # for the dashboard; the nannies' 100 ms memory check, here every 500 ms): 8% of a
    # core between the client and two workers, measured idle, down to 2%, which on two
    # cores is taken from the workers' trials
    settings = {
        "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
        "distributed.worker.profile.enabled": False,
        "distributed.admin.tick.interval": "1s",
        "distributed.admin.system-monitor.interval": "2s",
        "distributed.worker.memory.monitor-interval": "500ms",
    }
    with (
        dask.config.set(settings),
        _workers_ignore_interrupts(),
    ):
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # its HTTP routes, off 8787
            silence_logs=logging.ERROR,
            env=BLAS_ENV,
            # workers that fill the cores run manifold3d's oneTBB on one thread each, as BLAS;
            # fewer workers than cores keep its threads (a lone worker uses every core)
            preload=["formgraph.sweeps.workerinit"] if n >= _cores() else [],
        )
    try:
        c = Client(cluster, direct_to_workers=True)  # results straight from the workers
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
    shared_disk: bool = False,
    bp: Blueprint | None = None,
) -> Totals:
    """Run ``variants`` (index, params) and call ``on_row`` on the client as each finishes.

    ``shared_disk``: the client sees the workers' ``cache_dir`` (a folder on a shared
    filesystem), so nodes found there are loaded, not scheduled, as on an embedded cluster.
    ``bp``: the blueprint of an earlier call, so workers rebuild the graph only once for a
    series of runs (an optimisation study's batches).
    """
    if not variants:  # all done already (a resumed sweep): no cluster needed
        return Totals()
    with connect(client, workers) as c:
        return start(
            g, variants, targets, on_row, c,
            cache_dir=cache_dir, worker_cache=worker_cache, shared_disk=shared_disk,
            embedded=client is None, bp=bp,
        ).wait()  # fmt: skip


def start(
    g: Graph,
    variants: Sequence[tuple[int, dict[str, Any]]],
    targets: Targets,
    on_row: Callable[[int, RowResult], None],
    c: Any,
    *,
    cache_dir: str | os.PathLike[str] | None = None,
    worker_cache: bool = False,
    shared_disk: bool = False,
    embedded: bool = False,
    bp: Blueprint | None = None,
) -> Running:
    """Plan ``variants`` and hand their tasks to the cluster of the client ``c``; the rows
    are delivered by :meth:`Running.wait`.

    ``embedded``: ``c`` is the client of a cluster on this machine (its disk is ours).
    Several runs may be in flight at once (an optimisation study asks its next batch while
    one runs): the scheduler starts a later run's tasks when workers have nothing earlier
    to do, so the workers never wait for the client between batches.
    """
    if bp is None:
        bp = blueprint(g, None if cache_dir is None else str(cache_dir), worker_cache)
    bp_key = f"graph-{bp.token}"
    embedded = embedded or shared_disk
    visible = None
    if embedded and (cache_dir is not None or worker_cache):  # the workers' disk is ours
        visible = DiskCache(default_cache_dir() if worker_cache else cache_dir)
    threads = sum(w.get("nthreads", 1) for w in c.scheduler_info()["workers"].values())
    # a few variants to a task when there are many per thread: Dask's overhead per task
    # is paid once per few light variants, and the table still grows steadily
    cap = FILES_CHUNK_CAP if targets.exports or targets.render else CHUNK_CAP
    chunk = max(1, min(cap, len(variants) // (8 * max(threads, 1))))
    dsk, rows, chunks, totals = build(g, bp_key, variants, targets, visible, chunk)
    dsk[bp_key] = bp
    return Running(c, dsk, rows, chunks, totals, on_row)


class Running:
    """A run whose tasks the cluster holds; :meth:`wait` delivers its rows as they finish."""

    def __init__(
        self,
        c: Any,
        dsk: dict[str, Any],
        rows: dict[str, list[int]],
        chunks: dict[str, list[str]],
        totals: Totals,
        on_row: Callable[[int, RowResult], None],
    ):
        self.c, self.dsk, self.rows, self.chunks = c, dsk, rows, chunks
        self.totals, self.on_row = totals, on_row
        self.futures: list[Any] = []
        if rows:
            self.futures = c.get(dsk, list(chunks), sync=False, optimize_graph=False)

    def cancel(self) -> None:
        """Withdraw every task still held (an interrupted study's batch in flight)."""
        if self.futures:
            self.c.cancel(self.futures)

    def wait(self) -> Totals:
        """Call ``on_row`` for every variant as its row task finishes; the totals.

        A row task that dies with its worker is run again (its rows one by one, so only a
        variant that kills its worker fails); a result lost with a worker is asked again.
        """
        from distributed import as_completed

        c, dsk, rows, chunks, futures = self.c, self.dsk, self.rows, self.chunks, self.futures
        totals = self.totals
        if not rows:
            return totals
        seen: dict[str, tuple[float, str]] = {}
        pending = as_completed(futures)
        resubmitted: dict[str, int] = {}
        suspects: list[str] = []  # one-row tasks killed with others: each again, alone

        def deliver(finished: list[tuple[str, RowResult]]) -> None:
            for row_key, result in finished:
                seen.update(result.costs)
                for index in rows[row_key]:
                    self.on_row(index, result)

        ended = False
        try:
            for batch in pending.batches():  # one gather per batch: no round trip per task
                done = [f for f in batch if f.status == "finished"]
                stuck = False
                try:
                    got = c.sync(c._gather, done, callback_timeout=GATHER_SECONDS)
                    results = dict(zip([f.key for f in done], got, strict=True))
                except TimeoutError:  # dask/distributed#3196: a dying worker can deadlock
                    results, stuck = {}, True  # the gather; its tasks again, on new keys
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
                    # its data lost with a worker since as_completed said it was done:
                    # Dask recomputes it, or deadlocks (#3196); ours again, on new keys
                    gone = stuck or fut.status in ("pending", "lost")
                    if fut.key in results:
                        finished = results[fut.key].rows
                    elif len(chunks[fut.key]) > 1 and (gone or _killed(fut)):
                        # one variant of the task kills its worker (out of memory, a crash
                        # in compiled code): each of its rows again on its own, so only that
                        # one fails and the others are not blamed for it
                        again = c.get(
                            dsk, _split(dsk, chunks, fut.key), sync=False, optimize_graph=False
                        )
                        futures.extend(again)
                        pending.update(again)
                        fut.release()
                        continue
                    elif gone or _killed(fut):  # it, or a task beside it on the dying worker
                        suspects.append(fut.key)
                        fut.release()
                        continue
                    else:
                        finished = _chunk_result(fut, chunks[fut.key])
                    fut.release()
                    deliver(finished)
            # a worker that dies takes every task it holds with it: run each killed row
            # alone, one after another, so only the one that kills is blamed. Each on a new
            # key: under its own, the scheduler may still hold the KilledWorker it just gave
            # (its release is asynchronous), and an innocent row would be blamed at once
            for key in suspects:
                fresh = _again(dsk, chunks, key)
                (alone,) = c.get(dsk, [fresh], sync=False, optimize_graph=False)
                futures.append(alone)
                finished = _chunk_result(alone, chunks[fresh])  # waits GATHER_SECONDS at most
                alone.release()
                deliver(finished)
            ended = True
        finally:
            # every future is released once delivered; cancelling them all again would
            # withdraw a row key that a run still in flight shares (the same variant asked
            # twice by an optimiser)
            if not ended:
                c.cancel(futures)
        totals.computed = sum(1 for _, st in seen.values() if st == "computed")
        totals.cached = sum(1 for _, st in seen.values() if st == "cached")
        return totals


def _killed(fut: Any) -> bool:
    """Whether a task failed because the workers running it kept dying (KilledWorker)."""
    if fut.status != "error":
        return False
    try:
        return type(fut.exception()).__name__ == "KilledWorker"
    except Exception:  # lost with its worker: said when its result is asked for
        return False


def _again(dsk: dict[str, Any], chunks: dict[str, list[str]], task_key: str) -> str:
    """The task ``task_key`` put in ``dsk`` again under a key the scheduler has never seen
    (the same rows, the same shared inputs); that key."""
    fresh = f"again-{uuid.uuid4().hex}-{task_key}"
    dsk[fresh] = dsk[task_key]
    chunks[fresh] = chunks[task_key]
    return fresh


def _cores() -> int:
    """The cores this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def _split(dsk: dict[str, Any], chunks: dict[str, list[str]], task_key: str) -> list[str]:
    """The rows of the row task ``task_key`` as tasks of one row each (:func:`_row_task`);
    their keys."""
    _, bp_key, job, packed, *_ = dsk[task_key]
    return [_row_task(dsk, chunks, bp_key, job, (plan,)) for plan in packed.unpack().plans]


def _chunk_result(fut: Any, row_keys: list[str]) -> list[tuple[str, RowResult]]:
    try:
        return fut.result(timeout=GATHER_SECONDS).rows
    except TimeoutError:
        msg = LOST
    except Exception as exc:  # KilledWorker after too many deaths, or a bug of ours
        if type(exc).__name__ == "KilledWorker":
            msg = "the Dask workers running this variant kept dying (out of memory?)"
        else:
            msg = one_line(exc)
    return [(k, RowResult(msg, 0.0, {}, {}, None, {})) for k in row_keys]
