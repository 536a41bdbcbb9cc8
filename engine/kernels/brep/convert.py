"""Our exact curves and surfaces as OpenCASCADE edges, wires and faces, and back.

A NURBS curve goes to OCC as it is: its degree, its knots (distinct values with their
multiplicities, as OCC keeps them), its control points and weights (``Geom_BSplineCurve``;
a surface likewise, ``Geom_BSplineSurface``), after clamping (the same curve on a knot
vector whose ends repeat ``p + 1`` times, The NURBS Book A5.4 by knot insertion: OCC's
non-periodic splines end on their end control points).

A curve that bounds a face is first cut where it has a corner (an inner knot of
multiplicity >= p: only C0 there), each piece extracted exactly (:func:`respace`), and
each piece told for what it is, so CAD receives what a designer drew: a piece of degree 1
is a chain of line segments; a rational quadratic piece whose points lie on one circle (a
conic is fixed by five of its points, so seven on a circle make it that circle) is an arc
of that circle, and neighbouring arcs of one circle join into one (a whole circle is one
closed edge); anything else stays the B-spline it is. A rounded rectangle becomes four lines
and four arcs; extruded, its sides are planes and cylinders, the faces a machinist's CAM
expects, not B-spline patches.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeWire,
)
from OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int, Array2_double, Array2_gp_Pnt
from OCP.GC import GC_MakeArcOfCircle
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface
from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pln, gp_Pnt

from ..nurbs import clamp, clamp_surface, curve_evaluate, homogeneous, project, respace
from . import BrepError, occ

__all__ = [
    "Piece",
    "bspline_curve",
    "bspline_surface",
    "curve_pieces",
    "edges_of",
    "plane_face",
    "wire_of",
]

CurveTuple = tuple[np.ndarray, int, np.ndarray, "np.ndarray | None"]

_ON = 1e-10  # relative distance within which sample points lie on a line or circle


@dataclass(frozen=True)
class Piece:
    """One smooth piece of a curve: ``kind`` ``line`` (``points`` its two ends), ``arc``
    (``points`` start, a point inside, end; ``center``, ``radius``, ``normal``), or
    ``bspline`` (``curve``, the exact piece)."""

    kind: str
    points: np.ndarray
    curve: CurveTuple | None = None
    center: np.ndarray | None = None
    radius: float = 0.0
    normal: np.ndarray | None = None


def _gp(p: np.ndarray) -> gp_Pnt:
    return gp_Pnt(float(p[0]), float(p[1]), float(p[2]))


def _knots_and_mults(knots: np.ndarray) -> tuple[Array1_double, Array1_int]:
    values, counts = np.unique(np.asarray(knots, dtype=np.float64), return_counts=True)
    k = Array1_double(1, len(values))
    m = Array1_int(1, len(values))
    for i, (v, c) in enumerate(zip(values.tolist(), counts.tolist(), strict=True), start=1):
        k.SetValue(i, v)
        m.SetValue(i, c)
    return k, m


def bspline_curve(
    control_points: np.ndarray, degree: int, knots: np.ndarray, weights: np.ndarray | None
) -> Geom_BSplineCurve:
    """The OCC curve of a NURBS curve, exactly (clamped first where it is not).

    Raises
    ------
    BrepError
        When OCC refuses the data (it checks knots, multiplicities and weights again).
    """
    cp, p, k, w = clamp(np.asarray(control_points, float), int(degree), knots, weights)
    poles = Array1_gp_Pnt(1, len(cp))
    for i, row in enumerate(cp.tolist(), start=1):
        poles.SetValue(i, gp_Pnt(*row))
    kv, mv = _knots_and_mults(k)
    try:
        if w is None or np.all(w == w[0]):
            return Geom_BSplineCurve(poles, kv, mv, p, False)
        wa = Array1_double(1, len(w))
        for i, x in enumerate(np.asarray(w, float).tolist(), start=1):
            wa.SetValue(i, x)
        return Geom_BSplineCurve(poles, wa, kv, mv, p, False)
    except occ.FAILURES:
        raise BrepError(f"OpenCASCADE refuses a curve of degree {p} on {len(cp)} points") from None


def bspline_surface(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
) -> Geom_BSplineSurface:
    """The OCC surface of a NURBS surface, exactly (u along the first axis)."""
    cp, ku, kv, w = clamp_surface(control_points, degree_u, degree_v, knots_u, knots_v, weights)
    nu, nv = cp.shape[:2]
    poles = Array2_gp_Pnt(1, nu, 1, nv)
    rows = cp.tolist()
    for i in range(nu):  # one call per control point: OCC's arrays take no buffer
        for j in range(nv):
            poles.SetValue(i + 1, j + 1, gp_Pnt(*rows[i][j]))
    kum, mum = _knots_and_mults(ku)
    kvm, mvm = _knots_and_mults(kv)
    try:
        if w is None or np.all(w == w.flat[0]):
            return Geom_BSplineSurface(poles, kum, kvm, mum, mvm, degree_u, degree_v)
        wa = Array2_double(1, nu, 1, nv)
        wl = np.asarray(w, float).tolist()
        for i in range(nu):
            for j in range(nv):
                wa.SetValue(i + 1, j + 1, wl[i][j])
        return Geom_BSplineSurface(poles, wa, kum, kvm, mum, mvm, degree_u, degree_v)
    except occ.FAILURES:
        raise BrepError(
            f"OpenCASCADE refuses a surface of degrees {degree_u} x {degree_v} on "
            f"{nu} x {nv} points"
        ) from None


# ------------------------------------------------------------------------------ pieces


def _breaks(p: int, knots: np.ndarray) -> np.ndarray:
    """The domain's ends and the inner knots where the curve may have a corner (C0)."""
    values, counts = np.unique(knots, return_counts=True)
    a, b = knots[p], knots[-p - 1]
    inner = values[(values > a) & (values < b) & (counts >= p)]
    return np.concatenate([[a], inner, [b]])


def _line(points: np.ndarray, scale: float) -> bool:
    """Whether control points lie on the segment from the first to the last, in order
    (then the curve is that segment: it stays in their hull and moves one way)."""
    a, b = points[0], points[-1]
    d = b - a
    length = float(np.linalg.norm(d))
    if length <= _ON * scale:
        return False
    t = (points - a) @ d / length**2
    off = np.linalg.norm(points - a - t[:, None] * d, axis=1)
    return bool(np.all(off <= _ON * scale) and np.all(np.diff(t) >= -_ON))


def _circle(samples: np.ndarray, scale: float) -> tuple[np.ndarray, float, np.ndarray] | None:
    """The circle through the samples (centre, radius, unit normal), when all lie on it."""
    p0, p1, p2 = samples[0], samples[len(samples) // 2], samples[-1]
    a, b = p1 - p0, p2 - p0
    n = np.cross(a, b)
    nn = float(np.dot(n, n))
    if nn <= (_ON * scale) ** 4:
        return None  # collinear: no circle
    # the circumcentre of p0, p1, p2
    c = p0 + (np.dot(b, b) * np.cross(n, a) + np.dot(a, a) * np.cross(b, n)) / (2 * nn)
    r = float(np.linalg.norm(p0 - c))
    unit = n / np.sqrt(nn)
    on_circle = np.abs(np.linalg.norm(samples - c, axis=1) - r) <= _ON * max(r, scale)
    in_plane = np.abs((samples - c) @ unit) <= _ON * max(r, scale)
    if not (on_circle.all() and in_plane.all()):
        return None
    return c, r, unit


def curve_pieces(
    control_points: np.ndarray, degree: int, knots: np.ndarray, weights: np.ndarray | None
) -> list[Piece]:
    """A curve cut at its corners, each piece told for what it is (line, arc, B-spline),
    consecutive arcs of one circle joined. In the curve's direction."""
    cp, p, k, w = clamp(np.asarray(control_points, float), int(degree), knots, weights)
    scale = max(1.0, float(np.abs(cp).max()))
    if p == 1:  # a polyline: its segments, repeated points left out
        step = np.linalg.norm(np.diff(cp, axis=0), axis=1) > _ON * scale
        keep = np.r_[True, step]
        pts = cp[keep]
        return [Piece("line", pts[i : i + 2]) for i in range(len(pts) - 1)]
    breaks = _breaks(p, k)
    pw = homogeneous(cp, w)
    out: list[Piece] = []
    for a, b in zip(breaks[:-1].tolist(), breaks[1:].tolist(), strict=True):  # per piece
        tau = np.concatenate([[a] * (p + 1), k[(k > a) & (k < b)], [b] * (p + 1)])
        cpi, wi = project(respace(p, k, pw, tau), w is not None)
        if wi is not None and np.all(wi == wi[0]):
            wi = None
        if _line(cpi, scale):
            out.append(Piece("line", cpi[[0, -1]]))
            continue
        if p == 2:
            samples = curve_evaluate(cpi, p, tau, wi, np.linspace(a, b, 7))
            circle = _circle(samples, scale)
            if circle is not None:
                c, r, n = circle
                out.append(Piece("arc", samples[[0, 3, 6]], None, c, r, n))
                continue
        out.append(Piece("bspline", cpi[[0, -1]], (cpi, p, tau, wi)))
    return _joined_arcs(out, scale)


def _same_circle(x: Piece, y: Piece, scale: float) -> bool:
    assert x.center is not None and y.center is not None
    assert x.normal is not None and y.normal is not None
    tol = _ON * max(scale, x.radius)
    return bool(
        np.linalg.norm(x.center - y.center) <= tol
        and abs(x.radius - y.radius) <= tol
        and np.dot(x.normal, y.normal) > 1 - 1e-9
    )


def _joined_arcs(pieces: list[Piece], scale: float) -> list[Piece]:
    out: list[Piece] = []
    for piece in pieces:
        last = out[-1] if out else None
        if (
            piece.kind == "arc"
            and last is not None
            and last.kind == "arc"
            and _same_circle(last, piece, scale)
        ):
            # one arc from the first's start through the joint to the second's end
            pts = np.stack([last.points[0], last.points[2], piece.points[2]])
            out[-1] = Piece("arc", pts, None, last.center, last.radius, last.normal)
        else:
            out.append(piece)
    if len(out) > 1 and out[0].kind == "arc" and out[-1].kind == "arc":
        first, last = out[0], out[-1]
        if _same_circle(first, last, scale):  # the curve starts inside an arc: join round
            pts = np.stack([last.points[0], last.points[2], first.points[2]])
            out = [Piece("arc", pts, None, last.center, last.radius, last.normal), *out[1:-1]]
    return out


def _arc_edge(piece: Piece, scale: float) -> object:
    start, mid, end = piece.points
    assert piece.center is not None and piece.normal is not None
    if np.linalg.norm(start - end) <= _ON * max(scale, piece.radius):
        # a whole circle: one closed edge starting where the curve does
        x = start - piece.center
        axes = gp_Ax2(_gp(piece.center), gp_Dir(*piece.normal.tolist()), gp_Dir(*x.tolist()))
        return BRepBuilderAPI_MakeEdge(gp_Circ(axes, piece.radius)).Edge()
    arc = GC_MakeArcOfCircle(_gp(start), _gp(mid), _gp(end)).Value()
    return BRepBuilderAPI_MakeEdge(arc).Edge()


def edges_of(pieces: list[Piece], scale: float = 1.0) -> list[object]:
    """One OCC edge per piece, in order."""
    out = []
    for piece in pieces:
        try:
            if piece.kind == "line":
                a, b = piece.points
                out.append(BRepBuilderAPI_MakeEdge(_gp(a), _gp(b)).Edge())
            elif piece.kind == "arc":
                out.append(_arc_edge(piece, scale))
            else:
                assert piece.curve is not None
                out.append(BRepBuilderAPI_MakeEdge(bspline_curve(*piece.curve)).Edge())
        except occ.FAILURES:
            raise BrepError(f"a {piece.kind} piece of a curve cannot be made an edge") from None
    return out


def wire_of(curve: CurveTuple, what: str, split: bool = True) -> object:
    """The closed wire of a closed curve: its pieces joined (``split``), or the whole curve
    as one B-spline edge (a loft's sections, which must match edge for edge).

    Raises
    ------
    BrepError
        When the pieces do not join into one closed wire.
    """
    cp = np.asarray(curve[0], float)
    scale = max(1.0, float(np.abs(cp).max()))
    if split:
        edges = edges_of(curve_pieces(*curve), scale)
    else:
        try:
            edges = [BRepBuilderAPI_MakeEdge(bspline_curve(*curve)).Edge()]
        except occ.FAILURES:
            raise BrepError(f"{what} cannot be made an edge") from None
    if not edges:
        raise BrepError(f"{what} has no length")
    maker = BRepBuilderAPI_MakeWire()
    for e in edges:
        maker.Add(e)
    if not maker.IsDone():
        raise BrepError(f"{what}: its pieces do not join end to end")
    wire = maker.Wire()
    if not wire.Closed():
        raise BrepError(f"{what} is open: a face is bounded by closed curves")
    return wire


def plane_face(
    outer: object, holes: list[object], origin: np.ndarray, normal: np.ndarray
) -> object:
    """The face on a given plane (origin, normal) bounded by ``outer`` and ``holes``."""
    try:
        pln = gp_Pln(_gp(origin), gp_Dir(*np.asarray(normal, float).tolist()))
        maker = BRepBuilderAPI_MakeFace(pln, outer, True)
        for h in holes:
            maker.Add(h)
        return maker.Face()
    except occ.FAILURES:
        raise BrepError("the outlines do not bound a face") from None
