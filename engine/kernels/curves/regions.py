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
  that ``is_valid`` refuses is made valid by GEOS's ``linework`` method (the faces of its
  noded linework, taken alternately: even-odd for a self-intersecting ring) and the rings
  are combined by symmetric difference, pairwise in a balanced tree.
- The result comes back as rings with outer boundaries counter-clockwise and holes
  clockwise (GEOS's signed-area ``is_ccw`` of all rings, the wrong ones reversed), each
  closed by its first point.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely

__all__ = [
    "OPERATIONS",
    "boolean",
    "each_region",
    "even_odd_region",
    "match_rings",
    "rings_of",
]

OPERATIONS = ("union", "difference", "intersection", "xor")


_FEW = 64  # up to this many rings, one creation call per ring beats one over an index


def _closed(rings: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Each ring as a C-contiguous float array closed by its first point (in XY).

    GEOS copies a closed, contiguous coordinate buffer in one block; a ring it must close
    itself goes point by point (five times slower on long rings). Rings of (m, 3) points
    are taken as they are: every predicate and overlay of GEOS is planar (z is ignored),
    and copying out an (m, 2) array costs more than the polygon itself.
    """
    out = []
    for i, r in enumerate(rings):  # one step per ring; its points are copied as a block
        r = np.ascontiguousarray(r, dtype=np.float64)
        if len(r) and not (r[0, 0] == r[-1, 0] and r[0, 1] == r[-1, 1]):
            r = np.concatenate([r, r[:1]])
        if len(r) < 4:
            raise ValueError(
                f"ring {i} has {max(len(r) - 1, 0)} distinct points; a region needs 3 or more"
            )
        out.append(r)
    return out


def _linearrings(rings: Sequence[np.ndarray]) -> np.ndarray:
    """An array of shapely LinearRings from (m_i, 2) point arrays, closed or not."""
    closed = _closed(rings)
    if len(closed) <= _FEW:
        out = np.empty(len(closed), dtype=object)
        out[:] = [shapely.linearrings(r) for r in closed]
        return out
    sizes = np.array([len(r) for r in closed])
    return shapely.linearrings(
        np.concatenate(closed), indices=np.repeat(np.arange(len(sizes)), sizes)
    )


def _polygons(rings: Sequence[np.ndarray]) -> np.ndarray:
    """An array of shapely Polygons, one per ring (closed or not), made straight from the
    coordinates when there are few (no ring built then cloned into its polygon)."""
    closed = _closed(rings)
    if len(closed) <= _FEW:
        out = np.empty(len(closed), dtype=object)
        out[:] = [shapely.polygons(r) for r in closed]
        return out
    return shapely.polygons(_linearrings(closed))


def _even_odd_each(polys: np.ndarray) -> np.ndarray:
    """Each one-ring polygon as the region its ring bounds by the even-odd rule: a valid
    polygon is that already; GEOS's ``linework`` repair (the faces of the noded ring, taken
    alternately) only where ``is_valid`` says no."""
    bad = ~shapely.is_valid(polys)
    if bad.any():
        polys = polys.copy()
        polys[bad] = shapely.make_valid(polys[bad], method="linework")
    return polys


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
    rings : sequence of (m, 2) or (m, 3) float
        Closed polylines, each with or without its closing point, any orientation (z, if
        given, is ignored).

    Returns
    -------
    shapely Polygon, MultiPolygon or an empty geometry
    """
    if len(rings) == 0:
        return shapely.Polygon()
    if len(rings) == 1:
        return _even_odd_each(_polygons(rings))[0]
    lr = _linearrings(rings)
    if shapely.is_simple(shapely.multilinestrings(lr)):
        return _nested(lr)
    return _xor_tree(_even_odd_each(shapely.polygons(lr)))


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
    polys = _even_odd_each(_polygons(rings))
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


def rings_of(
    region: shapely.Geometry, with_z: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The boundary rings of a region: outer boundaries CCW, holes CW.

    Lines and points a boolean may leave (two squares that share an edge intersect in a
    segment) bound no area and are dropped. The orientation is GEOS's signed-area test
    (``is_ccw``) of every ring at once; the rings the wrong way round are reversed in C
    before their points are read out, in one call.

    Parameters
    ----------
    region : shapely geometry
    with_z : bool
        Give (N, 3) points at z = 0 (read out so, not copied into a wider array after).

    Returns
    -------
    coords : (N, 2) or (N, 3) float
        Every ring's points, each ring closed (its first point repeated at its end), ring
        after ring; no point repeats the one before it.
    offsets : (r + 1,) int
        Ring i is ``coords[offsets[i]:offsets[i + 1]]``.
    hole : (r,) bool
        Whether ring i is a hole.
    """
    if shapely.get_type_id(region) == 3:  # one polygon: no copy of it as its own part
        parts = np.array([region], dtype=object)
    else:
        parts = shapely.get_parts(region)
        parts = parts[shapely.get_type_id(parts) == 3]  # polygons only
    parts = parts[~shapely.is_empty(parts)]
    if len(parts) == 0:
        dims = 3 if with_z else 2
        return np.zeros((0, dims)), np.zeros(1, dtype=np.int64), np.zeros(0, dtype=bool)
    rings = shapely.get_rings(parts)
    interiors = shapely.get_num_interior_rings(parts)
    hole = np.ones(len(rings), dtype=bool)
    hole[np.concatenate([[0], np.cumsum(interiors + 1)[:-1]])] = False
    flip = shapely.is_ccw(rings) == hole
    if flip.any():
        rings = rings.copy()
        rings[flip] = shapely.reverse(rings[flip])
    # a 2-D ring read with z gives z = NaN, set to 0 in place: one array, no widening copy
    coords = shapely.get_coordinates(rings, include_z=with_z)
    if with_z:
        coords[:, 2] = 0.0
    offsets = np.concatenate([[0], np.cumsum(shapely.get_num_coordinates(rings))])
    x, y = coords[:, 0], coords[:, 1]
    repeat = np.empty(len(coords), dtype=bool)
    repeat[0] = False
    np.logical_and(x[1:] == x[:-1], y[1:] == y[:-1], out=repeat[1:])
    repeat[offsets[1:-1]] = False  # one ring's end and the next one's start may meet
    if repeat.any():  # GEOS leaves none in an overlay's result; kept safe all the same
        gone = np.concatenate([[0], np.cumsum(repeat)])[offsets]
        coords, offsets = np.compress(~repeat, coords, axis=0), offsets - gone
    return coords, offsets, hole


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
            if np.array_equal(_sorted_points(g), _sorted_points(ring)):
                match = (i, _ccw(g) == _ccw(ring))
                break
        found.append(match)
    return found


def _sorted_points(ring: np.ndarray) -> np.ndarray:
    """The ring's points in lexicographic order (the same for any start and direction)."""
    return ring[np.lexsort((ring[:, 1], ring[:, 0]))]


def _ccw(ring: np.ndarray) -> bool:
    x, y = ring[:, 0], ring[:, 1]
    twice = np.dot(x[:-1], y[1:]) - np.dot(y[:-1], x[1:]) + x[-1] * y[0] - y[-1] * x[0]
    return bool(twice > 0)
