"""The studio's 3-D scene: node values as vtk actors that the browser draws (vtk.js).

The page's view is rendered client side: trame-vtk serializes the plotter's actors and
sends each data array once, keyed by its hash. So a slider step must change the arrays
in place and never add or remove actors it can keep: :meth:`StudioScene.update` copies
each new dataset into the one its actor already draws, and the arrays that did not change
(the faces of a tube whose twist moved) keep their hash and are not sent again.

Colours, shading and lines are the desktop viewer's (:mod:`formgraph.viewer.style`), back
faces included: vtk.js draws an actor's back-face property, but trame-vtk does not send it,
so :func:`send_back_faces` adds it to the actor's serialization (one actor, one dataset: a
second actor culling the other side would send every array twice).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from formgraph.viewer.scene import datasets_of, expand, geometry_items
from formgraph.viewer.style import BACKGROUND, PALETTE, apply_material, mix, style

__all__ = ["StudioScene", "make_plotter", "send_back_faces"]

DRAWN = ("meshes", "surfaces", "features", "curves", "points")  # control overlays left out


def send_back_faces() -> None:
    """Make trame-vtk send each actor's back-face property (``setBackfaceProperty``).

    Wraps the serializer registered for vtk's actors; an actor without a back-face
    property serializes exactly as before. trame-vtk fills its registry again when its
    protocol starts, so this is called before each update (it does nothing when the
    wrapper is in place).
    """
    from trame_vtk.modules.vtk.serializers import registry
    from trame_vtk.modules.vtk.serializers.serialize import serialize
    from trame_vtk.modules.vtk.serializers.utils import reference_id, wrap_id

    for name in ("vtkActor", "vtkOpenGLActor"):
        original = registry.SERIALIZERS.get(name)
        if original is None or getattr(original, "sends_back_faces", False):
            continue

        def serializer(parent, actor, actor_id, context, depth, _original=original):
            out = _original(parent, actor, actor_id, context, depth)
            back = actor.GetBackfaceProperty() if out is not None else None
            if back is not None:
                back_id = reference_id(back)
                instance = serialize(actor, back, back_id, context, depth + 1)
                if instance:
                    out["dependencies"].append(instance)
                    out["calls"].append(["setBackfaceProperty", [wrap_id(back_id)]])
            return out

        serializer.sends_back_faces = True  # type: ignore[attr-defined]
        registry.SERIALIZERS[name] = serializer


def make_plotter() -> Any:
    """An off-screen plotter whose scene only the browser renders."""
    import pyvista as pv

    plotter = pv.Plotter(off_screen=True, window_size=(800, 600))
    plotter.set_background(BACKGROUND)
    return plotter


@dataclass
class _Part:
    data: Any
    actors: list[Any] = field(default_factory=list)


class StudioScene:
    """The shown nodes' geometry in a plotter, updated in place.

    Parameters
    ----------
    plotter : pyvista.Plotter
        The plotter the page's view serializes.
    """

    def __init__(self, plotter: Any):
        self.plotter = plotter
        self.parts: dict[tuple[str, str], _Part] = {}
        self.colors: dict[str, str] = {}
        self.added = 0  # actors added so far (a slider step should add none)

    def color_of(self, label: str) -> str:
        if label not in self.colors:
            self.colors[label] = PALETTE[len(self.colors) % len(PALETTE)]
        return self.colors[label]

    @staticmethod
    def prepare(shown: Iterable[tuple[str, Any]]) -> dict[tuple[str, str], Any]:
        """The datasets to draw for ``(label, value)`` pairs, by ``(label, kind)``.

        The costly half of an update (tessellating surfaces, normals, feature edges) and
        touching no actor, so the worker thread does it while the page stays responsive.
        """
        out = {}
        for label, value in (p for lv in shown for p in expand(*lv)):
            data = datasets_of(geometry_items(value))
            for kind in DRAWN:
                if kind in data:
                    out[(label, kind)] = _lean(data[kind])
        return out

    def update(self, shown: Iterable[tuple[str, Any]]) -> bool:
        """Draw ``(label, value)`` pairs; True when actors were added or removed."""
        return self.apply(self.prepare(shown))

    def apply(self, prepared: dict[tuple[str, str], Any]) -> bool:
        """Put prepared datasets in place (see :meth:`prepare`); True when actors were
        added or removed (a step that only changes geometry adds none)."""
        changed = False
        for key, new in prepared.items():
            part = self.parts.get(key)
            if part is None:
                self.parts[key] = self._add(*key, new)
                changed = True
            else:
                _copy_into(part.data, new)
        for key in [k for k in self.parts if k not in prepared]:
            for actor in self.parts.pop(key).actors:
                self.plotter.remove_actor(actor, render=False)
            changed = True
        return changed

    def _add(self, label: str, kind: str, data: Any) -> _Part:
        color = self.color_of(label)
        if kind == "features":
            kw = dict(color=mix(color, "black", 0.55), line_width=1.6)
        else:
            kw = style(kind, color)
            kw.pop("render_points_as_spheres", None)
            kw.pop("render_lines_as_tubes", None)
        part = _Part(data)
        actor = self.plotter.add_mesh(data, reset_camera=False, **kw)
        apply_material(actor, kind)  # Phong, and the back faces in BACK_FACE
        part.actors.append(actor)
        self.added += len(part.actors)
        return part

    def bounds(self) -> tuple[float, ...] | None:
        boxes = [np.asarray(p.data.bounds).reshape(3, 2) for p in self.parts.values()]
        boxes = [b for b, p in zip(boxes, self.parts.values(), strict=True) if p.data.n_points]
        if not boxes:
            return None
        lo = np.min([b[:, 0] for b in boxes], axis=0)
        hi = np.max([b[:, 1] for b in boxes], axis=0)
        return tuple(float(x) for x in np.column_stack([lo, hi]).ravel())


def _lean(data: Any) -> Any:
    """``data`` with float32 points and normals: what vtk.js draws with anyway, and half
    the bytes of float64 for every step sent to the browser."""
    if data.points.dtype != np.float32:
        data.points = data.points.astype(np.float32)
    for name in list(data.point_data.keys()):
        arr = data.point_data[name]
        if arr.dtype == np.float64:
            data.point_data[name] = arr.astype(np.float32)
    if "Normals" in data.point_data.keys():
        data.point_data.active_normals_name = "Normals"
    return data


def _copy_into(target: Any, new: Any) -> None:
    """Overwrite ``target``'s geometry with ``new``'s, keeping arrays that are equal.

    An array handed to vtk again with the same bytes keeps its hash in trame-vtk's
    serializer, but copying it still costs; the points, normals and cells are replaced
    only where they differ.
    """
    if target.n_points != new.n_points or not np.array_equal(target.points, new.points):
        target.points = new.points
    for cells in ("faces", "lines", "verts"):
        a, b = getattr(target, cells), getattr(new, cells)
        if len(a) != len(b) or not np.array_equal(a, b):
            setattr(target, cells, b)
    old_names = set(target.point_data.keys())
    for name in new.point_data.keys():
        arr = new.point_data[name]
        if name not in old_names or not np.array_equal(target.point_data[name], arr):
            target.point_data[name] = arr
    for name in old_names - set(new.point_data.keys()):
        target.point_data.remove(name)
    if "Normals" in new.point_data.keys():
        target.point_data.active_normals_name = "Normals"
