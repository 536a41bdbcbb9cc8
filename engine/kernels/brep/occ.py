"""The one place OpenCASCADE (OCP) is imported: its messages silenced, its shapes walked.

Importing this module imports OCP (about a second, once); nothing under
:mod:`formgraph.kernels.brep` but its submodules imports it, and they only when a node
runs. OCC prints statistics and traces to stdout through its default messenger: they are
turned down to failures here, once. Its exceptions (``Standard_Failure`` and kin) never
reach the user: every call that can raise is wrapped where it is made, and what went wrong
is said in our words (:class:`~formgraph.kernels.brep.BrepError`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher
from OCP.GProp import GProp_GProps
from OCP.Message import Message
from OCP.Standard import Standard_Failure
from OCP.TopAbs import (
    TopAbs_COMPOUND,
    TopAbs_EDGE,
    TopAbs_FACE,
    TopAbs_REVERSED,
    TopAbs_SHELL,
    TopAbs_SOLID,
    TopAbs_VERTEX,
    TopAbs_WIRE,
)
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound, TopoDS_Shape

__all__ = [
    "FAILURES",
    "KINDS",
    "area",
    "bounds",
    "compound",
    "explore",
    "indexed",
    "is_valid",
    "solids_of",
    "volume",
]


def _failures() -> tuple[type[BaseException], ...]:
    """Every exception class OCP binds (``Standard_DomainError``, ``StdFail_NotDone``,
    ``gp_VectorWithNullMagnitude``, ...: about a hundred, each a direct subclass of
    Exception, not of ``Standard_Failure`` as in C++), and RuntimeError for the C++
    exceptions pybind11 maps to it (a bad_alloc becomes MemoryError, left alone)."""
    import OCP.OCP as bound

    found: set[type[BaseException]] = {Standard_Failure, RuntimeError}
    for module in vars(bound).values():  # one pass over the bound modules, a few ms
        if type(module).__name__ != "module":
            continue
        for value in vars(module).values():
            if (
                isinstance(value, type)
                and issubclass(value, Exception)
                and value.__module__.startswith("OCP")
            ):
                found.add(value)
    return tuple(sorted(found, key=lambda c: c.__name__))


# What OCC's calls raise, as pybind11 maps them.
FAILURES: tuple[type[BaseException], ...] = _failures()

KINDS = {
    "vertex": TopAbs_VERTEX,
    "edge": TopAbs_EDGE,
    "wire": TopAbs_WIRE,
    "face": TopAbs_FACE,
    "shell": TopAbs_SHELL,
    "solid": TopAbs_SOLID,
    "compound": TopAbs_COMPOUND,
}
_CAST = {
    TopAbs_VERTEX: TopoDS.Vertex,
    TopAbs_EDGE: TopoDS.Edge,
    TopAbs_WIRE: TopoDS.Wire,
    TopAbs_FACE: TopoDS.Face,
    TopAbs_SHELL: TopoDS.Shell,
    TopAbs_SOLID: TopoDS.Solid,
}


def _silence() -> None:
    """OCC's default printer writes every info, trace and failure to stdout: none of it is
    for the user (failures are caught where they happen and said in our words)."""
    Message.DefaultMessenger_s().ChangePrinters().Clear()


_silence()


def explore(shape: TopoDS_Shape, kind: str) -> list[Any]:
    """Every sub-shape of ``kind`` in ``shape`` as met by a walk (a shared one as often as
    it is used, with the orientation of that use), cast to its class."""
    k = KINDS[kind]
    cast = _CAST[k]
    out = []
    e = TopExp_Explorer(shape, k)
    while e.More():
        out.append(cast(e.Current()))
        e.Next()
    return out


def indexed(shape: TopoDS_Shape, kind: str) -> list[Any]:
    """The distinct sub-shapes of ``kind`` (each once, whatever its uses), in OCC's
    numbering (``TopExp::MapShapes``): edge i of a message is item i here."""
    k = KINDS[kind]
    m = IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher()
    TopExp.MapShapes_s(shape, k, m)
    cast = _CAST[k]
    return [cast(m.FindKey(i)) for i in range(1, m.Size() + 1)]


def index_map(shape: TopoDS_Shape, kind: str) -> Any:
    """OCC's indexed map of the distinct sub-shapes of ``kind`` (1-based ``FindIndex``)."""
    m = IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher()
    TopExp.MapShapes_s(shape, KINDS[kind], m)
    return m


def solids_of(shape: TopoDS_Shape) -> list[Any]:
    """The solids in ``shape`` (itself when it is one)."""
    if shape.IsNull():
        return []
    if shape.ShapeType() == TopAbs_SOLID:
        return [TopoDS.Solid(shape)]
    return explore(shape, "solid")


def compound(shapes: list[TopoDS_Shape]) -> TopoDS_Shape:
    """One solid as itself; several as a compound holding them."""
    if len(shapes) == 1:
        return shapes[0]
    c = TopoDS_Compound()
    b = BRep_Builder()
    b.MakeCompound(c)
    for s in shapes:
        b.Add(c, s)
    return c


# The relative error the adaptive integration is run to: OCC's default fixed-order Gauss
# rule is off by 2e-4 on a disc bounded by a rational circle; the adaptive one is not.
EPS = 1e-10


def volume(shape: TopoDS_Shape) -> float:
    """The enclosed volume: the divergence theorem over the faces, each integrated by
    adaptive Gauss-Kronrod in its parameters to :data:`EPS` (relative)."""
    p = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, p, EPS)
    return float(p.Mass())


def area(shape: TopoDS_Shape) -> float:
    """The area of the faces, integrated as :func:`volume` is."""
    p = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, p, EPS)
    return float(p.Mass())


def is_valid(shape: TopoDS_Shape) -> bool:
    """OCC's own check of topology and geometry (``BRepCheck_Analyzer``)."""
    try:
        return bool(BRepCheck_Analyzer(shape).IsValid())
    except FAILURES:
        return False


def bounds(shape: TopoDS_Shape) -> np.ndarray:
    """The box around the shape's geometry (optimal: from the surfaces, not their control
    points nor tolerances), ``(2, 3)``."""
    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    if box.IsVoid():
        return np.zeros((2, 3))
    return np.stack([point(box.CornerMin()), point(box.CornerMax())])


def point(p: Any) -> np.ndarray:
    """A gp_Pnt (or gp_XYZ, gp_Dir, gp_Vec) as a (3,) array."""
    return np.array([p.X(), p.Y(), p.Z()])


def reversed_(shape: TopoDS_Shape) -> bool:
    return shape.Orientation() == TopAbs_REVERSED


def vertex_point(v: Any) -> np.ndarray:
    return point(BRep_Tool.Pnt_s(v))
