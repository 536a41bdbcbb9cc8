"""From node values to pyvista actors: one colour and one legend entry per shown node.

A :class:`Scene` draws a list of ``(label, value)`` pairs, where a value is any geometry, a
list of geometries or a multi-output tuple. Every label becomes a :class:`Layer` with at
most one actor per kind of geometry (points, curves, surfaces, meshes), plus the control
polygons of NURBS curves and the control nets of NURBS surfaces (hidden until toggled).
:meth:`Scene.update` redraws in place: an actor that exists keeps its dataset object, which
is overwritten with the new geometry, so the window is never rebuilt.

pyvista is imported inside the functions, so importing this module costs nothing.
"""

from __future__ import annotations

import textwrap
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from formgraph.geometry import Curve, Geometry, Mesh, NurbsCurve, NurbsSurface, Points, Surface

__all__ = ["PALETTE", "Layer", "Scene", "expand", "geometry_items", "view_axis"]

# matplotlib's tab10, which reads well on white and keeps neighbours apart
PALETTE = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#17becf",
    "#bcbd22",
    "#7f7f7f",
)
BACKGROUND = "white"
GRID_COLOR = "#8a8a8a"
ERROR_COLOR = "#b00020"
TEXT_COLOR = "#333333"

# the four kinds of drawn geometry, in drawing order, and the two control overlays
KINDS = ("meshes", "surfaces", "curves", "points")
OVERLAYS = ("polygon", "net")
LEGEND_FACE = {"meshes": "rectangle", "surfaces": "rectangle", "curves": "line", "points": "circle"}


def expand(label: str, value: Any) -> list[tuple[str, Any]]:
    """Split a multi-output tuple into one ``(label.field, value)`` pair per output."""
    if isinstance(value, tuple) and hasattr(value, "_fields"):
        return [(f"{label}.{name}", getattr(value, name)) for name in value._fields]
    return [(label, value)]


def geometry_items(value: Any) -> list[Geometry]:
    """Every geometry in ``value`` (a geometry, or lists and tuples of them, nested)."""
    if isinstance(value, Geometry):
        return [value]
    if isinstance(value, (list, tuple)):
        return [g for v in value for g in geometry_items(v)]
    return []


def describe(value: Any, items: Sequence[Geometry]) -> str:
    """A few words for the legend: what the value is and how big."""
    if not items:
        text = repr(value)
        text = text if len(text) <= 30 else text[:27] + "..."
        return f"{type(value).__name__} {text}, nothing to draw"
    if len(items) > 1:
        names = sorted({type(g).__name__ for g in items})
        return f"{len(items)} x {names[0] if len(names) == 1 else 'geometry'}"
    g = items[0]
    if isinstance(g, Mesh):
        return f"Mesh, {g.n_faces:,} faces"
    if isinstance(g, Points):
        return f"Points, {len(g):,}"
    return type(g).__name__


# ---------------------------------------------------------------------------- datasets


def _polylines(chains: Sequence[np.ndarray]) -> Any:
    """One PolyData holding every chain of points as a polyline."""
    import pyvista as pv

    chains = [np.asarray(c, dtype=np.float64) for c in chains if len(c) >= 2]
    if not chains:
        return None
    pts = np.concatenate(chains)
    sizes = np.array([len(c) for c in chains])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    cells = np.insert(np.arange(len(pts)), starts, sizes)
    return pv.PolyData(pts, lines=cells)


def _merge(datasets: Sequence[Any]) -> Any:
    datasets = [d for d in datasets if d is not None and d.n_points > 0]
    if not datasets:
        return None
    if len(datasets) == 1:
        return datasets[0]
    return datasets[0].append_polydata(*datasets[1:])


def _control_net(cp: np.ndarray) -> Any:
    """The rows and columns of a (nu, nv, 3) control grid as polylines."""
    import pyvista as pv

    nu, nv, _ = cp.shape
    idx = np.arange(nu * nv).reshape(nu, nv)
    rows = np.hstack([np.full((nu, 1), nv), idx]).ravel()
    cols = np.hstack([np.full((nv, 1), nu), idx.T]).ravel()
    return pv.PolyData(np.array(cp.reshape(-1, 3)), lines=np.concatenate([rows, cols]))


def _surface_resolution(s: Surface) -> tuple[int, int]:
    if isinstance(s, NurbsSurface):
        spans_u = max(1, len(np.unique(s.knots_u)) - 1)
        spans_v = max(1, len(np.unique(s.knots_v)) - 1)
        return int(np.clip(8 * spans_u, 32, 128)), int(np.clip(8 * spans_v, 32, 128))
    return 64, 64


def datasets_of(items: Sequence[Geometry]) -> dict[str, Any]:
    """The PolyData of each kind (and overlay) present in ``items``."""
    import pyvista as pv

    points = [np.asarray(g.xyz) for g in items if isinstance(g, Points) and len(g)]
    curves = [g for g in items if isinstance(g, Curve)]
    surfaces = [g for g in items if isinstance(g, Surface)]
    meshes = [g for g in items if isinstance(g, Mesh) and g.n_faces]
    out = {
        "points": pv.PolyData(np.concatenate(points)) if points else None,
        "curves": _polylines([c.display_points() for c in curves]),
        "surfaces": _merge([s.tessellate(*_surface_resolution(s)).to_pyvista() for s in surfaces]),
        "meshes": _merge([m.to_pyvista() for m in meshes]),
        "polygon": _polylines([c.control_points for c in curves if isinstance(c, NurbsCurve)]),
        "net": _merge(
            [_control_net(s.control_points) for s in surfaces if isinstance(s, NurbsSurface)]
        ),
    }
    return {k: v for k, v in out.items() if v is not None and v.n_points > 0}


# ----------------------------------------------------------------------------- colours


def _mix(color: str, other: str, t: float) -> tuple[float, float, float]:
    import pyvista as pv

    a = np.array(pv.Color(color).float_rgb)
    b = np.array(pv.Color(other).float_rgb)
    return tuple(float(x) for x in (1 - t) * a + t * b)  # type: ignore[return-value]


def _style(kind: str, color: str) -> dict[str, Any]:
    """add_mesh keywords for one kind of geometry drawn in ``color``."""
    if kind == "points":
        return dict(color=color, render_points_as_spheres=True, point_size=12, style="points")
    if kind == "curves":
        return dict(color=color, line_width=3.5, render_lines_as_tubes=True)
    if kind == "surfaces":
        return dict(
            color=color,
            smooth_shading=True,
            ambient=0.2,
            diffuse=0.8,
            specular=0.25,
            specular_power=20,
        )
    if kind == "meshes":
        return dict(
            color=color,
            show_edges=True,
            edge_color=_mix(color, "black", 0.45),
            ambient=0.2,
            diffuse=0.8,
        )
    # control polygon / net: thin lines in a paler shade, with their control points
    return dict(color=_mix(color, "black", 0.35), line_width=1.2, style="wireframe")


# ------------------------------------------------------------------------------- scene


@dataclass
class Part:
    """One actor of a layer and the dataset object it draws (overwritten on update)."""

    data: Any
    actor: Any
    vertices: Any = None  # control points drawn over a control polygon / net
    vertex_actor: Any = None


@dataclass
class Layer:
    """Everything drawn for one shown node: its colour and one part per kind."""

    label: str
    color: str
    summary: str = ""
    parts: dict[str, Part] = field(default_factory=dict)

    @property
    def kinds(self) -> list[str]:
        return [k for k in KINDS if k in self.parts]


def view_axis(bounds: Sequence[float], rel: float = 1e-9) -> int | None:
    """The axis (0, 1, 2) along which ``bounds`` are flat, or None for a 3-D extent.

    A flat z is preferred (a top view), then y, then x.
    """
    b = np.asarray(bounds, dtype=np.float64).reshape(3, 2)
    extent = b[:, 1] - b[:, 0]
    size = float(extent.max())
    if size <= 0.0:
        return None
    for axis in (2, 1, 0):
        if extent[axis] <= rel * size:
            return axis
    return None


class Scene:
    """The drawn state of a plotter: layers by label, legend, bounds grid and texts.

    Parameters
    ----------
    plotter : pyvista.Plotter
        Where to draw (on screen or off screen).
    """

    def __init__(self, plotter: Any):
        self.plotter = plotter
        self.layers: dict[str, Layer] = {}
        self.colors: dict[str, str] = {}
        self.show_polygons = False
        self.show_nets = False
        self.show_grid = True
        self.error: str | None = None
        self.view_shift = 0.0  # move the picture left, to leave room for the sliders
        self._drawn_grid: Any = None  # what the bounds grid and legend show now
        self._drawn_legend: list[Any] = []
        plotter.set_background(BACKGROUND)
        plotter.enable_anti_aliasing("ssaa")

    # ---------------------------------------------------------------------- drawing

    def color_of(self, label: str) -> str:
        if label not in self.colors:
            self.colors[label] = PALETTE[len(self.colors) % len(PALETTE)]
        return self.colors[label]

    def update(self, shown: Iterable[tuple[str, Any]]) -> None:
        """Draw ``(label, value)`` pairs, reusing the actors already there."""
        pairs = [p for label, value in shown for p in expand(label, value)]
        seen = set()
        for label, value in pairs:
            seen.add(label)
            items = geometry_items(value)
            layer = self.layers.get(label)
            if layer is None:
                layer = self.layers[label] = Layer(label, self.color_of(label))
            layer.summary = describe(value, items)
            self._update_layer(layer, datasets_of(items))
        for label in [lb for lb in self.layers if lb not in seen]:
            for kind in list(self.layers[label].parts):
                self._remove_part(self.layers[label], kind)
            del self.layers[label]
        # the legend follows the author's order of the shown nodes
        self.layers = {label: self.layers[label] for label, _ in pairs}
        self._legend()
        self._bounds_grid()

    def _update_layer(self, layer: Layer, data: dict[str, Any]) -> None:
        for kind in KINDS + OVERLAYS:
            new = data.get(kind)
            part = layer.parts.get(kind)
            if new is None:
                if part is not None:
                    self._remove_part(layer, kind)
                continue
            if part is None:
                layer.parts[kind] = self._add_part(layer, kind, new)
                continue
            part.data.copy_from(new)
            if part.vertices is not None:
                part.vertices.copy_from(_vertices(new))

    def _add_part(self, layer: Layer, kind: str, data: Any) -> Part:
        actor = self.plotter.add_mesh(data, reset_camera=False, **_style(kind, layer.color))
        part = Part(data, actor)
        if kind in OVERLAYS:
            part.vertices = _vertices(data)
            style = dict(_style("points", _mix(layer.color, "black", 0.35)), point_size=7)
            part.vertex_actor = self.plotter.add_mesh(part.vertices, reset_camera=False, **style)
            self._set_overlay_visible(
                part, self.show_polygons if kind == "polygon" else self.show_nets
            )
        return part

    def _remove_part(self, layer: Layer, kind: str) -> None:
        part = layer.parts.pop(kind)
        self.plotter.remove_actor(part.actor, render=False)
        if part.vertices is not None:
            self.plotter.remove_actor(part.vertex_actor, render=False)

    @staticmethod
    def _set_overlay_visible(part: Part, visible: bool) -> None:
        part.actor.SetVisibility(visible)
        part.vertex_actor.SetVisibility(visible)

    def toggle(self, overlay: str) -> bool:
        """Show or hide the control polygons (``'polygon'``) or control nets (``'net'``)."""
        if overlay == "polygon":
            self.show_polygons = visible = not self.show_polygons
        elif overlay == "net":
            self.show_nets = visible = not self.show_nets
        else:
            raise ValueError(f"overlay must be 'polygon' or 'net', got {overlay!r}")
        for layer in self.layers.values():
            if overlay in layer.parts:
                self._set_overlay_visible(layer.parts[overlay], visible)
        return visible

    def toggle_grid(self) -> bool:
        self.show_grid = not self.show_grid
        self._bounds_grid()
        return self.show_grid

    # ------------------------------------------------------------------ bounds, camera

    def bounds(self) -> tuple[float, ...] | None:
        """The bounds of the drawn geometry (control overlays included), or None if empty."""
        boxes = [
            np.asarray(part.data.bounds).reshape(3, 2)
            for layer in self.layers.values()
            for part in layer.parts.values()
            if part.data.n_points
        ]
        if not boxes:
            return None
        lo = np.min([b[:, 0] for b in boxes], axis=0)
        hi = np.max([b[:, 1] for b in boxes], axis=0)
        return tuple(float(x) for x in np.column_stack([lo, hi]).ravel())

    def fit_camera(self) -> None:
        """Frame everything: a top (or side) view of flat geometry, else isometric."""
        grid = self.grid_bounds()
        if grid is None:
            return
        bounds = grid[0] if self.show_grid else self.bounds()
        axis = view_axis(bounds)
        p = self.plotter
        # sliders take the right of the window: centre the picture in what is left; the
        # legend takes the top right: on a drawing, move the picture down below it
        legend = self._legend_height() if axis is not None else 0.0
        p.camera.SetWindowCenter(self.view_shift, legend)
        # flat geometry is a drawing: look straight at it, without perspective
        p.camera.parallel_projection = axis is not None
        {None: p.view_isometric, 2: p.view_xy, 1: p.view_xz, 0: p.view_yz}[axis](render=False)
        p.reset_camera(render=False, bounds=bounds)
        # leave room for the axis labels (and, on a drawing, the legend above it)
        self._zoom_to_fit(bounds, fill=0.8 if axis is None else 0.8 - legend)

    def _zoom_to_fit(self, bounds: Sequence[float], fill: float) -> None:
        """Zoom until the box's projection fills ``fill`` of the free part of the window.

        reset_camera frames the bounding sphere, which leaves a flat or long box small.
        """
        ren = self.plotter.renderer
        width, height = self.plotter.window_size
        free_w = width * (1.0 - self.view_shift)
        corners = np.array(np.meshgrid(*np.asarray(bounds).reshape(3, 2), indexing="ij"))
        corners = corners.reshape(3, -1).T
        for _ in range(2):  # perspective: the second pass corrects the first
            xy = np.empty((len(corners), 2))
            for k, c in enumerate(corners):  # eight corners
                ren.SetWorldPoint(*c, 1.0)
                ren.WorldToDisplay()
                xy[k] = ren.GetDisplayPoint()[:2]
            w, h = np.ptp(xy, axis=0)
            if w <= 0 and h <= 0:
                return
            factor = fill * min(free_w / max(w, 1e-9), height / max(h, 1e-9))
            self.plotter.camera.zoom(float(factor))

    def grid_bounds(self) -> tuple[tuple[float, ...], tuple[int, int, int]] | None:
        """The bounds grid's box, widened to round tick values, and its label counts."""
        bounds = self.bounds()
        if bounds is None:
            return None
        b = np.asarray(bounds).reshape(3, 2)
        size = float((b[:, 1] - b[:, 0]).max())
        box, counts = [], []
        for lo, hi in b:
            lo2, hi2, n = nice_range(lo, hi, size)
            box += [lo2, hi2]
            counts.append(n)
        return tuple(box), (counts[0], counts[1], counts[2])

    def _bounds_grid(self) -> None:
        p = self.plotter
        grid = self.grid_bounds() if self.show_grid else None
        if grid == self._drawn_grid and (grid is None) == (p.renderer.cube_axes_actor is None):
            return  # unchanged: rebuilding the axes is most of a slider step's drawing time
        self._drawn_grid = grid
        p.remove_bounds_axes()
        if grid is None:
            return
        box, (nx, ny, nz) = grid
        axis = view_axis(box)
        p.show_bounds(
            bounds=box,
            grid="back",
            location="outer",
            ticks="outside",
            color=GRID_COLOR,
            font_size=9,
            bold=False,
            xtitle="x",
            ytitle="y",
            ztitle="z",
            show_xaxis=axis != 0,
            show_yaxis=axis != 1,
            show_zaxis=axis != 2,
            show_xlabels=nx > 0,
            show_ylabels=ny > 0,
            show_zlabels=nz > 0,
            n_xlabels=max(nx, 2),
            n_ylabels=max(ny, 2),
            n_zlabels=max(nz, 2),
            fmt="%.4g",
            render=False,
        )

    # -------------------------------------------------------------------- legend, text

    def _legend_height(self) -> float:
        """The fraction of the window's height the legend takes (0 with no legend)."""
        n = len(self.layers)
        return 0.0 if n == 0 else min((20 * n + 8) / self.plotter.window_size[1], 0.5)

    def _legend(self) -> None:
        p = self.plotter
        entries = []
        for layer in self.layers.values():
            kinds = layer.kinds
            face = LEGEND_FACE[kinds[0]] if kinds else "none"
            text = f"{layer.label} ({layer.summary})" if layer.label else layer.summary
            entries.append([text, layer.color, face])
        if entries == self._drawn_legend and p.legend is not None:
            return
        self._drawn_legend = entries
        if p.legend is not None:
            p.remove_legend(render=False)
        if not entries:
            return
        # placed by hand: pyvista's loc="upper right" offsets x by the height, not the width
        # about 13-pixel text, whatever the window size
        win_w, win_h = p.window_size
        height = self._legend_height()
        width = min((7.5 * max(len(e[0]) for e in entries) + 34) / win_w, 0.45)
        legend = p.add_legend(
            entries,
            bcolor="white",
            border=True,
            size=(width, height),
            loc=None,
            background_opacity=0.85,
        )
        legend.SetPosition(0.985 - width, 0.985 - height)
        legend.SetPosition2(width, height)

    def set_status(self, text: str | None) -> None:
        """The line at the top left (evaluation time), or nothing."""
        if text is None:
            self.plotter.remove_actor("status", render=False)
            return
        self.plotter.add_text(
            text, position="upper_left", font_size=9, color=TEXT_COLOR, name="status"
        )

    def set_help(self, text: str) -> None:
        self.plotter.add_text(
            text, position="lower_right", font_size=8, color="#777777", name="help"
        )

    def set_error(self, message: str | None) -> None:
        """Show an error at the bottom left (red, wrapped), or clear it."""
        self.error = message
        if message is None:
            self.plotter.remove_actor("error", render=False)
            return
        lines = []
        for line in message.splitlines()[:12]:
            lines.extend(textwrap.wrap(line, 90) or [""])
        self.plotter.add_text(
            "\n".join(lines[:16]),
            position="lower_left",
            font_size=9,
            color=ERROR_COLOR,
            name="error",
        )

    def texts(self) -> dict[str, str]:
        """The texts on screen by name (status, error, help), for tests and notebooks."""
        out = {}
        for name in ("status", "error", "help"):
            actor = self.plotter.actors.get(name)
            if actor is not None:
                out[name] = _text_of(actor)
        return out


def nice_range(lo: float, hi: float, size: float, max_ticks: int = 9) -> tuple[float, float, int]:
    """``[lo, hi]`` widened to the nearest multiples of a round step, and the tick count.

    The step is 1, 2, 2.5 or 5 times a power of ten, at least ``size / 12`` (so labels on a
    short axis do not crowd), with at most ``max_ticks`` ticks; of those, the one that widens
    the range least (then the one with nearer five ticks). A thin axis (under ``size / 12``)
    keeps its ends and gets no labels (0: they would overlap); a flat one (``hi - lo`` tiny
    next to ``size``) gets one tick.
    """
    if size <= 0 or hi - lo <= 1e-9 * size:
        return lo, hi, 1
    if hi - lo < size / 12:  # a thin axis: widening it to a round step would swamp it
        return lo, hi, 0
    best: tuple[tuple[float, int], float, float, int] | None = None
    for power in range(int(np.floor(np.log10(hi - lo))) - 1, int(np.floor(np.log10(size))) + 2):
        for m in (1.0, 2.0, 2.5, 5.0):
            step = m * 10.0**power
            if step < size / 12:
                continue
            lo2 = step * np.floor(lo / step + 1e-9)
            hi2 = step * np.ceil(hi / step - 1e-9)
            n = int(round((hi2 - lo2) / step)) + 1
            key = (round(float(hi2 - lo2) / size, 9), abs(n - 5))
            if n <= max_ticks and (best is None or key < best[0]):
                best = (key, float(lo2), float(hi2), n)
    assert best is not None  # the largest step always fits in two or three ticks
    return best[1], best[2], best[3]


def _vertices(data: Any) -> Any:
    import pyvista as pv

    return pv.PolyData(np.array(data.points))


def _padded(bounds: Sequence[float], rel: float) -> tuple[float, ...]:
    b = np.asarray(bounds, dtype=np.float64).reshape(3, 2).copy()
    pad = rel * float((b[:, 1] - b[:, 0]).max())
    b[:, 0] -= pad
    b[:, 1] += pad
    return tuple(float(x) for x in b.ravel())


def _text_of(actor: Any) -> str:
    if hasattr(actor, "GetText") and actor.IsA("vtkCornerAnnotation"):
        return "\n".join(actor.GetText(i) or "" for i in range(8) if actor.GetText(i))
    return actor.GetInput()
