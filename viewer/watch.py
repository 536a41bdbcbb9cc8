"""Watch mode: redraw a graph whenever its YAML file (or a subgraph file it uses) is saved.

A :class:`Watcher` polls the files' modification stamps from the plotter's timer. Each
:meth:`Watcher.reload` reads, checks and evaluates the file again; a broken edit puts the
error in the window (and on stderr) and leaves the last good geometry on screen. Successive
versions share one memory cache, so an edit recomputes only the nodes it reaches.

Without a display, :class:`ScreenshotWatcher` does the same off screen: each good version
is rendered to a PNG (written atomically, so a viewer of the file never sees half of one)
and one status line is printed; a broken version prints its error and leaves the last good
PNG in place.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

from formgraph.core.errors import FormgraphError
from formgraph.core.registry import DEFAULT_BUDGET
from formgraph.evaluation.graph import load

from .app import Session
from .entry import _window_title
from .frame import Camera
from .scene import Scene

__all__ = ["ScreenshotWatcher", "Watcher", "display_problem", "watch"]


class _Watched:
    """What both watchers share: the files to watch, their stamps, and loading a version."""

    def __init__(
        self,
        path: str | os.PathLike[str],
        node: str | Iterable[str] | None,
        sets: Sequence[str],
        out_dir: str | os.PathLike[str],
        budget: int,
        layout: str,
        edges: bool | None,
        camera: Camera | None = None,
        inputs_dir: str | os.PathLike[str] | None = None,
    ):
        self.camera = camera
        self.inputs_dir = inputs_dir  # the read nodes' folder (--inputs), if not the graph's
        self.path = Path(path)
        self.node = node
        self.sets = list(sets)
        self.out_dir = out_dir
        self.budget = budget
        self.layout = layout
        self.edges = edges
        self.stamp: tuple[Any, ...] | None = None
        self.files: list[Path] = [self.path]  # the graph's file and its subgraph files

    def _stamp(self) -> tuple[Any, ...] | None:
        return _stamps(self.path, self.files)

    def poll(self) -> bool | None:
        """Reload if a watched file changed since the last look; None when none did."""
        stamp = self._stamp()
        if stamp is None or stamp == self.stamp:
            return None
        return self.reload()

    def reload(self) -> bool:
        raise NotImplementedError

    def _load(self, memory: Any) -> tuple[Any, dict[str, Any]]:
        """The file's graph (sharing ``memory``, the previous version's cache) and the
        ``--set`` params read against it; the files to watch become its files."""
        from formgraph.cli.main import parse_sets

        graph = load(
            self.path, out_dir=self.out_dir, budget=self.budget, inputs_dir=self.inputs_dir
        )
        self.files = [self.path, *graph.files[1:]]
        self.stamp = self._stamp()
        if memory is not None:
            graph.memory = memory  # an edit recomputes what it reaches
        return graph, parse_sets(graph, self.sets)

    def _watch_files_of(self, exc: Exception) -> None:
        """A broken subgraph file is watched too."""
        if getattr(exc, "files", None):
            self.files = [self.path, *exc.files[1:]]  # type: ignore[attr-defined]
            self.stamp = self._stamp()


class Watcher(_Watched):
    """A graph file drawn in a plotter and redrawn when the file changes.

    Parameters
    ----------
    path : str or path
        The YAML graph file.
    node : str or list of str, optional
        The nodes to show; default: the graph's results.
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
        node: str | Iterable[str] | None = None,
        *,
        plotter: Any,
        sets: Sequence[str] = (),
        out_dir: str | os.PathLike[str] = "out",
        budget: int = DEFAULT_BUDGET,
        layout: str = "overlay",
        edges: bool | None = None,
        camera: Camera | None = None,
        inputs_dir: str | os.PathLike[str] | None = None,
        color: str | None = None,
    ):
        super().__init__(path, node, sets, out_dir, budget, layout, edges, camera, inputs_dir)
        self.color = color
        self.plotter = plotter
        self.session: Session | None = None
        self.reloads = 0
        self._blank: Scene | None = None  # shows the error of a broken first version

    @property
    def scene(self) -> Any:
        return self.session.scene if self.session is not None else None

    def reload(self) -> bool:
        """Read, check and evaluate the file again and redraw.

        Returns True when the new version is drawn; False when it is broken, in which case
        its error is shown in the window and on stderr and the last good geometry stays.
        """
        from formgraph.core.errors import UsageError

        self.stamp = self._stamp()
        self.reloads += 1
        try:
            previous = self.session.graph if self.session is not None else None
            graph, params = self._load(previous.memory if previous is not None else None)
            if self.session is None:
                self.session = Session(
                    graph,
                    self.node,
                    plotter=self.plotter,
                    params=params,
                    layout=self.layout,
                    edges=self.edges,
                    camera=self.camera,
                    color=self.color,
                )
                self.session.add_keys()
                self.session.scene.set_error(None)  # an error left by a broken start
            else:
                self.session.replace_graph(graph, params)
        except (FormgraphError, UsageError) as exc:
            self._watch_files_of(exc)
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
    node: str | Iterable[str] | None = None,
    *,
    sets: Sequence[str] = (),
    out_dir: str | os.PathLike[str] = "out",
    budget: int = DEFAULT_BUDGET,
    size: tuple[int, int] = (1024, 768),
    interval: float = 0.3,
    layout: str = "overlay",
    edges: bool | None = None,
    camera: Camera | None = None,
    inputs_dir: str | os.PathLike[str] | None = None,
    color: str | None = None,
) -> Watcher:
    """Open a window on ``graph_path`` that redraws whenever the file is saved.

    The file is polled every ``interval`` seconds. A broken edit shows its error in the
    window and on stderr and keeps the last good geometry; the window stays open until
    closed (``q``).
    """
    for item in sets:
        if "=" not in item:
            from formgraph.core.errors import UsageError

            raise UsageError(f"--set takes NAME=VALUE, got {item!r}")
    from .entry import make_plotter, view_count

    views = 1
    if layout == "side":  # the window's views are fixed: as many as the first version shows
        try:
            views = view_count(
                load(graph_path, out_dir=out_dir, budget=budget, inputs_dir=inputs_dir), node
            )
        except FormgraphError:
            views = 1 if node is None else len([node] if isinstance(node, str) else list(node))
    title = _window_title(graph_path) + " (watching)"
    plotter = make_plotter(views, layout, size, title=title)
    watcher = Watcher(
        graph_path,
        node,
        plotter=plotter,
        sets=sets,
        out_dir=out_dir,
        budget=budget,
        layout=layout,
        edges=edges,
        camera=camera,
        inputs_dir=inputs_dir,
        color=color,
    )
    watcher.reload()
    plotter.add_timer_event(
        max_steps=2**31 - 1,
        duration=max(50, int(interval * 1000)),
        callback=lambda _step: watcher.poll(),
    )
    print(f"watching {graph_path} (close the window or press q to stop)", file=sys.stderr)
    plotter.show()
    return watcher


# --------------------------------------------------------------------------- headless


def display_problem() -> str | None:
    """Why a window cannot open here (no display), or None when one can.

    Only Linux and the BSDs are checked (elsewhere a window system is always there). VTK
    draws its windows through X, so ``DISPLAY`` must be set (a Wayland desktop sets it for
    XWayland), and a local display's socket must exist: VTK aborts the whole process on a
    display that does not answer.
    """
    if not sys.platform.startswith(("linux", "freebsd", "openbsd", "netbsd")):
        return None
    display = os.environ.get("DISPLAY", "")
    if not display:
        if os.environ.get("WAYLAND_DISPLAY"):
            return "there is a Wayland display but no X display for VTK (DISPLAY is not set)"
        return "there is no display (DISPLAY is not set)"
    host, _, number = display.partition(":")
    number = number.split(".", 1)[0]
    if host in ("", "unix") and number.isdigit():
        if not Path(f"/tmp/.X11-unix/X{number}").exists():
            return f"DISPLAY={display}, but no X server listens there"
    return None


class ScreenshotWatcher(_Watched):
    """Watch a graph file without a window: a PNG and a status line per good version.

    Each change is loaded, checked and evaluated (sharing the memory cache with the
    previous version, so an edit recomputes only what it reaches) and rendered off screen
    to ``screenshot``, written atomically. A broken version prints its error and keeps the
    last good PNG.

    Parameters
    ----------
    path, node, sets, out_dir, budget, layout, edges, camera
        As for :class:`Watcher` (``camera``: a :class:`~.frame.Camera`, automatic if None).
    screenshot : str or path
        The PNG to (re)write.
    size : (int, int)
        Image size in pixels.
    out, err : text streams
        Where the status lines and the errors go.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        screenshot: str | os.PathLike[str],
        node: str | Iterable[str] | None = None,
        *,
        sets: Sequence[str] = (),
        out_dir: str | os.PathLike[str] = "out",
        budget: int = DEFAULT_BUDGET,
        size: tuple[int, int] = (1024, 768),
        layout: str = "overlay",
        edges: bool | None = None,
        camera: Camera | None = None,
        out: Any = None,
        err: Any = None,
        inputs_dir: str | os.PathLike[str] | None = None,
        color: str | None = None,
    ):
        super().__init__(path, node, sets, out_dir, budget, layout, edges, camera, inputs_dir)
        self.color = color
        self.screenshot = Path(screenshot)
        self.size = size
        self.out = out if out is not None else sys.stdout
        self.err = err if err is not None else sys.stderr
        self.memory: Any = None  # the cache shared by successive versions
        self.written = 0  # PNGs written
        self.last_error: str | None = None

    def reload(self) -> bool:
        """Load, evaluate and render the file once; True when a new PNG was written."""
        from formgraph.core.errors import UsageError

        from .entry import make_plotter

        self.stamp = self._stamp()
        try:
            graph, params = self._load(self.memory)
            views = 1
            if self.layout == "side":
                from .entry import view_count

                views = view_count(graph, self.node)
            plotter = make_plotter(views, self.layout, self.size, off_screen=True)
            try:
                session = Session(
                    graph,
                    self.node,
                    plotter=plotter,
                    params=params,
                    timing=False,
                    layout=self.layout,
                    edges=self.edges,
                    camera=self.camera,
                    color=self.color,
                )
                self.screenshot.parent.mkdir(parents=True, exist_ok=True)
                tmp = self.screenshot.with_name(f".{self.screenshot.name}.{os.getpid()}.tmp.png")
                plotter.screenshot(str(tmp))
                os.replace(tmp, self.screenshot)
            finally:
                plotter.close()
        except (FormgraphError, UsageError) as exc:
            self._watch_files_of(exc)
            return self._failed(str(exc))
        except Exception as exc:  # a bug of ours must not end the watch
            return self._failed(f"internal error: {type(exc).__name__}: {exc}")
        self.memory = graph.memory
        self.written += 1
        self.last_error = None
        print(f"{self.path.name}: {session.status_line()}, wrote {self.screenshot}", file=self.out)
        self.out.flush()
        return True

    def _failed(self, message: str) -> bool:
        self.last_error = message
        kept = (
            f" (kept {self.screenshot}, the last version that worked)"
            if self.written
            else f" ({self.screenshot} not written)"
        )
        print(message + kept, file=self.err)
        self.err.flush()
        return False

    def run(self, interval: float = 0.3, stop: Callable[[], bool] | None = None) -> None:
        """Render now, then poll every ``interval`` seconds until ``stop()`` (or Ctrl-C)."""
        print(
            f"watching {self.path} (a new {self.screenshot} on every good save; Ctrl-C stops)",
            file=self.err,
        )
        self.reload()
        while stop is None or not stop():
            time.sleep(interval)
            self.poll()


def _stamps(path: Path, files: Sequence[Path]) -> tuple[Any, ...] | None:
    """(mtime, size) of each file; None while the graph's own file is missing (mid-save)."""
    stamps: list[Any] = []
    for f in files:
        try:
            st = f.stat()
        except OSError:
            if f == path:
                return None
            stamps.append(None)
            continue
        stamps.append((st.st_mtime_ns, st.st_size))
    return tuple(stamps)
