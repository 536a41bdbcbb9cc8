"""Curves from points: polylines, Bezier chains, Catmull-Rom splines, subdivision, offsets."""

from __future__ import annotations

from enum import Enum
from typing import Annotated, NamedTuple

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Expression, Variables
from formgraph.geometry import Curve, NurbsCurve, ParametricCurve, Points
from formgraph.kernels import curves as kc
from formgraph.kernels.curves import measure as kmeasure
from formgraph.kernels.curves.adaptive import refine_breaks
from formgraph.nodes import _outlines as _o


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


def _polyline(points: np.ndarray, closed: bool) -> NurbsCurve:
    """A degree-1 curve through ``points``, merging repeated consecutive points (a
    subdivided or offset polygon can repeat a point; a polyline needs no zero spans)."""
    p = kc.drop_repeats(points, closed)
    for _ in range(3):  # NurbsCurve.polyline's knots are cumulative chords: keep them distinct
        ring = np.vstack([p, p[:1]]) if closed else p
        cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(ring, axis=0), axis=1))])
        grows = np.diff(cum) > 0.0
        keep = np.concatenate([[True], grows[: len(p) - 1]])
        if closed and not grows[-1]:
            keep[-1] = False
        if keep.all():
            break
        p = p[keep]
    if len(p) < 2:
        raise ValueError("the result has fewer than two distinct points")
    return NurbsCurve.polyline(p, closed=closed)


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


def _control_polygon(curve: Curve) -> tuple[np.ndarray, bool]:
    """The control polygon of a NURBS curve (or the drawn polyline of any other curve),
    without the repeated closing point, and whether it is closed."""
    if isinstance(curve, NurbsCurve):
        p = np.asarray(curve.control_points)
    else:
        p = np.asarray(curve.display_points())
    closed = curve.closed
    if closed and len(p) > 1:
        p = p[:-1]
    return p, closed


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
    p, closed = _control_polygon(curve)
    ctx.guard(kc.subdivided_count(len(p), closed, iterations), "points")
    out = InputError.call("curve", kc.subdivide_polygon, p, closed=closed, iterations=iterations)
    return _polyline(out, closed=closed)


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


@node("curves.resample", version=2)
def resample(
    curve: Curve,
    count: Annotated[int | None, Range(min=2)] = None,
    spacing: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> NurbsCurve:
    """Points evenly spaced along the curve by arc length, joined as a polyline.

    Give ``count`` or ``spacing``. The points lie exactly on the curve: the arc length is
    integrated by Gauss-Legendre quadrature and inverted by Newton steps (a polyline is
    resampled along its straight segments). A closed curve stays closed, its first point
    not repeated in the count.

    Parameters
    ----------
    curve : Curve
        Any curve.
    count : int
        Number of points (open: both ends included; closed: >= 3).
    spacing : float
        Distance along the curve between points; rounded so it divides the length evenly.
    """
    if (count is None) == (spacing is None):
        raise InputError("count", "give exactly one of count and spacing")
    closed = curve.closed
    if isinstance(curve, NurbsCurve) and curve.degree == 1:
        p, _ = _control_polygon(curve)
        length = InputError.call("curve", kc.polyline_length, p, closed)
        n = _o.divisions(length, count, spacing, closed, ctx, "resample")
        out = InputError.call("curve", kc.resample_polyline, p, count=n, closed=closed)
        return _polyline(out, closed=closed)

    t = _o.even_parameters(curve, closed, count, spacing, ctx, "resample")
    return _polyline(curve.evaluate(t), closed=closed)


@node("curves.offset", version=1)
def offset(
    curve: Curve,
    distance: float,
    miter_limit: Annotated[float, Range(min=1)] = 4.0,
    *,
    ctx: Context,
) -> NurbsCurve:
    """The bisector offset of a polyline in the XY plane (mitred corners), as a polyline.

    Each vertex moves by distance / sin(a/2) along the bisector of its corner angle a, so
    every edge ends up at exactly ``distance`` from its original; straight runs move
    straight. A positive distance grows a closed curve whichever way it runs, and lies to
    the left of the direction of travel on an open one (as shapely's offset_curve).
    Convex corners whose mitre would reach past ``miter_limit * distance`` are clipped
    (bevelled). Curves that are not polylines are offset through their drawn polyline
    (use curves.resample first to choose the resolution).

    This is a local construction: where the distance exceeds the local size of the shape
    the result loops over itself (a warning says how many edges folded);
    ``offset.marching_squares`` is the node that resolves self-intersections (and islands
    and holes). An inward offset of a closed curve past its inradius, where nothing is
    left, is an error pointing there (the construction would turn the polygon inside out:
    an 8-gon of radius 1 offset by -2 would come out with radius 1.16).

    Parameters
    ----------
    curve : Curve
        The curve to offset; its z is carried along, the offset is in XY.
    distance : float
        Offset distance; positive grows closed curves, goes left on open ones.
    miter_limit : float
        Longest mitre, as a multiple of the distance, before a corner is bevelled.
    """
    if isinstance(curve, NurbsCurve) and curve.degree == 1:
        p, closed = _control_polygon(curve)
    else:
        p, closed = np.asarray(curve.display_points()), curve.closed
        if closed:
            p = p[:-1]
    out, source = InputError.call(
        "curve",
        kc.bisector_offset,
        p,
        closed=closed,
        distance=distance,
        miter_limit=miter_limit,
        return_source=True,
    )
    inside_out, folded = kc.offset_folds(p, out, source, closed, inward=closed and distance < 0)
    if inside_out:
        raise InputError(
            "distance",
            f"an inward offset by {abs(distance):g} turns the curve inside out: the distance "
            "is past the curve's inradius (nothing is left inside) or past half its width "
            "somewhere, where the bisector offset cannot be right; offset.marching_squares "
            "gives the true offset (no loops when nothing is left)",
        )
    if folded:
        ctx.warn(
            f"the offset folds over itself at {folded} edge(s): the distance exceeds the "
            "local size of the curve there; offset.marching_squares resolves the loops"
        )
    return _polyline(out, closed=closed)


class CurveMeasures(NamedTuple):
    length: float
    area: float
    closed: bool


@node("curves.measure", version=2)
def measure(curve: Curve) -> CurveMeasures:
    """Length of a curve, the area it encloses if closed and planar, and whether it is closed.

    Gauss-Legendre quadrature (8 points) of the speed ``|C'(t)|`` and of the vector area
    ``1/2 C x C'`` on every knot span of a NURBS curve, each split in 8 (a parametric curve:
    its ``samples`` intervals, split where needed until the length is good to 1e-12 of
    itself, with the expressions' exact derivatives); the area is 0 for an open or
    non-planar curve.

    Parameters
    ----------
    curve : Curve
        Any curve.
    """
    t0, t1 = curve.domain
    if isinstance(curve, NurbsCurve):
        knots = np.unique(curve.knots[(curve.knots >= t0) & (curve.knots <= t1)])
        split = 1 if curve.degree == 1 else 8
        steps = np.arange(split) / split
        inner = knots[:-1, None] + np.diff(knots)[:, None] * steps
        breaks = np.append(inner.reshape(-1), knots[-1])
    else:
        breaks = np.linspace(t0, t1, max(2, getattr(curve, "samples", 256)) + 1)
        breaks = refine_breaks(  # exact derivatives, so the quadrature alone limits it
            lambda t: np.linalg.norm(curve.derivative(t), axis=1), breaks, rtol=1e-12
        )
    closed = curve.closed
    length, area = kmeasure.length_and_area(curve.evaluate, curve.derivative, breaks, closed)
    return CurveMeasures(length=length, area=area, closed=closed)
