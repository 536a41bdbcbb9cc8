"""The ``formgraph`` command line.

Exit codes: 0 ok, 1 a graph or node error (the message on stderr), 2 a usage error.
No Python traceback reaches the user unless ``--debug``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import traceback
import warnings
from collections.abc import Sequence
from typing import Any

from ..core.errors import FormgraphError, FormgraphWarning, GraphError
from ..core.terminal import StatusLine
from .options import (
    UsageError,
    camera_arg,
    camera_options,
    graph_options,
    parse_sets,
    size_text,
)


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="formgraph", description="Evaluate, check, view and document formgraph graphs."
    )
    ap.add_argument("--debug", action="store_true", help="show Python tracebacks")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = sub.add_parser("run", help="evaluate nodes (default: every sink) and write exports")
    run.add_argument("graph")
    run.add_argument("nodes", nargs="*", metavar="NODE")
    graph_options(run)
    run.add_argument("--out", default="out", metavar="DIR", help="output directory (./out)")
    run.add_argument("--no-cache", action="store_true", help="do not use the on-disk cache")
    run.add_argument("--cache-dir", default=None, help=argparse.SUPPRESS)
    run.add_argument("--profile", action="store_true", help="print a table of node timings")
    run.add_argument(
        "--strict", action="store_true", help="treat warnings as errors (exit 1 if any)"
    )

    chk = sub.add_parser("check", help="validate a graph; exit 1 with every problem")
    chk.add_argument("graph")
    chk.add_argument(
        "--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS
    )

    def view_options(p: argparse.ArgumentParser) -> None:
        p.add_argument("graph")
        p.add_argument(
            "nodes", nargs="*", metavar="NODE", help="nodes to show (default: the results)"
        )
        graph_options(p)
        p.add_argument(
            "--layout",
            choices=("overlay", "side"),
            default="overlay",
            help="several nodes in one view (overlay) or side by side, one view each",
        )
        p.add_argument(
            "--edges", action="store_true", help="draw every mesh face's edges (default: coarse)"
        )
        p.add_argument("--size", default="1024x768", metavar="WxH")
        p.add_argument(
            "--color",
            metavar="NAME",
            default=None,
            help="colour points and meshes by an attribute, with a colour bar",
        )
        camera_options(p)
        p.add_argument("--out", default="out", metavar="DIR", help=argparse.SUPPRESS)

    view = sub.add_parser("view", help="show nodes' outputs (window, or PNG with --screenshot)")
    view_options(view)
    view.add_argument("--screenshot", metavar="FILE.png", help="render off screen to a PNG")

    watch = sub.add_parser("watch", help="re-evaluate and redraw when the file changes")
    view_options(watch)
    watch.add_argument(
        "--screenshot",
        metavar="FILE.png",
        help="no window: write FILE.png on every good save and print a status line",
    )
    watch.add_argument("--interval", type=float, default=0.3, help=argparse.SUPPRESS)

    draw = sub.add_parser("graph", help="draw the graph itself (SVG or PNG)")
    draw.add_argument("graph")
    draw.add_argument("nodes", nargs="*", metavar="NODE", help="with --run: the nodes to evaluate")
    draw.add_argument(
        "-o", "--output", metavar="FILE", help="FILE.svg or FILE.png (default: GRAPH.svg here)"
    )
    graph_options(draw)
    draw.add_argument(
        "--run",
        action="store_true",
        help="evaluate first (the nodes given, else every sink, exports included) and colour "
        "each node computed or cached, with its seconds",
    )
    draw.add_argument("--out", default="out", metavar="DIR", help="output directory (./out)")
    draw.add_argument("--no-cache", action="store_true", help="do not use the on-disk cache")
    draw.add_argument("--cache-dir", default=None, help=argparse.SUPPRESS)

    nodes = sub.add_parser(
        "nodes",
        help="the node catalogue, one node type's ports, or the node types a graph file uses",
        description="Without TYPE: every node type. With a node type (mesh.box): its ports "
        "and outputs. With a graph file (GRAPH.yaml): the node types it uses, each with its "
        "nodes, and its ports and outputs as a node type where it has 'outputs:'.",
    )
    nodes.add_argument("type", nargs="?", metavar="TYPE|GRAPH.yaml")
    nodes.add_argument("--markdown", action="store_true", help="the catalogue as Markdown")
    nodes.add_argument(
        "--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS
    )

    params = sub.add_parser(
        "params",
        help="a graph's params: type, default, range or choices, slider step, doc",
        description="List the params of GRAPH in the file's order: type, default, range "
        "(min .. max, or the choices), the step the studio's slider moves by, and the doc.",
    )
    params.add_argument("graph")
    params.add_argument("--json", action="store_true", help="one JSON object per param, a list")
    params.add_argument(
        "--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS
    )

    schema = sub.add_parser("schema", help="JSON Schema of the YAML format")
    schema.add_argument(
        "--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS
    )

    from .optimize import add_parser as add_optimize
    from .serve import add_parser as add_serve
    from .sweep import add_parsers

    add_parsers(sub)
    add_optimize(sub)
    add_serve(sub)
    return ap


class _ProgressLine(StatusLine):
    """'cooking node (k/n)' on a terminal, for runs that take more than a moment."""

    def __init__(self, stream: Any):
        # quiet for the first half second, then at most 20 updates a second
        super().__init__(stream, quiet_for=0.5, interval=0.05)

    def __call__(self, node: str, done: int, total: int) -> None:
        self.show(f"cooking '{node}' ({done + 1}/{total} nodes)")


def _profile_table(stats: dict[str, Any], nodes: dict[str, str]) -> str:
    from ..evaluation.cache import sizeof  # noqa: F401  (sizes come with the stats)

    rows = [f"{'node':<24} {'type':<24} {'status':<9} {'seconds':>9} {'size':>10}  warnings"]
    total = 0.0
    for name, st in stats.items():
        total += st.seconds
        size = size_text(st.nbytes)
        items = getattr(st, "items", None)
        notes = list(st.warnings)
        if items is not None:  # a repeated node: one row, with how many of its items ran
            unit = getattr(st, "unit", "items")  # a simulated node's items are its steps
            notes.insert(0, f"{items} {unit}, {st.computed_items}/{items} computed")
        rows.append(
            f"{name:<24} {nodes.get(name, ''):<24} {st.status:<9} {st.seconds:>9.4f} "
            f"{size:>10}  {'; '.join(notes)}"
        )
    rows.append(f"{'total':<24} {'':<24} {'':<9} {total:>9.4f}")
    return "\n".join(rows)


def _describe(value: Any) -> str:
    if isinstance(value, str) and os.path.isabs(value):
        if os.path.isfile(value):
            return f"wrote {os.path.relpath(value)}"
        return f"{os.path.relpath(value)} is missing (it was not written)"
    return repr(value)


def _load_with_cache(args: argparse.Namespace) -> Any:
    """The graph a command names, with the disk cache unless ``--no-cache``."""
    from ..evaluation.cache import default_cache_dir
    from ..evaluation.graph import load

    cache_dir = None if args.no_cache else (args.cache_dir or default_cache_dir())
    return load(
        args.graph,
        out_dir=args.out,
        cache_dir=cache_dir,
        budget=args.budget,
        inputs_dir=args.inputs,
    )


def cmd_run(args: argparse.Namespace) -> int:

    g = _load_with_cache(args)
    params = parse_sets(g, args.set)
    progress = _ProgressLine(sys.stderr)
    g.progress = progress
    try:
        outs = g.evaluate(args.nodes, **params) if args.nodes else g.evaluate_all(**params)
    finally:
        progress.clear()
    label = "error" if args.strict else "warning"
    for name, value in outs.items():
        print(f"{name}: {_describe(value)}")
        for w in g.stats.get(name).warnings if name in g.stats else []:
            print(f"  {label}: {w}", file=sys.stderr)
    for name, st in g.stats.items():
        if name not in outs:
            for w in st.warnings:
                print(f"{name}: {label}: {w}", file=sys.stderr)
    if args.profile:
        print(_profile_table(g.stats, g.nodes))
    count = sum(len(st.warnings) for st in g.stats.values())
    if args.strict and count:
        print(
            f"formgraph: --strict: {count} warning{'s' if count != 1 else ''} (see above)",
            file=sys.stderr,
        )
        return 1
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    from ..evaluation.graph import load
    from ..language.params import param_warnings

    g = load(args.graph)
    for p in param_warnings(g.param_defs, g.file_label):
        print(f"{p.where.prefix()}: warning: {p.message}", file=sys.stderr)
    print(f"{args.graph}: ok ({len(g.nodes)} nodes, {len(g.params)} params)")
    return 0


def _size_arg(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise UsageError(f"--size takes WIDTHxHEIGHT, e.g. 1024x768, got {text!r}") from None
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise UsageError(f"--size {text}: each side must be 16 to 8192 pixels")
    return w, h


def _no_window(command: str, args: argparse.Namespace) -> None:
    """Refuse a window where none can open, saying what to do instead (exit 2)."""
    from formgraph.viewer import display_problem

    problem = display_problem()
    if problem is None:
        return
    raise UsageError(
        f"{command} opens a window, but {problem}. Add --screenshot FILE.png to render "
        f"off screen instead{' (a new PNG on every save)' if command == 'watch' else ''}, "
        f"or run it under a virtual display: xvfb-run formgraph {command} {args.graph} ..."
    )


def cmd_view(args: argparse.Namespace) -> int:
    from ..evaluation import graph as _graph

    try:
        from formgraph import viewer
    except ImportError as exc:  # pragma: no cover - pyvista is a dependency
        raise GraphError(f"the viewer needs pyvista: {exc}") from None
    size = _size_arg(args.size)
    if not args.screenshot:
        _no_window("view", args)
    g = _graph.load(args.graph, out_dir=args.out, budget=args.budget, inputs_dir=args.inputs)
    params = parse_sets(g, args.set)
    nodes = args.nodes or None
    edges = True if args.edges else None
    camera = camera_arg(args)
    if args.screenshot:
        path = viewer.screenshot(
            g,
            args.screenshot,
            node=nodes,
            size=size,
            layout=args.layout,
            edges=edges,
            camera=camera,
            color=args.color,
            **params,
        )
        print(f"wrote {path}")
        return 0
    viewer.show(
        g,
        node=nodes,
        size=size,
        layout=args.layout,
        edges=edges,
        camera=camera,
        color=args.color,
        **params,
    )
    return 0


def cmd_watch(args: argparse.Namespace) -> int:
    from formgraph import viewer

    size = _size_arg(args.size)
    nodes = args.nodes or None
    edges = True if args.edges else None
    for item in args.set:
        if "=" not in item:
            raise UsageError(f"--set takes NAME=VALUE, got {item!r}")
    options = dict(
        sets=args.set,
        out_dir=args.out,
        inputs_dir=args.inputs,
        budget=args.budget,
        size=size,
        layout=args.layout,
        edges=edges,
        camera=camera_arg(args),
        color=args.color,
    )
    if args.screenshot:
        viewer.ScreenshotWatcher(args.graph, args.screenshot, nodes, **options).run(
            interval=args.interval
        )
        return 0
    _no_window("watch", args)
    viewer.watch(args.graph, node=nodes, **options)
    return 0


def cmd_graph(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..drawgraph.layout import draw_graph, failed_nodes

    output = args.output or f"{Path(args.graph).stem}.svg"
    if output != "-" and Path(output).suffix.lower() not in (".svg", ".png"):
        raise UsageError(f"-o {output}: the drawing is written as .svg or .png")
    g = _load_with_cache(args)
    g.set(**parse_sets(g, args.set))  # the param boxes show the values used
    failure: FormgraphError | None = None
    if args.run:
        progress = _ProgressLine(sys.stderr)
        g.progress = progress
        try:
            g.evaluate(args.nodes) if args.nodes else g.evaluate_all()
        except FormgraphError as exc:  # still draw: how far the run got, the failure red
            failure = exc
        finally:
            progress.clear()
    elif args.nodes:
        raise UsageError("NODE names are what --run evaluates; add --run")
    failed = failed_nodes(failure) if failure is not None else []
    drawing = draw_graph(g, failed=failed)
    if output == "-":
        sys.stdout.write(drawing.svg)
    else:
        path = drawing.save(output)
        run = f", after a run of {len(g.stats)} nodes" if args.run else ""
        run += f", {', '.join(failed)} failed" if failed else ""
        print(f"wrote {path} ({len(g.nodes)} nodes, {len(g.params)} params{run})")
    if failure is not None:
        raise failure
    return 0


def cmd_nodes(args: argparse.Namespace) -> int:
    from ..core.registry import node_types
    from ..language.catalogue import catalogue_text, markdown, node_text
    from ..language.params import suggest

    if args.markdown:
        sys.stdout.write(markdown())
        return 0
    if args.type and args.type.endswith((".yaml", ".yml")):  # a graph file
        from ..evaluation.graph import load
        from .listing import nodes_text

        print(nodes_text(load(args.type)))
        return 0
    if args.type:
        registry = node_types()
        if args.type not in registry:
            raise GraphError(f"unknown node type '{args.type}'{suggest(args.type, registry)}")
        print(node_text(registry[args.type]))
        return 0
    print(catalogue_text())
    return 0


def cmd_params(args: argparse.Namespace) -> int:
    from ..evaluation.graph import load
    from .listing import params_rows, params_text

    g = load(args.graph)
    if args.json:
        json.dump(params_rows(g), sys.stdout, indent=2, default=str)
        sys.stdout.write("\n")
    else:
        print(params_text(g))
    return 0


def cmd_schema(args: argparse.Namespace) -> int:
    from ..language.catalogue import json_schema

    json.dump(json_schema(), sys.stdout, indent=2)
    sys.stdout.write("\n")
    return 0


COMMANDS = {
    "run": cmd_run,
    "check": cmd_check,
    "view": cmd_view,
    "watch": cmd_watch,
    "graph": cmd_graph,
    "nodes": cmd_nodes,
    "params": cmd_params,
    "schema": cmd_schema,
    "sweep": lambda args: _sweep_command("cmd_sweep", args),
    "cache": lambda args: _sweep_command("cmd_cache", args),
    "optimize": lambda args: _optimize_command(args),
    "serve": lambda args: _serve_command(args),
}


def _serve_command(args: argparse.Namespace) -> int:
    from .serve import cmd_serve

    return cmd_serve(args)


def _optimize_command(args: argparse.Namespace) -> int:
    from .optimize import cmd_optimize

    return cmd_optimize(args)


def _sweep_command(name: str, args: argparse.Namespace) -> int:
    from . import sweep as cli_sweep

    return getattr(cli_sweep, name)(args)


def main(argv: Sequence[str] | None = None) -> int:
    ap = _parser()
    args = ap.parse_args(argv)  # exits 2 on a usage error
    try:
        with warnings.catch_warnings():
            # the commands print node warnings themselves, once, next to the node's output
            warnings.simplefilter("ignore", FormgraphWarning)
            return COMMANDS[args.command](args)
    except UsageError as exc:
        print(f"formgraph: {exc}", file=sys.stderr)
        return 2
    except FormgraphError as exc:
        if args.debug:
            traceback.print_exc()
        else:
            print(str(exc), file=sys.stderr)
            if exc.__cause__ is not None:
                print("(run with --debug for the Python traceback)", file=sys.stderr)
        return 1
    except BrokenPipeError:
        return 0
    except OSError as exc:
        if args.debug:
            traceback.print_exc()
        print(f"formgraph: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug of ours: still no traceback without --debug
        if args.debug:
            traceback.print_exc()
        else:
            print(
                f"formgraph: internal error: {type(exc).__name__}: {exc} (run with --debug "
                f"for the traceback, and please report it)",
                file=sys.stderr,
            )
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
