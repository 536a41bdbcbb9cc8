"""A solid as a closed, outward triangle mesh within a tolerance (OCC's ``BRepMesh``).

``BRepMesh_IncrementalMesh`` triangulates each face so that no triangle strays more than
``tolerance`` from the surface (and no two neighbours turn by more than ``angle``), with
the nodes along each edge shared by the faces that meet there. The faces' triangles are
gathered (turned over on a face used reversed, so every triangle faces out of the solid)
and their shared nodes merged by position: a closed shell gives a closed mesh.

OCC keeps a triangulation on the faces it meshed, so meshing the solid itself would change
what later calls see (a finer mesh kept, a coarser one not made again): the faces of a
copy of the topology (sharing the geometry, nothing recomputed) are meshed instead, and the
solid is left as it was.
"""

from __future__ import annotations

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.TopLoc import TopLoc_Location

from . import BrepError, occ

__all__ = ["tessellate"]


def _face_arrays(face: object) -> tuple[np.ndarray, np.ndarray] | None:
    loc = TopLoc_Location()
    tri = BRep_Tool.Triangulation_s(face, loc)
    if tri is None:
        return None
    n, m = tri.NbNodes(), tri.NbTriangles()
    # one call per node and per triangle: OCC's arrays have no buffer to read at once
    xyz = np.array([tri.Node(i).Coord() for i in range(1, n + 1)], dtype=np.float64)
    t = np.array([tri.Triangle(i).Get() for i in range(1, m + 1)], dtype=np.int64) - 1
    if not loc.IsIdentity():
        tr = loc.Transformation()
        rows = np.array([[tr.Value(r, c) for c in range(1, 5)] for r in range(1, 4)])
        xyz = xyz @ rows[:, :3].T + rows[:, 3]
    if occ.reversed_(face):
        t = t[:, [0, 2, 1]]
    return xyz.reshape(-1, 3), t.reshape(-1, 3)


def tessellate(
    shape: object, tolerance: float, angle: float = 0.5, guard: object = None
) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of ``shape`` no farther than ``tolerance`` from it.

    Parameters
    ----------
    shape : OCC shape
    tolerance : float
        The largest distance from a triangle to the surface (model units), > 0.
    angle : float
        The largest angle between neighbouring triangles along a curved surface, radians.
    guard : callable, optional
        Called with the number of triangles before they are gathered (the budget).

    Returns
    -------
    vertices : (n, 3) float
    triangles : (m, 3) int
        Counter-clockwise seen from outside the solid.
    """
    copy = BRepBuilderAPI_Copy(shape, False, False).Shape()
    try:
        BRepMesh_IncrementalMesh(copy, float(tolerance), False, float(angle), False)
    except occ.FAILURES:
        raise BrepError(f"OpenCASCADE could not mesh the solid within {tolerance:g}") from None
    faces = occ.explore(copy, "face")
    if guard is not None:
        total = 0
        for f in faces:
            tri = BRep_Tool.Triangulation_s(f, TopLoc_Location())
            total += 0 if tri is None else tri.NbTriangles()
        guard(total)
    parts = [_face_arrays(f) for f in faces]
    missing = sum(p is None for p in parts)
    if missing:
        raise BrepError(f"OpenCASCADE left {missing} face(s) unmeshed")
    if not parts:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    sizes = np.array([len(p[0]) for p in parts])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    xyz = np.concatenate([p[0] for p in parts])
    tris = np.concatenate([p[1] + s for p, s in zip(parts, starts, strict=True)])
    # the faces' copies of the nodes along shared edges: merged where they coincide
    unique, inverse = np.unique(xyz, axis=0, return_inverse=True)
    tris = inverse.reshape(-1)[tris]
    keep = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
    return unique, tris[keep]
