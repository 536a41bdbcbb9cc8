"""From node values to pyvista actors: one colour and one legend entry per shown node.

A :class:`Scene` draws a list of ``(label, value)`` pairs, where a value is any geometry, a
list of geometries or a multi-output tuple, in one view (the window, or one subplot of the
side by side layout). Every label becomes a :class:`Layer` with at most one actor per kind
of geometry (points, curves, surfaces, meshes), the feature edges of its surfaces and
meshes, and the control polygons of NURBS curves and control nets of NURBS surfaces
(hidden until toggled). How each is shaded is in :mod:`.style`, the framing in
:mod:`.frame`.
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

from formgraph.geometry import Mesh

from .datasets import KINDS, colour_by, datasets_of, describe, expand, geometry_items, vertices_of
from .frame import Camera, ScaleBar, fit_scenes, nice_range, sample, size_text, view_axis
from .style import (
    BACKGROUND,
    COARSE_FACES,
    ERROR_COLOR,
    GRID_COLOR,
    PALETTE,
    TEXT_COLOR,
    apply_material,
    mix,
    set_edges,
    style,
)

__all__ = [
    "PALETTE",
    "TEXT_COLOR",
    "Layer",
    "Scene",
    "fit_scenes",
    "nice_range",
    "view_axis",
]

# the control overlays, and the lines
# drawn along feature edges and open boundaries of surfaces and meshes
OVERLAYS = ("polygon", "net")
LINES = ("features",)
LEGEND_FACE = {"meshes": "rectangle", "surfaces": "rectangle", "curves": "line", "points": "circle"}
STATUS_HEIGHT = 26  # pixels a line of text takes at the top or bottom of a view


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
    mesh_faces: int = 0  # faces of the meshes drawn (what makes a mesh coarse)

    @property
    def kinds(self) -> list[str]:
        return [k for k in KINDS if k in self.parts]


class Scene:
    """The drawn state of one view: layers by label, legend or title, texts, scale.

    Parameters
    ----------
    plotter : pyvista.Plotter
        Where to draw (on screen or off screen).
    subplot : (int, int), optional
        The subplot of ``plotter`` this scene draws in (the plotter's only one by default).
    titled : bool
        Name what is shown in a title at the top left (one node per view, as in the side
        by side layout) instead of in a legend at the top right.
    edges : bool, optional
        Draw the edges of every mesh face (True), of none (False), or of coarse meshes only
        (None, at most :data:`~.style.COARSE_FACES` faces).
    colors : dict, optional
        Label -> colour, shared between scenes so that a node keeps its colour.
    color_by : str, optional
        An attribute to colour points, surfaces and meshes by, with a colour bar (a
        ``color`` of 3 or 4 components in 0..1 is drawn as those colours).
    """

    def __init__(
        self,
        plotter: Any,
        subplot: tuple[int, int] | None = None,
        *,
        titled: bool = False,
        edges: bool | None = None,
        colors: dict[str, str] | None = None,
        color_by: str | None = None,
    ):
        self.plotter = plotter
        self.color_by = color_by
        self.subplot = subplot
        self.titled = titled
        self.edges = edges
        self.layers: dict[str, Layer] = {}
        self.colors: dict[str, str] = colors if colors is not None else {}
        self.captions: dict[str, str] = {}  # label -> node type, for titles
        self.show_polygons = False
        self.show_nets = False
        self.show_grid = False
        self.error: str | None = None
        self.view_shift = 0.0  # move the picture left, to leave room for the sliders
        self._drawn_grid: Any = None  # what the bounds grid and legend show now
        self._drawn_legend: list[Any] = []
        self._legend_width = 0.0  # fraction of the view's width the legend takes
        self.free = (0.0, 0.0, 1.0, 1.0)  # where the last fit put the picture (fractions)
        self.camera = Camera()  # where fit_scenes looks from (automatic unless told)
        self.activate()
        self.renderer = plotter.renderer
        plotter.set_background(BACKGROUND)
        plotter.enable_anti_aliasing("ssaa")
        self.scale_bar = ScaleBar(self.renderer)

    def set_frame(self, bounds: Sequence[float] | None) -> None:
        """An invisible box (8 points, opacity 0) that this view's clipping planes must
        keep: views sharing a camera then never clip what another view draws."""
        import pyvista as pv

        self.activate()
        if bounds is None:
            self.plotter.remove_actor("frame", render=False)
            return
        b = np.asarray(bounds, dtype=np.float64).reshape(3, 2)
        corners = np.array(np.meshgrid(*b, indexing="ij")).reshape(3, -1).T
        actor = self.plotter.add_mesh(
            pv.PolyData(corners), opacity=0.0, name="frame", reset_camera=False, pickable=False
        )
        actor.SetPickable(False)

    def activate(self) -> None:
        """Make this scene's subplot the one the plotter draws in."""
        if self.subplot is not None:
            self.plotter.subplot(*self.subplot)

    def size(self) -> tuple[int, int]:
        """This view's size in pixels."""
        w, h = self.renderer.GetSize()
        if w <= 0 or h <= 0:  # not rendered yet: the window's share
            rows, cols = self.plotter.shape
            ww, wh = self.plotter.window_size
            return max(1, ww // cols), max(1, wh // rows)
        return int(w), int(h)

    # ---------------------------------------------------------------------- drawing

    def color_of(self, label: str) -> str:
        if label not in self.colors:
            self.colors[label] = PALETTE[len(self.colors) % len(PALETTE)]
        return self.colors[label]

    def update(self, shown: Iterable[tuple[str, Any]]) -> None:
        """Draw ``(label, value)`` pairs, reusing the actors already there."""
        self.activate()
        pairs = [p for label, value in shown for p in expand(label, value)]
        seen = set()
        for label, value in pairs:
            seen.add(label)
            items = geometry_items(value)
            layer = self.layers.get(label)
            if layer is None:
                layer = self.layers[label] = Layer(label, self.color_of(label))
            layer.summary = describe(value, items)
            layer.mesh_faces = sum(g.n_faces for g in items if isinstance(g, Mesh))
            self._update_layer(layer, datasets_of(items))
        for label in [lb for lb in self.layers if lb not in seen]:
            for kind in list(self.layers[label].parts):
                self._remove_part(self.layers[label], kind)
            del self.layers[label]
        # the legend follows the author's order of the shown nodes
        self.layers = {label: self.layers[label] for label, _ in pairs}
        self._legend()
        self._bounds_grid()
        self._size_line()

    def _update_layer(self, layer: Layer, data: dict[str, Any]) -> None:
        for kind in KINDS + OVERLAYS + LINES:
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
                part.vertices.copy_from(vertices_of(new))
        self._layer_edges(layer)

    def _add_part(self, layer: Layer, kind: str, data: Any) -> Part:
        options = style(kind, layer.color)
        if kind in ("points", "surfaces", "meshes"):
            options.update(colour_by(data, self.color_by))
        actor = self.plotter.add_mesh(data, reset_camera=False, **options)
        apply_material(actor, kind)
        part = Part(data, actor)
        if kind in OVERLAYS:
            part.vertices = vertices_of(data)
            points = dict(style("points", mix(layer.color, "black", 0.35)), point_size=7)
            part.vertex_actor = self.plotter.add_mesh(part.vertices, reset_camera=False, **points)
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

    def edges_shown(self, layer: Layer, kind: str = "meshes") -> bool:
        """Whether the face edges of a layer's meshes (or surfaces) are drawn."""
        if self.edges is not None:
            return self.edges
        return kind == "meshes" and 0 < layer.mesh_faces <= COARSE_FACES

    def _layer_edges(self, layer: Layer) -> None:
        for kind in ("meshes", "surfaces"):
            if kind in layer.parts:
                set_edges(layer.parts[kind].actor, self.edges_shown(layer, kind))

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

    def toggle_edges(self) -> bool:
        """Draw the edges of every face, or of none (the first press turns them all on
        unless every mesh shows them already)."""
        meshes = [lay for lay in self.layers.values() if "meshes" in lay.parts]
        shown = bool(meshes) and all(self.edges_shown(lay) for lay in meshes)
        self.edges = not shown
        for layer in self.layers.values():
            self._layer_edges(layer)
        return self.edges

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

    def points(self) -> np.ndarray:
        """A sample of the drawn points (what the camera frames), (m, 3)."""
        chunks = [
            sample(np.asarray(part.data.points))
            for layer in self.layers.values()
            for kind, part in layer.parts.items()
            if part.data.n_points and (kind in KINDS or part.actor.GetVisibility())
        ]
        return np.concatenate(chunks) if chunks else np.zeros((0, 3))

    def margins(self, axis: int | None) -> tuple[float, float, float, float]:
        """Pixels kept free at the left, bottom, right and top (texts, legend, scale)."""
        top = self._legend_height() * self.size()[1] + 8 if not self.titled else 2 * 20 + 8
        top = max(top, STATUS_HEIGHT)
        bottom = STATUS_HEIGHT + (ScaleBar.HEIGHT if axis is not None else 0)
        side = 10.0
        if self.show_grid:  # the grid's labels go around the box
            w, h = self.size()
            side, bottom, top = side + 0.08 * w, bottom + 0.06 * h, top + 0.04 * h
        return side, bottom, side, top

    def margin_options(self, axis: int | None) -> list[tuple[float, float, float, float]]:
        """:meth:`margins`, and with a legend the other way to keep clear of it: the
        picture beside the legend rather than below it (a tall drawing fits better so)."""
        options = [self.margins(axis)]
        if not self.titled and self.layers and not self.show_grid:
            left, bottom, right, _ = options[0]
            right += self._legend_width * self.size()[0] + 8
            options.append((left, bottom, right, float(STATUS_HEIGHT)))
        return options

    def fit_camera(self, others: Sequence[Scene] = ()) -> None:
        """Frame everything (and what ``others``, sharing this camera, draw): a straight
        view without perspective of flat geometry (a drawing), else an isometric one."""
        fit_scenes([self, *others])

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
        self.activate()
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
        """The fraction of the view's height the legend takes (0 with no legend)."""
        n = 0 if self.titled else len(self.layers)
        return 0.0 if n == 0 else min((20 * n + 8) / self.size()[1], 0.5)

    def _legend(self) -> None:
        if self.titled:
            self._title()
            return
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
        self._legend_width = 0.0
        if not entries:
            return
        # placed by hand: pyvista's loc="upper right" offsets x by the height, not the width
        # about 13-pixel text, whatever the window size
        win_w, win_h = self.size()
        height = self._legend_height()
        width = min((7.5 * max(len(e[0]) for e in entries) + 34) / win_w, 0.6)
        legend = p.add_legend(
            entries,
            bcolor="white",
            border=True,
            size=(width, height),
            loc=None,
            background_opacity=0.85,
        )
        self._legend_width = width
        legend.SetPosition(0.985 - width, 0.985 - height)
        legend.SetPosition2(width, height)

    def _title(self) -> None:
        """Name, node type and size of what this view shows, in its colour."""
        lines = []
        for layer in self.layers.values():
            caption = self.captions.get(layer.label.split(".", 1)[0], "")
            lines.append((layer.label, ", ".join(x for x in (caption, layer.summary) if x)))
        color = next(iter(self.layers.values())).color if self.layers else TEXT_COLOR
        head = "  ".join(label for label, _ in lines)
        tail = "; ".join(text for _, text in lines)
        self.plotter.add_text(
            head, position=(10, self.size()[1] - 28), font_size=12, color=color, name="title"
        )
        self.plotter.add_text(
            tail, position=(10, self.size()[1] - 46), font_size=8, color=TEXT_COLOR, name="caption"
        )

    def _size_line(self) -> None:
        """The size of what is drawn, in model units, at the bottom left."""
        bounds = self.bounds()
        if bounds is None:
            self.plotter.remove_actor("size", render=False)
            return
        self.plotter.add_text(
            size_text(bounds, view_axis(bounds)),
            position=(12, 6),
            font_size=8,
            color=TEXT_COLOR,
            name="size",
        )

    def set_status(self, text: str | None, position: str = "upper_left") -> None:
        """The line with the evaluation time (at the top left), or nothing."""
        self.activate()
        if text is None:
            self.plotter.remove_actor("status", render=False)
            return
        self.plotter.add_text(text, position=position, font_size=9, color=TEXT_COLOR, name="status")

    def set_help(self, text: str) -> None:
        self.activate()
        self.plotter.add_text(
            text, position="lower_right", font_size=8, color="#777777", name="help"
        )

    def set_error(self, message: str | None) -> None:
        """Show an error at the bottom left (red, wrapped), or clear it."""
        self.activate()
        self.error = message
        if message is None:
            self.plotter.remove_actor("error", render=False)
            return
        width = max(30, int(self.size()[0] / 7.5))
        lines = []
        for line in message.splitlines()[:12]:
            lines.extend(textwrap.wrap(line, width) or [""])
        self.plotter.add_text(
            "\n".join(lines[:16]),
            position=(10, STATUS_HEIGHT),
            font_size=9,
            color=ERROR_COLOR,
            name="error",
        )

    def texts(self) -> dict[str, str]:
        """The texts on screen by name (status, error, help, ...), for tests and notebooks."""
        self.activate()
        out = {}
        for name in ("status", "error", "help", "title", "caption", "size"):
            actor = self.plotter.actors.get(name)
            if actor is not None:
                out[name] = _text_of(actor)
        return out


def _text_of(actor: Any) -> str:
    if hasattr(actor, "GetText") and actor.IsA("vtkCornerAnnotation"):
        return "\n".join(actor.GetText(i) or "" for i in range(8) if actor.GetText(i))
    return actor.GetInput()
