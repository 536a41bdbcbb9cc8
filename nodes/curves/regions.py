"""Outlines for cutting: rounded rectangles, polygons and region booleans.

Each adapts a kernel of :mod:`formgraph.kernels.curves` (``shapes``, ``regions``). Region
nodes read a list of closed curves in the XY plane as one region by the even-odd rule, as
``offset.marching_squares`` does, and give back closed outlines: outer boundaries
counter-clockwise, holes clockwise; their sampling and the curves back from the region are
:mod:`formgraph.nodes._outlines`.
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Vec3
from formgraph.geometry import Curve, NurbsCurve
from formgraph.kernels.curves import regions as kregions
from formgraph.kernels.curves import shapes as kshapes
from formgraph.nodes import _outlines as _o


@node("curves.rectangle", version=1)
def rectangle(
    size: list[float],
    center: Vec3 = (0.0, 0.0, 0.0),
    radius: Annotated[float, Range(min=0)] = 0.0,
) -> NurbsCurve:
    """A closed rectangle with exact circular corners, counter-clockwise.

    With ``radius`` 0 the corners are sharp (a degree-1 polygon). Otherwise the outline is
    one rational quadratic NURBS: every corner an exact quarter circle (middle weight
    sqrt(2)/2, The NURBS Book A7.1), every side a straight quadratic piece, joined by
    double knots; SVG, PDF and DXF export it exactly (arcs and lines). It starts at the
    bottom-right corner and runs counter-clockwise.

    Parameters
    ----------
    size : list[float]
        [width, height], both positive.
    center : Vec3
        Centre of the rectangle.
    radius : float
        Corner radius, at most half the shorter side (then the short sides vanish: a
        slot, or a circle when square).

    Example
    -------
    ``plate: {type: curves.rectangle, size: [80, 30], radius: 4}``
    """
    try:
        cp, degree, knots, w = kshapes.rounded_rectangle(size, center, radius)
    except ValueError as exc:
        port = next((q for q in ("size", "center") if str(exc).startswith(q)), "radius")
        raise InputError(port, str(exc)) from None
    return NurbsCurve(cp, degree, knots, w)


@node("curves.polygon", version=1)
def polygon(
    sides: Annotated[int, Range(min=3)],
    radius: Annotated[float, Range(min=0)],
    center: Vec3 = (0.0, 0.0, 0.0),
    angle: float = 0.0,
    *,
    ctx: Context,
) -> NurbsCurve:
    """A regular polygon, closed, counter-clockwise, its corners on a circle of ``radius``.

    Parameters
    ----------
    sides : int
        Number of sides (>= 3).
    radius : float
        Distance from the centre to every corner (> 0).
    center : Vec3
        Centre.
    angle : float
        Direction of the first corner, degrees counter-clockwise from +x.

    Example
    -------
    ``hex: {type: curves.polygon, sides: 6, radius: 5}``
    """
    ctx.guard(sides, "polygon corners")
    port = "sides" if sides < 3 else "radius"
    corners = InputError.call(port, kshapes.regular_polygon, sides, radius, center, angle)
    return NurbsCurve.polyline(corners, closed=True)


class Operation(str, Enum):
    """A region boolean."""

    union = "union"  # in a or in b
    difference = "difference"  # in a and not in b
    intersection = "intersection"  # in both
    xor = "xor"  # in exactly one


@node("curves.boolean", version=1)
def boolean(
    a: list[Curve],
    b: list[Curve],
    operation: Operation = Operation.union,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """Union, difference, intersection or xor of two regions bounded by closed curves.

    ``a`` and ``b`` are each read as one region by the even-odd rule (nested curves make
    holes), as ``offset.marching_squares`` reads its input; z is dropped. Curves are
    sampled so that every chord is within ``tolerance`` of its curve (NURBS by a bound on
    their curvature, then checked at every chord's midpoint; polylines exactly at their
    vertices), and the regions are combined by GEOS (shapely's overlay). Out come closed
    outlines at z = 0, outer boundaries counter-clockwise and holes clockwise; a curve the
    operation leaves whole (a hole that touches nothing, the plate around it) comes back
    exact, as the input curve itself, and a NURBS curve it cuts comes back as its exact
    arcs between the cuts (the cuts found by Newton's method on the exact curves), joined
    with straight pieces into one NURBS outline.

    Parameters
    ----------
    a : list[Curve]
        Closed curves bounding the first region.
    b : list[Curve]
        Closed curves bounding the second region.
    operation : Operation
        union, difference (a minus b), intersection or xor.
    tolerance : float
        Largest distance between a curve and its sampling. Default: 1e-5 of the size of
        the inputs.

    Example
    -------
    ``plate: {type: curves.boolean, a: ["@outline"], b: ["@hole1", "@hole2"],
    operation: difference}``
    """
    if isinstance(a, Curve):
        a = [a]
    if isinstance(b, Curve):
        b = [b]
    everything = [*a, *b]
    if not everything:
        raise InputError("a", "give curves to a or b, got none")
    tol = _o.sampling_tolerance(tolerance, everything, "a")
    ra, sa, xa = _o.sample_rings(a, "a", tol, ctx)
    rb, sb, xb = _o.sample_rings(b, "b", tol, ctx)
    region = kregions.boolean(
        _o.make_region(kregions.even_odd_region, ra, "a"),
        _o.make_region(kregions.even_odd_region, rb, "b"),
        operation.value,
    )
    return _o.outline_curves(region, everything, [*sa, *sb], [*xa, *xb], tol, ctx)


@node("curves.union", version=1)
def union(
    curves: list[Curve],
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """The union of the regions of closed curves: overlapping outlines merged into one.

    Each curve bounds its own region (by the even-odd rule: a self-intersecting curve is
    fine) and the regions are united, so two overlapping circles become one outline where
    ``offset.marching_squares`` (which reads the whole list by the even-odd rule) would cut
    their overlap out. A curve inside another is swallowed; to keep a hole, subtract it
    with ``curves.boolean``. Sampling, orientation and exactness as ``curves.boolean``.

    Parameters
    ----------
    curves : list[Curve]
        Closed curves in the XY plane (z is dropped).
    tolerance : float
        Largest distance between a curve and its sampling. Default: 1e-5 of the size of
        the inputs.

    Example
    -------
    ``blob: {type: curves.union, curves: ["@circle_a", "@circle_b"]}``
    """
    if isinstance(curves, Curve):
        curves = [curves]
    if not curves:
        raise InputError("curves", "the union needs at least one curve, got none")
    tol = _o.sampling_tolerance(tolerance, curves)
    rings, sampled, sources = _o.sample_rings(curves, "curves", tol, ctx)
    region = _o.make_region(kregions.each_region, rings, "curves")
    return _o.outline_curves(region, curves, sampled, sources, tol, ctx)
