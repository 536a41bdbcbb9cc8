"""Timing harness shared by every benchmark module in bench/.

Each ``bench/bench_*.py`` defines ``run(table: Table) -> None`` and adds rows. The row a
user's claim rests on is :meth:`Table.compare`: ours **through the public API** (a graph
evaluated as a user calls it, or ``fg.*``), beside **the kernel alone**, against
**references written the way their own users write them**, timed in interleaved rounds whose
order turns, reported as medians with their range (min-max) and the ratio of ours to each
reference per round (its median and range). :meth:`Table.memory` does the same for peak
memory. ``python bench/run.py [name ...]`` prints the table; ``--markdown`` prints the table
the documentation shows, from that one run. :func:`through` makes the call of one node as
a user makes it, on new values each call.
"""

from __future__ import annotations

import gc
import itertools
import os
import statistics
import time
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

# ``BENCH_CLOCK=cpu`` times CPU seconds of this process instead of wall seconds: on a
# machine shared with other jobs, far steadier (every row here is single-threaded: one
# BLAS thread; a threaded reference would have its threads' time added up). A row that
# measures parallel work (workers, subprocesses) passes ``clock="wall"`` itself.
CLOCK = os.environ.get("BENCH_CLOCK", "wall")
if CLOCK not in ("wall", "cpu"):
    raise SystemExit(f"BENCH_CLOCK must be wall or cpu, got {CLOCK!r}")
_CLOCKS = {"wall": time.perf_counter, "cpu": time.process_time}
# ``BENCH_SMOKE=1``: every implementation called once, in one round, no warm-up: checks that
# each module runs through (its numbers mean nothing) in a fraction of a real run's time.
SMOKE = os.environ.get("BENCH_SMOKE", "") not in ("", "0")
_now = _CLOCKS[CLOCK]


def through(node: str, params: dict[str, Callable[[int], Any]], /, **inputs: Any) -> Callable:
    """A call of node type ``node`` as a user makes it: a graph of that one node (named
    ``n``; its ``inputs`` may read the ``params`` as ``"=name"``), evaluated with each param
    set to ``params[name](k)`` for k = 1, 2, ... call after call: a new value every call,
    so neither the cache nor early cutoff answers (a geometry value is made in the call,
    as a user's own arrays would be)."""
    import formgraph as fg
    from formgraph.geometry import Geometry

    g = fg.Graph()
    for name, make in params.items():
        first = make(0)
        if isinstance(first, Geometry):
            g.add_param(name, type=type(first).__name__)
        else:
            g.add_param(name, first)
    g.add("n", node, **inputs)
    steps = itertools.count(1)

    def call() -> Any:
        k = next(steps)
        return g.evaluate("n", **{name: make(k) for name, make in params.items()})

    return call


@dataclass
class Stat:
    """Per-round values of one implementation: their median and range."""

    values: list[float]

    @property
    def median(self) -> float:
        return statistics.median(self.values)

    @property
    def low(self) -> float:
        return min(self.values)

    @property
    def high(self) -> float:
        return max(self.values)


@dataclass
class Row:
    case: str
    impl: str
    seconds: float | None
    note: str = ""
    # set by compare(): the per-round times and, for references, ours / theirs per round
    stat: Stat | None = None
    ratio: Stat | None = None
    unit: str = "s"  # "s" or "bytes" (memory rows)
    role: str = ""  # "api", "kernel", "reference" (compare rows); "" for rows added


@dataclass
class Table:
    rows: list[Row] = field(default_factory=list)

    # -- the row every claim rests on -------------------------------------------------------
    def compare(
        self,
        case: str,
        *,
        api: Callable[[], object],
        kernel: Callable[[], object] | None = None,
        references: dict[str, Callable[[], object]] | None = None,
        rounds: int = 7,
        min_seconds: float = 0.1,
        clock: str | None = None,
        note: str = "",
        notes: dict[str, str] | None = None,
        warmup: bool = True,
    ) -> dict[str, Stat]:
        """Time ``api`` (ours as a user calls it), ``kernel`` (ours without the graph) and
        each reference in ``rounds`` interleaved rounds whose order turns by one each round.

        Each implementation is called once to warm up (imports, caches a user would also have
        warm, JIT compilation); the number of calls per timing is fixed from a second call
        (the first of a graph can take 400 ms of imports: sized on it, a 1 ms call was
        timed once a round, just after ``gc.collect()``, and read 60% slow) so a
        timing lasts about ``min_seconds``. ``warmup=False`` skips both calls (a reference
        of a minute: one call a round, its imports in its first). A reference that fails to
        import is noted as not installed, never silently dropped. Returns the
        per-implementation :class:`Stat`.
        """
        now = _CLOCKS[clock] if clock else _now
        if SMOKE:
            rounds, min_seconds, warmup = 1, 0.0, False
        impls: list[tuple[str, str, Callable[[], object]]] = [("formgraph", "api", api)]
        if kernel is not None:
            impls.append(("formgraph kernel", "kernel", kernel))
        missing: dict[str, str] = {}
        for name, fn in (references or {}).items():
            impls.append((name, "reference", fn))
        numbers: dict[str, int] = {}
        for name, _, fn in list(impls):
            if not warmup:
                numbers[name] = 1
                continue
            try:
                fn()  # the first call pays for imports: the timing is sized on a second
                t0 = now()
                fn()
                first = now() - t0
            except ImportError as exc:
                missing[name] = f"not installed ({exc.name})"
                impls = [i for i in impls if i[0] != name]
                continue
            numbers[name] = max(1, int(min_seconds / max(first, 1e-9)))
        times: dict[str, list[float]] = {name: [] for name, _, _ in impls}
        for r in range(rounds):
            k = r % len(impls)
            for name, _, fn in impls[k:] + impls[:k]:
                if name in missing:
                    continue
                gc.collect()
                n = numbers[name]
                t0 = now()
                try:
                    for _ in range(n):
                        fn()
                except ImportError as exc:  # (not warmed up: found missing here)
                    missing[name] = f"not installed ({exc.name})"
                    continue
                times[name].append((now() - t0) / n)
        impls = [i for i in impls if i[0] not in missing]
        times = {name: t for name, t in times.items() if name not in missing}
        stats = {name: Stat(v) for name, v in times.items()}
        ours = times["formgraph"]
        notes = notes or {}
        for name, role, _ in impls:
            ratio = None
            if role == "reference":
                ratio = Stat([a / b for a, b in zip(ours, times[name], strict=True)])
            self.rows.append(
                Row(
                    case,
                    name,
                    stats[name].median,
                    notes.get(name, note if role == "api" else ""),
                    stat=stats[name],
                    ratio=ratio,
                    role=role,
                )
            )
        for name, why in missing.items():
            self.rows.append(Row(case, name, None, why, role="reference"))
        return stats

    def memory(
        self,
        case: str,
        *,
        api: Callable[[], object],
        references: dict[str, Callable[[], object]] | None = None,
        note: str = "",
    ) -> dict[str, int]:
        """Peak memory allocated while each call runs (tracemalloc, which numpy reports to),
        ours through the API against each reference; the result is dropped before the next."""
        peaks: dict[str, int] = {}
        impls = [("formgraph", "api", api)] + [
            (n, "reference", f) for n, f in (references or {}).items()
        ]
        for name, _role, fn in impls:
            gc.collect()
            tracemalloc.start()
            try:
                result = fn()
                del result
            except ImportError as exc:
                tracemalloc.stop()
                self.rows.append(Row(case, name, None, f"not installed ({exc.name})", unit="bytes"))
                continue
            _, peak = tracemalloc.get_traced_memory()
            tracemalloc.stop()
            peaks[name] = peak
        for name, role, _ in impls:
            if name in peaks:
                ratio = None
                if role == "reference" and peaks[name]:
                    ratio = Stat([peaks["formgraph"] / peaks[name]])
                self.rows.append(
                    Row(
                        case,
                        name,
                        float(peaks[name]),
                        note if role == "api" else "",
                        ratio=ratio,
                        unit="bytes",
                        role=role,
                    )
                )
        return peaks

    # -- rows measured elsewhere (the studio's page clock) ----------------------------------
    def add(
        self,
        case: str,
        impl: str,
        values: list[float] | None,
        note: str = "",
    ) -> None:
        """A row measured by the module itself (e.g. in a browser): its values' median and
        range; None when it could not be measured (the note says why)."""
        stat = Stat(list(values)) if values else None
        self.rows.append(Row(case, impl, stat.median if stat else None, note, stat=stat))

    # -- output ------------------------------------------------------------------------------
    def _cases(self) -> dict[str, list[Row]]:
        cases: dict[str, list[Row]] = {}
        for row in self.rows:
            cases.setdefault(row.case, []).append(row)
        return cases

    def render(self) -> str:
        head = "time" if CLOCK == "wall" else "cpu time"
        lines = [
            f"{'case':<52} {'impl':<24} {head + ' (median [range])':>30} {'ours/theirs':>22}  note",
            "-" * 140,
        ]
        for case, rows in self._cases().items():
            for r in rows:
                lines.append(f"{case:<52} {r.impl:<24} {_value(r):>30} {_ratio(r):>22}  {r.note}")
        return "\n".join(lines)

    def markdown(self) -> str:
        """The table as the documentation shows it: one row per case and implementation."""
        head = "time" if CLOCK == "wall" else "CPU time"
        lines = [
            f"| case | implementation | {head}, median [range] | ours / theirs, median [range] "
            "| note |",
            "|---|---|---|---|---|",
        ]
        for case, rows in self._cases().items():
            for i, r in enumerate(rows):
                label = case if i == 0 else ""
                lines.append(f"| {label} | {r.impl} | {_value(r)} | {_ratio(r)} | {r.note} |")
        return "\n".join(lines)


def _value(r: Row) -> str:
    if r.seconds is None:
        return "-"
    fmt = _mib if r.unit == "bytes" else _fmt
    if r.stat is None or len(r.stat.values) < 2:
        return fmt(r.seconds)
    return f"{fmt(r.stat.median)} [{fmt(r.stat.low)}-{fmt(r.stat.high)}]"


def _ratio(r: Row) -> str:
    """Ours divided by theirs: below 1 we are faster (or smaller)."""
    if r.ratio is not None:
        s = r.ratio
        if len(s.values) < 2:
            return f"{s.median:.2f}"
        return f"{s.median:.2f} [{s.low:.2f}-{s.high:.2f}]"
    return ""


def _fmt(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.1f} us"
    if seconds < 1.0:
        return f"{seconds * 1e3:.2f} ms"
    return f"{seconds:.2f} s"


def _mib(n: float) -> str:
    return f"{n / 2**20:.1f} MiB"
