"""Fillets, chamfers and shells (OCC's ``BRepFilletAPI`` and ``BRepOffsetAPI``), each
failure explained.

Every result is checked (``BRepCheck_Analyzer``): OCC can return a fillet it calls done
that is not a valid solid (a radius of 5.1 on a box 10 wide is "done"). When an operation
fails, or makes an invalid solid, the reason is looked for in the geometry first
(:mod:`.diagnose`: the narrowest face against the radius; a convex round thinner than the
wall), then in what OCC reports (the fillet's faulty contours and their
``ChFiDS_ErrorStatus``, its faulty vertices; the offset's ``BRepOffset_Error``), and said
with the edges or faces by number.
"""

from __future__ import annotations

from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid
from OCP.BRepFilletAPI import BRepFilletAPI_MakeChamfer, BRepFilletAPI_MakeFillet
from OCP.BRepLib import BRepLib
from OCP.BRepOffset import BRepOffset_Error, BRepOffset_Mode
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffsetShape, BRepOffsetAPI_MakeThickSolid
from OCP.ChFiDS import ChFiDS_ErrorStatus
from OCP.collections import List_TopoDS_Shape
from OCP.GeomAbs import GeomAbs_JoinType, GeomAbs_Shape, GeomAbs_SurfaceType
from OCP.ShapeUpgrade import ShapeUpgrade_ShapeDivideContinuity
from OCP.TopoDS import TopoDS

from . import BrepError, occ
from .diagnose import Adjacency, narrowest, numbers

__all__ = ["chamfer", "fillet", "shell", "usable_edges"]

_STATUS = {
    ChFiDS_ErrorStatus.ChFiDS_StartsolFailure: (
        "no round of that radius fits where it starts: the radius may be too large for "
        "the faces there"
    ),
    ChFiDS_ErrorStatus.ChFiDS_WalkingFailure: (
        "the round could not be followed along them: the faces meet at an angle that "
        "changes too fast, or curve more tightly than the radius"
    ),
    ChFiDS_ErrorStatus.ChFiDS_TwistedSurface: (
        "the rounded surface would twist through itself: try a smaller radius"
    ),
}


def usable_edges(adj: Adjacency, edges: list[int]) -> tuple[list[int], list[int]]:
    """The selected edges split into those with a corner to round or cut and those
    without (where two faces meet smoothly, a seam, a collapsed edge)."""
    keep, smooth = [], []
    for i in edges:  # one normal comparison per selected edge
        (smooth if adj.smooth(i) else keep).append(i)
    return keep, smooth


def _room_problem(adj: Adjacency, edges: list[int], size: float, noun: str) -> str | None:
    tight = narrowest(adj, edges)
    if tight is None or size < tight.room:
        return None
    than = "larger than" if size > tight.room else "as large as"
    if tight.both_sides:
        return (
            f"the {noun} {size:g} is {than} half the narrowest adjacent face (face "
            f"{tight.face}), which is {tight.width:.4g} wide and is cut on both sides "
            f"(edges {numbers(list(tight.edges))}): the two would meet"
        )
    across = (
        f"between edges {numbers(list(tight.edges))}"
        if len(tight.edges) == 2
        else f"across edge {tight.edges[0]}"
    )
    return (
        f"the {noun} {size:g} is {than} the narrowest adjacent face (face {tight.face}), "
        f"which is {tight.width:.4g} wide {across}"
    )


def _result(shape: object) -> object | None:
    """The solid(s) of an OCC result, None when it holds none or is not valid."""
    solids = occ.solids_of(shape)
    if not solids:
        return None
    out = occ.compound(solids)
    return out if occ.is_valid(out) else None


def fillet(shape: object, radius: float, edges: list[int], adj: Adjacency) -> object:
    """``shape`` with ``edges`` (OCC's numbers, 0-based, each with a corner) rounded.

    Raises
    ------
    BrepError
        Why not, with the edges by number (port ``radius`` when the radius is the cause).
    """
    maker = BRepFilletAPI_MakeFillet(shape)
    for i in edges:
        maker.Add(radius, adj.edges[i])
    try:
        maker.Build()
        done = maker.IsDone()
        out = _result(maker.Shape()) if done else None
    except occ.FAILURES:
        done, out = False, None
    if out is not None:
        return out
    room = _room_problem(adj, edges, radius, "radius")
    if room is not None:
        raise BrepError(room, "radius")
    reasons = []
    if not done:
        for k in range(1, maker.NbFaultyContours() + 1):
            ic = maker.FaultyContour(k)
            members = [
                adj.edge_index.FindIndex(maker.Edge(ic, j)) - 1
                for j in range(1, maker.NbEdges(ic) + 1)
            ]
            why = _STATUS.get(maker.StripeStatus(ic), "OpenCASCADE could not build the round")
            reasons.append(f"along edges {numbers(sorted(members))}: {why}")
        for k in range(1, maker.NbFaultyVertices() + 1):
            p = occ.vertex_point(maker.FaultyVertex(k))
            reasons.append(
                f"at the corner ({', '.join(f'{x:.4g}' for x in p)}) the rounds of the edges "
                "meeting there cannot be joined"
            )
    if not reasons:
        reasons.append(
            f"OpenCASCADE could not round edges {numbers(edges)} into a valid solid: try a "
            "smaller radius, or fewer edges at once"
        )
    raise BrepError(f"the fillet of radius {radius:g} fails " + "; ".join(reasons), "radius")


def chamfer(shape: object, distance: float, edges: list[int], adj: Adjacency) -> object:
    """``shape`` with ``edges`` cut at 45 degrees, ``distance`` back along each face."""
    maker = BRepFilletAPI_MakeChamfer(shape)
    for i in edges:
        maker.Add(distance, adj.edges[i])
    try:
        maker.Build()
        out = _result(maker.Shape()) if maker.IsDone() else None
    except occ.FAILURES:
        out = None
    if out is not None:
        return out
    room = _room_problem(adj, edges, distance, "distance")
    if room is not None:
        raise BrepError(room, "distance")
    raise BrepError(
        f"OpenCASCADE could not chamfer edges {numbers(edges)} by {distance:g} into a valid "
        "solid: try a smaller distance, or fewer edges at once",
        "distance",
    )


_OFFSET = {
    BRepOffset_Error.BRepOffset_C0Geometry: (
        "a face of the solid has a crease inside it (a surface that is only C0): offsetting "
        "needs faces smooth inside"
    ),
    BRepOffset_Error.BRepOffset_BadNormalsOnGeometry: "a face has no normal somewhere",
    BRepOffset_Error.BRepOffset_NotConnectedShell: "the solid's faces are not all connected",
    BRepOffset_Error.BRepOffset_CannotTrimEdges: (
        "the offset faces do not meet again: the thickness is too large for a narrow face "
        "or a tight round"
    ),
    BRepOffset_Error.BRepOffset_CannotFuseVertices: (
        "the offset corners do not join: the thickness is too large for the faces there"
    ),
    BRepOffset_Error.BRepOffset_CannotExtentEdge: (
        "the offset faces cannot be extended to meet: the thickness is too large for a face there"
    ),
    BRepOffset_Error.BRepOffset_MixedConnectivity: "the solid's faces join in a non-manifold way",
}


def _too_thin_rounds(adj: Adjacency, thickness: float) -> list[tuple[int, float]]:
    """Convex rounds (cylinders, spheres, tori bulging out) of radius <= ``thickness``: an
    inward wall of that thickness turns them inside out."""
    out = []
    for f, face in enumerate(adj.faces):  # one query per face
        s = BRepAdaptor_Surface(face)
        t = s.GetType()
        if t == GeomAbs_SurfaceType.GeomAbs_Cylinder:
            r = s.Cylinder().Radius()
        elif t == GeomAbs_SurfaceType.GeomAbs_Sphere:
            r = s.Sphere().Radius()
        elif t == GeomAbs_SurfaceType.GeomAbs_Torus:
            r = s.Torus().MinorRadius()
        else:
            continue
        if r > thickness:
            continue
        # convex: the outward normal points away from the axis (the surface's own normal,
        # which points away for these, kept by a forward face)
        if not occ.reversed_(face):
            out.append((f, float(r)))
    return out


def smooth_faces(shape: object, faces: list[object]) -> tuple[object, list[object]]:
    """``shape`` with every face cut where its surface is only C0 (a rational circle's
    double knots: the same surface, in C1 pieces, which OCC's offset needs), and the
    pieces that ``faces`` became (``ShapeUpgrade_ShapeDivideContinuity``)."""
    divide = ShapeUpgrade_ShapeDivideContinuity(shape)
    divide.SetBoundaryCriterion(GeomAbs_Shape.GeomAbs_C1)
    divide.SetPCurveCriterion(GeomAbs_Shape.GeomAbs_C1)
    divide.SetSurfaceCriterion(GeomAbs_Shape.GeomAbs_C1)
    if not divide.Perform():
        return shape, faces
    context = divide.GetContext()
    pieces = [p for f in faces for p in occ.explore(context.Apply(f), "face")]
    return divide.Result(), pieces


def shell(shape: object, thickness: float, faces: list[int], adj: Adjacency) -> object:
    """``shape`` hollowed to walls of ``thickness`` (> 0: inward, the outside kept; < 0:
    outward), ``faces`` removed to open it (none: a closed hollow, a sealed cavity).
    Faces that are only C0 inside are first cut into C1 pieces (:func:`smooth_faces`)."""
    offset = -float(thickness)
    try:
        original = shape
        shape, removed = smooth_faces(shape, [adj.faces[f] for f in faces])
        if faces:
            closing = List_TopoDS_Shape()
            for f in removed:
                closing.Append(f)
            maker = BRepOffsetAPI_MakeThickSolid()
            maker.MakeThickSolidByJoin(
                shape, closing, offset, 1e-6, BRepOffset_Mode.BRepOffset_Skin, False, False,
                GeomAbs_JoinType.GeomAbs_Arc,
            )  # fmt: skip
            error = maker.MakeOffset().Error()
            out = _result(maker.Shape()) if maker.IsDone() else None
        else:
            maker = BRepOffsetAPI_MakeOffsetShape()
            maker.PerformByJoin(
                shape, offset, 1e-6, BRepOffset_Mode.BRepOffset_Skin, False, False,
                GeomAbs_JoinType.GeomAbs_Arc,
            )  # fmt: skip
            error = maker.MakeOffset().Error()
            out = None
            if maker.IsDone():
                inner = occ.solids_of(maker.Shape())
                if not inner:  # an offset of a solid gives its shell: make it a solid
                    inner = [
                        BRepBuilderAPI_MakeSolid(TopoDS.Shell(s)).Solid()
                        for s in occ.explore(maker.Shape(), "shell")
                    ]
                if inner:
                    for s in inner:
                        BRepLib.OrientClosedSolid_s(s)
                    outer, core = (original, inner[0]) if offset < 0 else (inner[0], original)
                    out = _result(BRepAlgoAPI_Cut(outer, core).Shape())
    except occ.FAILURES:
        error, out = BRepOffset_Error.BRepOffset_UnknownError, None
    if out is not None:
        return out
    if thickness > 0:
        thin = _too_thin_rounds(adj, thickness)
        if thin:
            listed = ", ".join(f"{f} (radius {r:g})" for f, r in thin[:8])
            raise BrepError(
                f"the thickness {thickness:g} is not less than the radius of the rounded "
                f"faces {listed}: inward, they would turn inside out; make the wall thinner "
                "or the rounds larger",
                "thickness",
            )
    why = _OFFSET.get(error, "OpenCASCADE could not offset the faces")
    opened = f" with faces {numbers(faces)} removed" if faces else ""
    raise BrepError(f"the shell of thickness {thickness:g}{opened} fails: {why}", "thickness")
