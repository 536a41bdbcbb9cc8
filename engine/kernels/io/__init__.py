"""File-format kernels: mesh exporters, 2-D drawings, DXF, and the number formatting they share.

- ``exporters``: binary and ASCII STL, OBJ, PLY from flat face arrays;
- ``meshdata``: checked face arrays, fan triangles, normals, and the mesh report (open and
  non-manifold edges, zero-area faces) behind the export warnings;
- ``drawing``: 2-D paths (polylines, cubics, exact arcs) to SVG and PDF;
- ``dxf``: exact SPLINE entities and mesh faces through ezdxf;
- ``numfmt`` and ``shortest``: vectorized shortest round-trip decimals laid out as text.

Every writer returns ``bytes``; writing them atomically is the export nodes' job.
"""

from __future__ import annotations

from .drawing import Path2D, drawing_bounds, pdf_bytes, svg_bytes
from .dxf import dxf_bytes
from .exporters import (
    obj_bytes,
    ply_binary,
    stl_ascii,
    stl_ascii_chunks,
    stl_binary,
)
from .meshdata import MeshReport, check_mesh, fan_triangles, mesh_report, triangle_normals

__all__ = [
    "MeshReport",
    "Path2D",
    "check_mesh",
    "drawing_bounds",
    "dxf_bytes",
    "fan_triangles",
    "mesh_report",
    "obj_bytes",
    "pdf_bytes",
    "ply_binary",
    "stl_ascii",
    "stl_ascii_chunks",
    "stl_binary",
    "svg_bytes",
    "triangle_normals",
]
