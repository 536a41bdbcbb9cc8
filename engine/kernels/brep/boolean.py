"""Booleans of solids (OCC's general fuse, ``BOPAlgo_BOP``), failures and no-ops told.

The boolean runs as ``BRepAlgoAPI_Fuse`` / ``_Cut`` / ``_Common`` run it (the same
``BOPAlgo_BOP`` under them), called directly because only it reports why it failed: its
alerts (a self-intersecting argument, intersections it could not compute) become
sentences. A boolean that succeeds but does nothing a designer meant is told too, from
volumes (Gauss integration, exact to rounding): a union of solids that do not overlap (the
result is several solids), a difference whose tool does not reach the solid, an
intersection that is empty; "only touch" when the solids' boundaries meet
(``BRepExtrema_DistShapeShape``: distance 0) without any volume in common.
"""

from __future__ import annotations

from dataclasses import dataclass

from OCP.BOPAlgo import (
    BOPAlgo_AlertBOPNotAllowed,
    BOPAlgo_AlertIntersectionFailed,
    BOPAlgo_AlertIntersectionOfPairOfShapesFailed,
    BOPAlgo_AlertNullInputShapes,
    BOPAlgo_AlertSelfInterferingShape,
    BOPAlgo_AlertSolidBuilderFailed,
    BOPAlgo_AlertTooSmallEdge,
    BOPAlgo_BOP,
    BOPAlgo_Operation,
)
from OCP.BRepExtrema import BRepExtrema_DistShapeShape

from . import BrepError, occ

__all__ = ["OPERATIONS", "Outcome", "boolean"]

OPERATIONS = {
    "union": BOPAlgo_Operation.BOPAlgo_FUSE,
    "difference": BOPAlgo_Operation.BOPAlgo_CUT,
    "intersection": BOPAlgo_Operation.BOPAlgo_COMMON,
}

_ALERTS = [
    (BOPAlgo_AlertSelfInterferingShape, "one of the solids intersects itself"),
    (BOPAlgo_AlertTooSmallEdge, "a solid has an edge too small to intersect reliably"),
    (
        BOPAlgo_AlertIntersectionOfPairOfShapesFailed,
        "the intersection of two of their faces could not be computed (faces that meet "
        "almost tangentially, or almost coincide)",
    ),
    (BOPAlgo_AlertIntersectionFailed, "the intersection of their faces could not be computed"),
    (BOPAlgo_AlertSolidBuilderFailed, "the pieces could not be joined into solids"),
    (BOPAlgo_AlertBOPNotAllowed, "the shapes cannot be combined that way"),
    (BOPAlgo_AlertNullInputShapes, "a solid is empty"),
]

_REL = 1e-9  # volumes within this fraction of each other are the same


@dataclass(frozen=True)
class Outcome:
    """A boolean's result and what a designer should hear about it (or None)."""

    shape: object
    warning: str | None


def _touch(a: object, b: object) -> bool:
    d = BRepExtrema_DistShapeShape(a, b)
    return bool(d.IsDone() and d.Value() <= 1e-7)


def _run(a: object, tools: list[object], operation: str) -> tuple[object, bool]:
    bop = BOPAlgo_BOP()
    bop.AddArgument(a)
    for t in tools:
        bop.AddTool(t)
    bop.SetOperation(OPERATIONS[operation])
    bop.SetRunParallel(False)
    try:
        bop.Perform()
    except occ.FAILURES:
        raise BrepError(f"the {operation} fails inside OpenCASCADE") from None
    if bop.HasErrors():
        for alert, words in _ALERTS:
            if bop.HasError(alert.get_type_descriptor_s()):
                raise BrepError(f"the {operation} fails: {words}")
        raise BrepError(f"the {operation} fails: OpenCASCADE could not combine the solids")
    return bop.Shape(), bool(bop.HasWarnings())


def boolean(a: object, tools: list[object], operation: str) -> Outcome:
    """``a`` united with, minus, or intersected with the ``tools`` (OCC shapes).

    The result is checked (``BRepCheck_Analyzer``, a third of the boolean's own time)
    when OCC's boolean reported warnings; a boolean of valid solids without any is valid
    by its construction (BOPAlgo's intersections and splits are checked inside it).

    Raises
    ------
    BrepError
        When OCC fails or makes something that is not a valid solid.
    """
    shape, warned = _run(a, tools, operation)
    solids = occ.solids_of(shape)
    result = occ.compound(solids) if solids else occ.compound([])
    if solids and warned and not occ.is_valid(result):
        raise BrepError(f"the {operation} makes a solid that is not valid (OpenCASCADE's check)")
    return Outcome(result, _said(a, tools, operation, result, len(solids)))


def _said(a: object, tools: list[object], operation: str, result: object, n: int) -> str | None:
    """What the designer should hear about a boolean that did not do what it says."""
    if operation == "union":
        given = len(occ.solids_of(a)) + sum(len(occ.solids_of(t)) for t in tools)
        if n <= 1 or n < given:
            return None
        touching = any(_touch(a, t) for t in tools)
        how = "only touch (along an edge or at a point)" if touching else "do not overlap"
        return f"the solids {how}: the union is {n} separate solids"
    if operation == "difference":
        va, vr = occ.volume(a), occ.volume(result)
        if abs(va - vr) > _REL * max(abs(va), 1e-300):
            return None
        if any(_touch(a, t) for t in tools):
            return "b only touches a: nothing is cut away"
        return "b does not reach a: nothing is cut away"
    if n and occ.volume(result) > 0:  # intersection
        return None
    if any(_touch(a, t) for t in tools):
        return "the solids only touch: their intersection has no volume (the result is empty)"
    return "the solids do not overlap: their intersection is empty"
