"""Voronoi cells and Delaunay triangles of points in the plane.

* :func:`cells`: each point's Voronoi cell clipped to a region, in the points' order.
  GEOS's diagram (the dual of its incremental Delaunay triangulation,
  ``shapely.voronoi_polygons`` with ``ordered=True``, extended to the region's box) cut by
  the region exactly (``shapely.intersection``, vectorized over all cells). A cell of a
  non-convex region can fall apart into pieces; the piece that holds the point is its
  cell (the others are reported), so every point gets one cell that contains it.
* :func:`triangles`: the Delaunay triangulation (Qhull through ``scipy.spatial.Delaunay``),
  counter-clockwise.
* :func:`coincident`: the first two points that coincide (they have no cell of their own).

Plain arrays and shapely geometries in and out.
"""

from __future__ import annotations

import numpy as np
import shapely

__all__ = ["cells", "coincident", "triangles"]


def coincident(xy: np.ndarray) -> tuple[int, int] | None:
    """The first pair (i < j) of points ``xy`` (n, 2) at exactly the same place, or None."""
    p = np.ascontiguousarray(np.asarray(xy, dtype=np.float64) + 0.0)  # -0.0 is 0.0
    rows = p.view(np.dtype((np.void, 16))).reshape(-1)
    order = np.argsort(rows, kind="stable")
    same = np.flatnonzero(rows[order][1:] == rows[order][:-1])
    if not len(same):
        return None
    pairs = np.sort(np.stack([order[same], order[same + 1]], axis=1), axis=1)
    i, j = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))[0]]
    return int(i), int(j)


def cells(xy: np.ndarray, region: shapely.Geometry) -> tuple[np.ndarray, np.ndarray]:
    """The Voronoi cell of each point ``xy`` (n, 2) (n >= 2, distinct, inside ``region``)
    clipped to ``region`` (a polygon).

    Returns
    -------
    polygons : (n,) shapely Polygons
        Cell i of point i, without holes (a hole of the region inside a cell is left out
        of it: the cell is the region's part round the point, bounded by its outline).
    split : (n,) bool
        The cells the region cut into pieces or holed (only the point's piece, without
        its holes, is kept).
    """
    p = np.asarray(xy, dtype=np.float64)
    sites = shapely.multipoints(p)
    diagram = shapely.voronoi_polygons(sites, extend_to=region, ordered=True)
    raw = shapely.get_parts(diagram)
    clipped = shapely.intersection(raw, region)
    odd = (shapely.get_type_id(clipped) != 3) | (shapely.get_num_interior_rings(clipped) > 0)
    split = np.zeros(len(p), dtype=bool)
    pts = shapely.points(p)
    for i in np.flatnonzero(odd).tolist():  # one step per odd cell: rare
        # a collection (a polygon with a stray line or point where it touches the region's
        # outline at a corner), pieces, or a hole: the polygon round the point, unholed
        parts = shapely.get_parts(clipped[i])
        parts = parts[(shapely.get_type_id(parts) == 3) & (shapely.area(parts) > 0)]
        hold = shapely.intersects(parts, pts[i])
        piece = parts[np.argmax(hold)] if hold.any() else parts[np.argmax(shapely.area(parts))]
        split[i] = len(parts) > 1 or shapely.get_num_interior_rings(piece) > 0
        clipped[i] = shapely.polygons(shapely.get_exterior_ring(piece))
    return clipped, split


def triangles(xy: np.ndarray) -> np.ndarray:
    """(t, 3) the Delaunay triangles of points ``xy`` (n, 2), each counter-clockwise.

    Raises
    ------
    ValueError
        Fewer than 3 points, or all on one line (no triangle).
    """
    from scipy.spatial import Delaunay, QhullError

    p = np.asarray(xy, dtype=np.float64)
    if len(p) < 3:
        raise ValueError(f"a triangulation needs at least 3 points, got {len(p)}")
    try:
        tri = Delaunay(p).simplices.astype(np.int64)
    except QhullError:
        raise ValueError("the points all lie on one line: they make no triangle") from None
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    turn = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    tri[turn < 0] = tri[turn < 0][:, ::-1]
    return tri
