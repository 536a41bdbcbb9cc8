"""``brep.extrude``, ``brep.revolve``, ``brep.loft``, ``brep.from_surfaces``: exact solids
from curves and surfaces.

A region is read as ``curves.boolean`` reads it (the even-odd rule, holes included, the
outlines left whole or cut exactly: :mod:`formgraph.nodes._outlines`); each of its parts
becomes a planar face bounded by exact edges, each outline cut at its corners into lines,
circular arcs and B-spline pieces (:mod:`formgraph.kernels.brep.convert`), so an extruded
circle has a cylindrical side and a revolved segment a cone.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import Range
from formgraph.geometry import Curve, NurbsSurface, Solid, Surface

from ._common import call, nurbs_of, regions, requires, solid


def _wires(parts: list, port: str, turn: bool = False) -> list:
    """The wires of each part (outer, holes); ``turn`` maps (x, y) to (x, 0, y)."""
    from formgraph.kernels.brep import convert

    def curve(c: tuple) -> tuple:
        if not turn:
            return c
        cp = np.asarray(c[0], float)
        return (np.c_[cp[:, 0], np.zeros(len(cp)), cp[:, 1]], c[1], c[2], c[3])

    out = []
    for k, (outer, holes) in enumerate(parts):  # one face per part of the region
        o = call(port, convert.wire_of, curve(outer), f"outline {k}")
        hs = [call(port, convert.wire_of, curve(h), f"a hole of outline {k}") for h in holes]
        out.append((o, hs))
    return out


@node("brep.extrude", version=1, requires=requires)
def extrude(
    curves: list[Curve],
    height: float,
    center: bool = False,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Solid:
    """The region of closed curves in the XY plane (holes included) extruded along z.

    The region is the even-odd one ``curves.boolean`` reads (a curve inside another is a
    hole); each outline becomes exact edges (lines, circular arcs, B-splines), so the side
    of an extruded circle is a cylinder and that of a spline a surface of extrusion.

    Parameters
    ----------
    curves : list[Curve]
        Closed NURBS curves in the XY plane.
    height : float
        How far along +z (a negative height goes down); not 0.
    center : bool
        Centre the solid on z = 0 (from -height/2 to height/2).
    tolerance : float | None
        How finely the outlines are sampled to find the region (the edges themselves stay
        exact); default 1e-5 of their extent.

    Example
    -------
    ``plate: {type: brep.extrude, curves: ["@outline", "@hole"], height: 6}``
    """
    from formgraph.kernels.brep import build

    if height == 0 or not np.isfinite(height):
        raise InputError("height", f"must be finite and not 0 (no volume), got {height:g}")
    parts = regions(curves, "curves", tolerance, ctx)
    wires = _wires(parts, "curves")
    h = abs(float(height))  # made upwards from its bottom, z0
    z0 = -h / 2 if center else min(0.0, float(height))
    shape = call("curves", build.extrude, wires, h, z0)
    return solid(shape, "extrude", curves=list(curves), height=h, z0=z0)


@node("brep.revolve", version=1, requires=requires)
def revolve(
    curves: list[Curve],
    angle: Annotated[float, Range(min=0, max=360)] = 360.0,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Solid:
    """The region of closed curves in the XY plane at x >= 0, turned into the XZ plane (y
    becomes z) and revolved about the z axis.

    As ``mesh.revolve``: x is the distance from the axis, y the height. Lines parallel to
    the axis become cylinders, others cones or planes, circular arcs spheres or tori,
    splines surfaces of revolution: exact.

    Parameters
    ----------
    curves : list[Curve]
        Closed NURBS curves in the XY plane, all at x >= 0 (they may touch the axis).
    angle : float
        Degrees about the axis, up to 360 (all the way round).
    tolerance : float | None
        How finely the outlines are sampled to find the region; default 1e-5 of their
        extent.

    Example
    -------
    ``knob: {type: brep.revolve, curves: "@profile"}``
    """
    from formgraph.kernels.brep import build

    if not angle > 0:
        raise InputError("angle", f"must be > 0 degrees, got {angle:g}")
    parts = regions(curves, "curves", tolerance, ctx)
    lowest = min(
        float(np.min(np.asarray(c[0])[:, 0])) for outer, holes in parts for c in [outer, *holes]
    )
    span = max(float(np.max(np.abs(np.asarray(outer[0])))) for outer, _ in parts)
    if lowest < -1e-9 * max(span, 1.0):
        raise InputError(
            "curves",
            f"the profile reaches x = {lowest:.4g}: a revolved region lies on one side of "
            "the axis, at x >= 0",
        )
    wires = _wires(parts, "curves", turn=True)
    shape = call("curves", build.revolve, wires, float(angle))
    return solid(shape, "revolve", curves=list(curves), angle=angle)


def _simple(cp: np.ndarray, degree: int, knots: np.ndarray, w: np.ndarray | None) -> bool:
    """Whether a closed section does not cross itself (sampled, in its best-fit plane)."""
    import shapely

    from formgraph.kernels.nurbs import curve_evaluate

    a, b = knots[degree], knots[-degree - 1]
    pts = curve_evaluate(cp, degree, knots, w, np.linspace(a, b, 257))
    centred = pts - pts.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    flat = centred @ vt[:2].T
    return bool(shapely.is_simple(shapely.linearrings(flat)))


@node("brep.loft", version=1, requires=requires)
def loft(curves: list[Curve], ruled: bool = False) -> Solid:
    """A solid through closed section curves, in order (OCC's ``ThruSections``).

    Parameters
    ----------
    curves : list[Curve]
        Two or more closed NURBS curves, the sections from one end to the other, each a
        simple loop (not crossing itself).
    ruled : bool
        Flat between consecutive sections instead of smooth through them all.

    Example
    -------
    ``tower: {type: brep.loft, curves: ["@base", "@middle", "@top"]}``
    """
    from formgraph.kernels.brep import build, convert
    from formgraph.nodes._outlines import closes

    if len(curves) < 2:
        raise InputError("curves", f"a loft needs two sections or more, got {len(curves)}")
    sections = nurbs_of(curves, "curves", "section")
    for k, (c, data) in enumerate(zip(curves, sections, strict=True)):
        if not closes(c):
            raise InputError("curves", f"section {k} is open: a solid's sections are closed")
        if not _simple(*data):
            raise InputError(
                "curves", f"section {k} crosses itself: a loft's sections are simple loops"
            )
    wires = [
        call("curves", convert.wire_of, s, f"section {k}", False) for k, s in enumerate(sections)
    ]
    shape = call("curves", build.loft, wires, bool(ruled))
    return solid(shape, "loft", curves=list(curves), ruled=ruled)


@node("brep.from_surfaces", version=1, requires=requires)
def from_surfaces(
    surfaces: list[Surface],
    tolerance: Annotated[float | None, Range(min=0)] = None,
) -> Solid:
    """The solid that NURBS surfaces enclose, sewn together along their shared boundaries.

    The surfaces must close: every boundary of one is met by another (or collapses to a
    point, as a pole). Which way each faces does not matter: the solid is turned outward.

    Parameters
    ----------
    surfaces : list[Surface]
        NURBS surfaces, together a closed shell.
    tolerance : float | None
        How far apart two boundaries may be and still be sewn; default 1e-6 of the
        surfaces' extent.

    Example
    -------
    ``body: {type: brep.from_surfaces, surfaces: ["@side", "@bottom", "@top"]}``
    """
    from formgraph.kernels.brep import build, convert

    if not surfaces:
        raise InputError("surfaces", "no surfaces: give the faces of a closed shell")
    data = []
    for k, s in enumerate(surfaces):
        if not isinstance(s, NurbsSurface):
            raise InputError(
                "surfaces",
                f"surface {k} is a {type(s).__name__}; a solid is sewn from NURBS surfaces",
            )
        w = s.weights if s.rational else None
        data.append((s.control_points, s.degree_u, s.degree_v, s.knots_u, s.knots_v, w))
    extent = max(float(np.ptp(np.asarray(d[0]).reshape(-1, 3), axis=0).max()) for d in data)
    tol = float(tolerance) if tolerance is not None else max(1e-6 * extent, 1e-7)
    occ_surfaces = [call("surfaces", convert.bspline_surface, *d) for d in data]
    shape, free = call("surfaces", build.sew, occ_surfaces, tol)
    if shape is None:
        where = "; ".join(
            "(" + ", ".join(f"{x:.4g}" for x in seg.mean(axis=0)) + ")" for seg in free[:4]
        )
        more = f" and {len(free) - 4} more" if len(free) > 4 else ""
        raise InputError(
            "surfaces",
            f"the surfaces do not close: {len(free)} free edge(s), boundaries no other "
            f"surface meets within {tol:.3g}, around {where}{more}; a solid needs a closed "
            "shell (add the missing surfaces, or raise the tolerance for near misses)",
        )
    return solid(shape, "from_surfaces", surfaces=list(surfaces), tolerance=tol)
