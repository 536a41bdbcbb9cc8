"""Run the benchmarks: ``python bench/run.py`` (all) or ``python bench/run.py nurbs mesh``.

The "ours/theirs" column is our time (through the public API) divided by the reference's,
per interleaved round: its median and range; below 1 we are faster. ``--markdown`` prints the
table the documentation shows (``python bench/run.py --markdown > docs/speed-table.md``),
headed by how it was made (commit, clock, machine, load, each module's duration).

A module that fails does not stop the others: its failure is a row of the table and the exit
status is 1, so a long run always ends with every row that could be measured.

``--jobs N`` runs modules in N processes at once (``BENCH_CLOCK=cpu`` only: each process
times its own CPU seconds, and a row's ratios come from rounds interleaved within one
process). The modules that time parallel work or wall clock (:data:`ALONE`) still run one
at a time, after the others, with nothing beside them.
"""

from __future__ import annotations

import importlib
import os
import sys
import time
import traceback

# One BLAS thread: comparisons stay stable on a shared 2-core machine (set it to override).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
import platform  # noqa: E402  (after the thread settings)
import subprocess  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from harness import CLOCK, Row, Table  # noqa: E402

# Modules whose rows are wall-clock times of parallel work (workers, a browser, a server)
# or of whole commands: never run beside another module.
ALONE = {"fabrication", "optimize", "studio", "sweep"}


def _commit() -> str:
    """The commit the run measured, marked when the tree had changes."""
    try:
        rev = subprocess.run(
            ["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(HERE.parent), "status", "--porcelain", "--", "src", "bench"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return f"{rev} (with uncommitted changes)" if dirty else rev


def _load() -> str:
    try:
        return Path("/proc/loadavg").read_text().split()[0]
    except OSError:
        return "unknown"


def _cpu() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _run_module(name: str) -> tuple[list[Row], str | None, float]:
    """Run ``bench_<name>`` into a table of its own: (its rows, its failure, seconds)."""
    table = Table()
    t0 = time.perf_counter()
    print(f"running bench_{name} ...", file=sys.stderr, flush=True)
    error = None
    try:
        importlib.import_module(f"bench_{name}").run(table)
    except Exception as exc:  # noqa: BLE001  (report it as a row; the other modules go on)
        traceback.print_exc()
        error = f"{type(exc).__name__}: {exc}"
        table.add(f"bench_{name}", "failed", None, error)
    seconds = time.perf_counter() - t0
    print(f"  bench_{name}: {seconds:.0f} s", file=sys.stderr, flush=True)
    return table.rows, error, seconds


def _option(argv: list[str], flag: str) -> tuple[list[str], str | None]:
    if flag not in argv:
        return argv, None
    i = argv.index(flag)
    if i + 1 >= len(argv):
        raise SystemExit(f"{flag} needs a value")
    return argv[:i] + argv[i + 2 :], argv[i + 1]


def main(argv: list[str]) -> int:
    markdown = "--markdown" in argv
    argv = [a for a in argv if a != "--markdown"]
    argv, jobs_text = _option(argv, "--jobs")
    jobs = int(jobs_text) if jobs_text else 1
    if jobs > 1 and CLOCK != "cpu":
        raise SystemExit("--jobs times modules side by side: give BENCH_CLOCK=cpu with it")
    names = argv or sorted(p.stem[len("bench_") :] for p in HERE.glob("bench_*.py"))
    load_before, started = _load(), time.time()
    results: dict[str, tuple[list[Row], str | None, float]] = {}
    side_by_side = [n for n in names if n not in ALONE] if jobs > 1 else []
    if side_by_side:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        spawn = multiprocessing.get_context("spawn")  # each module in a fresh interpreter
        with ProcessPoolExecutor(jobs, mp_context=spawn, max_tasks_per_child=1) as pool:
            futures = {name: pool.submit(_run_module, name) for name in side_by_side}
            for name, fut in futures.items():
                try:
                    results[name] = fut.result()
                except Exception as exc:  # noqa: BLE001  (its process died: a crash, a kill)
                    row = Row(f"bench_{name}", "failed", None, f"{type(exc).__name__}: {exc}")
                    results[name] = ([row], f"{type(exc).__name__}: {exc}", 0.0)
    for name in names:
        if name not in results:
            results[name] = _run_module(name)
    table = Table()
    for name in names:  # in the order asked, however they ran
        table.rows.extend(results[name][0])
    failed = [n for n in names if results[n][1] is not None]
    durations = ", ".join(f"{n} {results[n][2]:.0f} s" for n in names)
    if markdown:
        total = (time.time() - started) / 60
        how = f" --jobs {jobs}" if jobs > 1 else ""
        print(
            f"Made by `{'BENCH_CLOCK=cpu ' if CLOCK == 'cpu' else ''}python bench/run.py "
            f"--markdown{how}` at commit {_commit()} on "
            f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime(started))}: "
            f"{os.cpu_count()} cores ({_cpu()}), Python {platform.python_version()}, "
            f"{'CPU' if CLOCK == 'cpu' else 'wall'} time unless a row says otherwise; load "
            f"average {load_before} at the start and {_load()} at the end; {total:.0f} min in "
            f"all ({durations})."
            + (f" Failed: {', '.join(failed)} (their rows say why)." if failed else "")
            + "\n"
        )
        print(table.markdown())
    else:
        print(table.render())
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
