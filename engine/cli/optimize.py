"""The ``formgraph optimize`` command (wired into :mod:`formgraph.cli.main`)."""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

from ..core.terminal import StatusLine
from .options import UsageError, graph_options, parse_sets
from .sweep import cache_choice, cache_options, vary_and_workers

__all__ = ["add_parser", "cmd_optimize", "progress_text"]


def add_parser(sub: Any) -> None:
    """Add the ``optimize`` subcommand to the CLI's subparsers."""
    op = sub.add_parser(
        "optimize",
        help="search a design space for the best designs (optuna on Dask)",
        description="Search the --vary space for designs that minimise or maximise scalar "
        "outputs under constraints. Writes DIR/trials.csv, DIR/pareto.csv, DIR/progress.png "
        "and DIR/study.journal; running the same command again continues the study to its "
        "budget.",
    )
    op.add_argument("graph")
    op.add_argument(
        "--vary",
        action="extend",
        nargs="+",
        default=[],
        required=True,
        metavar="NAME=SPEC",
        help="0.5:2 (an interval), 1:12 (an int param's whole numbers), 1,2,5 (a choice)",
    )
    op.add_argument("--minimize", action="extend", nargs="+", default=[], metavar="NODE.OUTPUT")
    op.add_argument("--maximize", action="extend", nargs="+", default=[], metavar="NODE.OUTPUT")
    op.add_argument(
        "--constraint",
        action="append",
        default=[],
        metavar='"EXPR <= NUMBER"',
        help='over params and NODE.OUTPUT values, e.g. "size.volume >= 1000"',
    )
    op.add_argument("--budget", dest="trials", type=int, required=True, metavar="N")
    op.add_argument("--method", choices=("tpe", "nsga2", "cmaes", "random"), default="tpe")
    op.add_argument("--seed", type=int, default=0, metavar="S")
    op.add_argument("--batch", type=int, default=8, metavar="K", help="trials run together (8)")
    op.add_argument("--out", default="out", metavar="DIR", help="output directory (./out)")
    op.add_argument(
        "--scheduler", metavar="ADDRESS", help="an existing Dask scheduler (tcp://host:8786)"
    )
    op.add_argument("--workers", type=int, metavar="N", help="embedded workers (one per core)")
    op.add_argument("--export", action="store_true", help="write the front's designs' exports")
    op.add_argument("--render", metavar="NODE", help="draw the front's designs into front.png")
    cache_options(op)
    graph_options(op, budget_flag="--element-budget")


def progress_text(done: int, total: int, best: str, rate: float) -> str:
    """'optimize 40/100 trials, best size.area = 571.2, 3.1/s, ETA 0:19'."""
    text = f"optimize {done}/{total} trials, {best}"
    if rate > 0:
        left = (total - done) / rate
        text += f", {rate:.1f}/s, ETA {int(left // 60)}:{int(left % 60):02d}"
    return text


class _Progress(StatusLine):
    def __call__(self, done: int, total: int, best: str, rate: float) -> None:
        self.show(progress_text(done, total, best, rate), force=done >= total)


def cmd_optimize(args: argparse.Namespace) -> int:
    """``formgraph optimize``."""
    from ..evaluation.cache import default_cache_dir
    from ..evaluation.graph import load
    from ..sweeps.api import EACH_WORKER

    vary = vary_and_workers(args)
    try:
        from ..sweeps.optimize import optimize, require_optuna

        require_optuna()
    except ImportError as exc:
        raise UsageError(str(exc)) from None
    cache_dir, shared = cache_choice(args)
    g = load(
        args.graph,
        out_dir=args.out,
        cache_dir=default_cache_dir() if cache_dir is EACH_WORKER else cache_dir,
        budget=args.budget,
        inputs_dir=getattr(args, "inputs", None),
    )
    g.set(**parse_sets(g, args.set))
    progress = _Progress(sys.stderr, interval=0.1)
    t0 = time.perf_counter()
    try:
        study = optimize(
            g,
            vary,
            args.minimize,
            args.maximize,
            args.constraint,
            budget=args.trials,
            method=args.method,
            seed=args.seed,
            batch=args.batch,
            out=args.out,
            client=args.scheduler,
            workers=args.workers,
            cache_dir=cache_dir,
            shared_cache=shared,
            export=args.export,
            render=args.render,
            progress=progress,
        )
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    finally:
        progress.clear()
    study.seconds = time.perf_counter() - t0
    print(study.summary())
    return 0
