"""``curves.hull``: the convex hull in the XY plane (:mod:`formgraph.kernels.curves.hull`)."""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Geometry, NurbsCurve
from formgraph.kernels.curves import hull as khull
from formgraph.nodes._pointsets import points_of


@node("curves.hull", version=1)
def hull(
    geometry: Geometry | list[Geometry],
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> NurbsCurve:
    """The convex hull in the XY plane of points, curves or meshes: one closed,
    counter-clockwise polyline at z = 0.

    OpenSCAD's ``hull()`` of 2-D shapes, Grasshopper's Convex Hull. Everything is seen from
    +z (z dropped); the hull's corners are input points (qhull through scipy), collinear
    points on its sides left out. Curves give their points: polylines their vertices, other
    curves points whose chords stay within ``tolerance`` of them (the hull of a circle is
    a polygon inscribed within the tolerance).

    Parameters
    ----------
    geometry : Geometry | list[Geometry]
        Points, curves, meshes, or a list of them; at least 3 points not all on one line.
    tolerance : float
        Largest distance between a curve and its chords. Default: 1e-5 of the size of
        everything given.

    Example
    -------
    ``outline: {type: curves.hull, geometry: "@pins"}``
    """
    xyz, _ = points_of(geometry, tolerance, ctx)
    xy = xyz[:, :2]
    try:
        corners = khull.hull_2d(xy)
    except khull.FlatHull as exc:
        raise InputError("geometry", str(exc)) from None
    ring = np.column_stack([xy[corners], np.zeros(len(corners))])
    return NurbsCurve.polyline(ring, closed=True)
