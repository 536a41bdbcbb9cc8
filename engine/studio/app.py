"""``formgraph serve``: start the studio on a graph file and print its URL.

The first line printed is the URL with the secret token (and nothing is printed before it,
so a script can read it); then the server runs until Ctrl-C.
"""

from __future__ import annotations

import contextlib
import ipaddress
import os
import socket
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, TextIO

from formgraph.core.errors import GraphError, Problem, Where
from formgraph.core.registry import DEFAULT_BUDGET

from .guard import Guard, new_token
from .session import StudioSession

__all__ = ["serve", "url_host"]

WILDCARDS = ("0.0.0.0", "::", "")


def url_host(host: str) -> str:
    """How the printed URL names ``host`` (a wildcard bind: this machine's name)."""
    if host in WILDCARDS:
        return socket.gethostname()
    try:
        if ipaddress.ip_address(host).version == 6:
            return f"[{host}]"
    except ValueError:
        pass
    return host


def _loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


@contextlib.contextmanager
def _own_argv() -> Iterator[None]:
    """trame reads sys.argv for options of its own (--port, --host, ...): hide ours."""
    saved = sys.argv
    sys.argv = saved[:1]
    try:
        yield
    finally:
        sys.argv = saved


def serve(
    graph: str | os.PathLike[str],
    *,
    host: str = "127.0.0.1",
    port: int = 8765,
    open_browser: bool = True,
    out_dir: str | os.PathLike[str] = "out",
    sets: Sequence[str] = (),
    budget: int = DEFAULT_BUDGET,
    inputs_dir: str | os.PathLike[str] | None = None,
    out: TextIO | None = None,
) -> int:
    """Serve the studio on ``graph`` until interrupted; returns the exit code.

    Parameters
    ----------
    graph : str or path
        The graph file to edit, view, tune, save and run.
    host : str
        The address to listen on; the default keeps the studio to this machine.
    port : int
        The port (0: any free one; the URL says which).
    open_browser : bool
        Open the URL in the default browser once the server listens.
    out_dir : str or path
        Where Run writes the exports.
    sets : sequence of str
        ``NAME=VALUE`` params to start with.
    budget, inputs_dir
        As for :func:`formgraph.load` (the read nodes' folder; default the graph's).
    out : text stream
        Where the URL goes (standard output by default).
    """
    path = Path(graph)
    if not path.is_file():
        raise GraphError(Problem(Where(str(path)), "no such graph file"))
    out = out if out is not None else sys.stdout
    # wslink announces itself on standard output; the URL must be the first line there
    os.environ["WSLINK_READY_MSG"] = ""
    # no permessage-deflate: a step's arrays are floats, which deflate shrinks by 8 % for
    # 20-40 ms of the server's time each (and the browser's to inflate)
    os.environ.setdefault("WSLINK_WS_COMPRESS", "0")
    token = new_token()
    names = [] if host in WILDCARDS else [host]
    if host in WILDCARDS:
        names += [socket.gethostname(), socket.getfqdn()]
    guard = Guard(token, names)
    session = StudioSession(path, out_dir=out_dir, sets=sets, budget=budget, inputs_dir=inputs_dir)
    from .page import Page

    page = Page(session, guard)

    def announce(**_: Any) -> None:
        url = f"http://{url_host(host)}:{page.server.port}/index.html?token={token}"
        print(url, file=out, flush=True)
        print(
            f"formgraph studio: {path} (output folder {out_dir}); Ctrl-C stops",
            file=sys.stderr,
            flush=True,
        )
        if not _loopback(host):
            print(
                f"formgraph studio: listening on {host}, not only on this machine: whoever "
                "can reach it and has the URL can run graphs here and save this file",
                file=sys.stderr,
                flush=True,
            )
        if open_browser:
            import webbrowser

            webbrowser.open(url)

    page.ctrl.on_server_ready.add(announce)
    try:
        with _own_argv():
            page.server.start(
                port=port,
                host=host,
                open_browser=False,
                show_connection_info=False,
                disable_logging=True,
                timeout=0,
            )
    except KeyboardInterrupt:
        pass
    finally:
        page.close()
    return 0
