"""Curves from points: polylines, Bezier chains, Catmull-Rom splines, subdivision, and
curves from expressions (``curves.parametric``).
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Expression, Variables
from formgraph.geometry import Curve, NurbsCurve, ParametricCurve, Points
from formgraph.kernels import curves as kc
from formgraph.nodes.curves._common import control_polygon, polyline_curve


@node("curves.polyline", version=1)
def polyline(points: Points, closed: bool = False) -> NurbsCurve:
    """The straight segments through the points, as an exact degree-1 NURBS curve.

    The parameter runs along the arc length (knots are the cumulative chord lengths).

    Parameters
    ----------
    points : Points
        At least two distinct points, in order.
    closed : bool
        Join the last point back to the first.
    """
    return NurbsCurve.polyline(points.xyz, closed=closed)


class Spacing(str, Enum):
    """Knot spacing of a Catmull-Rom spline: interval |P[i+1] - P[i]| ** alpha."""

    uniform = "uniform"  # alpha = 0
    centripetal = "centripetal"  # alpha = 1/2: no cusps or self-intersections in a segment
    chordal = "chordal"  # alpha = 1


class Ends(str, Enum):
    """How an open Catmull-Rom spline treats its first and last points."""

    processing = "processing"  # they only shape the end tangents (curveVertex)
    clamped = "clamped"  # the curve passes through them too


@node("curves.bezier", version=1)
def bezier(points: Points) -> NurbsCurve:
    """A chain of cubic Bezier segments, laid out as Processing's bezierVertex; exact.

    The first point starts the chain; each segment then takes (control, control, end), so
    the count is 4, 7, 10, ... Each segment is one span of the cubic NURBS (interior knots
    of multiplicity 3); the parameter runs 0..1 over the first segment, 1..2 over the
    second, and so on.

    Parameters
    ----------
    points : Points
        3k + 1 points: start, then control, control, end per segment.

    Example
    -------
    ``s: {type: curves.bezier, points: [[0, 0], [1, 2], [3, 2], [4, 0]]}``
    """
    return NurbsCurve(*InputError.call("points", kc.bezier_chain, points.xyz))


@node("curves.catmull_rom", version=1)
def catmull_rom(
    points: Points,
    closed: bool = False,
    tension: float = 0.0,
    spacing: Spacing = Spacing.uniform,
    ends: Ends = Ends.processing,
) -> NurbsCurve:
    """A Catmull-Rom spline through the points, converted exactly to a cubic NURBS curve.

    Each segment is one Bezier piece; knots are the spline's own parameter values, so the
    curve is C1 at every point it passes (and across the seam when closed). Repeated
    consecutive points are dropped. Centripetal spacing (Yuksel et al. 2011) never makes
    a cusp or a loop within a segment, whatever the spacing of the points; uniform is
    Processing's curveVertex.

    Parameters
    ----------
    points : Points
        The points to pass through (at least 2 distinct; 4 with ends: processing).
    closed : bool
        Join the last point back to the first, smoothly.
    tension : float
        Processing's curveTightness: 0 is Catmull-Rom, 1 straight segments; tangents are
        scaled by (1 - tension).
    spacing : Spacing
        Knot spacing: uniform, centripetal or chordal.
    ends : Ends
        Open curves: processing (the first and last points only shape the end tangents) or
        clamped (the curve passes through every point).
    """
    result = InputError.call(
        "points",
        kc.catmull_rom,
        points.xyz,
        closed=closed,
        tension=tension,
        spacing=spacing.value,
        ends=ends.value,
    )
    return NurbsCurve(*result)


@node("curves.subdivide", version=1)
def subdivide(
    curve: Curve, iterations: Annotated[int, Range(min=0)] = 3, *, ctx: Context
) -> NurbsCurve:
    """Cubic B-spline subdivision of the curve's control polygon, as a polyline.

    Each round inserts edge midpoints and moves every vertex to 1/8, 6/8, 1/8 of its
    neighbours and itself (Lane-Riesenfeld); the polygon doubles and converges to the
    uniform cubic B-spline of the control points. Open curves keep their end points; closed
    ones wrap around. A curve without control points (parametric) subdivides its drawn
    polyline.

    Parameters
    ----------
    curve : Curve
        The curve whose control polygon is refined.
    iterations : int
        Rounds of subdivision; the point count roughly doubles each round.
    """
    p, closed = control_polygon(curve)
    ctx.guard(kc.subdivided_count(len(p), closed, iterations), "points", port="iterations")
    out = InputError.call("curve", kc.subdivide_polygon, p, closed=closed, iterations=iterations)
    return polyline_curve(out, closed=closed)


@node("curves.parametric", version=2)
def parametric(
    x: Annotated[Expression, Variables("t")],
    y: Annotated[Expression, Variables("t")],
    z: Annotated[Expression, Variables("t")] = "0",  # type: ignore[assignment]
    t: list[float] = (0.0, 1.0),  # type: ignore[assignment]
    samples: Annotated[int, Range(min=2)] = 256,
    *,
    ctx: Context,
) -> ParametricCurve:
    """A curve from expressions in t (and the graph params), exact at every t.

    The expressions are evaluated whenever the curve is (vectorized over t); tangents come
    from central differences. The curve is checked at ``samples`` parameters when the node
    runs: a NaN or infinity is an error naming the expression and the t where it happened.

    Parameters
    ----------
    x, y : Expression
        Coordinates as expressions in t, e.g. "radius * cos(t)".
    z : Expression
        Height as an expression in t.
    t : list[float]
        [start, end] of the parameter range, start < end.
    samples : int
        How many points draw the curve, and the default resolution of later sampling.

    Example
    -------
    ``spiral: {type: curves.parametric, x: "cos(t)", y: "sin(t)", z: "t / 10",
    t: ["=0", "=2*pi*turns"]}``
    """
    if len(t) != 2 or not t[0] < t[1]:
        raise InputError("t", f"t must be [start, end] with start < end, got {list(t)}")
    ctx.guard(samples, "samples")
    fx, fy, fz = x, y, z
    curve = ParametricCurve(fx, fy, fz, (float(t[0]), float(t[1])), samples)
    curve.sample(samples)  # raises, naming the expression and t, if anything is not finite
    return curve
