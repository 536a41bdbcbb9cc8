"""What the commands share: usage errors, the options every graph command takes, and the
parsing of ``--set NAME=VALUE`` by each param's type."""

from __future__ import annotations

import argparse
from typing import Any

from ..core.errors import UsageError
from ..core.registry import DEFAULT_BUDGET
from ..language.params import parse_sets

__all__ = ["UsageError", "graph_options", "parse_sets", "size_text"]


def _budget(text: str) -> int:
    try:
        value = int(text.replace("_", ""))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def graph_options(p: argparse.ArgumentParser, budget_flag: str = "--budget") -> None:
    p.add_argument(
        "--set",
        action="extend",
        nargs="+",
        default=[],
        metavar="NAME=VALUE",
        help="override graph params (parsed by each param's type); several may follow one --set",
    )
    p.add_argument(
        "--inputs",
        default=None,
        metavar="DIR",
        help="the folder read nodes read from (default: the graph file's folder)",
    )
    p.add_argument(
        budget_flag,
        dest="budget",
        type=_budget,
        default=DEFAULT_BUDGET,
        help=f"element budget per node (default {DEFAULT_BUDGET:,})",
    )
    p.add_argument(
        "--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS
    )


def camera_options(p: argparse.ArgumentParser) -> None:
    """``--camera``, ``--azimuth`` and ``--elevation``: where a picture looks from."""
    p.add_argument(
        "--camera",
        choices=("iso", "top", "front", "side", "bottom"),
        help="look from a named view (default: straight on for flat geometry, else iso)",
    )
    p.add_argument(
        "--azimuth",
        type=float,
        metavar="DEG",
        help="turn about +z: 0 looks from the front (-y), 90 from the right side (+x)",
    )
    p.add_argument(
        "--elevation", type=float, metavar="DEG", help="look from above (90) or below (-90)"
    )


def camera_arg(args: argparse.Namespace) -> Any:
    """The ``formgraph.viewer.Camera`` of ``--camera/--azimuth/--elevation`` (or None)."""
    from formgraph.viewer.frame import Camera

    if args.camera is None and args.azimuth is None and args.elevation is None:
        return None
    try:
        return Camera(args.camera, args.azimuth, args.elevation)
    except ValueError as exc:
        raise UsageError(f"--{exc}") from None  # "--elevation must be from -90 to 90 ..."


def size_text(n: int) -> str:
    for unit in ("B", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return str(n)
