"""The ``formgraph sweep`` and ``formgraph cache`` commands (wired into
:mod:`formgraph.cli.main`)."""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Any

from .options import UsageError, camera_arg, camera_options, graph_options, parse_sets, size_text

__all__ = ["add_parsers", "cmd_cache", "cmd_sweep"]


def add_parsers(sub: Any) -> None:
    """Add the ``sweep`` and ``cache`` subcommands to the CLI's subparsers."""
    sw = sub.add_parser(
        "sweep",
        help="run many variants on Dask: a table, exports, a contact sheet",
        description="Vary params over a grid, random or Latin hypercube samples; write "
        "DIR/sweep.csv as variants finish (a rerun resumes), exports under DIR/variants/NNNN/ "
        "with --export, and DIR/sheet.png with --render.",
    )
    sw.add_argument("graph")
    sw.add_argument(
        "--vary",
        action="extend",
        nargs="+",
        default=[],
        required=True,
        metavar="NAME=SPEC",
        help="SPEC: 1:12 (each whole number), 0.5:2:7 (7 values from 0.5 to 2), 1,2,5 (a "
        "list), 0.5:2 (an interval, for random and lhs)",
    )
    sw.add_argument("--method", choices=("grid", "random", "lhs"), default="grid")
    sw.add_argument("--samples", type=int, metavar="N", help="variants for random and lhs")
    sw.add_argument("--seed", type=int, default=0, metavar="S", help="sampling seed (0)")
    sw.add_argument(
        "--measure",
        action="extend",
        nargs="+",
        default=[],
        metavar="NODE[.OUTPUT]",
        help="scalar outputs to tabulate",
    )
    sw.add_argument("--export", action="store_true", help="write each variant's exports")
    sw.add_argument("--render", metavar="NODE", help="draw NODE per variant into sheet.png")
    sw.add_argument("--per-sheet", type=int, default=100, metavar="N", help=argparse.SUPPRESS)
    camera_options(sw)
    sw.add_argument(
        "--scheduler", metavar="ADDRESS", help="an existing Dask scheduler (tcp://host:8786)"
    )
    sw.add_argument("--workers", type=int, metavar="N", help="embedded workers (one per core)")
    sw.add_argument("--out", default="out", metavar="DIR", help="output directory (./out)")
    cache_options(sw)
    graph_options(sw)

    cache = sub.add_parser(
        "cache",
        help="the disk cache: info, clear, prune [--max-size SIZE]",
        description="The disk cache is bounded (2 GiB unless $FORMGRAPH_CACHE_MAX_SIZE says "
        "otherwise); the least recently used entries go first.",
    )
    cache.add_argument("action", choices=("info", "clear", "prune"))
    cache.add_argument("--max-size", metavar="SIZE", help="e.g. 500M, 2GiB, 10GB")
    cache.add_argument("--cache-dir", default=None, help=argparse.SUPPRESS)
    cache.add_argument(
        "--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS
    )


def cache_options(p: argparse.ArgumentParser) -> None:
    """``--cache DIR`` (a folder every worker may share) and ``--no-cache``."""
    p.add_argument("--no-cache", action="store_true", help="do not use the on-disk cache")
    p.add_argument(
        "--cache",
        "--cache-dir",
        dest="cache_dir",
        default=None,
        metavar="DIR",
        help="the disk cache folder (default ~/.cache/formgraph); with --scheduler, a folder "
        "on a filesystem every worker mounts at the same path, shared by all of them",
    )


def cache_choice(args: argparse.Namespace) -> tuple[Any, bool]:
    """The cache folder the workers use, and whether the client sees it too."""
    from ..evaluation.cache import default_cache_dir
    from ..sweeps.api import EACH_WORKER

    if args.no_cache:
        return None, False
    if args.cache_dir:
        return args.cache_dir, True  # named: the same folder for the client and each worker
    if args.scheduler:
        return EACH_WORKER, False  # the client's folder means nothing on other machines
    return default_cache_dir(), False


def _camera(args: argparse.Namespace) -> tuple[Any, Any, Any] | None:
    """The sheet's camera as the plain (view, azimuth, elevation) the workers are sent."""
    camera = camera_arg(args)
    return None if camera is None else (camera.view, camera.azimuth, camera.elevation)


def vary_and_workers(args: argparse.Namespace) -> dict[str, str]:
    """``--vary`` as {name: spec}, after checking it and ``--workers`` (UsageError)."""
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers takes a positive count, got {args.workers}")
    if args.workers is not None and args.scheduler:
        raise UsageError("--workers is for the embedded cluster; --scheduler has its own")
    vary: dict[str, str] = {}
    for item in args.vary:
        name, sep, spec = item.partition("=")
        if not sep or not name.strip() or not spec.strip():
            raise UsageError(f"--vary takes NAME=SPEC, e.g. turns=1:12, got {item!r}")
        if name.strip() in vary:
            raise UsageError(f"--vary {name.strip()} is given twice")
        vary[name.strip()] = spec.strip()
    return vary


def cmd_sweep(args: argparse.Namespace) -> int:
    """``formgraph sweep``."""
    from ..evaluation.cache import default_cache_dir
    from ..evaluation.graph import load
    from ..sweeps.api import EACH_WORKER, TerminalProgress, sweep

    vary = vary_and_workers(args)
    cache_dir, shared = cache_choice(args)
    g = load(
        args.graph,
        out_dir=args.out,
        cache_dir=default_cache_dir() if cache_dir is EACH_WORKER else cache_dir,
        budget=args.budget,
        inputs_dir=getattr(args, "inputs", None),
    )
    g.set(**parse_sets(g, args.set))
    progress = TerminalProgress(sys.stderr)
    t0 = time.perf_counter()
    try:
        result = sweep(
            g,
            vary,
            args.measure,
            method=args.method,
            samples=args.samples,
            seed=args.seed,
            export=args.export,
            render=args.render,
            out=args.out,
            client=args.scheduler,
            workers=args.workers,
            cache_dir=cache_dir,
            shared_cache=shared,
            per_sheet=args.per_sheet,
            camera=_camera(args),
            progress=progress,
        )
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    finally:
        progress.clear()
    result.seconds = time.perf_counter() - t0
    print(result.summary())
    for row in result.rows:
        if row["status"] == "failed":
            print(f"variant {row['variant']}: {row['error']}", file=sys.stderr)
    return 0


def cmd_cache(args: argparse.Namespace) -> int:
    """``formgraph cache info|clear|prune``."""
    from ..evaluation.cache import DiskCache, default_cache_dir, parse_size

    limit = None
    for text, where in (
        (os.environ.get("FORMGRAPH_CACHE_MAX_SIZE"), "FORMGRAPH_CACHE_MAX_SIZE"),
        (args.max_size, "--max-size"),
    ):
        if text:
            try:
                limit = parse_size(text)
            except ValueError as exc:
                raise UsageError(f"{where}: {exc}") from None
    cache = DiskCache(args.cache_dir or default_cache_dir(), max_bytes=limit)
    if args.action == "clear":
        n, freed = cache.clear()
        print(f"{cache.root}: removed {n:,} entries ({size_text(freed)})")
        return 0
    if args.action == "prune":
        n, freed = cache.prune()
        info = cache.info()
        print(
            f"{cache.root}: removed {n:,} entries ({size_text(freed)}); {info.entries:,} left "
            f"({size_text(info.bytes)} of {size_text(info.max_bytes)})"
        )
        return 0
    info = cache.info()
    print(f"cache: {info.root}")
    print(f"entries: {info.entries:,}")
    print(
        f"size: {size_text(info.bytes)} of {size_text(info.max_bytes)} "
        "(least recently used go first)"
    )
    if info.oldest is not None:
        fmt = "%Y-%m-%d %H:%M"
        print(
            f"last used: {time.strftime(fmt, time.localtime(info.oldest))} .. "
            f"{time.strftime(fmt, time.localtime(info.newest))}"
        )
    return 0
