"""Interactive viewing, sliders and screenshots of graphs and geometry values.

A :class:`Session` ties a graph (or a bare geometry value) to a plotter: it evaluates the
shown nodes through the graph's cache, draws them with a :class:`~.scene.Scene`, and
:meth:`Session.apply_params` is what every slider calls. It needs no window, so tests drive
it off screen.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from formgraph.core.errors import FormgraphError, GraphError, Problem, Where
from formgraph.evaluation.graph import Graph, load
from formgraph.language.model import Items, Wire, parse_input
from formgraph.language.params import param_kind

from .frame import Camera
from .scene import PALETTE, TEXT_COLOR, Scene, fit_scenes

__all__ = ["LAYOUTS", "Session", "Slider", "shown_nodes"]

HELP = "c control polygons   n control nets   e edges   g grid   f fit   v isometric   q quit"
HELP_LINES = "c control polygons   n control nets\ne edges   g grid   f fit   v iso   q quit"
LAYOUTS = ("overlay", "side")


def shown_nodes(graph: Graph, node: str | Iterable[str] | None = None) -> list[str]:
    """What to show: ``node`` (names, ``name.output`` allowed), else the graph's results.

    The results are the nodes wired into its export nodes (``@mesh`` feeding
    ``export.stl``), in author order; a graph without exports shows its sinks.
    """
    registry = graph.node_types()  # subgraph files too
    if node is not None:
        names = [node] if isinstance(node, str) else list(node)
        for n in names:
            _check_target(graph, registry, n)
        return names
    shown: list[str] = []
    for name, type_name in graph.nodes.items():
        if not registry[type_name].is_export:
            continue
        for raw in graph.node_inputs(name).values():
            for wire in _wires(raw):
                if registry[graph.nodes[wire.node]].is_export:
                    continue
                target = str(wire)[1:]
                if target not in shown:
                    shown.append(target)
    return shown or graph.sinks()


def _check_target(graph: Graph, registry: dict[str, Any], target: str) -> None:
    from formgraph.language.params import suggest

    where = Where(graph.file)
    if target in graph.nodes:
        return
    base, _, output = target.partition(".")
    if base not in graph.nodes:
        raise GraphError(Problem(where, f"no node '{target}'{suggest(target, graph.nodes)}"))
    spec = registry[graph.nodes[base]]
    if output == "frames" and graph._nodes[base].simulate is not None:
        return  # every step's output, drawn together
    if not spec.multi_output or output not in spec.outputs:
        outputs = ", ".join(spec.outputs) if spec.multi_output else "only one, unnamed"
        raise GraphError(
            Problem(
                where,
                f"node '{base}' ({spec.name}) has no output '{output}'; its outputs: {outputs}",
            )
        )


def _wires(raw: Any) -> list[Wire]:
    try:
        value = parse_input(raw)
    except FormgraphError:
        return []
    if isinstance(value, Wire):
        return [value]
    if isinstance(value, Items):
        return [i for i in value.items if isinstance(i, Wire)]
    return []


@dataclass(frozen=True)
class Slider:
    """A numeric graph param with a range: what a slider needs."""

    name: str
    min: float
    max: float
    value: float
    integer: bool
    doc: str = ""


class Session:
    """A graph (or geometry values) drawn in a plotter, re-evaluated on demand.

    Parameters
    ----------
    source : Graph, str, path, geometry or list of geometries
        A graph, a graph file, or values to draw as they are.
    node : str or list of str, optional
        The nodes to show (``name`` or ``name.output``); default: the graph's results.
    plotter : pyvista.Plotter
        Where to draw; for ``layout="side"`` one with a subplot per shown node, side by
        side (see :func:`make_plotter`).
    params : dict
        Param values for the evaluations (sliders change them).
    timing : bool
        Draw the last evaluation time at the top left.
    layout : {"overlay", "side"}
        All shown nodes in one view, each in its colour with a legend entry; or one view
        per node, side by side, with linked cameras, each titled with the node's name, type
        and size.
    edges : bool, optional
        Draw mesh face edges always (True), never (False), or on coarse meshes (None).
    camera : Camera, optional
        Where the views look from (:class:`~.frame.Camera`); automatic if None.
    color : str, optional
        Colour the points and meshes by this attribute (point or face), with a colour bar;
        a 3-component ``color`` attribute is shown as the RGB colours it holds.
    """

    def __init__(
        self,
        source: Any,
        node: str | Iterable[str] | None = None,
        *,
        plotter: Any,
        params: dict[str, Any] | None = None,
        timing: bool = True,
        layout: str = "overlay",
        edges: bool | None = None,
        camera: Camera | None = None,
        color: str | None = None,
    ):
        if layout not in LAYOUTS:
            raise ValueError(f"layout must be one of {', '.join(LAYOUTS)}, got {layout!r}")
        if isinstance(source, (str, os.PathLike)):
            source = load(source)
        self.graph: Graph | None = source if isinstance(source, Graph) else None
        self.value = None if self.graph is not None else source
        self.node = node
        self.plotter = plotter
        self.layout = layout
        self.params: dict[str, Any] = dict(params or {})
        self.timing = timing
        self.color = color  # an attribute to colour by (with a colour bar), or None
        self.seconds: float | None = None
        self.targets = shown_nodes(self.graph, node) if self.graph is not None else []
        self.controls_x = 0.76  # where the column of sliders starts (fraction of the width)
        self._slider_values: dict[str, float] = {}
        self._slider_specs: dict[str, Slider] = {}
        self.widgets: dict[str, Any] = {}  # slider widgets by param name
        shown = self.evaluate()
        self.scenes = self._make_scenes(len(shown), edges)
        for scene in self.scenes:
            scene.camera = camera or Camera()
        self._draw(shown)
        self.fit_camera()
        self._status()

    def _make_scenes(self, n: int, edges: bool | None) -> list[Scene]:
        if self.layout == "overlay":
            return [Scene(self.plotter, edges=edges, color_by=self.color)]
        rows, cols = self.plotter.shape
        if rows != 1 or cols < n:
            raise ValueError(
                f"the side by side layout of {n} views needs a plotter of shape (1, {n}) or "
                f"wider, got {self.plotter.shape}; make it with make_plotter()"
            )
        colors: dict[str, str] = {}
        scenes = [
            Scene(
                self.plotter, (0, i), titled=True, edges=edges, colors=colors, color_by=self.color
            )
            for i in range(n)
        ]
        if n > 1:
            self.plotter.link_views(list(range(n)))
        if cols > n:  # the last column holds the sliders
            self.controls_x = self.plotter.renderers[n].GetViewport()[0] + 0.02
        return scenes

    @property
    def scene(self) -> Scene:
        """The (first) view."""
        return self.scenes[0]

    def _draw(self, shown: list[tuple[str, Any]]) -> None:
        if self.layout == "overlay":
            self.scene.update(shown)
            return
        if len(shown) != len(self.scenes):
            raise GraphError(
                f"{len(shown)} nodes to show side by side, but the window has "
                f"{len(self.scenes)} views; start the viewer again"
            )
        for scene, (label, value) in zip(self.scenes, shown, strict=True):
            if self.graph is not None:
                base = _base(self.graph, label) if label else label
                scene.captions = {base: self.graph.nodes.get(base, "")}
            scene.update([(label, value)])

    def fit_camera(self) -> None:
        """Frame what is drawn (every view, with the camera they share)."""
        fit_scenes(self.scenes)

    # ---------------------------------------------------------------------- evaluation

    def evaluate(self) -> list[tuple[str, Any]]:
        """``(label, value)`` of every shown node, evaluated with the current params."""
        if self.graph is None:
            if self.layout == "side" and isinstance(self.value, (list, tuple)):
                return [(f"{i + 1}", v) for i, v in enumerate(self.value)]
            return [(_label_of(self.value), self.value)]
        bases = list(dict.fromkeys(_base(self.graph, t) for t in self.targets))
        t0 = time.perf_counter()
        outs = self.graph.evaluate(bases, **self.params)
        self.seconds = time.perf_counter() - t0
        shown = []
        for t in self.targets:
            base = _base(self.graph, t)
            value = outs[base]
            if t != base:
                output = t[len(base) + 1 :]
                if output == "frames" and self.graph._nodes[base].simulate is not None:
                    value = self.graph.frames(base, **self.params)  # from the caches
                else:
                    value = getattr(value, output)
            shown.append((t, value))
        return shown

    def apply_params(self, **values: Any) -> bool:
        """Re-evaluate with some params changed and redraw in place (the slider callback).

        Only the nodes the changed params reach recompute (see ``graph.stats``). On an
        error the message is shown in the window and on stderr, the last good geometry
        stays, and the params are left as they were. Returns whether it succeeded.
        """
        if self.graph is None:
            raise ValueError("a geometry value has no params; pass a graph to use params")
        self._require_open()
        old = dict(self.params)
        self.params.update(values)
        try:
            shown = self.evaluate()
        except FormgraphError as exc:
            self.params = old
            self.report(str(exc))
            return False
        self._draw(shown)
        self.scene.set_error(None)
        self._status()
        for name, value in values.items():
            if name in self.widgets:
                rep = self.widgets[name].GetRepresentation()
                if isinstance(value, bool):  # a check box: state 1 is on
                    rep.SetState(int(value))
                    continue
                self._slider_values[name] = value
                rep.SetValue(float(value))
                self._title_slider(name, value)
        self.plotter.render()
        return True

    def closed(self) -> bool:
        """Whether the plotter is closed (pyvista closes an off-screen plotter in show())."""
        return getattr(self.plotter, "render_window", None) is None

    def _require_open(self) -> None:
        if self.closed():
            raise RuntimeError(
                "this session's plotter is closed, so nothing can be drawn in it: pyvista "
                "closes a plotter at the end of show(), and off screen right away; keep it "
                "open with plotter.show(auto_close=False), or take pictures with "
                "plotter.screenshot(path) instead of show()"
            )

    def replace_graph(self, graph: Graph, params: dict[str, Any] | None = None) -> None:
        """Show a new version of the graph (watch mode), keeping the camera if it still fits.

        Raises
        ------
        FormgraphError
            When the new version fails; what is drawn, and the session, stay as they were.
        """
        self._require_open()
        old = (self.graph, self.targets, self.params, self.seconds)
        old_bounds = self.scene.bounds()
        try:
            self.graph, self.params = graph, dict(params or {})
            self.targets = shown_nodes(graph, self.node)
            shown = self.evaluate()
            self._draw(shown)
        except BaseException:
            self.graph, self.targets, self.params, self.seconds = old
            raise
        self.scene.set_error(None)
        self._status()
        if _camera_lost(old_bounds, self.scene.bounds()):
            self.fit_camera()
        self.plotter.render()

    def report(self, message: str) -> None:
        """Show an error in the window and on stderr, keeping what is drawn."""
        print(message, file=sys.stderr)
        if self.closed():
            return  # no window to show it in: stderr has it
        kept = "\n(the picture is the last version that worked)" if self.scene.layers else ""
        self.scene.set_error(message + kept)
        self.plotter.render()

    def _status(self) -> None:
        if not self.timing or self.graph is None or self.seconds is None:
            return
        name = Path(self.graph.file).name if self.graph.file else "graph"
        text = f"{name}: {self.status_line()}"
        if self.layout == "overlay":
            self.scene.set_status(text)
        elif self._has_controls_column():  # at the top of the sliders' column
            self._controls_frame()
            self.plotter.add_text(
                text, position="upper_left", font_size=12, color=TEXT_COLOR, name="status"
            )
        else:  # under the first view's title
            scene = self.scenes[0]
            scene.activate()
            self.plotter.add_text(
                text,
                position=(10, scene.size()[1] - 62),
                font_size=8,
                color=TEXT_COLOR,
                name="status",
            )

    def _has_controls_column(self) -> bool:
        return self.layout == "side" and self.plotter.shape[1] > len(self.scenes)

    def _controls_frame(self) -> tuple[float, float, float, float]:
        """Make the sliders' subplot active: (left, right) of the sliders as fractions of
        it, and its left edge and width as fractions of the window."""
        if self._has_controls_column():
            self.plotter.subplot(0, len(self.scenes))
            vx0, _, vx1, _ = self.plotter.renderer.GetViewport()
            return 0.08, 0.92, vx0, vx1 - vx0
        self.scene.activate()
        return self.controls_x, 0.97, 0.0, 1.0

    def status_line(self) -> str:
        """``'evaluated in 8.7 ms (3 computed, 4 cached)'`` for the last evaluation."""
        stats = self.graph.stats if self.graph is not None else {}
        computed = sum(1 for s in stats.values() if s.status == "computed")
        cached = len(stats) - computed
        seconds = self.seconds or 0.0
        return f"evaluated in {_ms(seconds)} ({computed} computed, {cached} cached)"

    # ------------------------------------------------------------------ interaction

    def sliders(self) -> list[Slider]:
        """Every numeric graph param that has both a min and a max."""
        if self.graph is None:
            return []
        out = []
        values = {**self.graph.params, **self.params}
        for name, p in self.graph.param_defs.items():
            value = values.get(name)
            if p.min is None or p.max is None or isinstance(value, bool):
                continue
            if not isinstance(value, (int, float)):
                continue
            integer = param_kind(p) is int or (p.type is not None and p.type.name == "int")
            out.append(Slider(name, float(p.min), float(p.max), float(value), integer, p.doc))
        return out

    def on_slider(self, name: str, value: float) -> bool:
        """A slider moved: round integer params, skip repeats, then :meth:`apply_params`."""
        spec = next(s for s in self.sliders() if s.name == name)
        v: float | int = int(round(value)) if spec.integer else float(value)
        if self._slider_values.get(name) == v:
            return True
        self._slider_values[name] = v
        self._title_slider(name, v)
        return self.apply_params(**{name: v})

    def _title_slider(self, name: str, value: float) -> None:
        """The slider's title, ``name = value   (min to max)``: the value lives in the
        title, not in a label over the knob, which would run into the slider above."""
        widget = self.widgets.get(name)
        spec = self._slider_specs.get(name)
        if widget is None or spec is None:
            return
        shown = f"{value:.0f}" if spec.integer else f"{value:.4g}"
        widget.GetRepresentation().SetTitleText(
            f"{name} = {shown}   ({spec.min:g} to {spec.max:g})"
        )

    def toggles(self) -> list[str]:
        """Every bool graph param (each gets a check box)."""
        if self.graph is None:
            return []
        values = {**self.graph.params, **self.params}
        return [n for n in self.graph.param_defs if isinstance(values.get(n), bool)]

    def on_toggle(self, name: str, state: bool) -> bool:
        """A check box was clicked: :meth:`apply_params` with the bool param set."""
        return self.apply_params(**{name: bool(state)})

    def add_toggles(self, top: float) -> None:
        """One check box per bool param, below the sliders (``top`` is where they start)."""
        values = {**self.graph.params, **self.params} if self.graph is not None else {}
        width, height = self.plotter.window_size
        box = max(14, int(0.03 * height))
        left, _, vx0, vw = self._controls_frame()
        for i, name in enumerate(self.toggles()):
            y = top - i * 0.06
            widget = self.plotter.add_checkbox_button_widget(
                lambda state, name=name: self.on_toggle(name, state),
                value=bool(values[name]),
                position=(int((vx0 + left * vw) * width), int(y * height)),
                size=box,
                color_on="steelblue",
                color_off="white",
                background_color=TEXT_COLOR,
            )
            self.plotter.add_text(  # placed in the subplot's own pixels
                name,
                position=(int(left * vw * width) + box + 8, int(y * height)),
                font_size=7,
                color=TEXT_COLOR,
            )
            self.widgets[name] = widget

    def add_sliders(self) -> None:
        """One slider per ranged numeric param, in a column at the right, then a check box
        per bool param. The view is shifted left so that they do not cover the geometry.
        """
        sliders = self.sliders()
        toggles = self.toggles()
        if not sliders and not toggles:
            return
        if not sliders:
            self.add_toggles(0.74)
            self._make_room()
            self.plotter.render()
            return
        step = min(0.11, 0.72 / len(sliders))
        left, right, _, _ = self._controls_frame()
        for i, s in enumerate(sliders):
            y = 0.74 - i * step
            self._slider_values[s.name] = int(s.value) if s.integer else s.value
            widget = self.plotter.add_slider_widget(
                lambda v, name=s.name: self.on_slider(name, v),
                rng=(s.min, s.max),
                value=s.value,
                title=f"{s.name}   ({s.min:g} to {s.max:g})",
                pointa=(left, y),
                pointb=(right, y),
                color=TEXT_COLOR,
                interaction_event="always",
                fmt="%.0f" if s.integer else "%.3g",
                title_height=0.018,
            )
            _style_slider(widget.GetRepresentation())
            self.widgets[s.name] = widget
            self._slider_specs[s.name] = s
            self._title_slider(s.name, s.value)
        if toggles:
            self.add_toggles(0.74 - len(sliders) * step - 0.02)
        self._make_room()
        self.plotter.render()

    def _make_room(self) -> None:
        """Frame the geometry beside the column of sliders."""
        if self.layout == "overlay":
            self.scene.view_shift = 1.0 - self.controls_x + 0.01
        self.fit_camera()

    def add_keys(self) -> None:
        """Key toggles: control polygons, control nets, grid, fit."""
        p = self.plotter

        def toggle(what: str) -> None:
            for scene in self.scenes:
                if what == "grid":
                    scene.toggle_grid()
                elif what == "edges":
                    scene.toggle_edges()
                else:
                    scene.toggle(what)
            if what == "grid":  # the grid's labels need room around the geometry
                self.fit_camera()
            p.render()

        p.add_key_event("c", lambda: toggle("polygon"))
        p.add_key_event("n", lambda: toggle("net"))
        p.add_key_event("g", lambda: toggle("grid"))
        p.add_key_event("e", lambda: toggle("edges"))
        p.add_key_event("f", lambda: (self.fit_camera(), p.render()))
        if self.layout == "overlay":
            self.scene.set_help(HELP)
            return
        short = HELP_LINES
        if self._has_controls_column():
            self._controls_frame()
            p.add_text(short, position="lower_left", font_size=8, color="#777777", name="help")
        else:
            self.scenes[-1].set_help(short)


def _style_slider(rep: Any) -> None:
    """A slim slider: thin grey track, small accent knob, value above, name below."""
    import pyvista as pv

    rep.SetSliderLength(0.018)
    rep.SetSliderWidth(0.022)
    rep.SetTubeWidth(0.006)
    rep.SetEndCapLength(0.004)
    rep.SetEndCapWidth(0.022)
    rep.SetLabelHeight(0.018)
    rep.ShowSliderLabelOff()  # the value is in the title (see Session._title_slider)
    rep.GetTubeProperty().SetColor(pv.Color("#c8c8c8").float_rgb)
    rep.GetCapProperty().SetColor(pv.Color("#c8c8c8").float_rgb)
    rep.GetSliderProperty().SetColor(pv.Color(PALETTE[0]).float_rgb)
    rep.GetSelectedProperty().SetColor(pv.Color(PALETTE[3]).float_rgb)
    for prop in (rep.GetTitleProperty(), rep.GetLabelProperty()):
        prop.SetBold(False)
        prop.SetShadow(False)


def _camera_lost(old: Any, new: Any) -> bool:
    """Whether new bounds no longer suit a camera framed for the old ones."""
    import numpy as np

    from .frame import view_axis

    if old is None or new is None:
        return new is not None
    a, b = np.asarray(old).reshape(3, 2), np.asarray(new).reshape(3, 2)
    size_a = float(np.linalg.norm(a[:, 1] - a[:, 0]))
    size_b = float(np.linalg.norm(b[:, 1] - b[:, 0]))
    slack = 0.25 * max(size_a, 1e-12)
    outside = bool(np.any(b[:, 0] < a[:, 0] - slack) or np.any(b[:, 1] > a[:, 1] + slack))
    return outside or size_b < 0.3 * size_a or view_axis(old) != view_axis(new)


def _base(graph: Graph, target: str) -> str:
    return target if target in graph.nodes else target.split(".", 1)[0]


def _label_of(value: Any) -> str:
    return ""  # a value shown as it is: the legend says what it is


def _ms(seconds: float) -> str:
    return f"{seconds * 1000:.1f} ms" if seconds < 10 else f"{seconds:.1f} s"
