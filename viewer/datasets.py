"""From node values to pyvista datasets: what a value holds (:func:`geometry_items`), its
description, one dataset per kind of geometry (:func:`datasets_of`) and the colouring by an
attribute (:func:`colour_by`). :mod:`.scene` turns them into actors.

pyvista is imported inside the functions, so importing this module costs nothing.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from formgraph.geometry import (
    Curve,
    Field,
    Geometry,
    Mesh,
    NurbsCurve,
    NurbsSurface,
    Points,
    Solid,
    Surface,
)

from .style import shaded

__all__ = [
    "KINDS",
    "colour_by",
    "datasets_of",
    "describe",
    "expand",
    "geometry_items",
    "vertices_of",
]

# the four kinds of drawn geometry, in drawing order
KINDS = ("meshes", "surfaces", "curves", "points")


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
    """The PolyData of each kind, overlay and line set present in ``items``.

    Surfaces and meshes come with split point normals for smooth shading; ``features``
    holds their feature edges and open boundaries (see :func:`~.style.shaded`).
    """

    points = [g.to_pyvista() for g in items if isinstance(g, Points) and len(g)]
    curves = [g for g in items if isinstance(g, Curve)]
    surfaces = [g for g in items if isinstance(g, Surface)]
    meshes = [g for g in items if isinstance(g, Mesh) and g.n_faces]
    # fields: a preview; solids: brep.mesh's tessellation at its default tolerance
    previews = [g.display_mesh() for g in items if isinstance(g, (Field, Solid))]
    meshes += [m for m in previews if m is not None and m.n_faces]
    surface_data = _merge([s.tessellate(*_surface_resolution(s)).to_pyvista() for s in surfaces])
    mesh_data = _merge([m.to_pyvista() for m in meshes])
    out: dict[str, Any] = {
        "points": _merge(points),
        "curves": _polylines([c.display_points() for c in curves]),
        "polygon": _polylines([c.control_points for c in curves if isinstance(c, NurbsCurve)]),
        "net": _merge(
            [_control_net(s.control_points) for s in surfaces if isinstance(s, NurbsSurface)]
        ),
    }
    lines = []
    for kind, data in (("surfaces", surface_data), ("meshes", mesh_data)):
        if data is None:
            continue
        out[kind], edges = shaded(data)
        lines.append(edges)
    out["features"] = _merge(lines)
    return {k: v for k, v in out.items() if v is not None and v.n_points > 0}


def colour_by(data: Any, name: str | None) -> dict[str, Any]:
    """add_mesh keywords that colour ``data`` by its attribute ``name`` (a point array, else
    a cell array), with a colour bar titled by the name; nothing when it has no such
    array. A ``color`` of 3 or 4 components in 0..1 is shown as RGB(A), without a bar."""
    if not name:
        return {}
    where = "point" if name in data.point_data else "cell" if name in data.cell_data else None
    if where is None:
        return {}
    values = np.asarray((data.point_data if where == "point" else data.cell_data)[name])
    options: dict[str, Any] = {"scalars": name, "preference": where, "color": None}
    if name == "color" and values.ndim == 2 and values.shape[1] in (3, 4):
        return {**options, "rgb": True}
    if values.ndim == 2 and values.shape[1] > 1:  # a vector: by its length
        options["component"] = None
    return {
        **options,
        "cmap": "viridis",
        "show_scalar_bar": True,
        "scalar_bar_args": {
            "title": name,
            "vertical": True,
            "position_x": 0.88,
            "position_y": 0.12,
            "height": 0.6,
            "width": 0.06,
            "color": "black",
            "fmt": "%.3g",
        },
    }


def vertices_of(data: Any) -> Any:
    import pyvista as pv

    return pv.PolyData(np.array(data.points))
