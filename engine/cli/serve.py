"""``formgraph serve``: the studio's command line (the studio itself is formgraph.studio)."""

from __future__ import annotations

import argparse
from typing import Any

from .options import UsageError, graph_options

__all__ = ["add_parser", "cmd_serve"]


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"a port is 0 to 65535 (0: any free one), got {value}")
    return value


def add_parser(sub: Any) -> None:
    serve = sub.add_parser(
        "serve",
        help="the studio: edit, see and tune a graph in the browser (a local web page)",
        description="Serve a local web page on GRAPH: its YAML in an editor, its drawing, "
        "a 3-D view and a control per param. The first line printed is the page's URL, "
        "with a secret token; requests without it are refused.",
    )
    serve.add_argument("graph")
    serve.add_argument(
        "--host",
        default="127.0.0.1",
        help="the address to listen on (default 127.0.0.1: this machine only)",
    )
    serve.add_argument("--port", type=_port, default=8765, help="the port (default 8765)")
    serve.add_argument(
        "--no-browser", action="store_true", help="do not open the page in a browser"
    )
    serve.add_argument(
        "--out", default="out", metavar="DIR", help="where Run writes the exports (./out)"
    )
    graph_options(serve)


def cmd_serve(args: argparse.Namespace) -> int:
    for item in args.set:
        if "=" not in item:
            raise UsageError(f"--set takes NAME=VALUE, got {item!r}")
    try:
        from formgraph.studio import serve
    except ImportError as exc:  # pragma: no cover - the studio's packages are dependencies
        raise UsageError(f"the studio needs trame: {exc}") from None
    return serve(
        args.graph,
        host=args.host,
        port=args.port,
        open_browser=not args.no_browser,
        out_dir=args.out,
        sets=args.set,
        budget=args.budget,
        inputs_dir=args.inputs,
    )
