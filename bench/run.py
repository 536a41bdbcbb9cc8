"""Run the benchmarks: ``python bench/run.py`` (all) or ``python bench/run.py nurbs mesh``.

The "ours/theirs" column is our time (through the public API) divided by the reference's,
per interleaved round: its median and range; below 1 we are faster. ``--markdown`` prints the
table the documentation shows (``python bench/run.py --markdown > docs/speed-table.md``).
"""

from __future__ import annotations

import importlib
import os
import sys

# One BLAS thread: comparisons stay stable on a shared 2-core machine (set it to override).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
from pathlib import Path  # noqa: E402  (after the thread settings)

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from harness import Table  # noqa: E402


def main(argv: list[str]) -> int:
    markdown = "--markdown" in argv
    argv = [a for a in argv if a != "--markdown"]
    names = argv or sorted(p.stem[len("bench_") :] for p in HERE.glob("bench_*.py"))
    table = Table()
    for name in names:
        module = importlib.import_module(f"bench_{name}")
        print(f"running bench_{name} ...", file=sys.stderr, flush=True)
        module.run(table)
    print(table.markdown() if markdown else table.render())
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
