"""Exact solids (issue 38): our brep nodes against the same OpenCASCADE calls made directly,
so the rows measure the layer between (selectors, the validity check every result gets,
the diagnosis tables, the graph), which must stay thin.

- ``brep.fillet`` of the 12 edges of a 40 x 30 x 20 box, a new radius each call: ours
  through a graph (``brep.box`` upstream, cached); the kernel alone
  (:func:`formgraph.kernels.brep.features.fillet`, with its adjacency); OCP as its users
  write it (``BRepFilletAPI_MakeFillet``, ``Add`` each edge, ``Shape()``), and the same
  followed by the ``BRepCheck_Analyzer`` check our kernel makes of every result.
- ``brep.boolean`` of two filleted boxes (a union; both fillets and the union recomputed,
  the radius changing each call) against ``MakeFillet`` twice and ``BRepAlgoAPI_Fuse``.
- ``export.step`` of that union (a new product name each call, the solid upstream cached)
  against ``STEPCAFControl_Writer`` with a named, coloured label written to a file, and the
  plain ``STEPControl_Writer``.
- ``brep.mesh`` of the filleted box at tolerance 0.01 against ``BRepMesh_IncrementalMesh``
  alone and followed by reading its triangles out face by face into numpy, as a user
  turning it into arrays writes it.
"""

from __future__ import annotations

import itertools
import tempfile
from pathlib import Path

import numpy as np

import formgraph as fg


def _occ_fillet(shape, radius):
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    maker = BRepFilletAPI_MakeFillet(shape)
    e = TopExp_Explorer(shape, TopAbs_EDGE)
    while e.More():
        maker.Add(radius, TopoDS.Edge(e.Current()))
        e.Next()
    return maker.Shape()


def _box(size, center):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    corner = np.asarray(center, float) - np.asarray(size, float) / 2
    return BRepPrimAPI_MakeBox(gp_Pnt(*corner.tolist()), *size).Shape()


def _fillet_rows(table, radii) -> None:
    from OCP.BRepCheck import BRepCheck_Analyzer

    from formgraph.kernels.brep import features
    from formgraph.kernels.brep.diagnose import Adjacency

    g = fg.Graph()
    g.add_param("r", 2.0)
    g.add("b", "brep.box", size=[40, 30, 20])
    g.add("f", "brep.fillet", solid="@b", radius="=r")
    box = g.evaluate("b").shape
    occ_box = _box([40, 30, 20], [0, 0, 0])

    def api():
        return g.evaluate("f", r=next(radii))

    def kernel():
        adj = Adjacency(box)
        return features.fillet(box, next(radii), list(range(12)), adj)

    def occ():
        return _occ_fillet(occ_box, next(radii))

    def occ_checked():
        out = _occ_fillet(occ_box, next(radii))
        assert BRepCheck_Analyzer(out).IsValid()
        return out

    table.compare(
        "brep.fillet, 12 edges of a box",
        api=api,
        kernel=kernel,
        references={"OCP MakeFillet": occ, "OCP MakeFillet + check": occ_checked},
        note="graph: selector, adjacency, fillet, validity check",
        notes={
            "formgraph kernel": "features.fillet with its adjacency",
            "OCP MakeFillet": "Add each edge, Shape()",
            "OCP MakeFillet + check": "and BRepCheck_Analyzer, as our kernel checks",
        },
    )


def _union_graph() -> fg.Graph:
    g = fg.Graph()
    g.add_param("r", 2.0)
    g.add_param("name", "part")
    g.add("a", "brep.box", size=[40, 30, 20])
    g.add("b", "brep.box", size=[30, 30, 30], center=[20, 10, 10])
    g.add("fa", "brep.fillet", solid="@a", radius="=r")
    g.add("fb", "brep.fillet", solid="@b", radius="=r")
    g.add("u", "brep.boolean", a="@fa", b=["@fb"])
    return g


def _boolean_rows(table, radii) -> None:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse

    from formgraph.kernels.brep import boolean

    g = _union_graph()
    a, b = _box([40, 30, 20], [0, 0, 0]), _box([30, 30, 30], [20, 10, 10])
    fa, fb = _occ_fillet(a, 2.0), _occ_fillet(b, 2.0)

    def api():
        return g.evaluate("u", r=next(radii))

    def kernel():
        return boolean.boolean(fa, [fb], "union")

    def occ():
        r = next(radii)
        return BRepAlgoAPI_Fuse(_occ_fillet(a, r), _occ_fillet(b, r)).Shape()

    table.compare(
        "brep.boolean, union of two filleted boxes",
        api=api,
        kernel=kernel,
        references={"OCP fillets + Fuse": occ},
        note="both fillets and the union, radius changed",
        notes={
            "formgraph kernel": "the union alone, fillets made once",
            "OCP fillets + Fuse": "MakeFillet twice, BRepAlgoAPI_Fuse",
        },
    )


def _step_rows(table) -> None:
    from OCP.Quantity import Quantity_Color, Quantity_TypeOfColor
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool

    folder = Path(tempfile.mkdtemp(prefix="bench-brep-"))
    g = fg.Graph(out_dir=folder)
    for name, kind, inputs in [
        ("a", "brep.box", {"size": [40, 30, 20]}),
        ("b", "brep.box", {"size": [30, 30, 30], "center": [20, 10, 10]}),
        ("fa", "brep.fillet", {"solid": "@a", "radius": 2}),
        ("fb", "brep.fillet", {"solid": "@b", "radius": 2}),
        ("u", "brep.boolean", {"a": "@fa", "b": ["@fb"]}),
    ]:
        g.add(name, kind, **inputs)
    g.add_param("name", "part")
    g.add("s", "export.step", path="u.step", solids=["@u"], names=["=name"],
          colors=["#8fa3b8"])  # fmt: skip
    shape = g.evaluate("u").shape
    names = (f"part {k}" for k in itertools.count())

    def api():
        return g.evaluate("s", name=next(names))

    def xcaf():
        doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
        shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
        colours = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
        label = shapes.AddShape(shape, False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(next(names)))
        c = Quantity_Color(0.56, 0.64, 0.72, Quantity_TypeOfColor.Quantity_TOC_sRGB)
        colours.SetColor(label, c, XCAFDoc_ColorType.XCAFDoc_ColorSurf)
        w = STEPCAFControl_Writer()
        w.SetNameMode(True)
        w.SetColorMode(True)
        w.Transfer(doc, STEPControl_StepModelType.STEPControl_AsIs)
        w.Write(str(folder / "occ.step"))

    def plain():
        w = STEPControl_Writer()
        w.Transfer(shape, STEPControl_StepModelType.STEPControl_AsIs)
        w.Write(str(folder / "plain.step"))

    table.compare(
        "export.step, the filleted union",
        api=api,
        references={"OCP STEPCAFControl_Writer": xcaf, "OCP STEPControl_Writer": plain},
        note="named, coloured, written to a file",
        notes={
            "OCP STEPCAFControl_Writer": "XCAF label, name, colour, Write",
            "OCP STEPControl_Writer": "no name or colour",
        },
    )


def _mesh_rows(table, tolerances) -> None:
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopLoc import TopLoc_Location

    from formgraph.kernels.brep import occ, tessellate

    g = fg.Graph()
    g.add_param("tol", 0.01)
    g.add("b", "brep.box", size=[40, 30, 20])
    g.add("f", "brep.fillet", solid="@b", radius=3)
    g.add("m", "brep.mesh", solid="@f", tolerance="=tol")
    shape = g.evaluate("f").shape

    def api():
        return g.evaluate("m", tol=next(tolerances))

    def kernel():
        return tessellate.tessellate(shape, next(tolerances), 0.35)

    def mesh_only():
        copy = BRepBuilderAPI_Copy(shape, False, False).Shape()
        BRepMesh_IncrementalMesh(copy, next(tolerances), False, 0.35, False)
        return copy

    def to_arrays():
        copy = mesh_only()
        out = []
        for face in occ.explore(copy, "face"):
            tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
            xyz = [tri.Node(i).Coord() for i in range(1, tri.NbNodes() + 1)]
            t = [tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)]
            out.append((np.array(xyz), np.array(t) - 1))
        return out

    table.compare(
        "brep.mesh, filleted box, tolerance 0.01",
        api=api,
        kernel=kernel,
        references={"OCP IncrementalMesh": mesh_only, "OCP IncrementalMesh + arrays": to_arrays},
        note="closed, outward, shared nodes merged",
        notes={
            "formgraph kernel": "tessellate.tessellate",
            "OCP IncrementalMesh": "on a copy, triangles left in OCC",
            "OCP IncrementalMesh + arrays": "and read out per face to numpy",
        },
    )


def run(table) -> None:
    radii = (2.0 + 1e-9 * k for k in itertools.count())
    _fillet_rows(table, radii)
    _boolean_rows(table, radii)
    _step_rows(table)
    _mesh_rows(table, (0.01 * (1 + 1e-9 * k) for k in itertools.count()))
