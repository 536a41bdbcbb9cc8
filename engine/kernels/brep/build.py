"""Solids made from numbers, regions, sections and surfaces (OCC's primitives and sweeps).

Every function returns an OCC shape that is one valid solid (or says why not, in a
:class:`~formgraph.kernels.brep.BrepError`): OCC's ``BRepCheck_Analyzer`` is asked after
each construction, because OCC's makers can report success on a shape that is not valid.
"""

from __future__ import annotations

import math

import numpy as np
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeSolid,
    BRepBuilderAPI_Sewing,
)
from OCP.BRepLib import BRepLib
from OCP.BRepOffsetAPI import BRepOffsetAPI_ThruSections
from OCP.BRepPrimAPI import (
    BRepPrimAPI_MakeBox,
    BRepPrimAPI_MakeCylinder,
    BRepPrimAPI_MakePrism,
    BRepPrimAPI_MakeRevol,
)
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Vec
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS

from . import BrepError, convert, occ, transform

__all__ = ["box", "cylinder", "extrude", "loft", "revolve", "sew"]

Region = tuple[object, list[object]]  # an outer wire and its hole wires


def _checked(shape: object, what: str) -> object:
    solids = occ.solids_of(shape)
    if not solids:
        raise BrepError(f"{what} made no solid")
    out = occ.compound(solids)
    if not occ.is_valid(out):
        raise BrepError(f"{what} made a solid that is not valid (OpenCASCADE's check fails)")
    return out


def box(size: np.ndarray, center: np.ndarray) -> object:
    """An axis-aligned box of ``size`` (3,) around ``center`` (3,)."""
    s = np.asarray(size, float)
    corner = np.asarray(center, float) - s / 2
    try:
        return BRepPrimAPI_MakeBox(gp_Pnt(*corner.tolist()), *s.tolist()).Solid()
    except occ.FAILURES:
        raise BrepError(f"a box of size {s.tolist()} cannot be made") from None


def cylinder(radius: float, height: float, center: np.ndarray) -> object:
    """A cylinder along z around ``center``, from ``center.z - height / 2`` up."""
    c = np.asarray(center, float)
    axes = gp_Ax2(gp_Pnt(c[0], c[1], c[2] - height / 2), gp_Dir(0, 0, 1))
    try:
        return BRepPrimAPI_MakeCylinder(axes, radius, height).Solid()
    except occ.FAILURES:
        raise BrepError(
            f"a cylinder of radius {radius:g} and height {height:g} cannot be made"
        ) from None


def _faces(regions: list[Region], origin: np.ndarray, normal: np.ndarray) -> list[object]:
    return [convert.plane_face(outer, holes, origin, normal) for outer, holes in regions]


def extrude(regions: list[Region], height: float, z0: float) -> object:
    """Planar faces in the XY plane (each an outer wire and its hole wires) swept along
    +z by ``height``, starting at ``z = z0``: one solid per face (a compound of them)."""
    faces = _faces(regions, np.zeros(3), np.array([0.0, 0.0, 1.0]))
    out = []
    for face in faces:
        try:
            prism = BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, height)).Shape()
        except occ.FAILURES:
            raise BrepError("the region cannot be extruded") from None
        out.extend(occ.solids_of(prism))
    shape = occ.compound(out)
    if z0 != 0.0:
        shape = transform.moved(shape, np.array([0.0, 0.0, z0]))
    return _checked(shape, "the extrusion")


def revolve(regions: list[Region], angle: float) -> object:
    """Planar faces in the XZ plane (profile x >= 0) turned about the z axis by
    ``angle`` degrees (360: all the way round)."""
    faces = _faces(regions, np.zeros(3), np.array([0.0, -1.0, 0.0]))
    axis = gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1))
    out = []
    for face in faces:
        try:
            if angle >= 360.0:
                made = BRepPrimAPI_MakeRevol(face, axis, 2 * math.pi, False).Shape()
            else:
                made = BRepPrimAPI_MakeRevol(face, axis, math.radians(angle), False).Shape()
        except occ.FAILURES:
            raise BrepError("the profile cannot be revolved") from None
        out.extend(occ.solids_of(made))
    return _checked(occ.compound(out), "the revolution")


def loft(wires: list[object], ruled: bool) -> object:
    """A solid through closed section wires in order (``ruled``: flat between sections)."""
    maker = BRepOffsetAPI_ThruSections(True, ruled, 1e-6)
    for w in wires:
        maker.AddWire(w)
    maker.CheckCompatibility(True)
    try:
        maker.Build()
        if not maker.IsDone():
            raise BrepError("the sections cannot be lofted into one solid")
        shape = maker.Shape()
    except occ.FAILURES:
        raise BrepError("the sections cannot be lofted into one solid") from None
    return _checked(shape, "the loft")


def sew(surfaces: list[object], tolerance: float) -> tuple[object | None, list[np.ndarray]]:
    """The closed solid that OCC surfaces bound, sewn within ``tolerance``.

    Returns
    -------
    solid : OCC shape or None
        None when the sewn shell is open.
    free : list of (2, 3) float
        Each free edge (a boundary no other surface meets) as its two end points.
    """
    sewing = BRepBuilderAPI_Sewing(tolerance, True, True, True, False)
    for k, s in enumerate(surfaces):
        try:
            face = BRepBuilderAPI_MakeFace(s, 1e-7).Face()
        except occ.FAILURES:
            raise BrepError(f"surface {k} cannot be made a face", "surfaces") from None
        sewing.Add(face)
    try:
        sewing.Perform()
        sewn = sewing.SewedShape()
    except occ.FAILURES:
        raise BrepError("the surfaces cannot be sewn together", "surfaces") from None
    free = []
    for i in range(1, sewing.NbFreeEdges() + 1):
        e = sewing.FreeEdge(i)
        v0, v1 = TopExp.FirstVertex_s(e), TopExp.LastVertex_s(e)
        free.append(np.stack([occ.vertex_point(v0), occ.vertex_point(v1)]))
    if free:
        return None, free
    shells = occ.explore(sewn, "shell")
    solids = []
    for shell in shells:
        try:
            solid = BRepBuilderAPI_MakeSolid(TopoDS.Shell(shell)).Solid()
            BRepLib.OrientClosedSolid_s(solid)  # outward, whatever way the surfaces face
        except occ.FAILURES:
            raise BrepError("the sewn shell does not make a solid", "surfaces") from None
        solids.append(solid)
    if not solids:
        raise BrepError("the surfaces make no closed shell", "surfaces")
    return _checked(occ.compound(solids), "sewing the surfaces"), []
