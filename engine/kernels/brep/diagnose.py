"""Why a feature failed, in a designer's words: the geometry around the edges and faces.

OCC's fillet reports little (which contour failed, a ``ChFiDS_ErrorStatus``) and often
nothing: it can build a shape that is not valid and say it is done. So the reason is
measured here. A round of radius r on an edge eats into each of the two faces the edge
joins, about r deep (exactly r where they meet square); a face narrower than that across
the edge has no room for it, and a face rounded on two opposite sides needs twice the room.
The width of a face across an edge is the distance from the edge to the nearest edge of the
face that does not touch it (``BRepExtrema_DistShapeShape``); a face bounded by the edge
alone (a disc) has as its width its inradius, twice its area over its perimeter.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepLProp import BRepLProp_SLProps
from OCP.collections import IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp

from . import occ

__all__ = ["Adjacency", "Narrow", "narrowest", "numbers"]


def numbers(items: list[int], most: int = 8) -> str:
    """``3, 7 and 9`` (at most ``most`` shown)."""
    shown = [str(i) for i in items[:most]]
    if len(items) > most:
        return ", ".join(shown) + f" and {len(items) - most} more"
    return shown[0] if len(shown) == 1 else ", ".join(shown[:-1]) + " and " + shown[-1]


class Adjacency:
    """Which faces meet at each edge of a shape, and the edges of each face, in OCC's
    numbering of its distinct edges and faces."""

    def __init__(self, shape: object):
        self.shape = shape
        self.edges = occ.indexed(shape, "edge")
        self.faces = occ.indexed(shape, "face")
        self.face_index = occ.index_map(shape, "face")
        self.edge_index = occ.index_map(shape, "edge")
        self.vertex_index = occ.index_map(shape, "vertex")
        m = IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher()
        TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, m)
        self._faces_of: list[list[int]] = []
        find = self.face_index.FindIndex
        for e in self.edges:  # one lookup per edge
            found = m.FindFromKey(e)
            n = found.Size()
            if n <= 2:  # a manifold edge: its first and last use (iterating OCC's list
                # from Python costs 100 times more than these two calls)
                ids = sorted({find(found.First()) - 1, find(found.Last()) - 1}) if n else []
            else:
                ids = sorted({find(f) - 1 for f in found})
            self._faces_of.append(ids)
        self._edges_of: list[list[int]] | None = None
        self._surfaces: dict[int, BRepAdaptor_Surface] = {}

    def faces_of(self, edge: int) -> list[int]:
        """The distinct faces edge ``edge`` bounds (one for a seam or an open edge)."""
        return self._faces_of[edge]

    def edges_of(self, face: int) -> list[int]:
        if self._edges_of is None:
            self._edges_of = [[] for _ in self.faces]
            for e, faces in enumerate(self._faces_of):
                for f in faces:
                    self._edges_of[f].append(e)
        return self._edges_of[face]

    def smooth(self, edge: int) -> bool:
        """Whether the two faces at ``edge`` meet without a corner (tangent there), or it
        bounds one face only (a seam): nothing to round or cut."""
        faces = self._faces_of[edge]
        if len(faces) != 2 or BRep_Tool.Degenerated_s(self.edges[edge]):
            return True
        n0, n1 = (self._normal_at_middle(edge, f) for f in faces)
        if n0 is None or n1 is None:
            return False
        return bool(np.dot(n0, n1) > 1.0 - 1e-9)

    def _surface(self, face: int) -> BRepAdaptor_Surface:
        """The face's surface adaptor, made once per face (a face has several edges)."""
        if face not in self._surfaces:
            self._surfaces[face] = BRepAdaptor_Surface(self.faces[face])
        return self._surfaces[face]

    def _normal_at_middle(self, edge: int, face: int) -> np.ndarray | None:
        e, f = self.edges[edge], self.faces[face]
        try:
            c2d = BRepAdaptor_Curve2d(e, f)
            t = 0.5 * (c2d.FirstParameter() + c2d.LastParameter())
            uv = c2d.Value(t)
            props = BRepLProp_SLProps(self._surface(face), uv.X(), uv.Y(), 1, 1e-9)
            if not props.IsNormalDefined():
                return None
            n = occ.point(props.Normal())
        except occ.FAILURES:
            return None
        return -n if occ.reversed_(f) else n

    def _ends(self, edge: int) -> set[int]:
        e = self.edges[edge]
        return {
            self.vertex_index.FindIndex(TopExp.FirstVertex_s(e)),
            self.vertex_index.FindIndex(TopExp.LastVertex_s(e)),
        }

    def width(self, edge: int, face: int) -> tuple[float, int | None]:
        """How wide face ``face`` is across edge ``edge``, and the edge on the other side
        (None for a face bounded by the edge alone)."""
        v = self._ends(edge)
        e = self.edges[edge]
        best, other = np.inf, None
        for j in self.edges_of(face):  # one distance per edge of the face: a few
            if j == edge:
                continue
            ej = self.edges[j]
            if self._ends(j) & v or BRep_Tool.Degenerated_s(ej):
                continue  # a neighbour along the boundary, not across the face
            d = BRepExtrema_DistShapeShape(e, ej)
            if d.IsDone() and d.Value() < best:
                best, other = d.Value(), j
        if other is None:
            perimeter = sum(_length(self.edges[j]) for j in self.edges_of(face))
            return (2.0 * occ.area(self.faces[face]) / perimeter if perimeter > 0 else 0.0), None
        return float(best), other


def _length(edge: object) -> float:
    if BRep_Tool.Degenerated_s(edge):
        return 0.0
    return float(GCPnts_AbscissaPoint.Length_s(BRepAdaptor_Curve(edge)))


@dataclass(frozen=True)
class Narrow:
    """The tightest face across the selected edges: its width, the room a feature of
    that size has there (the width, or half of it when the edge across is also
    selected), and the edges on its two sides."""

    width: float
    room: float
    face: int
    edges: tuple[int, ...]
    both_sides: bool


def narrowest(adj: Adjacency, edges: list[int]) -> Narrow | None:
    """The face with the least room for a feature on ``edges`` (None: no face found)."""
    chosen = set(edges)
    best: Narrow | None = None
    for i in edges:  # one width per selected edge and face
        for f in adj.faces_of(i):
            w, other = adj.width(i, f)
            both = other is not None and other in chosen
            room = w / 2 if both else w
            if best is None or room < best.room:
                pair = (i,) if other is None else tuple(sorted((i, other)))
                best = Narrow(w, room, f, pair, both)
    return best
