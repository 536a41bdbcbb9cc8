"""What the commands share: usage errors, the options every graph command takes, and the
parsing of ``--set NAME=VALUE`` by each param's type."""

from __future__ import annotations

import argparse
import struct
import zlib
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
        "--inputs",
        default=None,
        metavar="DIR",
        help="the folder read nodes read from (default: the graph file's folder)",
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
            from ..language.params import suggest

            raise GraphError(
                f"--set {name}: unknown param{suggest(name, defs)}; params are "
                f"{', '.join(defs) or 'none'}"
            )
        from ..language.params import param_kind
        from ..language.yamlread import load_value

        kind = param_kind(defs[name])
        declared = defs[name].type
        if declared is not None and declared.is_geometry:
            out[name] = file_value(name, declared, text)
            continue
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


def file_value(name: str, declared: Any, text: str) -> Any:
    """The geometry a ``--set NAME=FILE`` names, read as the ``read.*`` node would read it.

    The path is the user's own (relative to the working directory, not confined: a graph
    from elsewhere cannot choose it), opened as a regular file under the input size cap.

    Raises
    ------
    GraphError
        A file that cannot be read, or whose content does not fit the param's type.
    """
    from pathlib import Path

    from ..core import safety
    from ..core.errors import PathError
    from ..geometry import Mesh, NurbsCurve, Points
    from ..kernels.io import readers

    kind = declared.kinds[0]
    base, many = kind.base, kind.is_list
    try:
        data = safety.read_input(Path(text).expanduser())
    except PathError as exc:
        raise GraphError(f"--set {name}: {exc}") from None
    try:
        if base is Mesh and not many:
            return Mesh(*readers.mesh_arrays(text, data))
        if base is Points and not many:
            ext = readers.extension(text, readers.POINT_FORMATS)
            return Points(readers.POINT_FORMATS[ext](data))
        if base.__name__ in ("Curve", "NurbsCurve"):
            ext = readers.extension(text, readers.CURVE_FORMATS)
            found, _ = readers.CURVE_FORMATS[ext](data, DEFAULT_BUDGET)
            curves = [NurbsCurve(*c.curve) for c in found]
            if many:
                return curves
            if len(curves) != 1:
                raise ValueError(
                    f"it holds {len(curves)} curves; a Curve param takes one (declare the "
                    f"param list[Curve] for all of them)"
                )
            return curves[0]
    except (ValueError, IndexError, KeyError, TypeError, OverflowError, RecursionError,
            struct.error, zlib.error) as exc:  # fmt: skip
        raise GraphError(f"--set {name}: cannot read {text!r}: {exc}") from None
    raise GraphError(
        f"--set {name}: a {declared.name} param is not read from a file (Mesh, Points, Curve "
        f"and list[Curve] are)"
    )


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
