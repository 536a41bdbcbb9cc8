"""Solids as STEP AP214 (ISO 10303-21): manifold solid B-reps, exact, named and coloured.

OCC's own STEP translator writes each solid as a ``MANIFOLD_SOLID_BREP`` of
``ADVANCED_FACE`` s on their exact surfaces (planes, cylinders, tori, B-splines) with their
trimming edges and p-curves, the schema CAD programs read for machining. The solids go
through an XCAF document (``STEPCAFControl_Writer``) so each is a product with its name
(``PRODUCT``) and, when given, its colour (a ``STYLED_ITEM`` on its faces). The file is
written to memory (``WriteStream``), in millimetres; its header's date is replaced by a
fixed one so the same solids give the same bytes (the exporter then leaves an unchanged
file alone).

One ambiguity of the format is removed first: a face on a closed surface (a sphere, a
torus, a periodic B-spline), say the part of a sphere outside a box's corner, can be read
back by OCC as the other side of its loop (the eighth instead of the seven eighths). When
a solid has faces on such surfaces, its closed faces are cut along a seam before writing
(``ShapeUpgrade_ShapeDivideClosed``: the same surfaces, more faces), so every face's loops
say on which side it lies.
"""

from __future__ import annotations

import io
import re

from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.GeomAbs import GeomAbs_SurfaceType
from OCP.Interface import Interface_Static
from OCP.Quantity import Quantity_Color, Quantity_TypeOfColor
from OCP.ShapeUpgrade import ShapeUpgrade_ShapeDivideClosed
from OCP.STEPCAFControl import STEPCAFControl_Writer
from OCP.STEPControl import STEPControl_StepModelType
from OCP.TCollection import TCollection_ExtendedString
from OCP.TDataStd import TDataStd_Name
from OCP.TDocStd import TDocStd_Document
from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool

from . import BrepError, occ

__all__ = ["unambiguous", "write"]

_FILE_NAME = re.compile(rb"FILE_NAME\(.*?\);\n", re.DOTALL)


def _closed_face(face: object) -> bool:
    """Whether ``face`` lies on a closed surface other than a cylinder or a cone (whose
    seamed faces OCC reads back as written)."""
    surface = BRepAdaptor_Surface(face)
    if surface.GetType() in (
        GeomAbs_SurfaceType.GeomAbs_Cylinder,
        GeomAbs_SurfaceType.GeomAbs_Cone,
    ):
        return False
    return bool(surface.IsUClosed() or surface.IsVClosed())


def unambiguous(shape: object) -> object:
    """``shape``, or when a face of it is :func:`_closed_face`, the shape with its
    closed faces cut in two along a seam."""
    if not any(_closed_face(f) for f in occ.indexed(shape, "face")):
        return shape
    divide = ShapeUpgrade_ShapeDivideClosed(shape)
    divide.SetNbSplitPoints(1)
    try:
        divide.Perform()
        return divide.Result()
    except occ.FAILURES:
        return shape


def write(
    shapes: list[object],
    names: list[str],
    colours: list[tuple[float, float, float] | None],
    title: str = "formgraph",
) -> bytes:
    """A STEP AP214 file of ``shapes`` (solids or compounds of them), one product each.

    Parameters
    ----------
    shapes : list of OCC shapes
    names : list of str
        Each product's name.
    colours : list of (r, g, b) in 0..1 (sRGB) or None
        Each solid's surface colour (None: none written).
    title : str
        The file's name in its header.

    Returns
    -------
    bytes

    Raises
    ------
    BrepError
        When OCC's translator refuses a shape.
    """
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    shapes_tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    colour_tool = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    for shape, name, colour in zip(shapes, names, colours, strict=True):  # one product each
        label = shapes_tool.AddShape(unambiguous(shape), False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))
        if colour is not None:
            c = Quantity_Color(*colour, Quantity_TypeOfColor.Quantity_TOC_sRGB)
            colour_tool.SetColor(label, c, XCAFDoc_ColorType.XCAFDoc_ColorSurf)
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    writer = STEPCAFControl_Writer()
    writer.SetNameMode(True)
    writer.SetColorMode(True)
    buf = io.BytesIO()
    try:
        if not writer.Transfer(doc, STEPControl_StepModelType.STEPControl_AsIs):
            raise BrepError("OpenCASCADE's STEP translator refuses the solids")
        writer.WriteStream(buf)
    except occ.FAILURES:
        raise BrepError("OpenCASCADE's STEP translator fails on the solids") from None
    safe = title.replace("'", "''").encode()
    fixed = (
        b"FILE_NAME('" + safe + b".stp','1970-01-01T00:00:00',(''),(''),'formgraph',"
        b"'formgraph (OpenCASCADE)','');\n"
    )
    return _FILE_NAME.sub(lambda _: fixed, buf.getvalue(), count=1)
