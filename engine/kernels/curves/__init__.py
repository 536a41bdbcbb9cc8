"""Curve kernels: Bezier chains, Catmull-Rom splines and surfaces, and polyline operations.

- ``splines``: exact cubic NURBS from Bezier chains and Catmull-Rom points (curves and
  bicubic surfaces);
- ``polylines``: B-spline subdivision of a control polygon, length and even
  resampling, the bisector offset;
- ``arclength``: the arc length of any curve from its derivative, its inverse, and even
  division by it.

The whole family is one import: ``from formgraph.kernels import curves``.
"""

from __future__ import annotations

from .arclength import (
    arc_length_table,
    even_arc_parameters,
    even_lengths,
    parameters_at_lengths,
)
from .polylines import (
    bisector_offset,
    drop_repeats,
    offset_folds,
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
    "even_lengths",
    "even_arc_parameters",
    "bisector_offset",
    "drop_repeats",
]
