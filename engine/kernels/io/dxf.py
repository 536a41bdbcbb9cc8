"""DXF drawings through ezdxf: exact NURBS as SPLINE, polylines, meshes as MESH.

ezdxf is a well-kept, pure-Python DXF library whose documents open in AutoCAD, BricsCAD,
Rhino, FreeCAD and LibreCAD; writing the DXF tag soup ourselves would be a long way to the
same place. The document is written with fixed metadata (creation time, GUIDs) so the same
drawing gives the same bytes every time — a rerun then leaves the file untouched.
"""

from __future__ import annotations

import io
from collections.abc import Sequence

import numpy as np

from .exporters import check_mesh

__all__ = ["dxf_bytes"]

Spline = tuple[np.ndarray, int, np.ndarray, np.ndarray | None]  # (cp, degree, knots, weights)
Polyline = tuple[np.ndarray, bool]  # (points (n, 3), closed)
MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]  # (vertices, face_indices, face_offsets)

INSUNITS = {"unitless": 0, "in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6}


def _check_spline(i: int, spline: Spline) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:
    try:
        cp, degree, knots, weights = spline
    except (TypeError, ValueError):
        raise ValueError(
            f"spline {i} must be (control_points, degree, knots, weights), got {type(spline)}"
        ) from None
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
    return cp, degree, knots, w


def dxf_bytes(
    splines: Sequence[Spline] = (),
    polylines: Sequence[Polyline] = (),
    meshes: Sequence[MeshArrays] = (),
    units: str = "mm",
) -> bytes:
    """A DXF (R2010) drawing: NURBS as exact SPLINEs, polylines, meshes as MESH entities.

    - SPLINE: degree, knot vector, control points and — when any differs from 1 — weights,
      exactly as given (rational flag set), so a circle stays a circle.
    - Polylines: LWPOLYLINE when every z is 0 (a 2-D drawing), else a 3-D POLYLINE.
    - MESH: vertices and faces of any sizes, as they are.

    Parameters
    ----------
    splines : sequence of (control_points (n, 3), degree, knots (n + degree + 1,), weights)
        ``weights`` (n,) positive, or None for a non-rational spline.
    polylines : sequence of (points (n >= 2, 3), closed)
    meshes : sequence of (vertices (n, 3), face_indices, face_offsets)
    units : {"mm", "cm", "m", "in", "ft", "unitless"}
        Drawing units ($INSUNITS).

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
        pts, closed = item
        p = np.asarray(pts, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] not in (2, 3) or len(p) < 2:
            raise ValueError(f"polyline {i}: points must be (n >= 2, 3), got shape {p.shape}")
        if not np.all(np.isfinite(p)):
            raise ValueError(f"polyline {i}: points must be finite")
        if p.shape[1] == 2:
            p = np.column_stack([p, np.zeros(len(p))])
        checked_polylines.append((p, bool(closed)))
    checked_meshes = [check_mesh(*m) for m in meshes]

    previous = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True  # no clock, no random GUIDs
    try:
        doc = _document(ezdxf, checked_splines, checked_polylines, checked_meshes)
        doc.header["$INSUNITS"] = INSUNITS[units]
        stream = io.StringIO()
        doc.write(stream)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = previous
    return stream.getvalue().encode(doc.output_encoding)


def _document(ezdxf, splines, polylines, meshes):
    doc = ezdxf.new("R2010", setup=False)
    msp = doc.modelspace()
    for cp, degree, knots, w in splines:  # one iteration per curve
        spline = msp.add_spline(degree=degree)
        spline.control_points = cp
        spline.knots = knots
        if np.any(w != 1.0):
            spline.weights = w
            spline.dxf.flags = spline.dxf.flags | spline.RATIONAL
    for p, closed in polylines:
        if np.all(p[:, 2] == 0):
            msp.add_lwpolyline(p[:, :2], format="xy", close=closed)
        else:
            msp.add_polyline3d(p, close=closed)
    for v, fi, fo in meshes:
        mesh = msp.add_mesh()
        with mesh.edit_data() as data:
            # ezdxf takes lists of vertices and of faces: the library's interface
            data.vertices = v.tolist()
            data.faces = [f.tolist() for f in np.split(fi, fo[1:-1])] if fo.size > 1 else []
    return doc
