"""Mesh kernels: half-edge connectivity, subdivision, and the polygon-mesh operations.

- ``halfedge``: vectorized half-edge build (twin, next, face, vertex fans), boundaries and
  non-manifold edges reported as :class:`MeshTopologyError`;
- ``subdivision``: Catmull-Clark and Doo-Sabin with open boundaries;
  ``catmull_clark_levels``: each Catmull-Clark level's connectivity in closed form and its
  rules as sparse matrices;
- ``meshops``: box, merge, transform, face normals, dihedral angles, triangulation;
- ``polygon``: ear clipping of one polygon loop (O(k^2) at worst, vectorized rounds);
- ``grid``: the quads of a structured grid (tessellation and ``surfaces.grid``), poles
  collapsed;
- ``primitives``: cylinder, UV sphere, torus, plane;
- ``repair``: weld, orient, cap; ``solidify``: thickened shells;
- ``boolean``: union, difference, intersection through manifold3d;
- ``measure``: the edge table, union-find, areas, volumes, the solid report;
- ``keys``: the sort of int64 keys with their positions behind edge tables and welds;
  ``cells``: pairs of points closer than a tolerance (the weld's neighbour search).

The solid modules are imported on use (``from formgraph.kernels.mesh import repair``), so
``import formgraph`` does not pay for them.

Meshes are plain arrays ``(vertices (n, 3), face_indices (flat), face_offsets (faces + 1,))``.
"""

from __future__ import annotations

from . import halfedge, meshops, polygon, subdivision
from .grid import grid_faces
from .halfedge import Fans, HalfEdges, MeshTopologyError, build_halfedges, check_faces
from .polygon import WorkLimitError, triangulate_polygon

__all__ = [
    "Fans",
    "HalfEdges",
    "MeshTopologyError",
    "WorkLimitError",
    "build_halfedges",
    "check_faces",
    "grid_faces",
    "halfedge",
    "meshops",
    "polygon",
    "subdivision",
    "triangulate_polygon",
]
