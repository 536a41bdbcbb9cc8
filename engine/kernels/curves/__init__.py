"""Curve kernels: Bezier chains, Catmull-Rom splines and surfaces, and polyline operations.

- ``splines``: exact cubic NURBS from Bezier chains and Catmull-Rom points (curves and
  bicubic surfaces);
- ``polylines``: B-spline subdivision of a control polygon, arc length and even
  resampling, the bisector offset.

The whole family is one import: ``from formgraph.kernels import curves``.
"""

from __future__ import annotations

from .polylines import (
    arc_length_table,
    bisector_offset,
    drop_repeats,
    offset_folds,
    parameters_at_lengths,
    polyline_length,
    resample_count,
    resample_polyline,
    subdivide_polygon,
    subdivided_count,
)
from .splines import (
    ENDS,
    SPACINGS,
    CurveTuple,
    SurfaceTuple,
    bezier_chain,
    catmull_rom,
    catmull_rom_surface,
)

__all__ = [
    "offset_folds",
    "CurveTuple",
    "SurfaceTuple",
    "SPACINGS",
    "ENDS",
    "bezier_chain",
    "catmull_rom",
    "catmull_rom_surface",
    "subdivide_polygon",
    "subdivided_count",
    "polyline_length",
    "resample_count",
    "resample_polyline",
    "arc_length_table",
    "parameters_at_lengths",
    "bisector_offset",
    "drop_repeats",
]
