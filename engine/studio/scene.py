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

from formgraph.viewer.datasets import colour_by, datasets_of, expand, geometry_items
from formgraph.viewer.style import BACKGROUND, PALETTE, apply_material, mix, style

__all__ = [
    "ARRAYS_TOPIC",
    "Prepared",
    "SentArrays",
    "StudioScene",
    "make_plotter",
    "quantized_normals",
    "send_back_faces",
    "send_cells_once",
]

DRAWN = ("meshes", "surfaces", "features", "curves", "points")  # control overlays left out
COLOURED = ("meshes", "surfaces", "points")  # what an attribute colours (as in the viewer)
INTERNAL = {"Normals", "vtkOriginalPointIds", "vtkOriginalCellIds", "TCoords"}
ARRAYS_TOPIC = "formgraph.arrays"  # a step's new data arrays, sent ahead of its scene


class SentArrays:
    """The data arrays the pages were sent or told of, by hash, to send a step's new ones
    with it.

    vtk.js asks for each array of a scene it has not seen (one request per array, answered
    once the server's loop gets to it); the studio sends a step's new arrays ahead of its
    scene instead (:data:`ARRAYS_TOPIC`; the page's script hands them to vtk.js when it
    asks, see :data:`formgraph.studio.layout.ARRAYS`). An array the page holds already
    costs bytes when sent again, one it lacks a request: :meth:`fresh` errs neither way
    for the arrays of recent scenes, and the page asks for any it misses.
    """

    KEPT = 256  # hashes remembered (a scene has a few per actor)

    def __init__(self) -> None:
        self._seen: dict[str, None] = {}

    def fresh(self, scene: dict[str, Any]) -> list[str]:
        """The hashes of ``scene``'s arrays not in an earlier scene; all of them are
        remembered from now on."""
        from trame_vtk.modules.vtk.serializers import extract_array_hash

        out: dict[str, None] = {}
        for entry in extract_array_hash(scene):
            digest = entry.get("hash")
            if not digest:
                continue
            if digest not in self._seen:
                out[digest] = None
            self._seen.pop(digest, None)
            self._seen[digest] = None  # the newest last
        while len(self._seen) > self.KEPT:
            del self._seen[next(iter(self._seen))]
        return list(out)


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


def send_cells_once() -> None:
    """Make trame-vtk's polydata serializer convert each cell array once per change.

    trame-vtk sends a dataset's cells in vtk's legacy layout, which its serializer exports
    into a new array, hashes (md5) and scans for its range each time the scene is sent;
    a slider step sends the scene though the faces did not change (on the spiral tube,
    660 KB exported and hashed for nothing at every step). This serializer, otherwise
    trame-vtk's (its helpers, the same description), keeps each legacy array until its
    cell array changes: an unchanged one is the same array at the same time, whose hash
    trame-vtk has. Like :func:`send_back_faces`, called before each update.
    """
    from trame_vtk.modules.vtk.serializers import registry
    from trame_vtk.modules.vtk.serializers.helpers import (
        extract_required_fields,
        get_array_description,
    )
    from trame_vtk.modules.vtk.serializers.utils import get_js_array_type, reference_id

    original = registry.SERIALIZERS.get("vtkPolyData")
    if original is None or getattr(original, "sends_cells_once", False):
        return
    legacy = _LegacyCells()

    def serializer(parent, dataset, dataset_id, context, depth, requested_fields=None):
        if not dataset or not dataset.GetPoints():
            return original(parent, dataset, dataset_id, context, depth, requested_fields)
        points = dataset.GetPoints().GetData()
        js_type = get_js_array_type(points)
        convert = {}
        if js_type not in ("Float32Array", "Float64Array"):
            convert["dataType"] = "Float32Array" if "32" in js_type else "Float64Array"
        properties = {"points": get_array_description(points, context, **convert)}
        properties["points"]["vtkClass"] = "vtkPoints"
        for key, cells in (
            ("verts", dataset.GetVerts()),
            ("lines", dataset.GetLines()),
            ("polys", dataset.GetPolys()),
            ("strips", dataset.GetStrips()),
        ):
            if cells and cells.GetNumberOfCells():
                properties[key] = get_array_description(legacy(cells), context)
                properties[key]["vtkClass"] = "vtkCellArray"
        properties["fields"] = []
        wanted = ["Normals", "TCoords"] if requested_fields is None else requested_fields
        extract_required_fields(properties["fields"], parent, dataset, context, wanted)
        return {
            "parent": reference_id(parent),
            "id": dataset_id,
            "type": registry.class_name(dataset),
            "properties": properties,
        }

    serializer.sends_cells_once = True  # type: ignore[attr-defined]
    registry.SERIALIZERS["vtkPolyData"] = serializer


class _LegacyCells:
    """The legacy-layout array of each cell array, exported again only when it changed.

    Keyed by the cell array's address and modification time (vtk's global clock: a cell
    array made later at a freed one's address has a later time); the few latest kept.
    """

    KEPT = 16

    def __init__(self) -> None:
        self._kept: dict[tuple[str, int], Any] = {}

    def __call__(self, cells: Any) -> Any:
        from vtkmodules.vtkCommonCore import vtkIdTypeArray

        key = (cells.__this__, cells.GetMTime())
        out = self._kept.get(key)
        if out is None:
            out = vtkIdTypeArray()
            cells.ExportLegacyFormat(out)
            self._kept[key] = out
            while len(self._kept) > self.KEPT:
                del self._kept[next(iter(self._kept))]
        return out


def make_plotter() -> Any:
    """An off-screen plotter whose scene only the browser renders."""
    import pyvista as pv

    plotter = pv.Plotter(off_screen=True, window_size=(800, 600))
    plotter.set_background(BACKGROUND)
    return plotter


@dataclass
class Prepared:
    """What :meth:`StudioScene.prepare` makes (in the worker thread) for :meth:`apply`."""

    parts: dict[tuple[str, str], Any]
    attributes: list[str]  # the attributes there are to colour by
    color_by: str | None = None


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
        self.color_by: str | None = None  # the attribute the actors are coloured by

    def color_of(self, label: str) -> str:
        if label not in self.colors:
            self.colors[label] = PALETTE[len(self.colors) % len(PALETTE)]
        return self.colors[label]

    @staticmethod
    def prepare(shown: Iterable[tuple[str, Any]], color_by: str | None = None) -> Prepared:
        """The datasets to draw for ``(label, value)`` pairs, by ``(label, kind)``.

        The costly half of an update (tessellating surfaces, normals, feature edges) and
        touching no actor, so the worker thread does it while the page stays responsive.
        Only the arrays drawn are kept: the normals, and the attribute ``color_by``.
        """
        parts = {}
        names: set[str] = set()
        for label, value in (p for lv in shown for p in expand(*lv)):
            data = datasets_of(geometry_items(value))
            for kind in DRAWN:
                if kind in data:
                    names.update(_attributes(data[kind]))
                    parts[(label, kind)] = _lean(data[kind], color_by)
        return Prepared(parts, sorted(names), color_by if color_by in names else None)

    def update(self, shown: Iterable[tuple[str, Any]], color_by: str | None = None) -> bool:
        """Draw ``(label, value)`` pairs; True when actors were added or removed."""
        return self.apply(self.prepare(shown, color_by))

    def apply(self, prepared: Prepared) -> bool:
        """Put prepared datasets in place (see :meth:`prepare`); True when actors were
        added or removed (a step that only changes geometry adds none; a new colouring
        adds them all again)."""
        changed = False
        if prepared.color_by != self.color_by:
            self.clear()
            self.color_by = prepared.color_by
            changed = True
        for key, new in prepared.parts.items():
            part = self.parts.get(key)
            if part is None:
                self.parts[key] = self._add(*key, new)
                changed = True
            else:
                _copy_into(part.data, new)
                self._rescale(part)
        for key in [k for k in self.parts if k not in prepared.parts]:
            for actor in self.parts.pop(key).actors:
                self.plotter.remove_actor(actor, render=False)
            changed = True
        return changed

    def clear(self) -> None:
        for part in self.parts.values():
            for actor in part.actors:
                self.plotter.remove_actor(actor, render=False)
        self.parts.clear()
        if self.plotter.scalar_bars:
            self.plotter.scalar_bars.clear()

    def _add(self, label: str, kind: str, data: Any) -> _Part:
        color = self.color_of(label)
        if kind == "features":
            kw = dict(color=mix(color, "black", 0.55), line_width=1.6)
        else:
            kw = style(kind, color)
            kw.pop("render_points_as_spheres", None)
            kw.pop("render_lines_as_tubes", None)
            if kind in COLOURED:
                kw.update(colour_by(data, self.color_by))
        part = _Part(data)
        actor = self.plotter.add_mesh(data, reset_camera=False, render=False, **kw)
        apply_material(actor, kind)  # Phong, and the back faces in BACK_FACE
        part.actors.append(actor)
        self.added += len(part.actors)
        return part

    def _rescale(self, part: _Part) -> None:
        """The colour range follows the attribute's values as a slider changes them."""
        name = self.color_by
        if name is None or name == "color":
            return
        data = part.data
        values = data.point_data.get(name) if name in data.point_data else data.cell_data.get(name)
        if values is None or not len(values):
            return
        values = np.asarray(values, dtype=np.float64)
        if values.ndim == 2:
            values = np.linalg.norm(values, axis=1)
        lo, hi = float(np.nanmin(values)), float(np.nanmax(values))
        for actor in part.actors:
            actor.GetMapper().SetScalarRange(lo, hi if hi > lo else lo + 1.0)

    def bounds(self) -> tuple[float, ...] | None:
        boxes = [np.asarray(p.data.bounds).reshape(3, 2) for p in self.parts.values()]
        boxes = [b for b, p in zip(boxes, self.parts.values(), strict=True) if p.data.n_points]
        if not boxes:
            return None
        lo = np.min([b[:, 0] for b in boxes], axis=0)
        hi = np.max([b[:, 1] for b in boxes], axis=0)
        return tuple(float(x) for x in np.column_stack([lo, hi]).ravel())


def _attributes(data: Any) -> list[str]:
    """The point and cell attributes of ``data`` one could colour by."""
    names = [*data.point_data.keys(), *data.cell_data.keys()]
    return [n for n in names if n not in INTERNAL and not n.startswith(("vtk", "pyvista"))]


def _lean(data: Any, keep: str | None = None) -> Any:
    """``data`` with only the arrays drawn (the normals, and the attribute ``keep``), in
    float32 (what vtk.js draws with anyway, and half the bytes of float64 for every step
    sent to the browser), the normals in int8 (:func:`quantized_normals`)."""
    if data.points.dtype != np.float32:
        data.points = data.points.astype(np.float32)
    for on_points, attrs in ((True, data.point_data), (False, data.cell_data)):
        for name in list(attrs.keys()):
            if name not in ("Normals", keep):
                attrs.remove(name)
                continue
            arr = attrs[name]
            if name == "Normals" and on_points and name != keep:
                attrs[name] = quantized_normals(arr)
            elif arr.dtype == np.float64:
                attrs[name] = arr.astype(np.float32)
    if "Normals" in data.point_data.keys():
        data.point_data.active_normals_name = "Normals"
    return data


def quantized_normals(normals: np.ndarray) -> np.ndarray:
    """Unit normals as int8 (times 127, rounded): a quarter of float32's bytes, which a
    slider step sends again for every point. vtk.js copies normals of any type into its
    float buffers and its shaders normalize them, so only their direction counts, and the
    rounding turns it by at most about 0.4 degrees (0.5 / 127 radians per component)."""
    n = np.asarray(normals, dtype=np.float64)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    unit = n / np.where(length > 0, length, 1.0)
    return np.clip(np.rint(unit * 127.0), -127, 127).astype(np.int8)


def _copy_into(target: Any, new: Any) -> None:
    """Overwrite ``target``'s geometry with ``new``'s, keeping arrays that are equal.

    An array handed to vtk again with the same bytes keeps its hash in trame-vtk's
    serializer, but copying it still costs; the points, cells and arrays are replaced
    only where they differ, by ``new``'s own vtk objects (``new`` is not used after).
    """
    if target.n_points != new.n_points or not np.array_equal(target.points, new.points):
        target.SetPoints(new.GetPoints())
    for get, put in (
        ("GetPolys", "SetPolys"),
        ("GetLines", "SetLines"),
        ("GetVerts", "SetVerts"),
        ("GetStrips", "SetStrips"),
    ):
        theirs = getattr(new, get)()
        if not _same_cells(getattr(target, get)(), theirs):
            getattr(target, put)(theirs)
    for mine, theirs in (
        (target.GetPointData(), new.GetPointData()),
        (target.GetCellData(), new.GetCellData()),
    ):
        names = set()
        for i in range(theirs.GetNumberOfArrays()):
            arr = theirs.GetAbstractArray(i)
            names.add(arr.GetName())
            old = mine.GetAbstractArray(arr.GetName())
            if old is None or not _same_array(old, arr):
                mine.AddArray(arr)  # (in place of the one of that name: its role kept)
        for name in [mine.GetArrayName(i) for i in range(mine.GetNumberOfArrays())]:
            if name not in names:
                mine.RemoveArray(name)
    if new.GetPointData().GetNormals() is not None:
        target.GetPointData().SetActiveNormals("Normals")


def _same_cells(a: Any, b: Any) -> bool:
    """Whether two vtkCellArrays hold the same cells (compared in place, not exported)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if a.GetNumberOfCells() != b.GetNumberOfCells():
        return False
    if not a.GetNumberOfCells():
        return True
    return np.array_equal(
        vtk_to_numpy(a.GetOffsetsArray()), vtk_to_numpy(b.GetOffsetsArray())
    ) and np.array_equal(
        vtk_to_numpy(a.GetConnectivityArray()), vtk_to_numpy(b.GetConnectivityArray())
    )


def _same_array(a: Any, b: Any) -> bool:
    """Whether two vtk data arrays hold the same values, in the same type and shape."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if (
        a.GetDataType() != b.GetDataType()
        or a.GetNumberOfComponents() != b.GetNumberOfComponents()
        or a.GetNumberOfTuples() != b.GetNumberOfTuples()
        or not (a.IsNumeric() and b.IsNumeric())
    ):
        return False
    return np.array_equal(vtk_to_numpy(a), vtk_to_numpy(b))
