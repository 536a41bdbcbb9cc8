"""Watch mode: redraw a graph whenever its YAML file (or a subgraph file it uses) is saved.

A :class:`Watcher` polls the files' modification stamps from the plotter's timer. Each
:meth:`Watcher.reload` reads, checks and evaluates the file again; a broken edit puts the
error in the window (and on stderr) and leaves the last good geometry on screen. Successive
versions share one memory cache, so an edit recomputes only the nodes it reaches.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from formgraph.errors import FormgraphError
from formgraph.graph import load
from formgraph.registry import DEFAULT_BUDGET

from .app import Session, _window_title
from .scene import Scene

__all__ = ["Watcher", "watch"]


class Watcher:
    """A graph file drawn in a plotter and redrawn when the file changes.

    Parameters
    ----------
    path : str or path
        The YAML graph file.
    node : str, optional
        The node to show; default: the graph's results.
    plotter : pyvista.Plotter
        Where to draw.
    sets : sequence of str
        ``NAME=VALUE`` param overrides, as on the command line (read again on each reload,
        against the params of the new version of the file).
    out_dir, budget
        As for :func:`formgraph.load`.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        node: str | None = None,
        *,
        plotter: Any,
        sets: Sequence[str] = (),
        out_dir: str | os.PathLike[str] = "out",
        budget: int = DEFAULT_BUDGET,
    ):
        self.path = Path(path)
        self.node = node
        self.plotter = plotter
        self.sets = list(sets)
        self.out_dir = out_dir
        self.budget = budget
        self.session: Session | None = None
        self.stamp: tuple[Any, ...] | None = None
        self.files: list[Path] = [self.path]  # the graph's file and its subgraph files
        self.reloads = 0
        self._blank: Scene | None = None  # shows the error of a broken first version

    @property
    def scene(self) -> Any:
        return self.session.scene if self.session is not None else None

    def _stamp(self) -> tuple[Any, ...] | None:
        stamps: list[Any] = []
        for f in self.files:
            try:
                st = f.stat()
            except OSError:
                if f == self.path:
                    return None  # mid-save (an editor's rename): look again on the next tick
                stamps.append(None)
                continue
            stamps.append((st.st_mtime_ns, st.st_size))
        return tuple(stamps)

    def poll(self) -> bool | None:
        """Reload if the file changed since the last look; None when it did not."""
        stamp = self._stamp()
        if stamp is None or stamp == self.stamp:
            return None
        return self.reload()

    def reload(self) -> bool:
        """Read, check and evaluate the file again and redraw.

        Returns True when the new version is drawn; False when it is broken, in which case
        its error is shown in the window and on stderr and the last good geometry stays.
        """
        from formgraph.cli import UsageError, parse_sets

        self.stamp = self._stamp()
        self.reloads += 1
        try:
            graph = load(self.path, out_dir=self.out_dir, budget=self.budget)
            self.files = [self.path, *graph.files[1:]]
            self.stamp = self._stamp()
            if self.session is not None and self.session.graph is not None:
                graph.memory = self.session.graph.memory  # an edit recomputes what it reaches
            params = parse_sets(graph, self.sets)
            if self.session is None:
                self.session = Session(graph, self.node, plotter=self.plotter, params=params)
                self.session.add_keys()
                self.session.scene.set_error(None)  # an error left by a broken start
            else:
                self.session.replace_graph(graph, params)
        except (FormgraphError, UsageError) as exc:
            if getattr(exc, "files", None):  # a broken subgraph file is watched too
                self.files = [self.path, *exc.files[1:]]
                self.stamp = self._stamp()
            self._report(str(exc))
            return False
        except Exception as exc:  # a bug of ours must not close the designer's window
            self._report(f"internal error: {type(exc).__name__}: {exc}")
            return False
        self.plotter.render()
        return True

    def _report(self, message: str) -> None:
        if self.session is not None:
            self.session.report(message)
            return
        # nothing good drawn yet: an empty scene carries the error
        print(message, file=sys.stderr)
        if self._blank is None:
            self._blank = Scene(self.plotter)
        self._blank.set_error(message)
        self.plotter.render()

    def error_text(self) -> str | None:
        """The error on screen, if any."""
        scene = self.session.scene if self.session is not None else self._blank
        return None if scene is None else scene.error


def watch(
    graph_path: str | os.PathLike[str],
    node: str | None = None,
    *,
    sets: Sequence[str] = (),
    out_dir: str | os.PathLike[str] = "out",
    budget: int = DEFAULT_BUDGET,
    size: tuple[int, int] = (1024, 768),
    interval: float = 0.3,
) -> Watcher:
    """Open a window on ``graph_path`` that redraws whenever the file is saved.

    The file is polled every ``interval`` seconds. A broken edit shows its error in the
    window and on stderr and keeps the last good geometry; the window stays open until
    closed (``q``).
    """
    import pyvista as pv

    for item in sets:
        if "=" not in item:
            from formgraph.cli import UsageError

            raise UsageError(f"--set takes NAME=VALUE, got {item!r}")
    plotter = pv.Plotter(window_size=list(size), title=_window_title(graph_path) + " (watching)")
    watcher = Watcher(graph_path, node, plotter=plotter, sets=sets, out_dir=out_dir, budget=budget)
    watcher.reload()
    plotter.add_timer_event(
        max_steps=2**31 - 1,
        duration=max(50, int(interval * 1000)),
        callback=lambda _step: watcher.poll(),
    )
    print(f"watching {graph_path} (close the window or press q to stop)", file=sys.stderr)
    plotter.show()
    return watcher
