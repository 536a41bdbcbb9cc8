"""The exact offset of polylines through GEOS's buffer (shapely), and the choice of path.

GEOS's buffer (Martin Davis's offset-curve construction of JTS, ported to C++: each segment
offset, round joins as inscribed chords of the arc, the raw curve noded and polygonized) is
the well-kept engine of the field for exactly this, and at 1,000 vertices it is about 20
times cheaper than our distance field and marching squares (a fixed floor of some 7,000
numpy calls). What is ours is the reading of the input and the promise on the result:

- **Region.** Closed polylines are one region by the even-odd rule, built as
  ``curves.boolean`` builds it (:func:`formgraph.kernels.curves.regions.even_odd_region`:
  nesting when no ring touches another, else GEOS's linework repair and symmetric
  differences). The offset the marching path traces is the level set of the signed distance
  to every segment, so where the rings' linework holds more than the region's boundary (an
  edge two rings share, a spike that goes out and back, a ring of under three points) the
  offset is the region with the band of half-width ``|d|`` around the linework added
  (positive ``d``) or taken away (negative): exactly what the distance field gives. Open
  polylines are buffered as lines (round caps: the capsule of the distance field).
- **Accuracy.** Arcs are chords of at most ``quad_segs`` per quarter circle, chosen so the
  sagitta ``|d| (1 - cos(pi / (4 q)))`` stays under 0.4 of the tolerance, never fewer than
  GEOS's default of 8; straight parts are exact. GEOS first drops the input's shallow
  concave vertices (within 1 % of ``|d|`` of their neighbours' chord,
  ``BufferInputLineSimplifier``), which moves the result by at most that: within half the
  tolerance while ``|d| <= 0.05`` of the extent; above it the path is taken only where no
  vertex is that shallow (checked on the rings GEOS buffers), else declined.
- **Work.** The raw offset curve's size is bounded before GEOS runs (vertices plus arc
  chords against ``max_vertices``). Self-crossing input costs GEOS's repair far more than
  its vertex count says (300 random points joined up: 12,000 crossings, 20 s), so the
  crossings are counted first, exactly on small inputs and from a fixed sample of segment
  pairs on large ones; over :data:`MAX_CROSSINGS` the path is declined.
- **Result.** Loops come back as the marching path returns them: closed (first vertex not
  repeated), islands counter-clockwise and holes clockwise
  (:func:`~formgraph.kernels.curves.regions.rings_of`). A GEOS exception or an invalid
  result declines the path; :func:`offset_loops` then runs the marching path.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import shapely

from formgraph.kernels.curves.regions import NoArea, even_odd_region, rings_of

from .contour import split_loops
from .loops import simplify as simplify_loops
from .marching import DEFAULT_MAX_CELLS, check_options, offset_polylines, polyline_segments

__all__ = [
    "MAX_CROSSINGS",
    "BufferDeclined",
    "Offset",
    "buffer_polylines",
    "offset_loops",
    "quad_segs",
]

GEOS_QUAD_SEGS = 8  # GEOS's default chords per quarter circle: never fewer
GEOS_SIMPLIFY_FACTOR = 0.01  # GEOS BufferParameters::DEFAULT_SIMPLIFY_FACTOR, times |d|
# of the tolerance, for the chords of the round joins and caps: a chord's sagitta s moves
# the corner where a join meets another edge's offset at an angle a by s / sin(a), so 0.4
# put a hole's corner 1.13 tolerances off at a = 20 degrees; 0.1 costs 0-2 % more vertices
ARC_SHARE = 0.1
SIMPLIFY_SHARE = 0.5  # of the tolerance, for GEOS's dropping of shallow concave vertices
MAX_CROSSINGS = 2000  # self-crossings (estimated) above which GEOS's repair is too slow
_SAMPLED_PAIRS = 1 << 16  # segment pairs tested to estimate the crossings of a large input
_TOLERANCE = 1e-3  # default error, as a fraction of the input's extent


class BufferDeclined(Exception):
    """The GEOS path cannot promise the tolerance or the work here (or GEOS failed): the
    marching path is the one to run. The message says why."""


class Offset(NamedTuple):
    """An offset's loops and the path that made them (``"geos"`` or ``"marching"``)."""

    loops: list[np.ndarray]
    path: str
    declined: str  # why the GEOS path was not taken ("" when it was)


def quad_segs(distance: float, tolerance: float) -> int:
    """Chords per quarter circle that keep every arc's sagitta under ``ARC_SHARE`` of the
    tolerance (at least GEOS's default of 8).

    A chord spanning the angle ``theta`` of an arc of radius ``r`` strays
    ``r (1 - cos(theta / 2))`` from it; GEOS spans at most ``pi / (2 q)`` per chord.
    """
    r = abs(float(distance))
    sag = ARC_SHARE * float(tolerance)
    if not sag < r:
        return GEOS_QUAD_SEGS
    theta = 2.0 * np.arccos(1.0 - sag / r)
    return int(max(GEOS_QUAD_SEGS, np.ceil(0.5 * np.pi / theta)))


def buffer_polylines(
    polylines: Sequence[np.ndarray],
    closed: Sequence[bool],
    distance: float,
    tolerance: float | None = None,
    max_vertices: int = DEFAULT_MAX_CELLS,
) -> list[np.ndarray]:
    """Offset polylines by a signed distance through GEOS's buffer, to a tolerance.

    The same offset as :func:`~formgraph.kernels.offset.marching.offset_polylines` (the
    boundary of ``{f < distance}``, ``f`` the signed distance to the segments, negative
    inside the closed polylines by the even-odd rule), for input all closed or all open.

    Parameters
    ----------
    polylines : sequence of (n, 2) float
    closed : sequence of bool
        One flag per polyline, all True or all False.
    distance : float
        Nonzero: positive grows, negative shrinks (open input: nothing is left).
    tolerance : float, optional
        Largest error of the result, in model units. Default 0.1 % of the input's extent.
    max_vertices : int
        Largest raw offset curve (vertices plus arc chords) handed to GEOS.

    Returns
    -------
    list of (m, 2) float
        Closed loops (first vertex not repeated): islands counter-clockwise, holes
        clockwise.

    Raises
    ------
    ValueError
        For a bad argument, as `offset_polylines` does; also for mixed open and closed input.
    BufferDeclined
        When the path cannot promise the tolerance or the work (see the module's notes), or
        GEOS failed or returned an invalid region.

    Example
    -------
    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    >>> (loop,) = buffer_polylines([square], [True], -0.25)
    >>> bool(np.allclose(np.abs(loop - 0.5).max(axis=0), 0.25))
    True
    """
    a, b, seg_closed = polyline_segments(polylines, closed)
    distance = check_options(distance, 0, 0.0)
    all_closed = bool(seg_closed.all())
    if not all_closed and seg_closed.any():
        raise ValueError("the GEOS offset takes polylines all closed or all open, not mixed")
    if tolerance is None:
        # (Per coordinate: numpy reduces an (n, 2) array along its long axis slowly.)
        extent = max(
            max(a[:, k].max(), b[:, k].max()) - min(a[:, k].min(), b[:, k].min()) for k in range(2)
        )
        tol = _TOLERANCE * (float(extent) if extent > 0 else 2 * abs(distance))
    else:
        tol = float(tolerance)
        if not (np.isfinite(tol) and tol > 0):
            raise ValueError(f"tolerance must be a positive finite number, got {tolerance}")
    scale = tol / _TOLERANCE  # (the extent the tolerance is a share of)
    if not all_closed and distance < 0:
        return []  # an open polyline bounds nothing to shrink
    q = quad_segs(distance, tol)
    _check_work(a, b, len(polylines), q, max_vertices)
    pts = [np.asarray(p, dtype=float) for p in polylines]
    try:
        if all_closed:
            geom = _closed_offset(pts, a, b, distance, q, tol, scale)
        else:
            _check_crossings(a, b)
            lines = _lines(pts, closed=False)
            _check_shallow(pts, False, distance, tol, scale)
            geom = shapely.buffer(lines, distance, quad_segs=q)
        if not shapely.is_valid(geom):
            raise BufferDeclined("GEOS returned an invalid region")
    except shapely.errors.GEOSException as exc:
        raise BufferDeclined(f"GEOS failed: {exc}") from None
    coords, offsets, _ = rings_of(geom)
    # An overlay can leave a ring of no area (a sliver hole of three collinear points);
    # the field has none: dropped.
    if len(offsets) < 2:
        return []
    x, y = coords[:, 0], coords[:, 1]
    cross = x[:-1] * y[1:] - x[1:] * y[:-1]
    twice = np.add.reduceat(cross, offsets[:-1])  # twice each ring's signed area, but
    twice[:-1] -= cross[offsets[1:-1] - 1]  # without the step from one ring into the next
    keep = np.abs(twice) > 1e-12 * scale * scale
    return [coords[offsets[i] : offsets[i + 1] - 1] for i in range(len(offsets) - 1) if keep[i]]


def _closed_offset(pts, a, b, distance, q, tol, scale):
    """The offset of the even-odd region of closed polylines (see the module's notes).

    Whether the rings are simple (none crosses or touches itself or another) comes out of
    building the region: the crossings are counted only where they are not (before GEOS's
    repair, whose cost they bound), and a simple ring is not noded twice."""
    rings = [p for p in pts if len(p) >= 3]
    repaired = []

    def on_repair() -> None:
        repaired.append(True)
        _check_crossings(a, b)

    try:
        region = even_odd_region(rings, on_repair) if rings else shapely.Polygon()
    except NoArea as exc:  # the marching path offsets its linework (a point, a segment)
        raise BufferDeclined(str(exc)) from None
    simple = not repaired and len(rings) == len(pts)
    if not simple and not repaired:
        _check_crossings(a, b)
    area = _areal(region)
    # Rings that neither cross nor touch bound their region with all their linework.
    if simple or float(np.hypot(*(b - a).T).sum()) <= (1 + 1e-9) * float(shapely.length(area)):
        # The region's boundary is all the linework: its buffer is the level set.
        if abs(distance) > SIMPLIFY_SHARE * tol / GEOS_SIMPLIFY_FACTOR:
            coords, offsets, _ = rings_of(area)
            rings_out = [coords[offsets[i] : offsets[i + 1] - 1] for i in range(len(offsets) - 1)]
            _check_shallow(rings_out, True, distance, tol, scale)
        return shapely.buffer(area, distance, quad_segs=q)
    # Linework inside or outside the region's area (shared edges, spikes, degenerate
    # rings): the distance to it counts too.
    _check_shallow(pts, True, distance, tol, scale)
    band = shapely.buffer(_lines(pts, closed=True), abs(distance), quad_segs=q)
    if distance > 0:
        return shapely.union(area, band)
    return shapely.difference(area, band)


def _areal(region: shapely.Geometry) -> shapely.Geometry:
    """The polygonal part of a region (GEOS's repair may leave lines of collapsed parts)."""
    if shapely.get_type_id(region) in (3, 6):
        return region
    parts = shapely.get_parts(region)
    polys = parts[np.isin(shapely.get_type_id(parts), (3, 6))]
    return shapely.union_all(polys) if len(polys) else shapely.Polygon()


def _multi(lines: list[np.ndarray]) -> shapely.Geometry:
    """One MultiLineString of point arrays of any lengths (made in one call)."""
    sizes = [len(p) for p in lines]
    parts = shapely.linestrings(
        np.concatenate(lines), indices=np.repeat(np.arange(len(sizes)), sizes)
    )
    return shapely.multilinestrings(parts)


def _lines(pts: list[np.ndarray], closed: bool) -> shapely.Geometry:
    """The polylines as lines (a lone point as a zero-length line: GEOS buffers it round).

    A line that ends where it starts is given as two open ones, cut at a point away from
    its start: GEOS buffers a closed line as a ring, one offset curve a side, and where the
    ring runs back over itself (a spike out and back) that loses the round join at the
    spike's tip (GEOS 3.14: the band of a ring with a spike to (-0.25, 0) stopped at
    x = -0.25). The buffer of lines with round joins and caps is the set of points within
    the distance of them, which cutting a line into pieces that share their ends keeps."""
    lines = []
    for p in pts:
        if len(p) == 1:
            p = np.concatenate([p, p])
        elif closed:
            p = np.concatenate([p, p[:1]])
        if len(p) > 2 and p[0, 0] == p[-1, 0] and p[0, 1] == p[-1, 1]:
            away = np.flatnonzero((p[1:-1, 0] != p[0, 0]) | (p[1:-1, 1] != p[0, 1]))
            if len(away):  # (else one point repeated: a zero-length line, buffered round)
                k = int(away[0]) + 1
                lines += [p[: k + 1], p[k:]]
                continue
        lines.append(p)
    return _multi(lines) if len(lines) > 1 else shapely.linestrings(lines[0])


def _check_work(a: np.ndarray, b: np.ndarray, n_lines: int, q: int, limit: int) -> None:
    """Decline when the raw offset curve could pass ``limit`` vertices.

    Each vertex adds at most ``|turn| / (pi / (2 q)) + 2`` points to each side it is offset
    on, each end of an open polyline a half circle; first bounded with every turn at pi,
    then, if that passes the limit, with the turns measured.
    """
    n = a.shape[0]
    quantum = 0.5 * np.pi / q
    if 2 * (n * (np.pi / quantum + 2) + n_lines * 2 * np.pi / quantum) <= limit:
        return
    u = b - a
    turn = np.abs(np.arctan2(u[:-1, 0] * u[1:, 1] - u[:-1, 1] * u[1:, 0], (u[:-1] * u[1:]).sum(1)))
    total = 2 * (n * 2 + (turn.sum() + np.pi + n_lines * 2 * np.pi) / quantum)
    if total > limit:
        raise BufferDeclined(
            f"the offset curve would have about {total:,.0f} vertices, over the limit of "
            f"{limit:,} ({q} chords per quarter circle)"
        )


def _crosses(a, b, c, d) -> np.ndarray:
    """Whether segments ``a -> b`` and ``c -> d`` cross properly (each pair a row)."""

    def orient(p, q, r):
        return np.sign(
            (q[:, 0] - p[:, 0]) * (r[:, 1] - p[:, 1]) - (q[:, 1] - p[:, 1]) * (r[:, 0] - p[:, 0])
        )

    return (orient(a, b, c) * orient(a, b, d) < 0) & (orient(c, d, a) * orient(c, d, b) < 0)


def _check_crossings(a: np.ndarray, b: np.ndarray) -> None:
    """Decline when the segments cross each other more than :data:`MAX_CROSSINGS` times:
    counted over all pairs of a small input, estimated from a fixed sample of pairs of a
    large one (deterministic, so the same input always takes the same path)."""
    m = a.shape[0]
    pairs = m * (m - 1) // 2
    if pairs <= _SAMPLED_PAIRS:
        i, j = np.triu_indices(m, 1)
    else:
        rng = np.random.default_rng(0)
        i = rng.integers(0, m, _SAMPLED_PAIRS)
        j = rng.integers(0, m, _SAMPLED_PAIRS)
        keep = i != j
        i, j = i[keep], j[keep]
    hits = int(_crosses(a[i], b[i], a[j], b[j]).sum())
    estimate = hits * pairs / max(len(i), 1)
    if estimate > MAX_CROSSINGS:
        raise BufferDeclined(
            f"the polylines cross themselves about {estimate:,.0f} times, more than "
            f"{MAX_CROSSINGS:,}: GEOS's repair of such a tangle costs more than the field"
        )


def _check_shallow(
    pts: Sequence[np.ndarray], closed: bool, distance: float, tol: float, scale: float
) -> None:
    """Decline when GEOS's simplification could move the result by more than its share of
    the tolerance: ``|d|`` large and some vertex shallow (between ``1e-12`` of the extent
    and 1 % of ``|d|`` from its neighbours' chord, so GEOS may drop it)."""
    limit = GEOS_SIMPLIFY_FACTOR * abs(distance)
    if limit <= SIMPLIFY_SHARE * tol:
        return
    rows = [p for p in pts if len(p) >= 3]
    if not rows:
        return
    xy = np.concatenate(rows)
    sizes = np.array([len(p) for p in rows])
    start = np.repeat(np.cumsum(sizes) - sizes, sizes)
    pos = np.arange(len(xy)) - start
    size = np.repeat(sizes, sizes)
    prev = start + (pos - 1) % size
    nxt = start + (pos + 1) % size
    interior = np.ones(len(xy), dtype=bool) if closed else (pos > 0) & (pos < size - 1)
    p0, p1, p2 = xy[prev[interior]], xy[interior], xy[nxt[interior]]
    ab = p2 - p0
    den = (ab * ab).sum(1)
    s = np.clip(
        np.divide(((p1 - p0) * ab).sum(1), den, out=np.zeros_like(den), where=den > 0), 0, 1
    )
    gap = np.hypot(*(p1 - p0 - s[:, None] * ab).T)
    # GEOS deletes a vertex only within the limit of the window's start (its sampled check
    # measures the apex from the chord to each sample, the first being the start itself).
    near = np.fmin(np.hypot(*(p1 - p0).T), np.hypot(*(p2 - p1).T)) < limit
    shallow = (gap > 1e-12 * scale) & (gap < limit) & near
    if shallow.any():
        raise BufferDeclined(
            f"{int(shallow.sum())} vertices lie within 1 % of the distance ({limit:.3g}) of "
            "their neighbours' chord: GEOS would drop them, an error above the tolerance"
        )


def offset_loops(
    polylines: Sequence[np.ndarray],
    closed: Sequence[bool],
    distance: float,
    cell: float | None = None,
    smooth: int = 0,
    simplify: float = 0.0,
    max_cells: int = DEFAULT_MAX_CELLS,
    tolerance: float | None = None,
) -> Offset:
    """The offset of polylines by the path that suits them: GEOS's buffer when no ``cell``
    is given, ``smooth`` is 0 and the input is all closed or all open (and the GEOS path
    does not decline), else the distance field and marching squares.

    Parameters and errors as :func:`~formgraph.kernels.offset.marching.offset_polylines`;
    ``max_cells`` also bounds the GEOS path's raw offset curve, and ``tolerance`` is the
    GEOS path's (default 0.1 % of the input's extent).

    Returns
    -------
    Offset
        The loops (closed, first vertex not repeated; islands CCW, holes CW), the path
        taken and, if the GEOS path declined, why.
    """
    declined = ""
    if cell is None and smooth == 0 and (all(closed) or not any(closed)):
        check_options(distance, smooth, simplify)
        try:
            loops = buffer_polylines(polylines, closed, distance, tolerance, max_cells)
        except BufferDeclined as exc:
            declined = str(exc)
        else:
            if simplify > 0 and loops:
                sizes = np.array([0] + [len(lp) for lp in loops])
                xy, offsets = simplify_loops(np.concatenate(loops), np.cumsum(sizes), simplify)
                loops = split_loops(xy, offsets)
            return Offset(loops, "geos", "")
    loops = offset_polylines(polylines, closed, distance, cell, smooth, simplify, max_cells)
    return Offset(loops, "marching", declined)
