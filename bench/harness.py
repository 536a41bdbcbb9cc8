"""Timing harness shared by every benchmark module in bench/.

Each ``bench/bench_*.py`` defines ``run(table: Table) -> None`` and adds rows with
:meth:`Table.time`. ``python bench/run.py [name ...]`` runs them and prints one table
in which every reference library's time is shown next to ours, measured in the same run.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field

# ``BENCH_CLOCK=cpu`` times CPU seconds of this process instead of wall seconds: on a
# machine shared with other jobs, far steadier (every row here is single-threaded: one
# BLAS thread; a threaded reference would have its threads' time added up).
CLOCK = os.environ.get("BENCH_CLOCK", "wall")
if CLOCK not in ("wall", "cpu"):
    raise SystemExit(f"BENCH_CLOCK must be wall or cpu, got {CLOCK!r}")
_now = time.process_time if CLOCK == "cpu" else time.perf_counter


def best_time(
    fn: Callable[[], object],
    *,
    repeat: int = 5,
    min_seconds: float = 0.2,
    number: int | None = None,
) -> float:
    """Best wall time of one call of ``fn`` in seconds.

    Calls ``fn`` once to warm up, then takes the best of ``repeat`` rounds, each of which
    loops enough calls to last ``min_seconds`` (at least one), so short calls are not
    dominated by timer resolution.
    """
    t0 = _now()
    fn()
    first = _now() - t0
    if number is None:
        number = max(1, int(min_seconds / max(first, 1e-9)))
    if first > 2.0:  # slow reference: one more call is enough
        repeat, number = 1, 1
    best = float("inf")
    for _ in range(repeat):
        t0 = _now()
        for _ in range(number):
            fn()
        best = min(best, (_now() - t0) / number)
    return best


@dataclass
class Row:
    case: str
    impl: str
    seconds: float | None
    note: str = ""


@dataclass
class Table:
    rows: list[Row] = field(default_factory=list)

    def time(
        self,
        case: str,
        impl: str,
        fn: Callable[[], object],
        *,
        repeat: int = 5,
        note: str = "",
        number: int | None = None,
    ) -> float | None:
        """Time ``fn`` and record it; a reference that fails to import or run is noted."""
        try:
            seconds = best_time(fn, repeat=repeat, number=number)
        except ImportError as exc:
            self.rows.append(Row(case, impl, None, f"not installed ({exc.name})"))
            return None
        self.rows.append(Row(case, impl, seconds, note))
        return seconds

    def time_together(
        self,
        case: str,
        impls: list[tuple[str, Callable[[], object], str]],
        *,
        rounds: int = 7,
    ) -> None:
        """Time several implementations of one case in alternating rounds, best of each.

        ``impls`` holds ``(impl, fn, note)``. Every round times each ``fn`` once after the
        other (:func:`best_time` with one repeat), so a burst of load on a shared machine
        falls on all of them rather than on whichever ran during it.
        """
        best = {impl: float("inf") for impl, _, _ in impls}
        for _ in range(rounds):
            for impl, fn, _ in impls:
                best[impl] = min(best[impl], best_time(fn, repeat=1))
        for impl, _, note in impls:
            self.rows.append(Row(case, impl, best[impl], note))

    def add(self, case: str, impl: str, seconds: float | None, note: str = "") -> None:
        self.rows.append(Row(case, impl, seconds, note))

    def render(self) -> str:
        head = "time" if CLOCK == "wall" else "cpu time"
        lines = [f"{'case':<52} {'impl':<22} {head:>11} {'vs ours':>9}  note", "-" * 110]
        cases: dict[str, list[Row]] = {}
        for row in self.rows:
            cases.setdefault(row.case, []).append(row)
        for case, rows in cases.items():
            ours = next((r.seconds for r in rows if r.impl == "formgraph"), None)
            for r in rows:
                t = "-" if r.seconds is None else _fmt(r.seconds)
                ratio = (
                    f"{r.seconds / ours:8.2f}x"
                    if ours and r.seconds is not None and r.impl != "formgraph"
                    else ""
                )
                lines.append(f"{case:<52} {r.impl:<22} {t:>11} {ratio:>9}  {r.note}")
        return "\n".join(lines)


def _fmt(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.1f} us"
    if seconds < 1.0:
        return f"{seconds * 1e3:.2f} ms"
    return f"{seconds:.2f} s"
