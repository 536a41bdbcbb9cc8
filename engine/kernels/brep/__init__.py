"""Exact solids through OpenCASCADE (OCP): the thin layer between our values and its B-rep.

OCP (``cadquery-ocp-novtk``, the optional extra ``formgraph[brep]``) is imported on first
use, never by ``import formgraph``: :func:`missing` says, without importing it, whether it
is installed and how to install it (what the ``brep.*`` nodes report at check time).

- ``occ``: the one place OCP is imported; its messages silenced; its failures caught
- ``convert``: our NURBS curves and surfaces as OCC edges and faces, exactly (degree, knots
  with multiplicities, weights); a curve split into lines, circular arcs and B-spline
  pieces; planar faces with holes
- ``build``: boxes, cylinders, extrusions, revolutions, lofts, sewn shells
- ``topology``: edges and faces as arrays (centre, length or area, kind) for selectors;
  counts, volume, area, validity
- ``features``: fillets, chamfers, shells, with the failure explained
- ``boolean``: union, difference, intersection, with disjoint and touching solids told
- ``tessellate``: a closed, outward triangle mesh within a tolerance
- ``exchange``: OCC's binary format (the disk cache, pickling) and the tables the STEP
  writer reads
- ``stepread``: STEP files read in a child process, budgeted and time bounded
"""

from __future__ import annotations

import importlib.util

__all__ = ["INSTALL", "BrepError", "available", "missing"]

INSTALL = "pip install 'formgraph[brep]'"


class BrepError(ValueError):
    """An operation on solids that failed, said in the designer's words (the node makes it
    an error on the input it names)."""

    def __init__(self, message: str, port: str | None = None):
        super().__init__(message)
        self.port = port


def available() -> bool:
    """Whether OpenCASCADE (OCP) can be imported, found without importing it."""
    return importlib.util.find_spec("OCP") is not None


def missing() -> str | None:
    """None when OCP is installed; else the sentence a ``brep.*`` node's check reports."""
    if available():
        return None
    return (
        "exact solids need OpenCASCADE, an optional extra (66 MB) that is not installed: "
        f"install it with {INSTALL}"
    )
