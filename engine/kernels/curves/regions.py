"""Planar regions bounded by closed polylines, and their booleans, through GEOS (shapely).

GEOS (OverlayNG, with snapping noding) is the overlay engine of the field — PostGIS, QGIS
and shapely stand on it — and its robustness on near-degenerate input is the hard part of
polygon booleans; writing our own would be a long way to a worse place. What is ours: how
rings become a region and how the result comes back.

- A list of rings is one region by the even-odd rule (a point is inside when a ray from it
  crosses the rings an odd number of times), as ``offset.marching_squares`` reads it. When
  no ring touches another or itself (``is_simple`` of all the rings together, one noding
  pass), the region is built by nesting: a ring inside an even number of others is an outer
  boundary, the rings directly inside it (one level deeper) its holes. Otherwise each ring
  is made valid by GEOS's ``linework`` method (the faces of its noded linework, taken
  alternately: even-odd for a self-intersecting ring) and the rings are combined by
  symmetric difference, pairwise in a balanced tree.
- The result comes back as rings with outer boundaries counter-clockwise and holes
  clockwise (``orient_polygons``), each closed by its first point.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely

__all__ = ["OPERATIONS", "boolean", "each_region", "even_odd_region", "match_rings", "rings_of"]

OPERATIONS = ("union", "difference", "intersection", "xor")


def _linearrings(rings: Sequence[np.ndarray]) -> np.ndarray:
    """An array of shapely LinearRings from (m_i, 2) point arrays (closed by shapely)."""
    sizes = np.array([len(r) for r in rings])
    if np.any(sizes < 3):
        i = int(np.argmax(sizes < 3))
        raise ValueError(f"ring {i} has {sizes[i]} distinct points; a region needs 3 or more")
    out = np.empty(len(rings), dtype=object)
    for i, r in enumerate(rings):  # one call per ring (GEOS copies its points in C)
        out[i] = shapely.linearrings(r)
    return out


def _xor_tree(geoms: np.ndarray) -> shapely.Geometry:
    """The symmetric difference of all ``geoms``, combined pairwise (log n levels)."""
    g = np.asarray(geoms, dtype=object)
    while len(g) > 1:
        pairs = shapely.symmetric_difference(g[0 : len(g) - 1 : 2], g[1::2])
        g = np.concatenate([pairs, g[len(g) - 1 :]]) if len(g) % 2 else pairs
    return g[0]


def even_odd_region(rings: Sequence[np.ndarray]) -> shapely.Geometry:
    """The region the rings bound by the even-odd rule, as a valid (Multi)Polygon.

    Parameters
    ----------
    rings : sequence of (m, 2) float
        Closed polylines, each without its closing point, any orientation.

    Returns
    -------
    shapely Polygon, MultiPolygon or an empty geometry
    """
    if len(rings) == 0:
        return shapely.Polygon()
    lr = _linearrings(rings)
    if len(lr) == 1 and shapely.is_simple(lr[0]):
        return shapely.Polygon(lr[0])
    if shapely.is_simple(shapely.multilinestrings(lr)):
        return _nested(lr)
    polys = shapely.polygons(lr)
    bad = ~shapely.is_simple(lr)
    if bad.any():
        polys[bad] = shapely.make_valid(polys[bad], method="linework")
    return _xor_tree(polys)


def _nested(lr: np.ndarray) -> shapely.Geometry:
    """Region of rings that neither cross nor touch: holes by nesting depth."""
    polys = shapely.polygons(lr)
    tree = shapely.STRtree(polys)
    first = shapely.points(shapely.get_coordinates(shapely.get_point(lr, 0)))
    inner, outer = tree.query(first, predicate="within")  # ring `inner` lies inside `outer`
    depth = np.bincount(inner, minlength=len(lr))
    # the parent of a ring is the ring around it that is one level less deep
    direct = depth[outer] == depth[inner] - 1
    parent = np.full(len(lr), -1)
    parent[inner[direct]] = outer[direct]
    shells = np.flatnonzero(depth % 2 == 0)
    holes = np.flatnonzero(depth % 2 == 1)
    holes_of: dict[int, list[int]] = {int(s): [] for s in shells}
    for h in holes:  # one step per ring
        holes_of[int(parent[h])].append(int(h))
    parts = [shapely.Polygon(lr[s], [lr[h] for h in holes_of[int(s)]]) for s in shells]
    return parts[0] if len(parts) == 1 else shapely.MultiPolygon(parts)


def each_region(rings: Sequence[np.ndarray]) -> shapely.Geometry:
    """The union of the rings' regions, each ring read on its own (by the even-odd rule)."""
    if len(rings) == 0:
        return shapely.Polygon()
    lr = _linearrings(rings)
    polys = shapely.polygons(lr)
    bad = ~shapely.is_simple(lr)  # a ring that does not touch itself bounds a valid polygon
    if bad.any():
        polys[bad] = shapely.make_valid(polys[bad], method="linework")
    if len(polys) == 1:
        return polys[0]
    return shapely.union(polys[0], polys[1]) if len(polys) == 2 else shapely.union_all(polys)


def boolean(a: shapely.Geometry, b: shapely.Geometry, operation: str) -> shapely.Geometry:
    """``a`` op ``b`` for op in union, difference (a minus b), intersection, xor."""
    if operation == "union":
        return shapely.union(a, b)
    if operation == "difference":
        return shapely.difference(a, b)
    if operation == "intersection":
        return shapely.intersection(a, b)
    if operation == "xor":
        return shapely.symmetric_difference(a, b)
    raise ValueError(f"operation must be one of {', '.join(OPERATIONS)}; got {operation!r}")


def rings_of(region: shapely.Geometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The boundary rings of a region: outer boundaries CCW, holes CW.

    Lines and points a boolean may leave (two squares that share an edge intersect in a
    segment) bound no area and are dropped.

    Returns
    -------
    coords : (N, 2) float
        Every ring's points, each ring closed (its first point repeated at its end), ring
        after ring; no point repeats the one before it.
    offsets : (r + 1,) int
        Ring i is ``coords[offsets[i]:offsets[i + 1]]``.
    hole : (r,) bool
        Whether ring i is a hole.
    """
    parts = shapely.get_parts(region)
    parts = parts[shapely.get_type_id(parts) == 3]  # polygons only
    parts = parts[~shapely.is_empty(parts)]
    if len(parts) == 0:
        return np.zeros((0, 2)), np.zeros(1, dtype=np.int64), np.zeros(0, dtype=bool)
    parts = shapely.orient_polygons(parts, exterior_cw=False)
    rings = shapely.get_rings(parts)
    interiors = shapely.get_num_interior_rings(parts)
    hole = np.ones(len(rings), dtype=bool)
    hole[np.concatenate([[0], np.cumsum(interiors + 1)[:-1]])] = False
    coords, index = shapely.get_coordinates(rings, return_index=True)
    d = np.diff(coords, axis=0)
    repeat = np.r_[False, (d[:, 0] == 0) & (d[:, 1] == 0) & (index[1:] == index[:-1])]
    if repeat.any():  # GEOS leaves none in an overlay's result; kept safe all the same
        coords, index = coords[~repeat], index[~repeat]
    sizes = np.bincount(index, minlength=len(rings))
    return coords, np.concatenate([[0], np.cumsum(sizes)]), hole


def _key(ring: np.ndarray) -> tuple[int, float, float]:
    """A ring's size and its lexicographically smallest point: the same whatever its start
    and direction."""
    i = np.lexsort((ring[:, 1], ring[:, 0]))[0]
    return len(ring), float(ring[i, 0]), float(ring[i, 1])


def match_rings(
    out: Sequence[np.ndarray], given: Sequence[np.ndarray | None]
) -> list[tuple[int, bool] | None]:
    """Which result rings are an input ring unchanged (same points, any start and direction).

    GEOS keeps every vertex the overlay does not cut, bit for bit, so a ring that comes out
    whole has exactly its input's points. Returns, per result ring, ``(input index, same
    direction)`` or None.
    """
    keys: dict[tuple[int, float, float], list[int]] = {}
    for i, g in enumerate(given):  # one step per ring
        if g is not None and len(g) >= 3:
            keys.setdefault(_key(g), []).append(i)
    found: list[tuple[int, bool] | None] = []
    for ring in out:
        match = None
        for i in keys.get(_key(ring), []) if keys else []:
            g = given[i]
            assert g is not None
            if np.array_equal(np.unique(g, axis=0), np.unique(ring, axis=0)):
                match = (i, _ccw(g) == _ccw(ring))
                break
        found.append(match)
    return found


def _ccw(ring: np.ndarray) -> bool:
    x, y = ring[:, 0], ring[:, 1]
    return bool(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)) > 0)
