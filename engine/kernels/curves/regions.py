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
  that is not simple is made valid by GEOS's ``linework`` method (the faces of its noded
  linework, taken alternately: even-odd for a self-intersecting ring) and the rings are
  combined by symmetric difference, pairwise in a balanced tree.
- GEOS is given rings in XY (a 2-D overlay is a third cheaper than one carrying z).
- The result comes back as rings with outer boundaries counter-clockwise and holes
  clockwise (the sign of each ring's area, all in one pass; the wrong ones read
  backwards), each closed by its first point.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import shapely

__all__ = [
    "OPERATIONS",
    "NoArea",
    "boolean",
    "distinct_steps",
    "each_region",
    "even_odd_region",
    "match_rings",
    "planar",
    "rings_of",
]

OPERATIONS = ("union", "difference", "intersection", "xor")


_TINY = np.finfo(np.float64).tiny
_STAR = 1000  # rings of this many points are first tried as star-shaped (see _simple)
_FEW = 64  # up to this many rings, one creation call per ring beats one over an index


class NoArea(ValueError):
    """A ring of fewer than 3 distinct points: it bounds no area. ``ring`` is its index."""

    def __init__(self, ring: int) -> None:
        super().__init__(f"ring {ring} has fewer than 3 distinct points: it bounds no area")
        self.ring = ring


def _closed(rings: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Each ring as a C-contiguous (m, 2) float array closed by its first point.

    GEOS copies a closed, contiguous coordinate buffer in one block; a ring it must close
    itself goes point by point (five times slower on long rings). Rings of (m, 3) points
    lose their z here (:func:`planar`): every predicate and overlay of GEOS is planar, and
    a 3-D overlay still carries (and interpolates) z at every vertex, a third slower than
    the 2-D one (two 10,000-vertex rings: 0.61 against 0.45 ms).
    """
    out = []
    for i, r in enumerate(rings):  # one step per ring; its points are copied as a block
        r = np.asarray(r, dtype=np.float64)
        if r.ndim != 2 or r.shape[1] not in (2, 3):
            raise ValueError(f"ring {i} is not an (m, 2) or (m, 3) array of points")
        r = planar(r)
        if len(r) and not (r[0, 0] == r[-1, 0] and r[0, 1] == r[-1, 1]):
            r = np.concatenate([r, r[:1]])
        if len(r) < 4:
            raise NoArea(i)
        out.append(r)
    return out


def planar(points: np.ndarray) -> np.ndarray:
    """(m, 2) or (m, 3) points as a C-contiguous (m, 2) float array (shared when it is
    one already). The x and y columns are copied one at a time (a strided column copies
    at memory speed; a slice of rows of two goes a row at a time, 5x slower)."""
    p = np.asarray(points, dtype=np.float64)
    if p.shape[1] == 2:
        return np.ascontiguousarray(p)
    out = np.empty((len(p), 2))
    out[:, 0], out[:, 1] = p[:, 0], p[:, 1]
    return out


def distinct_steps(ring: np.ndarray) -> int:
    """How many points of a planar ring differ from the one before them (a closed ring's
    distinct vertices, repeats of a point in a row counted once), each point compared
    as one complex number: one contiguous pass."""
    z = planar(ring).view(np.complex128)[:, 0]
    return int(np.count_nonzero(z[1:] != z[:-1]))


def _linearrings(rings: Sequence[np.ndarray]) -> tuple[np.ndarray, list[np.ndarray]]:
    """An array of shapely LinearRings from (m_i, 2) point arrays, closed or not; and the
    closed (m_i, 2) arrays they were made of."""
    closed = _closed(rings)
    if len(closed) <= _FEW:
        out = np.empty(len(closed), dtype=object)
        out[:] = [shapely.linearrings(r) for r in closed]
        return out, closed
    sizes = np.array([len(r) for r in closed])
    lr = shapely.linearrings(
        np.concatenate(closed), indices=np.repeat(np.arange(len(sizes)), sizes)
    )
    return lr, closed


def _simple(lr: np.ndarray, closed: list[np.ndarray], box: np.ndarray) -> np.ndarray:
    """Whether each ring is simple: a long ring that winds once around the centre of its
    box, every edge turning the same way about it, is (:func:`_star_shaped`, half the time
    of GEOS's noding); the others, and the long ones that are not so, are asked of
    ``is_simple`` in one call."""
    simple = np.zeros(len(lr), dtype=bool)
    long = [i for i, r in enumerate(closed) if len(r) >= _STAR] if len(lr) <= _FEW else []
    for i in long:  # one step per long ring; its points are vectorized
        simple[i] = _star_shaped(closed[i], box[i])
    ask = ~simple
    if ask.all():
        return shapely.is_simple(lr)
    if ask.any():
        simple[ask] = shapely.is_simple(lr[ask])
    return simple


def _star_shaped(ring: np.ndarray, box: np.ndarray) -> bool:
    """Whether a closed ring is strictly star-shaped about the centre c of its box: every
    edge turns the same way about c (the sign of orient(p_i, p_i+1, c), trusted only past
    Shewchuk's error bound for it, 3.3e-16 (|detleft| + |detright|), here bounded by
    1e-15 of the box's area) and the ring crosses the ray from c once (its winding number
    is 1). Then every ray from c meets the ring once, so no two edges meet but
    neighbours at their shared point: the ring is simple. False says only "not shown"."""
    x0, y0, x1, y1 = box.tolist()
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    ax, ay = ring[:, 0] - cx, ring[:, 1] - cy
    det = ax[:-1] * ay[1:]
    det -= ay[:-1] * ax[1:]
    bound = 1e-15 * (x1 - x0) * (y1 - y0)
    up = ay > 0
    if det[0] > 0:  # counter-clockwise about c: crossings of the ray upward
        return bool(det.min() > bound) and np.count_nonzero(up[1:] & ~up[:-1]) == 1
    return bool(det.max() < -bound) and np.count_nonzero(up[:-1] & ~up[1:]) == 1


def _even_odd_each(
    lr: np.ndarray, closed: list[np.ndarray], on_repair: Callable[[], None] | None = None
) -> np.ndarray:
    """Each ring as the region it bounds by the even-odd rule, a polygon each.

    A simple ring (no crossing nor touching of its own) of two or more distinct points
    bounds a valid polygon as it is (with only two it would run back over itself, which
    is not simple); :func:`_simple` says so for half (a long star-shaped ring) to three
    quarters of what ``is_valid`` of its polygon costs, and :func:`_refuse_points` the
    rest. The others are repaired by the ``linework`` method (the faces of the noded
    ring, taken alternately); a ring of fewer than 3 distinct points is refused instead,
    as bounding no area. ``on_repair`` is called before any repair (see
    :func:`even_odd_region`).
    """
    simple = _simple(lr, closed, _refuse_points(lr))
    polys = shapely.polygons(lr)
    if not simple.all():
        bad = np.flatnonzero(~simple)
        for i in bad:  # one step per ring that is not simple
            if distinct_steps(shapely.get_coordinates(lr[i])) < 3:
                raise NoArea(int(i))
        if on_repair is not None:
            on_repair()
        polys[bad] = shapely.make_valid(polys[bad], method="linework")
        for i in bad:  # one step per ring that is not simple
            if _runs_over_itself(lr[i]):
                polys[i] = _odd_faces(shapely.get_coordinates(lr[i]))
    return polys


def _runs_over_itself(ring: shapely.Geometry) -> bool:
    """Whether a ring runs over a stretch of itself (collinear edges that overlap): its
    noded linework, where an overlap is kept once, is shorter than the ring."""
    line = shapely.linestrings(shapely.get_coordinates(ring))
    return bool(shapely.length(shapely.union_all(line)) < (1 - 1e-9) * shapely.length(line))


def _odd_faces(ring: np.ndarray) -> shapely.Geometry:
    """The even-odd region of a closed ring (first point repeated) from its definition: the
    faces of its noded linework whose inner point it crosses an odd number of times.

    Where a ring runs over a stretch of itself, GEOS's ``linework`` repair nodes the
    overlap into one edge and takes the faces alternately, so the faces on both sides of
    an edge walked twice (which the even-odd rule puts on the same side) come out one in,
    one out (a ring out along y = 0 and back over it kept a triangle it crosses twice).
    Here each face's point is tested with a ray to +x against every edge (the faces share
    the noded vertices exactly, so their union dissolves the edges between them)."""
    faces = shapely.get_parts(
        shapely.polygonize(shapely.get_parts(shapely.node(shapely.linestrings(ring))))
    )
    if len(faces) == 0:
        return shapely.Polygon()
    inner = shapely.get_coordinates(shapely.point_on_surface(faces))
    a, b = ring[:-1], ring[1:]
    odd = np.zeros(len(faces), dtype=bool)
    step = max(1, (1 << 22) // max(len(a), 1))  # face rows per block: bounded memory
    for k in range(0, len(faces), step):  # one step per block of faces
        x, y = inner[k : k + step, :1], inner[k : k + step, 1:]
        spans = (a[:, 1] > y) != (b[:, 1] > y)
        dy = np.where(spans, b[:, 1] - a[:, 1], 1.0)
        cut = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / dy
        odd[k : k + step] = (spans & (cut > x)).sum(axis=1) % 2 == 1
    return shapely.union_all(faces[odd]) if odd.any() else shapely.Polygon()


def _refuse_points(lr: np.ndarray) -> np.ndarray:
    """Refuse a ring that is one point repeated (its box has no size), which GEOS's
    ``is_simple`` passes; a ring of two distinct points runs back over itself, not simple.
    Returns the rings' boxes (xmin, ymin, xmax, ymax)."""
    box = shapely.bounds(lr)
    point = (box[:, 2] <= box[:, 0]) & (box[:, 3] <= box[:, 1])
    if point.any():
        raise NoArea(int(np.flatnonzero(point)[0]))
    return box


def _xor_tree(geoms: np.ndarray) -> shapely.Geometry:
    """The symmetric difference of all ``geoms``, combined pairwise (log n levels)."""
    g = np.asarray(geoms, dtype=object)
    while len(g) > 1:
        pairs = shapely.symmetric_difference(g[0 : len(g) - 1 : 2], g[1::2])
        g = np.concatenate([pairs, g[len(g) - 1 :]]) if len(g) % 2 else pairs
    return g[0]


def even_odd_region(
    rings: Sequence[np.ndarray], on_repair: Callable[[], None] | None = None
) -> shapely.Geometry:
    """The region the rings bound by the even-odd rule, as a valid (Multi)Polygon.

    Parameters
    ----------
    rings : sequence of (m, 2) or (m, 3) float
        Closed polylines, each with or without its closing point, any orientation (z, if
        given, is ignored).
    on_repair : callable, optional
        Called (with no argument) once the rings are found to cross or touch, themselves or
        each other, before GEOS repairs them: whether they are simple is then known without
        a second noding pass, and the caller may refuse the repair's cost by raising.

    Returns
    -------
    shapely Polygon, MultiPolygon or an empty geometry
    """
    if len(rings) == 0:
        return shapely.Polygon()
    if len(rings) == 1:
        return _even_odd_each(*_linearrings(rings), on_repair)[0]
    lr, closed = _linearrings(rings)
    _refuse_points(lr)
    if shapely.is_simple(shapely.multilinestrings(lr)):
        return _nested(lr)
    if on_repair is not None:
        on_repair()
    return _xor_tree(_even_odd_each(lr, closed))


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
    polys = _even_odd_each(*_linearrings(rings))
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
    region: shapely.Geometry, with_z: bool = False, steps: bool = False
) -> tuple[np.ndarray, ...]:
    """The boundary rings of a region: outer boundaries CCW, holes CW.

    Lines and points a boolean may leave (two squares that share an edge intersect in a
    segment) bound no area and are dropped. The points are read out in one call (straight
    from the polygons when they have no holes: no ring cloned), and every ring's
    direction comes from one pass over their coordinate differences, which also give the
    repeated points and the steps' lengths: the sign of its area (the trapezoid sum
    relative to its first point, as GEOS's ``Area.ofRingSigned``). The rings the wrong
    way round are read backwards as they are copied into the result (an overlay gives
    outer boundaries clockwise, so that is the usual case: no reversed geometry made).

    Parameters
    ----------
    region : shapely geometry
    with_z : bool
        Give (N, 3) points at z = 0.
    steps : bool
        Also give the length of every step between consecutive points.

    Returns
    -------
    coords : (N, 2) or (N, 3) float
        Every ring's points, each ring closed (its first point repeated at its end), ring
        after ring; no point repeats the one before it.
    offsets : (r + 1,) int
        Ring i is ``coords[offsets[i]:offsets[i + 1]]``.
    hole : (r,) bool
        Whether ring i is a hole.
    step : (N - 1,) float, with ``steps``
        ``step[j]`` is the distance from point j to point j + 1 (at a ring's last point,
        the jump to the next ring's first: no edge).
    """
    if shapely.get_type_id(region) == 3:  # one polygon: no copy of it as its own part
        parts = np.array([region], dtype=object)
    else:
        parts = shapely.get_parts(region)
        if (shapely.get_type_id(parts) == 6).any():  # a collection holding a MultiPolygon
            parts = shapely.get_parts(parts)  # (as make_valid gives: polygons and lines)
        parts = parts[shapely.get_type_id(parts) == 3]  # polygons only
    parts = parts[~shapely.is_empty(parts)]
    if len(parts) == 0:
        none = np.zeros((0, 3 if with_z else 2)), np.zeros(1, dtype=np.int64)
        return (*none, np.zeros(0, dtype=bool)) + ((np.zeros(0),) if steps else ())
    interiors = shapely.get_num_interior_rings(parts)
    if not interiors.any():  # no holes: each polygon's points are its ring's, none cloned
        xy = shapely.get_coordinates(parts)
        sizes = [len(xy)] if len(parts) == 1 else shapely.get_num_coordinates(parts)
        offsets = np.concatenate([[0], np.cumsum(sizes)])
        hole = np.zeros(len(parts), dtype=bool)
    else:
        rings = shapely.get_rings(parts)
        xy = shapely.get_coordinates(rings)
        offsets = np.concatenate([[0], np.cumsum(shapely.get_num_coordinates(rings))])
        hole = np.ones(len(rings), dtype=bool)
        hole[np.concatenate([[0], np.cumsum(interiors + 1)[:-1]])] = False
    xy, offsets, dx, dy = _without_repeats(xy, offsets)
    flip = (_twice_areas(xy, offsets, dy) > 0) == hole  # CCW (positive) holes, CW shells
    out: tuple[np.ndarray, ...] = (xy, offsets, hole)
    if with_z or flip.any():
        out = (_oriented(xy, offsets, flip, with_z), offsets, hole)
    if not steps:
        return out
    return (*out, _flipped_steps(_lengths(dx, dy), offsets, flip))


def _oriented(xy: np.ndarray, offsets: np.ndarray, flip: np.ndarray, with_z: bool) -> np.ndarray:
    """The rows of each ring ``[offsets[i], offsets[i + 1])`` copied out, read backwards
    where ``flip``; with ``with_z`` a z column of 0 added (xy has one or two columns)."""
    n, cols = xy.shape
    out = np.empty((n, 3 if with_z else cols))
    if len(flip) <= _FEW:  # a slice each, a flipped ring's rows read backwards
        for i, back in enumerate(flip.tolist()):  # one step per ring
            a, b = offsets[i], offsets[i + 1]
            step = -1 if back else 1
            for k in range(cols):  # a column at a time: strided copies at memory speed
                out[a:b, k] = xy[a:b, k][::step]
    else:  # one gather: row j of a flipped ring [a, b) comes from a + b - 1 - j
        source = np.arange(n)
        if flip.any():
            which = np.repeat(np.arange(len(flip)), np.diff(offsets))
            back = flip[which]
            source[back] = (offsets[:-1] + offsets[1:] - 1)[which[back]] - source[back]
        for k in range(cols):
            out[:, k] = xy[:, k][source]
    if with_z:
        out[:, 2] = 0.0
    return out


def _flipped_steps(seg: np.ndarray, offsets: np.ndarray, flip: np.ndarray) -> np.ndarray:
    """The step lengths of the rings as :func:`_oriented` puts them: a flipped ring's
    steps ``[a, b - 1)`` read backwards (the jumps between rings where they were)."""
    if not flip.any():
        return seg
    if len(flip) == 1:
        return seg[::-1]  # a view: the one ring's steps backwards
    if len(flip) <= _FEW:
        for i in np.flatnonzero(flip):  # one step per flipped ring
            a, b = offsets[i], offsets[i + 1] - 1
            seg[a:b] = seg[a:b][::-1]  # numpy buffers the overlapping copy
        return seg
    which = np.repeat(np.arange(len(flip)), np.diff(offsets))[:-1]  # ring of step j
    back = flip[which]
    back[offsets[1:-1] - 1] = False  # the jumps stay
    source = np.arange(len(seg))
    source[back] = (offsets[:-1] + offsets[1:] - 2)[which[back]] - source[back]
    return seg[source]


def _without_repeats(
    xy: np.ndarray, offsets: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The rings' points without a point equal to the one before it in its ring (GEOS
    leaves none in an overlay's result; a region that went through no overlay may), and
    the coordinate differences of consecutive points (``dx[j] = x[j + 1] - x[j]``)."""
    x, y = xy[:, 0], xy[:, 1]
    dx, dy = x[1:] - x[:-1], y[1:] - y[:-1]
    repeat = (dx == 0) & (dy == 0)
    repeat[offsets[1:-1] - 1] = False  # one ring's end and the next one's start may meet
    if not repeat.any():
        return xy, offsets, dx, dy
    keep = np.r_[True, ~repeat]  # point j + 1 goes when it repeats point j
    gone = np.concatenate([[0], np.cumsum(~keep)])[offsets]
    xy, offsets = np.compress(keep, xy, axis=0), offsets - gone
    x, y = xy[:, 0], xy[:, 1]
    return xy, offsets, x[1:] - x[:-1], y[1:] - y[:-1]


def _twice_areas(xy: np.ndarray, offsets: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Twice the signed area of every closed ring (positive: counter-clockwise), by the
    trapezoid form sum (x_j + x_{j+1} - 2 x_0)(y_{j+1} - y_j): exact in y translation,
    and x taken relative to the ring's first point, so far from the origin a small
    ring's sign holds (as GEOS's ``Area.ofRingSigned``). ``dy`` as from
    :func:`_without_repeats`."""
    x = xy[:, 0]
    r = len(offsets) - 1
    x0 = x[0] if r == 1 else np.repeat(x[offsets[:-1]], np.diff(offsets))[:-1]
    terms = x[:-1] + x[1:]
    terms -= 2 * x0
    terms *= dy
    if r == 1:
        return np.array([terms.sum()])
    terms[offsets[1:-1] - 1] = 0.0  # the step from one ring's end to the next one's start
    return np.add.reduceat(terms, offsets[:-1])


def _lengths(dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """sqrt(dx^2 + dy^2) in place (a third the time of ``np.hypot``); where the sum of
    squares is below the smallest normal double (steps under 1.5e-154, whose squares lose
    digits or underflow to 0), ``hypot``'s scaled sum instead."""
    seg = dx * dx
    seg += dy * dy
    small = seg < _TINY
    np.sqrt(seg, out=seg)
    if small.any():
        seg[small] = np.hypot(dx[small], dy[small])
    return seg


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
