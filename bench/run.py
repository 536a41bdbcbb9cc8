"""Run the benchmarks: ``python bench/run.py`` (all) or ``python bench/run.py nurbs mesh``.

The "ours/theirs" column is our time (through the public API) divided by the reference's,
per interleaved round: its median and range; below 1 we are faster. ``--markdown`` prints the
table the documentation shows (``python bench/run.py --markdown > docs/speed-table.md``),
headed by how it was made (commit, clock, machine, load, each module's duration).

A module that fails does not stop the others: its failure is a row of the table and the exit
status is 1, so a long run always ends with every row that could be measured.
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

from harness import CLOCK, Table  # noqa: E402


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


def main(argv: list[str]) -> int:
    markdown = "--markdown" in argv
    argv = [a for a in argv if a != "--markdown"]
    names = argv or sorted(p.stem[len("bench_") :] for p in HERE.glob("bench_*.py"))
    table = Table()
    load_before, started = _load(), time.time()
    durations: list[str] = []
    failed: list[str] = []
    for name in names:
        print(f"running bench_{name} ...", file=sys.stderr, flush=True)
        t0 = time.perf_counter()
        try:
            importlib.import_module(f"bench_{name}").run(table)
        except Exception as exc:  # noqa: BLE001  (report it as a row; the other modules go on)
            traceback.print_exc()
            failed.append(name)
            table.add(f"bench_{name}", "failed", None, f"{type(exc).__name__}: {exc}")
        seconds = time.perf_counter() - t0
        durations.append(f"{name} {seconds:.0f} s")
        print(f"  bench_{name}: {seconds:.0f} s", file=sys.stderr, flush=True)
    if markdown:
        total = (time.time() - started) / 60
        print(
            f"Made by `{'BENCH_CLOCK=cpu ' if CLOCK == 'cpu' else ''}python bench/run.py "
            f"--markdown` at commit {_commit()} on "
            f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime(started))}: "
            f"{os.cpu_count()} cores ({_cpu()}), Python {platform.python_version()}, "
            f"{'CPU' if CLOCK == 'cpu' else 'wall'} time unless a row says otherwise; load "
            f"average {load_before} at the start and {_load()} at the end; {total:.0f} min in "
            f"all ({', '.join(durations)})."
            + (f" Failed: {', '.join(failed)} (their rows say why)." if failed else "")
            + "\n"
        )
        print(table.markdown())
    else:
        print(table.render())
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
