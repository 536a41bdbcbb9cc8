"""DXF drawings through ezdxf: exact NURBS as SPLINE, polylines, meshes as MESH.

ezdxf is a well-kept, pure-Python DXF library whose documents open in AutoCAD, BricsCAD,
Rhino, FreeCAD and LibreCAD; writing the DXF tag soup ourselves would be a long way to the
same place. The document is written with fixed metadata (creation time, GUIDs), and its
CLASSES section registered in sorted order before ezdxf would fill it from a ``set`` (whose
order follows ``PYTHONHASHSEED``), so the same drawing gives the same bytes in every process
— a rerun then leaves the file untouched.

Every entity sits on a named layer with a colour (AutoCAD Color Index), so the cut,
engrave and tool-path lines of one drawing can be told apart in CAM software.
"""

from __future__ import annotations

import io
from collections.abc import Sequence

import numpy as np

from .colors import rgb
from .meshdata import check_mesh

__all__ = ["dxf_bytes"]

# (cp, degree, knots, weights[, closed[, layer]])
Spline = tuple  # noqa: UP006 (a tuple of 4 to 6 items)
Polyline = tuple  # (points (n, 3), closed[, layer])
MeshArrays = tuple  # (vertices, face_indices, face_offsets[, layer])
DEFAULT_LAYER = "0"

INSUNITS = {"unitless": 0, "in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6}


def _check_spline(i: int, spline: Spline) -> tuple:
    try:
        cp, degree, knots, weights = spline[:4]
        closed = bool(spline[4]) if len(spline) > 4 else False
        layer = spline[5] if len(spline) > 5 else DEFAULT_LAYER
    except (TypeError, ValueError, IndexError):
        raise ValueError(
            f"spline {i} must be (control_points, degree, knots, weights[, closed[, layer]]), "
            f"got {type(spline)}"
        ) from None
    layer = _layer_name(layer, f"spline {i}")
    cp = np.asarray(cp, dtype=np.float64)
    if cp.ndim != 2 or cp.shape[1] not in (2, 3):
        raise ValueError(f"spline {i}: control points must be (n, 3), got shape {cp.shape}")
    if cp.shape[1] == 2:
        cp = np.column_stack([cp, np.zeros(len(cp))])
    n = len(cp)
    degree = int(degree)
    if not 1 <= degree <= 11:
        raise ValueError(f"spline {i}: DXF splines have degree 1 to 11, got {degree}")
    if n < degree + 1:
        raise ValueError(
            f"spline {i}: degree {degree} needs at least {degree + 1} control points, got {n}"
        )
    knots = np.asarray(knots, dtype=np.float64).ravel()
    if knots.size != n + degree + 1:
        raise ValueError(
            f"spline {i}: {n} control points of degree {degree} need {n + degree + 1} knots, "
            f"got {knots.size}"
        )
    if np.any(np.diff(knots) < 0):
        raise ValueError(f"spline {i}: knots must not decrease")
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=np.float64).ravel()
    if w.size != n or np.any(w <= 0):
        raise ValueError(
            f"spline {i}: needs {n} positive weights, got {w.size} "
            f"(min {w.min() if w.size else 'none'})"
        )
    if not (np.all(np.isfinite(cp)) and np.all(np.isfinite(knots)) and np.all(np.isfinite(w))):
        raise ValueError(f"spline {i}: control points, knots and weights must be finite")
    return cp, degree, knots, w, closed, layer


def _layer_name(name: object, what: str) -> str:
    """A DXF layer name: non-empty, none of the characters DXF forbids in table names."""
    if not isinstance(name, str) or not name.strip() or any(ch in name for ch in '<>/\\":;?*|=`'):
        raise ValueError(
            f"{what}: a layer name must be a non-empty text without any of "
            f'< > / \\ " : ; ? * | = `, got {name!r}'
        )
    return name


def dxf_bytes(
    splines: Sequence[Spline] = (),
    polylines: Sequence[Polyline] = (),
    meshes: Sequence[MeshArrays] = (),
    units: str = "mm",
    layer_colors: dict[str, int] | None = None,
) -> bytes:
    """A DXF (R2010) drawing: NURBS as exact SPLINEs, polylines, meshes as MESH entities.

    - SPLINE: degree, knot vector, control points and — when any differs from 1 — weights,
      exactly as given (rational flag set), so a circle stays a circle; a closed outline
      gets the closed flag.
    - Polylines: LWPOLYLINE when every z is 0 (a 2-D drawing), else a 3-D POLYLINE.
    - MESH: vertices and faces of any sizes, as they are.

    Parameters
    ----------
    splines : sequence of (control_points (n, 3), degree, knots (n + degree + 1,), weights
        [, closed [, layer]])
        ``weights`` (n,) positive, or None for a non-rational spline.
    polylines : sequence of (points (n >= 2, 3), closed [, layer])
    meshes : sequence of (vertices (n, 3), face_indices, face_offsets [, layer])
    units : {"mm", "cm", "m", "in", "ft", "unitless"}
        Drawing units ($INSUNITS).
    layer_colors : dict of layer name -> AutoCAD Color Index (1 .. 255) or CSS colour
        Layers are created in the order of this mapping, then in the order the entities
        name them (colour 7, white/black, unless given). Layer "0" always exists. A CSS
        colour (``"red"``, ``"#ff8000"``) becomes the layer's true colour (group code 420),
        with the nearest index of the standard palette as its colour number.

    Returns
    -------
    bytes
        UTF-8 DXF text; ``ezdxf.recover``/``audit`` find no errors in it.
    """
    import ezdxf  # imported here: only DXF export needs it

    if units not in INSUNITS:
        raise ValueError(f"units must be one of {', '.join(INSUNITS)}; got {units!r}")
    checked_splines = [_check_spline(i, s) for i, s in enumerate(splines)]
    checked_polylines = []
    for i, item in enumerate(polylines):
        pts, closed = item[:2]
        layer = _layer_name(item[2] if len(item) > 2 else DEFAULT_LAYER, f"polyline {i}")
        p = np.asarray(pts, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] not in (2, 3) or len(p) < 2:
            raise ValueError(f"polyline {i}: points must be (n >= 2, 3), got shape {p.shape}")
        if not np.all(np.isfinite(p)):
            raise ValueError(f"polyline {i}: points must be finite")
        if p.shape[1] == 2:
            p = np.column_stack([p, np.zeros(len(p))])
        checked_polylines.append((p, bool(closed), layer))
    checked_meshes = [
        (*check_mesh(*m[:3]), _layer_name(m[3] if len(m) > 3 else DEFAULT_LAYER, f"mesh {i}"))
        for i, m in enumerate(meshes)
    ]
    colors: dict[str, int | tuple[int, int, int]] = {}
    for name, aci in (layer_colors or {}).items():
        _layer_name(name, "layer_colors")
        if isinstance(aci, str):
            colors[name] = rgb(aci)
            continue
        if isinstance(aci, bool) or not isinstance(aci, (int, np.integer)) or not 1 <= aci <= 255:
            raise ValueError(
                f"layer {name!r}: a colour is an AutoCAD Color Index 1 .. 255 or a CSS colour, "
                f"got {aci!r}"
            )
        colors[name] = int(aci)
    for item in (*checked_splines, *checked_polylines, *checked_meshes):
        colors.setdefault(item[-1], 7)

    previous = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True  # no clock, no random GUIDs
    try:
        doc = _document(ezdxf, checked_splines, checked_polylines, checked_meshes, colors)
        doc.header["$INSUNITS"] = INSUNITS[units]
        _register_classes_in_order(doc)
        stream = io.StringIO()
        doc.write(stream)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = previous
    return stream.getvalue().encode(doc.output_encoding)


def _register_classes_in_order(doc) -> None:
    """Fill the CLASSES section now, in a fixed order.

    At write time ezdxf adds a CLASS for each entity type in use, iterating a ``set`` of
    type names, whose order changes with ``PYTHONHASHSEED``; classes already registered are
    kept where they are, so registering the required ones and then the types in use in
    sorted order makes the section (and the file) the same in every process.
    """
    from ezdxf.sections.classes import REQ_R2004, REQUIRED_CLASSES

    doc.commit_pending_changes()
    for name in REQUIRED_CLASSES.get(doc.dxfversion, REQ_R2004):
        doc.classes.add_class(name)
    for name in sorted(doc.entitydb.dxf_types_in_use()):
        doc.classes.add_class(name)


def _nearest_aci(color: tuple[int, int, int]) -> int:
    """The AutoCAD Color Index (1 .. 255) nearest to an RGB colour."""
    from ezdxf.colors import DXF_DEFAULT_COLORS, int2rgb

    table = np.array([int2rgb(c) for c in DXF_DEFAULT_COLORS[1:256]], dtype=np.float64)
    return 1 + int(np.argmin(((table - np.asarray(color, dtype=np.float64)) ** 2).sum(axis=1)))


def _document(ezdxf, splines, polylines, meshes, colors):
    doc = ezdxf.new("R2010", setup=False)
    for name, color in colors.items():
        true = isinstance(color, tuple)
        aci = _nearest_aci(color) if true else color
        if name in doc.layers:  # "0", or a name differing only in case (DXF ignores case)
            layer = doc.layers.get(name)
            layer.dxf.color = aci
        else:
            layer = doc.layers.add(name, color=aci)
        if true:
            layer.rgb = color
    msp = doc.modelspace()
    for cp, degree, knots, w, closed, layer in splines:  # one iteration per curve
        spline = msp.add_spline(degree=degree, dxfattribs={"layer": layer})
        spline.control_points = cp
        spline.knots = knots
        if np.any(w != 1.0):
            spline.weights = w
            spline.dxf.flags = spline.dxf.flags | spline.RATIONAL
        if closed:
            spline.dxf.flags = spline.dxf.flags | spline.CLOSED
    for p, closed, layer in polylines:
        if np.all(p[:, 2] == 0):
            msp.add_lwpolyline(p[:, :2], format="xy", close=closed, dxfattribs={"layer": layer})
        else:
            msp.add_polyline3d(p, close=closed, dxfattribs={"layer": layer})
    for v, fi, fo, layer in meshes:
        mesh = msp.add_mesh(dxfattribs={"layer": layer})
        with mesh.edit_data() as data:
            # ezdxf takes lists of vertices and of faces: the library's interface
            data.vertices = v.tolist()
            data.faces = [f.tolist() for f in np.split(fi, fo[1:-1])] if fo.size > 1 else []
    return doc
