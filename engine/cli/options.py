"""What the commands share: usage errors, the options every graph command takes, and the
parsing of ``--set NAME=VALUE`` by each param's type."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import Any

import yaml

from ..core.errors import GraphError
from ..core.registry import DEFAULT_BUDGET

__all__ = ["UsageError", "graph_options", "parse_sets", "size_text"]


class UsageError(Exception):
    """A command line that does not make sense (exit code 2)."""


def _budget(text: str) -> int:
    try:
        value = int(text.replace("_", ""))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def graph_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--set",
        action="extend",
        nargs="+",
        default=[],
        metavar="NAME=VALUE",
        help="override graph params (parsed by each param's type); several may follow one --set",
    )
    p.add_argument(
        "--budget",
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


def parse_sets(graph: Any, items: Sequence[str]) -> dict[str, Any]:
    """``NAME=VALUE`` pairs parsed by each param's type (YAML scalars, lists allowed)."""
    out: dict[str, Any] = {}
    defs = graph.param_defs
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise UsageError(f"--set takes NAME=VALUE, got {item!r} (node names go before --set)")
        if name not in defs:
            from ..language.check import suggest

            raise GraphError(
                f"--set {name}: unknown param{suggest(name, defs)}; params are "
                f"{', '.join(defs) or 'none'}"
            )
        from ..language.check import param_kind
        from ..language.yamlread import load_value

        kind = param_kind(defs[name])
        if kind is str:
            value: Any = text
        elif kind in (int, float):
            value = _number(text)
            if kind is float and isinstance(value, int):
                value = float(value)
        else:
            try:
                value = load_value(text)  # YAML 1.2 numbers, as in the graph file
            except (yaml.YAMLError, ValueError, TypeError, RecursionError) as exc:
                shown = text if len(text) <= 40 else text[:37] + "..."
                why = getattr(exc, "problem", None) or exc
                raise UsageError(f"--set {name}: cannot read {shown!r}: {why}") from None
        out[name] = value
    return out


def _number(text: str) -> Any:
    """A number as people type it: 3, -2.5, 1e3, 0x10 (YAML 1.1 would read 1e3 as text)."""
    for parse in (int, float):
        try:
            return parse(text.strip().replace("_", ""))
        except ValueError:
            pass
    try:
        return int(text.strip(), 0)
    except ValueError:
        return text  # the param's check then says what was expected


def size_text(n: int) -> str:
    for unit in ("B", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return str(n)
