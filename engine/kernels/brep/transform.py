"""Affine maps of solids, exact: a rigid motion moves the shape (a location, nothing
copied); a uniform scale or a mirror maps its geometry exactly (planes stay planes,
circles circles); a non-uniform scale turns its surfaces into B-splines first, whose affine
image is exact (The NURBS Book 4.4)."""

from __future__ import annotations

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_GTransform, BRepBuilderAPI_Transform
from OCP.gp import gp_GTrsf, gp_Mat, gp_Trsf, gp_Vec, gp_XYZ

from . import BrepError, occ

__all__ = ["moved", "transformed"]


def moved(shape: object, offset: np.ndarray) -> object:
    """``shape`` translated by ``offset`` (3,)."""
    t = gp_Trsf()
    t.SetTranslation(gp_Vec(*np.asarray(offset, float).tolist()))
    return BRepBuilderAPI_Transform(shape, t, False).Shape()


def transformed(shape: object, linear: np.ndarray, offset: np.ndarray) -> object:
    """``shape`` under ``p -> linear @ p + offset``.

    Raises
    ------
    BrepError
        For a singular ``linear`` (it would flatten the solid).
    """
    a = np.asarray(linear, float)
    b = np.asarray(offset, float)
    det = float(np.linalg.det(a))
    if not abs(det) > 1e-300:
        raise BrepError("the map flattens the solid (a scale of 0)")
    s = abs(det) ** (1 / 3)
    similar = np.allclose(a @ a.T, s * s * np.eye(3), rtol=0, atol=1e-12 * s * s)
    try:
        if similar:
            t = gp_Trsf()
            t.SetValues(*a[0].tolist(), b[0], *a[1].tolist(), b[1], *a[2].tolist(), b[2])
            rigid = abs(s - 1.0) <= 1e-12 and det > 0
            return BRepBuilderAPI_Transform(shape, t, not rigid).Shape()
        g = gp_GTrsf(gp_Mat(*a.reshape(-1).tolist()), gp_XYZ(*b.tolist()))
        return BRepBuilderAPI_GTransform(shape, g, True).Shape()
    except occ.FAILURES:
        raise BrepError("the solid cannot be mapped that way") from None
