"""A solid's edges and faces as arrays, for per-element selectors, and its measures.

Edges and faces are numbered as OCC numbers the distinct sub-shapes of a shape
(``TopExp::MapShapes``, 0-based here): ``i`` in a selector, and the numbers an error
message names. Each edge has its centre (of mass: the middle of a segment, the centre of a
whole circle), its length and its kind; each face its centre, its area, its kind and the
outward normal at the point of its surface nearest its centre. The kinds are names a
selector compares with (``kind == circle``), each standing for a number (:data:`KINDS`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepGProp import BRepGProp
from OCP.GeomAbs import GeomAbs_CurveType, GeomAbs_SurfaceType
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.GProp import GProp_GProps
from OCP.ShapeAnalysis import ShapeAnalysis_Surface

from . import occ

__all__ = ["KINDS", "Table", "edge_table", "face_table", "measure"]

# Every kind a selector can name, as the number its ``kind`` holds: one table for edges
# and faces, so ``bspline`` means the same in both.
KINDS: dict[str, float] = {
    "line": 1.0,
    "circle": 2.0,
    "ellipse": 3.0,
    "hyperbola": 4.0,
    "parabola": 5.0,
    "bezier": 6.0,
    "bspline": 7.0,
    "offset": 8.0,
    "other": 9.0,
    "plane": 10.0,
    "cylinder": 11.0,
    "cone": 12.0,
    "sphere": 13.0,
    "torus": 14.0,
    "revolution": 15.0,
    "extrusion": 16.0,
    "degenerate": 17.0,
}
NAMES = {v: k for k, v in KINDS.items()}

_CURVE_KINDS = {
    GeomAbs_CurveType.GeomAbs_Line: "line",
    GeomAbs_CurveType.GeomAbs_Circle: "circle",
    GeomAbs_CurveType.GeomAbs_Ellipse: "ellipse",
    GeomAbs_CurveType.GeomAbs_Hyperbola: "hyperbola",
    GeomAbs_CurveType.GeomAbs_Parabola: "parabola",
    GeomAbs_CurveType.GeomAbs_BezierCurve: "bezier",
    GeomAbs_CurveType.GeomAbs_BSplineCurve: "bspline",
    GeomAbs_CurveType.GeomAbs_OffsetCurve: "offset",
}
_SURFACE_KINDS = {
    GeomAbs_SurfaceType.GeomAbs_Plane: "plane",
    GeomAbs_SurfaceType.GeomAbs_Cylinder: "cylinder",
    GeomAbs_SurfaceType.GeomAbs_Cone: "cone",
    GeomAbs_SurfaceType.GeomAbs_Sphere: "sphere",
    GeomAbs_SurfaceType.GeomAbs_Torus: "torus",
    GeomAbs_SurfaceType.GeomAbs_BezierSurface: "bezier",
    GeomAbs_SurfaceType.GeomAbs_BSplineSurface: "bspline",
    GeomAbs_SurfaceType.GeomAbs_SurfaceOfRevolution: "revolution",
    GeomAbs_SurfaceType.GeomAbs_SurfaceOfExtrusion: "extrusion",
    GeomAbs_SurfaceType.GeomAbs_OffsetSurface: "offset",
}


@dataclass(frozen=True)
class Table:
    """Per-element values of a solid's edges or faces (``n`` rows, in OCC's numbering).

    Attributes
    ----------
    shapes : list
        The OCC edges or faces.
    centre : (n, 3) float
    size : (n,) float
        Length of an edge, area of a face.
    kind : (n,) float
        The :data:`KINDS` number of each.
    normal : (n, 3) float or None
        Faces: the outward unit normal near the centre.
    """

    shapes: list[object]
    centre: np.ndarray
    size: np.ndarray
    kind: np.ndarray
    normal: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.shapes)

    def kind_name(self, i: int) -> str:
        return NAMES[float(self.kind[i])]


def edge_table(shape: object) -> Table:
    """Every distinct edge of ``shape``: centre, length, kind (degenerate edges, the
    collapsed sides at a cone's tip or a sphere's pole, have length 0)."""
    edges = occ.indexed(shape, "edge")
    n = len(edges)
    centre = np.zeros((n, 3))
    size = np.zeros(n)
    kind = np.zeros(n)
    props = GProp_GProps()
    for i, e in enumerate(edges):  # one OCC query per edge: its topology is not an array
        if BRep_Tool.Degenerated_s(e):
            centre[i] = occ.vertex_point(occ.explore(e, "vertex")[0])
            kind[i] = KINDS["degenerate"]
            continue
        props = GProp_GProps()
        BRepGProp.LinearProperties_s(e, props)
        centre[i] = occ.point(props.CentreOfMass())
        size[i] = props.Mass()
        kind[i] = KINDS[_CURVE_KINDS.get(BRepAdaptor_Curve(e).GetType(), "other")]
    return Table(edges, centre, size, kind)


def face_table(shape: object) -> Table:
    """Every distinct face of ``shape``: centre, area, kind, outward normal."""
    faces = occ.indexed(shape, "face")
    n = len(faces)
    centre = np.zeros((n, 3))
    size = np.zeros(n)
    kind = np.zeros(n)
    normal = np.zeros((n, 3))
    for i, f in enumerate(faces):  # one OCC query per face
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(f, props)
        c = props.CentreOfMass()
        centre[i] = occ.point(c)
        size[i] = props.Mass()
        kind[i] = KINDS[_SURFACE_KINDS.get(BRepAdaptor_Surface(f).GetType(), "other")]
        surface = BRep_Tool.Surface_s(f)
        uv = ShapeAnalysis_Surface(surface).ValueOfUV(c, 1e-7)
        lp = GeomLProp_SLProps(surface, uv.X(), uv.Y(), 1, 1e-9)
        if lp.IsNormalDefined():
            d = occ.point(lp.Normal())
            normal[i] = -d if occ.reversed_(f) else d
    return Table(faces, centre, size, kind, normal)


@dataclass(frozen=True)
class Measures:
    volume: float
    area: float
    solids: int
    faces: int
    edges: int
    vertices: int
    valid: bool


def measure(shape: object) -> Measures:
    """Volume, area, counts of distinct solids, faces, edges and vertices, and OCC's
    validity check."""
    return Measures(
        occ.volume(shape),
        occ.area(shape),
        len(occ.solids_of(shape)),
        len(occ.indexed(shape, "face")),
        len(occ.indexed(shape, "edge")),
        len(occ.indexed(shape, "vertex")),
        occ.is_valid(shape),
    )
