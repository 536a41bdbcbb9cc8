"""Solids to bytes and back (OCC's binary B-rep format, ``BinTools``), for the disk cache,
pickling and Dask.

``BinTools`` writes the topology and the exact geometry (no triangulation: what a mesh of
it looked like is no part of the solid) in a documented binary format that OCC reads back
to the same shape. Bytes from outside (a cache entry someone changed) are read in a guarded
call and must give solids; anything else is a ``ValueError``, which the cache takes as a
miss.
"""

from __future__ import annotations

import io

from OCP.BinTools import BinTools, BinTools_FormatVersion
from OCP.TopAbs import TopAbs_COMPOUND, TopAbs_SOLID
from OCP.TopoDS import TopoDS_Shape

from . import occ

__all__ = ["from_bytes", "to_bytes"]

_MAGIC = b"\nOpen CASCADE Topology V"  # how BinTools files begin (then the version)


def to_bytes(shape: object) -> bytes:
    """The shape in OCC's binary format, without triangulations."""
    buf = io.BytesIO()
    BinTools.Write_s(
        shape, buf, False, False, BinTools_FormatVersion.BinTools_FormatVersion_CURRENT
    )
    return buf.getvalue()


def from_bytes(data: bytes) -> object:
    """The shape ``data`` holds: a solid or a compound of solids (possibly none).

    Raises
    ------
    ValueError
        For bytes that are not that.
    """
    if not data.startswith(_MAGIC):
        raise ValueError("not an OpenCASCADE binary shape")
    shape = TopoDS_Shape()
    try:
        BinTools.Read_s(shape, io.BytesIO(data))
    except occ.FAILURES:
        raise ValueError("a damaged OpenCASCADE binary shape") from None
    if shape.IsNull():
        raise ValueError("an empty OpenCASCADE binary shape")
    if shape.ShapeType() not in (TopAbs_SOLID, TopAbs_COMPOUND):
        raise ValueError("an OpenCASCADE binary shape that is not a solid")
    if shape.ShapeType() == TopAbs_COMPOUND:
        if len(occ.explore(shape, "face")) != sum(
            len(occ.explore(s, "face")) for s in occ.solids_of(shape)
        ):
            raise ValueError("an OpenCASCADE binary shape with faces outside its solids")
    return shape
