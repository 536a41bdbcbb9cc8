"""Offset kernels: offsets of polylines through a signed distance field and marching squares.

- ``distance``: exact point-segment distances (a segment tree), crossing-number signs per row;
- ``band``: the field sampled on a band of a quadtree, and the checks for thin parts;
- ``contour``: marching squares on sparse samples, crossings joined into closed loops;
- ``loops``: flat loop storage and the clean-up passes (folds, crossings, simplification);
- ``refine``: vertices moved onto the exact level set, corner and chord points inserted;
- ``marching``: the pipeline, :func:`offset_polylines`, and its cell-size rule.
"""

from __future__ import annotations

from .contour import marching_squares
from .marching import OffsetTraceError, WorkLimit, default_cell, grid_cells, offset_polylines

__all__ = [
    "OffsetTraceError",
    "WorkLimit",
    "default_cell",
    "grid_cells",
    "marching_squares",
    "offset_polylines",
]
