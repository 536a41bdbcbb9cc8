"""Offset kernels: offsets of polylines through GEOS's buffer, or a signed distance field and
marching squares (any cell, smoothing, mixed open and closed input, and the fallback).

- ``distance``: exact point-segment distances (a segment tree), crossing-number signs per row;
- ``band``: the field sampled on a band of a quadtree, and the checks for thin parts;
- ``contour``: marching squares on sparse samples, crossings joined into closed loops;
- ``loops``: flat loop storage and the clean-up passes (folds, crossings, simplification);
- ``refine``: vertices moved onto the exact level set, corner and chord points inserted;
- ``marching``: the pipeline, :func:`offset_polylines`, and its cell-size rule;
- ``buffer``: the exact fast path through GEOS's buffer, :func:`buffer_polylines`, and
  :func:`offset_loops`, which takes it where it can promise the tolerance, else marching.
"""

from __future__ import annotations

from .buffer import BufferDeclined, Offset, buffer_polylines, offset_loops, quad_segs
from .contour import marching_squares
from .marching import OffsetTraceError, WorkLimit, default_cell, grid_cells, offset_polylines

__all__ = [
    "BufferDeclined",
    "Offset",
    "OffsetTraceError",
    "WorkLimit",
    "buffer_polylines",
    "default_cell",
    "grid_cells",
    "marching_squares",
    "offset_loops",
    "offset_polylines",
    "quad_segs",
]
