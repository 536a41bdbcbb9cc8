"""The studio's page: a trame server whose state shows a :class:`~.session.StudioSession`.

Its widgets (:mod:`.layout`): left, the YAML in Monaco (trame-code) with the check's
problems marked at their lines and listed under it; in the middle, the 3-D view (vtk.js in
the browser, fed by :class:`~.scene.StudioScene`) over the drawing of the graph
(:func:`formgraph.draw_graph`, coloured computed / cached / failed with times; a click on a
node shows it); right, a control per param with its reset. The top bar holds Save, Run,
Reload and the status line.

Everything the page asks of the engine goes through one :class:`~.worker.Worker`; results
come back to the event loop (``call_soon_threadsafe``) and are shown there.
"""

from __future__ import annotations

import asyncio
import gc
import itertools
import math
import sys
import threading
import time
from typing import Any

from formgraph.core.errors import Problem

from .layout import build
from .scene import ARRAYS_TOPIC
from .session import Control, Cooked, StudioSession, controls_of, plain
from .worker import Worker

__all__ = ["Page"]

EDIT_DELAY = 0.35  # seconds of no typing before an edit is checked and cooked
POLL_SECONDS = 0.5  # how often the graph's files are looked at
# after a step, how long the page waits for the next before it sends what the picture does
# not need: the graph's drawing with its times, and the whole scene for a page that loads
# later (the page open now gets each step's changes alone)
SETTLE_DELAY = 0.3
# work the page does not wait on (a settled step's drawing of the graph): the busy spinner
# is for recooks, saves and runs, not for it
BACKGROUND = ("drawing",)
_names = itertools.count()


def _markers(problems: list[Problem], severity: str = "error") -> list[dict[str, Any]]:
    return [
        {"line": p.where.line, "message": p.message, "severity": severity}
        for p in problems
        if p.where.line is not None
    ]


def _problem_lines(problems: list[Problem]) -> list[str]:
    out = []
    for p in problems:
        where = f"line {p.where.line}: " if p.where.line is not None else ""
        node = f"node '{p.where.node}': " if p.where.node else ""
        out.append(f"{where}{node}{p.message}")
    return out


class Page:
    """The trame server, its layout and the wiring between the page and the session."""

    def __init__(self, session: StudioSession, guard: Any):
        from trame.app import get_server

        from .scene import SentArrays, StudioScene, make_plotter

        self.session = session
        self.guard = guard
        self.server = get_server(f"formgraph-studio-{next(_names)}", client_type="vue3")
        self.state, self.ctrl = self.server.state, self.server.controller
        self.plotter = make_plotter()
        self.scene = StudioScene(self.plotter)
        self.loop: asyncio.AbstractEventLoop | None = None
        self._handoff = threading.Lock()  # the loop, or results made before it ran
        self._early: list[tuple[Any, ...]] = []
        self.worker = Worker(self._deliver, self._worker_error)
        session.progress = self.worker.check
        self.controls: list[Control] = []
        self._wanted: dict[str, Any] = {}  # the controls' values, as the page last set them
        self._resets = 0  # resets asked since the page was last sent the values
        self._editor_text = ""  # the editor's text as the loop last knew it
        self._disk_text: str | None = None  # the file's text as last read or saved
        self._color_by: str | None = None  # the attribute the page colours by
        self._edit_timer: Any = None
        self._framed: tuple[float, ...] | None = None  # the bounds the camera was fit to
        self.updates = 0  # view updates sent
        self._settle_timer: Any = None
        self._settled_svg: str | None = None  # the drawing to send once steps settle
        self._to_draw: Cooked | None = None  # a step to draw the graph of once they settle
        self._drawings = 0  # drawings of the graph shown (a late one must not cover a newer)
        self._sent = SentArrays()  # the data arrays the pages have
        self._scene_stale = False  # the state's whole scene is older than the picture
        from formgraph.viewer.watch import _Watched

        page = self

        class DiskWatch(_Watched):
            """The viewer's watching of a graph's files, asking the worker to reload."""

            def reload(self) -> bool:
                old, self.stamp = self.stamp, self._stamp()
                own = old is None or self.stamp is None or old[0] != self.stamp[0]
                if page.state.text == page._disk_text:
                    page.worker.submit("disk", page._open_disk)
                    return True
                if not own:  # a part or an input changed: the editor's version again
                    page.worker.submit("text", page.session.open, page.state.text)
                    return True
                page._say(  # the graph file itself, under unsaved edits: keep them
                    f"{page.session.path.name} changed on disk; the editor keeps your "
                    "edits (Reload takes the file's text, Save overwrites the file)",
                    True,
                )
                return False

        self.watch = DiskWatch(session.path, None, (), session.out_dir, session.budget, "", None)
        self.watch.stamp = self.watch._stamp()  # the first load reads this version
        self._init_state()
        self.layout, self.view = build(self)
        self.ctrl.on_server_bind.add(self._bind)
        self.ctrl.on_server_ready.add(self._ready)
        self.worker.submit("disk", self._open_disk)  # the first load, while the server starts

    # ------------------------------------------------------------------ state, layout

    def _init_state(self) -> None:
        s = self.state
        s.trame__title = f"{self.session.path.name} - formgraph studio"
        s.text = ""
        s.markers = []
        s.problems = []
        s.status = "loading..."
        s.status_bad = False
        s.controls = []
        s.params = {}
        s.graph_svg = ""
        s.shown = "the graph's results"
        s.busy = False
        s.cook_id = 0  # bumped after each picture sent (the bench waits on it)
        s.timing = {}  # where the last request's time went (read by bench/bench_studio.py)
        s.attributes = []  # the attributes of what is shown, to colour by
        s.colour_items = ["none"]  # (a list in the template would be new at each render)
        s.editor_options = {  # (likewise: a new object would make Monaco lay out again)
            "minimap": {"enabled": False},
            "fontSize": 13,
            "automaticLayout": True,
            "scrollBeyondLastLine": False,
        }
        s.color_by = "none"
        s.frames_n = 0  # the steps of the shown simulated nodes (0: no frame scrubber)
        s.frame_k = 0  # the step the scrubber shows

        @s.change("text")
        def _edited(text: str, **_: Any) -> None:
            if text == self._editor_text:
                return  # the text the server itself put in the editor
            self._editor_text = text
            if self._edit_timer is not None:
                self._edit_timer.cancel()
            loop = asyncio.get_event_loop()
            self._edit_timer = loop.call_later(
                EDIT_DELAY, lambda: self.worker.submit("text", self.session.open, text)
            )

        ctrl = self.ctrl
        ctrl.trigger("set_param")(self._set_param)
        ctrl.trigger("reset_param")(self._reset_param)
        ctrl.trigger("show_node")(self._show_node)
        ctrl.trigger("colour_by")(self._colour_by)
        ctrl.trigger("show_frame")(self._show_frame)
        ctrl.trigger("save")(self._save)
        ctrl.add("run")(self._run)
        ctrl.add("reload")(lambda: self.worker.submit("disk", self._open_disk))
        ctrl.add("reset_all")(self._reset_all)
        ctrl.add("show_results")(lambda: self.worker.submit("show", self.session.show, None))

    # --------------------------------------------------------------------- server life

    def _bind(self, wslink_server: Any) -> None:
        wslink_server.app.middlewares.append(self.guard.middleware)
        wslink_server.app.router.add_post("/paraview/", _session_config)

    def _ready(self, **_: Any) -> None:
        with self._handoff:
            self.loop = asyncio.get_event_loop()
            early, self._early = self._early, []
        for item in early:  # the first load, cooked while the server started
            self._apply(*item)
        self.loop.create_task(self._poll())

    async def _poll(self) -> None:
        while True:
            await asyncio.sleep(POLL_SECONDS)
            try:
                self.watch.poll()
            except OSError:
                pass

    def close(self) -> None:
        self.worker.stop()
        self.plotter.close()

    # ---------------------------------------------------------------- page -> engine

    def _control(self, name: str) -> Control | None:
        return next((c for c in self.controls if c.name == name), None)

    def _set_param(self, name: str, value: Any) -> None:
        c = self._control(name)
        if c is None:
            return
        value = _as_param(c, value)
        self._wanted[name] = value
        self.worker.submit("params", self._cook_params, dict(self._wanted))

    def _cook_params(self, values: dict[str, Any]) -> Cooked:
        return self.session.set_params(**values)

    def _reset_param(self, name: str) -> None:
        self._resets += 1  # the value goes back on the page with the step
        self._wanted.pop(name, None)
        self.worker.submit("params", self._reset, name)

    def _reset_all(self) -> None:
        self._resets += 1
        self._wanted.clear()
        self.worker.submit("params", self.session.reset_params)

    def _reset(self, name: str) -> Cooked:
        return self.session.reset_params(name)

    def _colour_by(self, name: str | None) -> None:
        """Colour by an attribute (``"none"``: by node), drawn again from the last result."""
        self._color_by = None if name in (None, "", "none") else str(name)
        self.worker.submit("show", lambda: self.session.last)

    def _show_frame(self, k: Any) -> None:
        """Show step ``k`` of the shown simulated nodes, from the caches (no recook)."""
        try:
            k = int(k)
        except (TypeError, ValueError):
            return
        self.worker.submit("frame", self.session.frame, k)

    def _show_node(self, name: str) -> None:
        self.worker.submit("show", self.session.show, [name])

    def _open_disk(self) -> Cooked:
        return self.session.open()  # the file's text

    def _save(self, text: Any = None) -> None:
        """Save the text the page sent with the click (the state's, from an older page)."""
        if not isinstance(text, str):
            text = self.state.text
        self.worker.submit("save", self._save_text, text)

    def _save_text(self, text: str) -> tuple[str, str, str | None]:
        try:
            path = self.session.save(text)
        except Exception as exc:  # a PathError or an OSError: said on the page
            return ("error", f"not saved: {exc}", None)
        return ("ok", f"saved {path.name}", text)

    def _run(self) -> None:
        self.worker.submit("run", self.session.run)

    # ---------------------------------------------------------------- engine -> page

    def _deliver(self, kind: str, result: Any, seconds: float) -> None:
        """In the worker thread: what can be made away from the page's loop (the datasets
        of the picture, the graph's drawing), then the rest on the loop."""
        if kind == "drawing":  # a slider step's drawing of the graph, once steps settled
            if result is not None and self.loop is not None:
                self.loop.call_soon_threadsafe(self._show_drawing, *result)
            return
        t0 = time.perf_counter()
        prepared = None
        # a slider step's drawing of the graph is made and sent once the steps settle
        # (:meth:`_settled`): made now, it would hold the interpreter while the page's loop
        # sends the picture
        later = kind == "params" and isinstance(result, Cooked)
        if isinstance(result, Cooked):
            datasets = None
            if result.ok and kind != "run":
                datasets = self.scene.prepare(result.shown, self._color_by)
            drawn = kind != "frame" and not later  # (a frame: the graph is as it was)
            svg = self._drawing(result) if drawn else None
            prepared = (datasets, svg, self._snapshot())
        seconds += time.perf_counter() - t0
        with self._handoff:
            if self.loop is None:  # the server is still starting: shown once it is ready
                if later:
                    prepared = (prepared[0], self._drawing(result), prepared[2])
                self._early.append((kind, result, seconds, prepared))
                return
        self.loop.call_soon_threadsafe(self._apply, kind, result, seconds, prepared)

    def _snapshot(self) -> dict[str, Any]:
        """What the page shows of the session, read in the worker thread, between two of
        its requests (the loop must not read a session the next request is changing)."""
        session = self.session
        graph = session.graph
        return {
            "text": session.text,
            "files": [session.path, *session.files()[1:]],
            "controls": controls_of(graph, session.values) if graph is not None else None,
            "values": dict(session.values),
            "shown_text": ", ".join(session.shown_names or ()) or "the graph's results",
            "exports": session.exports(),
        }

    def _worker_error(self, kind: str, exc: BaseException) -> None:
        message = f"internal error ({kind}): {type(exc).__name__}: {exc}"
        print(message, file=sys.stderr)
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self._say, message, True)

    def _say(self, text: str, bad: bool) -> None:
        with self.state:
            self.state.status = text
            self.state.status_bad = bad

    def _apply(self, kind: str, result: Any, seconds: float, prepared: Any = None) -> None:
        t0 = time.perf_counter()
        name = self.session.path.name
        if kind == "save":
            status, text, saved = result
            self.watch.stamp = self.watch._stamp()  # our own write: no reload
            if saved is not None:
                self._disk_text = saved
            self._say(f"{name}: {text}", status != "ok")
            return
        cooked: Cooked = result
        datasets, svg, snap = prepared if prepared is not None else (None, None, None)
        if snap is None:
            snap = self._snapshot()  # (a request with no Cooked result: not reached)
        s = self.state
        # the picture first, its arrays ahead of the state: then the state, in one message
        # (each message the page gets makes it render its template again)
        if datasets is not None:
            self._picture(datasets)
        t1 = time.perf_counter()
        if kind == "frame":
            with s:
                self._attributes(datasets)
                if cooked.frame is not None:
                    s.frame_k = cooked.frame
                    s.status = (
                        f"{name}: frame {cooked.frame} of {cooked.frames}, from the cache in "
                        f"{_ms(cooked.seconds)} (nothing recooked)"
                    )
                    s.status_bad = False
                s.busy = not self.worker.idle(ignore=BACKGROUND)
                s.cook_id = s.cook_id + 1
            self._settle()
            return
        with s:
            self._attributes(datasets)
            if kind == "disk":
                self._disk_text = snap["text"]
                if snap["text"] != s.text:
                    self._editor_text = s.text = snap["text"]  # the file's text, in the editor
            if kind in ("text", "disk") and snap["files"] != self.watch.files:
                self.watch.files = snap["files"]  # a subgraph file more or less to watch
                self.watch.stamp = self.watch._stamp()
            if kind == "run" and cooked.ok:
                written = ", ".join(snap["exports"]) or "nothing to export"
                s.status = f"{name}: ran in {_ms(cooked.seconds)}, wrote {written} into "
                s.status += f"{self.session.out_dir}"
                s.status_bad = False
                if svg is not None:
                    self._show_now(svg)
                return
            s.problems = _problem_lines(cooked.problems)
            if cooked.new_graph or not cooked.ok or kind in ("text", "disk"):
                s.markers = _markers(cooked.problems)
            if cooked.ok:  # what is left to say: the nodes' warnings
                s.markers = _markers(cooked.warnings, "warning")
                s.problems = [f"warning: {p}" for p in _problem_lines(cooked.warnings)]
            newer = kind == "params" and self.worker.waiting("params")
            if (
                snap["controls"] is not None
                and (cooked.new_graph or kind == "params")
                and not newer
            ):
                self.controls = snap["controls"]
                s.controls = [c.as_dict() for c in self.controls]
                # a slider step leaves the page's values alone: the page set them, and may
                # have moved on while this step cooked (sent back now, an older value would
                # overwrite a key press still on its way here, and the slider would step
                # on from it); a reset, a refused value or a new graph send the session's
                if kind != "params" or self._resets or not cooked.ok:
                    self._resets = 0
                    self._wanted = dict(snap["values"])
                    s.params = {c.name: plain(c.value) for c in self.controls}
                    s.dirty("params")  # the page's may differ from what was last sent
            if svg is not None and kind == "params":
                self._settled_svg = svg  # a slider step: the drawing once the steps settle
            elif kind == "params":
                self._to_draw = cooked  # drawn once the steps settle
            elif svg is not None:
                self._show_now(svg)
            s.shown = snap["shown_text"]
            if cooked.ok:
                s.frames_n = cooked.frames
                s.frame_k = cooked.frames  # a new cook shows the last step
            if cooked.ok:
                n = len(cooked.warnings)
                warned = f", {n} warning{'s' if n != 1 else ''}" if n else ""
                s.status = (
                    f"{name}: {cooked.computed} computed, {cooked.cached} cached in "
                    f"{_ms(cooked.seconds)}{warned}"
                )
                s.status_bad = False
            else:
                kept = " (the picture is the last version that worked)" if cooked.shown else ""
                lines = _problem_lines(cooked.problems) or [cooked.message]
                more = f" (+{len(lines) - 1} more)" if len(lines) > 1 else ""
                s.status = f"{name}: {lines[0]}{more}{kept}"
                s.status_bad = True
            s.busy = not self.worker.idle(ignore=BACKGROUND)
            s.cook_id = s.cook_id + 1
            s.timing = {
                "cook_ms": round(cooked.seconds * 1000, 2),
                # in the worker: queue, recook, datasets and drawing prepared
                "asked_to_done_ms": round(seconds * 1000, 2),
                "scene_ms": round((t1 - t0) * 1000, 2),  # arrays in place + serialization
                # status, controls, problems, drawing
                "state_ms": round((time.perf_counter() - t1) * 1000, 2),
                "step": s.cook_id,  # (so that two steps' timings always differ)
            }
        self._settle()

    def _attributes(self, datasets: Any) -> None:
        """The attributes to colour by, in the state (in a ``with state`` block)."""
        if datasets is not None:
            s = self.state
            s.attributes = datasets.attributes
            s.colour_items = ["none", *datasets.attributes]
            s.color_by = datasets.color_by or "none"

    def _show_now(self, svg: str) -> None:
        """A drawing of the graph shown with this request (in a ``with state`` block): one
        waiting for the steps to settle is older, and goes."""
        self._to_draw, self._settled_svg = None, None
        self._drawings += 1
        self.state.graph_svg = svg

    def _settle(self) -> None:
        """Send what the picture did not need (see SETTLE_DELAY), once steps pause."""
        if self.loop is None:
            return
        if self._settled_svg is None and self._to_draw is None and not self._scene_stale:
            return
        if self._settle_timer is not None:
            self._settle_timer.cancel()
        self._settle_timer = self.loop.call_later(SETTLE_DELAY, self._settled)

    def _settled(self) -> None:
        self._settle_timer = None
        if self._scene_stale:
            self._send_whole_scene()
        if self._to_draw is not None:  # drawn in the worker, shown by _show_drawing
            cooked, self._to_draw = self._to_draw, None
            graph = self.session.graph
            self.worker.submit("drawing", self._draw_step, cooked, graph, self._drawings)
        if self._settled_svg is not None:
            svg, self._settled_svg = self._settled_svg, None
            self._drawings += 1
            with self.state:
                self.state.graph_svg = svg

    def _draw_step(self, cooked: Cooked, graph: Any, drawings: int) -> tuple[str, int] | None:
        """In the worker: a settled step's drawing of the graph (None: the graph is no
        longer the one it cooked)."""
        if self.session.graph is not graph:
            return None
        svg = self._drawing(cooked)
        return None if svg is None else (svg, drawings)

    def _show_drawing(self, svg: str, drawings: int) -> None:
        """A settled step's drawing, unless a newer one was shown since it was asked for."""
        if drawings != self._drawings or self._to_draw is not None:
            return
        self._drawings += 1
        with self.state:
            self.state.graph_svg = svg

    def _drawing(self, cooked: Cooked) -> str | None:
        """The graph's drawing, coloured by the last evaluation (None: nothing to draw)."""
        from formgraph.core.errors import FormgraphError
        from formgraph.drawgraph.layout import draw_graph

        from .layout import clickable_svg

        graph = self.session.graph
        if graph is None:
            return None
        try:
            drawing = draw_graph(graph, stats=cooked.stats, failed=cooked.failed)
        except FormgraphError:
            return None
        return clickable_svg(drawing)

    def _picture(self, datasets: Any) -> None:
        from formgraph.viewer.app import _camera_lost

        from .scene import send_back_faces, send_cells_once

        added = self.scene.apply(datasets)
        send_back_faces()
        send_cells_once()
        bounds = self.scene.bounds()
        first = self._framed is None
        if first:
            self.plotter.reset_camera(render=False)  # a render would send the scene
        if not self._send_changes(immediately=first or bool(added)):
            self.view.update()
        if first:
            self.view.push_camera()
        elif added or _camera_lost(self._framed, bounds):
            # framed again in the browser, keeping the direction the user turned it to
            self.view.reset_camera()
        if first or added or _camera_lost(self._framed, bounds):
            self._framed = bounds
        self.updates += 1
        if first:
            # what is loaded by now (trame, vtk, the first graph: some 230,000 objects) lives
            # as long as the studio; out of the collector's sight, a full collection no
            # longer takes 80 ms of some slider step (their cycles, if garbage later, stay)
            gc.freeze()

    def _send_changes(self, immediately: bool = False) -> bool:
        """Send the page the scene's changes alone (False: not possible here).

        trame-vtk's ``update()`` serializes the scene twice, its changes for the pages open
        now and the whole of it into the state for a page that loads later (which the open
        page ignores); a step sends the changes, and the whole scene follows once the steps
        settle (:meth:`_settle`).
        """
        view = self.view
        window = getattr(view, "_VtkLocalView__view", None)  # trame-vtk 2.x's render window
        protocol = self.server.protocol
        if window is None or protocol is None or not hasattr(view, "_helper"):
            return False
        delta = view._helper.scene(
            window, new_state=False, widgets=view._widgets, orientation_axis=0
        )
        fresh = self._sent.fresh(delta)
        if fresh:  # the new arrays ahead of the scene: vtk.js need not ask for them
            get = self.server.protocol_call
            arrays = {h: get("viewport.geometry.array.get", h, True) for h in fresh}
            protocol.publish(ARRAYS_TOPIC, arrays)
        protocol.publish("trame.vtk.delta", delta)
        self._scene_stale = True
        if immediately:  # a first picture, or new actors: a page loading now needs them
            self._send_whole_scene()
        return True

    def _send_whole_scene(self) -> None:
        """The whole scene into the state, for a page that loads from now on (the pages
        open now got its changes; trame-vtk's own page ignores the state after its first)."""
        self._scene_stale = False
        view = self.view
        full = view._helper.scene(
            view._VtkLocalView__view, new_state=True, widgets=view._widgets, orientation_axis=0
        )
        self._sent.fresh(full)  # (a page loading it asks for its arrays)
        self.state[view._VtkLocalView__scene_id] = full


async def _session_config(request: Any) -> Any:
    """Where the page's websocket is, for the page's first request.

    trame's client, given no ``sessionURL``, first asks a ParaView-style launcher for one:
    a POST to ``paraview/`` beside the page, answered by this server with 405, which the
    browser logs as an error on every load before the client falls back to ``/ws``. This
    answers it as a launcher does (wslink's launcher protocol: a JSON object with
    ``sessionURL``), so the page connects at once and its console stays clean. The guard
    has checked the request (token, Host, Origin) before it gets here.
    """
    from aiohttp import web

    scheme = "wss" if request.secure else "ws"
    return web.json_response({"sessionURL": f"{scheme}://{request.host}/ws"})


def _as_param(c: Control, value: Any) -> Any:
    """A control's value as the param's type reads it."""
    if c.kind == "toggle":
        return bool(value)
    if c.kind in ("slider", "number"):
        try:
            number = float(value)
        except (TypeError, ValueError):
            return value  # the param's check says what was expected
        if not math.isfinite(number):
            return number  # the param's check says what was expected
        number = c.snap(number)
        if c.step == 1.0 and number.is_integer():
            return int(number)
        return number
    if c.kind == "text" and isinstance(value, str):
        from formgraph.language.yamlread import load_value

        try:
            return load_value(value)
        except Exception:  # not YAML: handed on as text, the param's check speaks
            return value
    return value


def _ms(seconds: float) -> str:
    return f"{seconds * 1000:.0f} ms" if seconds < 10 else f"{seconds:.1f} s"
