"""Curves from points: polylines, Bezier chains, Catmull-Rom splines, subdivision, offsets."""

from __future__ import annotations

from formgraph.geometry import NurbsCurve, Points
from formgraph.registry import node


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
