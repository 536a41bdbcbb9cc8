"""``curves.voronoi`` and ``curves.delaunay``: the Voronoi cells and the Delaunay triangles
of points in the XY plane (:mod:`formgraph.kernels.curves.voronoi`)."""

from __future__ import annotations

import numpy as np
import shapely

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.geometry import Curve, Mesh, NurbsCurve, Points, frozen_array
from formgraph.kernels.curves import regions as kregions
from formgraph.kernels.curves import voronoi as kvoronoi
from formgraph.nodes import _outlines as _o

MARGIN = 0.05  # the default region: the points' box, each side moved out by 5 % of its size


def _sites(points: Points, least: int, what: str) -> np.ndarray:
    xy = np.asarray(points.xyz)[:, :2]
    if len(xy) < least:
        raise InputError("points", f"{what} needs at least {least} points, got {len(xy)}")
    pair = kvoronoi.coincident(xy)
    if pair is not None:
        i, j = pair
        x, y = xy[i]
        raise InputError(
            "points",
            f"points {i} and {j} coincide at ({x:g}, {y:g}) in XY: each point needs a place "
            "of its own (drop one, e.g. with geometry.filter)",
        )
    return xy


def _region(region: Curve | list[Curve] | None, xy: np.ndarray, ctx: Context) -> shapely.Geometry:
    if region is None:
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        grow = MARGIN * float(max((hi - lo).max(), 1e-300))
        return shapely.box(*(lo - grow), *(hi + grow))
    curves = region if isinstance(region, list) else [region]
    if not curves:
        raise InputError("region", "the region has no curves")
    tol = _o.sampling_tolerance(None, curves, "region")
    rings, _, _ = _o.sample_rings(curves, "region", tol, ctx)
    area = _o.make_region(kregions.even_odd_region, rings, "region")
    if shapely.is_empty(area) or not shapely.area(area) > 0:
        raise InputError("region", "the region encloses no area")
    return area


@node("curves.voronoi", version=1)
def voronoi(
    points: Points, region: Curve | list[Curve] | None = None, *, ctx: Context
) -> list[Curve]:
    """The Voronoi cell of each point, clipped to a region: one closed counter-clockwise
    polyline per point, in the points' order.

    A point's cell is the part of the plane nearer to it than to any other point (its XY
    position; z is ignored and the cells lie on z = 0): GEOS's diagram, cut by the region
    exactly. The cells tile the region. A region with holes, or not convex, can cut a cell
    apart: the piece round the point is its cell (a warning counts them).

    Parameters
    ----------
    points : Points
        At least 2, no two at the same XY place, all inside the region.
    region : Curve | list[Curve] | None
        Closed curves bounding the region (even-odd, as ``curves.boolean`` reads them);
        none: the points' box, each side moved out by 5 % of its larger side.

    Example
    -------
    ``cells: {type: curves.voronoi, points: "@seeds", region: "@panel"}``
    """
    xy = _sites(points, 2, "a Voronoi diagram")
    ctx.guard(8 * len(xy), "cell corners")
    area = _region(region, xy, ctx)
    outside = ~shapely.intersects_xy(area, xy[:, 0], xy[:, 1])
    if outside.any():
        i = int(np.argmax(outside))
        raise InputError(
            "points",
            f"point {i} at ({xy[i, 0]:g}, {xy[i, 1]:g}) lies outside the region "
            f"({int(outside.sum())} points do): its cell would not hold it; keep the points "
            "inside (geometry.filter) or grow the region",
        )
    polygons, split = kvoronoi.cells(xy, area)
    if split.any():
        ctx.warn(
            f"the region cuts {int(split.sum())} cells into pieces or holes them: each keeps "
            "only the outline of its piece round its point"
        )
    coords, offsets, _, step = kregions.rings_of(
        shapely.geometrycollections(polygons), with_z=True, steps=True
    )
    if len(offsets) - 1 != len(xy):  # pragma: no cover - every cell holds its point
        raise InputError("points", "a cell came out empty: the points are too close together")
    xyz = frozen_array(coords)
    knots = frozen_array(_o.chord_knots(step, offsets))
    ones = frozen_array(np.ones(len(xyz)))
    return [  # one curve per cell; its points, knots and weights are views of three arrays
        NurbsCurve._of_valid(xyz[a:b], 1, knots[a + 2 * i : b + 2 * i + 2], ones[a:b])
        for i, (a, b) in enumerate(zip(offsets[:-1].tolist(), offsets[1:].tolist(), strict=True))
    ]


@node("curves.delaunay", version=1)
def delaunay(points: Points, *, ctx: Context) -> Mesh:
    """The Delaunay triangles of the points in XY: no point inside any triangle's
    circumcircle (Qhull through scipy). The mesh's vertices are the points themselves (z
    kept, so scattered heights make a terrain), with their attributes; every triangle is
    counter-clockwise seen from +z.

    Parameters
    ----------
    points : Points
        At least 3, not all on one line, no two at the same XY place.

    Example
    -------
    ``tin: {type: curves.delaunay, points: "@survey"}``
    """
    xy = _sites(points, 3, "a triangulation")
    ctx.guard(2 * len(xy), "triangles")
    try:
        tri = kvoronoi.triangles(xy)
    except ValueError as exc:
        raise InputError("points", str(exc)) from None
    return Mesh.trusted(
        np.asarray(points.xyz),
        tri.reshape(-1),
        np.arange(0, tri.size + 1, 3),
        points.point_data,
    )
