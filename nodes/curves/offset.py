"""``curves.offset``: a polyline offset by a distance, point by point (for loops that stay
simple; ``offset.marching_squares`` resolves the rest).
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve, NurbsCurve
from formgraph.kernels import curves as kc
from formgraph.nodes.curves._common import control_polygon, polyline_curve


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
        p, closed = control_polygon(curve)
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
    return polyline_curve(out, closed=closed)
