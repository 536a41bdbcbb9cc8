"""Polyline kernels: B-spline subdivision, length and resampling, bisector offset.

Pure array functions (numpy in, numpy out, inputs never modified), also the point-array
helpers the spline kernels in :mod:`formgraph.kernels.curves.splines` share. Point arrays may be
(n, 3) or (n, 2); (n, 2) gets z = 0. A closed polyline is given without repeating its
first point (a repeat is dropped).
"""

from __future__ import annotations

import math

import numpy as np

from .arclength import even_lengths

__all__ = [
    "as_points",
    "norms",
    "span_vectors",
    "spans",
    "drop_repeats",
    "subdivide_polygon",
    "subdivided_count",
    "polyline_length",
    "resample_count",
    "resample_polyline",
    "bisector_offset",
]


# --------------------------------------------------------------------------- helpers


def as_points(points: object, name: str = "points") -> np.ndarray:
    """``points`` as an (n, 3) float64 array (a view when it already is one), checked
    finite; (n, 2) gets z = 0. Callers never write into it."""
    try:
        a = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be an (n, 3) array of coordinates: {exc}") from None
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise ValueError(
            f"{name} must be an (n, 3) or (n, 2) array of coordinates, got shape {a.shape}"
        )
    if a.shape[1] == 2:
        a = np.concatenate([a, np.zeros((a.shape[0], 1))], axis=1)
    if not np.isfinite(a).all():
        i = int(np.argmin(np.isfinite(a).all(axis=1)))
        raise ValueError(f"{name} must be finite, but point {i} is {a[i].tolist()}")
    return a


def norms(d: np.ndarray) -> np.ndarray:
    """Row lengths of ``d`` (m, D); rows whose squares would underflow or overflow are
    measured again after scaling, so a tiny non-zero step never reads as zero."""
    n = np.sqrt(np.einsum("ij,ij->i", d, d))
    if n.size and not (n.min() > 1e-150 and n.max() < 1e150):
        scale = np.abs(d).max(axis=1)
        q = d / np.where(scale > 0.0, scale, 1.0)[:, None]
        n = scale * np.sqrt(np.einsum("ij,ij->i", q, q))
    return n


def span_vectors(p: np.ndarray, closed: bool) -> np.ndarray:
    """p[i+1] - p[i] for each span, the closing span p[0] - p[-1] last when closed."""
    d = np.diff(p, axis=0)
    return np.concatenate([d, p[:1] - p[-1:]]) if closed else d


def _keep_mask(p: np.ndarray, closed: bool) -> np.ndarray:
    """Mask of the points that differ from the one before them; when closed, trailing
    copies of the first point are dropped too."""
    keep = np.ones(len(p), dtype=bool)
    if len(p) < 2:
        return keep
    keep[1:] = norms(np.diff(p, axis=0)) > 0.0
    if closed:
        idx = np.flatnonzero(keep)
        while len(idx) > 1 and not norms(p[idx[:1]] - p[idx[-1:]])[0] > 0.0:
            keep[idx[-1]] = False
            idx = idx[:-1]
    return keep


def spans(p: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drop each point equal to the one before it (and, when closed, trailing copies of the
    first point), so no span has zero length.

    Returns
    -------
    points : (N, D), spans : (S, D) span vectors, lengths : (S,) all > 0 (S = N - 1, or N
    when closed; S = 0 when a single point is left).
    """
    d = span_vectors(p, closed)
    length = norms(d)
    if len(p) < 2 or length.min() > 0.0:
        return p, d, length
    q = p[_keep_mask(p, closed)]
    if len(q) < 2:
        return q, d[:0], length[:0]
    d = span_vectors(q, closed)
    return q, d, norms(d)


def drop_repeats(points: np.ndarray, closed: bool = False) -> np.ndarray:
    """``points`` (n, 3) without any point equal to the one before it (and, when closed,
    without trailing copies of the first point): a polyline with no zero-length span."""
    return spans(as_points(points), closed)[0].copy()


# --------------------------------------------------------------------------- subdivision


def subdivided_count(n: int, closed: bool, iterations: int) -> int:
    """Number of points after ``iterations`` rounds of :func:`subdivide_polygon`.

    Each round adds one point per edge: open n -> 2 n - 1, so 2**k (n - 1) + 1; closed
    n -> 2 n, so 2**k n. Exact Python integers (no overflow), for the size guard.
    """
    if iterations < 0:
        raise ValueError(f"iterations must be >= 0, got {iterations}")
    return (n << iterations) if closed else ((n - 1) << iterations) + 1


def subdivide_polygon(points: np.ndarray, closed: bool = False, iterations: int = 1) -> np.ndarray:
    """Cubic B-spline subdivision of a polygon (Lane & Riesenfeld 1980; Chaikin's scheme's
    cubic sibling).

    Each round inserts the midpoint of every edge and moves every original vertex to
    1/8 prev + 6/8 itself + 1/8 next. A closed polygon wraps and converges to the uniform
    cubic B-spline with the polygon as control points (a vertex's limit is
    (prev + 4 itself + next) / 6). An open polygon keeps its two end points (the curve
    rule of Catmull-Clark boundaries); its limit is the uniform cubic B-spline of the
    polygon extended by the reflected points 2 P0 - P1 and 2 Pn - Pn-1.

    Parameters
    ----------
    points : (n, 3) float
        n >= 2 open, >= 3 closed. When closed, a last point equal to the first is dropped.
    closed : bool
    iterations : int
        Rounds, >= 0.

    Returns
    -------
    (m, 3) float64
        m = :func:`subdivided_count` (n, closed, iterations); closed output does not repeat
        its first point. Original vertex i sits at index i * 2**iterations.
    """
    p = as_points(points)
    if closed:
        while len(p) > 1 and np.array_equal(p[0], p[-1]):
            p = p[:-1]
    need = 3 if closed else 2
    if len(p) < need:
        kind = "closed" if closed else "open"
        raise ValueError(
            f"subdividing an {kind} polygon needs at least {need} points, got {len(p)}"
        )
    if iterations < 0:
        raise ValueError(f"iterations must be >= 0, got {iterations}")
    for _ in range(iterations):
        n = len(p)
        if closed:
            nxt = np.concatenate([p[1:], p[:1]])
            mid = 0.5 * (p + nxt)  # mid[i] between p[i] and p[i+1]
            out = np.empty((2 * n, 3))
            out[1::2] = mid
            # 1/8 prev + 6/8 p + 1/8 next == (mid[i-1] + mid[i]) / 4 + p / 2
            out[2::2] = 0.25 * (mid[:-1] + mid[1:]) + 0.5 * p[1:]
            out[0] = 0.25 * (mid[-1] + mid[0]) + 0.5 * p[0]
        else:
            mid = 0.5 * (p[:-1] + p[1:])
            out = np.empty((2 * n - 1, 3))
            out[1::2] = mid
            out[2:-1:2] = 0.25 * (mid[:-1] + mid[1:]) + 0.5 * p[1:-1]
            out[0], out[-1] = p[0], p[-1]
        p = out
    return p.copy() if iterations == 0 else p


# --------------------------------------------------------------------------- resampling


def polyline_length(points: np.ndarray, closed: bool = False) -> float:
    """Total length of a polyline (including the closing edge when ``closed``)."""
    p = as_points(points)
    return float(norms(span_vectors(p, closed)).sum()) if len(p) > 1 else 0.0


def resample_count(length: float, spacing: float, closed: bool = False) -> int:
    """Number of points :func:`resample_polyline` gives for ``spacing`` on a polyline of
    ``length``: the spacing is rounded to the nearest one that divides the length evenly
    (at least 1 segment open, 3 points closed). For the size guard, before allocating."""
    if not (math.isfinite(spacing) and spacing > 0.0):
        raise ValueError(f"spacing must be a positive number, got {spacing}")
    segments = length / spacing
    if not segments < 2.0**53:
        raise ValueError(
            f"spacing {spacing} on a curve of length {length:g} would give more than 2^53 points"
        )
    segments = int(round(segments))
    return max(3, segments) if closed else max(1, segments) + 1


def resample_polyline(
    points: np.ndarray,
    count: int | None = None,
    spacing: float | None = None,
    closed: bool = False,
) -> np.ndarray:
    """Points evenly spaced by arc length along a polyline.

    Parameters
    ----------
    points : (n, 3) float
        Polyline vertices in order. When closed, the closing edge is implied (a last point
        equal to the first is fine too).
    count : int, optional
        Number of points: open >= 2, both end points included; closed >= 3, the first at
        points[0] and not repeated at the end.
    spacing : float, optional
        Target distance along the curve; rounded to divide the length evenly (see
        :func:`resample_count`). Give exactly one of ``count`` and ``spacing``.
    closed : bool

    Returns
    -------
    (count, 3) float64
        Consecutive points are equally far apart measured along the polyline.

    Raises
    ------
    ValueError
        Neither or both of count and spacing, a count too small, or a polyline of zero
        length.
    """
    if (count is None) == (spacing is None):
        raise ValueError("resampling needs exactly one of count and spacing")
    p, d, seg = spans(as_points(points), closed)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = float(cum[-1])
    if not total > 0.0:
        raise ValueError("cannot resample a polyline of zero length (all its points coincide)")
    if count is None:
        count = resample_count(total, float(spacing), closed)
    need = 3 if closed else 2
    if count < need:
        kind = "closed" if closed else "open"
        raise ValueError(f"resampling an {kind} polyline needs count >= {need}, got {count}")
    s = even_lengths(total, count, closed)
    i = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
    f = ((s - cum[i]) / seg[i])[:, None]
    out = p[i] + f * d[i]
    if not closed:
        out[-1] = p[-1]
    return out


# --------------------------------------------------------------------------- offset


def bisector_offset(
    points: np.ndarray,
    closed: bool = False,
    distance: float = 0.0,
    miter_limit: float = 4.0,
    return_source: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Offset a polyline in the XY plane by moving each vertex along its corner bisector.

    Each vertex moves by ``distance / sin(a / 2)`` along the bisector of its corner angle a,
    i.e. to the intersection of its two edges' offset lines, so every edge of the result
    lies at exactly ``distance`` from its original edge (a mitre join). Collinear vertices
    (a = 180 degrees) move straight along the normal. Where the corner is convex on the
    offset side and the mitre would reach farther than ``miter_limit * |distance|`` from
    the vertex, it is clipped: two vertices on the two offset lines, on the line
    perpendicular to the bisector at that distance (the "clipped mitre" of GEOS/shapely,
    whose ``offset_curve(join_style="mitre")`` it matches). Concave corners keep the exact
    intersection point.

    Sides: on an open polyline a positive distance is to the left of the direction of
    travel (counter-clockwise normal of each edge), as shapely's ``offset_curve``; on a
    closed one a positive distance grows the curve whichever way it runs (the side follows
    the sign of the signed area).

    This is a local construction: where the offset distance exceeds the local feature size
    the result self-intersects (it has loops); ``offset.marching_squares`` is the tool that
    resolves those. z is carried over from each vertex; repeated points are dropped.

    Parameters
    ----------
    points : (n, 3) float
        Vertices; closed polylines do not repeat the first point (a repeat is dropped).
    closed : bool
    distance : float
    miter_limit : float
        Largest mitre length as a multiple of ``|distance|``; >= 1.
    return_source : bool
        Also return, for each output vertex, the index of the input vertex (after dropping
        repeats) it comes from.

    Returns
    -------
    offset : (m, 3) float64
        m = n plus one per clipped corner.
    source : (m,) int64, only when ``return_source``

    Raises
    ------
    ValueError
        Non-finite input, fewer than 2 (open) / 3 (closed) distinct points, a miter limit
        below 1, or a closed polyline with zero area (it has no outside).
    """
    p = as_points(points)
    if not math.isfinite(distance):
        raise ValueError(f"distance must be a finite number, got {distance}")
    if not (math.isfinite(miter_limit) and miter_limit >= 1.0):
        raise ValueError(f"miter_limit must be a number >= 1, got {miter_limit}")
    p = p[_keep_mask(p[:, :2], closed)]
    n = len(p)
    need = 3 if closed else 2
    if n < need:
        kind = "closed" if closed else "open"
        raise ValueError(
            f"offsetting an {kind} polyline needs at least {need} distinct points (in XY), got {n}"
        )
    xy = p[:, :2]
    if closed:
        d_left = -distance * _orientation(xy)
        edge = np.concatenate([xy[1:], xy[:1]]) - xy  # edge[i]: i -> i+1
    else:
        d_left = distance
        edge = np.diff(xy, axis=0)
    e = edge / np.hypot(edge[:, 0], edge[:, 1])[:, None]
    if closed:
        e_in, e_out = np.roll(e, 1, axis=0), e
    else:
        e_in = np.concatenate([e[:1], e])
        e_out = np.concatenate([e, e[-1:]])
    n_in = np.stack([-e_in[:, 1], e_in[:, 0]], axis=1)
    n_out = np.stack([-e_out[:, 1], e_out[:, 0]], axis=1)
    c = np.clip(np.einsum("ij,ij->i", e_in, e_out), -1.0, 1.0)
    cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]
    src = np.arange(n)
    if d_left == 0.0:
        return (p.copy(), src) if return_source else p.copy()
    side = math.copysign(1.0, d_left)
    reversal = 1.0 + c <= 1e-12
    convex = (side * cross < 0.0) | reversal
    clip = convex & (1.0 + c < 2.0 / miter_limit**2)
    safe = np.where(reversal, 1.0, 1.0 + c)
    mitre = xy + d_left * (n_in + n_out) / safe[:, None]
    cos_h = np.sqrt(0.5 * (1.0 + c[clip]))
    sin_h = np.sqrt(0.5 * (1.0 - c[clip]))
    lam = (abs(d_left) * (miter_limit - cos_h) / sin_h)[:, None]
    first = xy[clip] + d_left * n_in[clip] + lam * e_in[clip]
    second = xy[clip] + d_left * n_out[clip] - lam * e_out[clip]
    counts = 1 + clip.astype(np.int64)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    out = np.empty((int(counts.sum()), 3))
    out[start, :2] = mitre
    out[start[clip], :2] = first
    out[start[clip] + 1, :2] = second
    source = np.repeat(src, counts)
    out[:, 2] = p[source, 2]
    return (out, source) if return_source else out


def offset_folds(
    points: np.ndarray, offset: np.ndarray, source: np.ndarray, closed: bool, inward: bool = False
) -> tuple[bool, int]:
    """How an offset polyline went wrong, if it did: (inside out, folded edges).

    An edge of a bisector offset runs parallel to its source edge, the same way while the
    distance is below the local size of the shape; past it the edge has shrunk through
    zero length and runs backwards ("folded"), and the result loops. An inward offset of
    a closed polygon past its inradius (the largest circle inside it) turns the whole
    polygon inside out: every edge folds, its signed area no longer lies between 0 and the
    original's (an 8-gon of radius 1 offset by -2 comes out as an 8-gon of radius 1.16).

    Parameters
    ----------
    points : (n, 3) float
        The polyline that was offset, repeats dropped as in :func:`bisector_offset`.
    offset, source : as returned by ``bisector_offset(..., return_source=True)``
    closed : bool
    inward : bool
        The offset was towards the inside of a closed polyline (it should shrink).

    Returns
    -------
    inside_out : bool
        Closed only: every edge folded, or (inward) the offset's signed area is not
        strictly between 0 and the original's, same sign.
    folded : int
        Number of offset edges that run against their source edge.
    """
    p = as_points(points)[:, :2]
    p = p[_keep_mask(p, closed)]
    q = np.asarray(offset, dtype=np.float64)[:, :2]
    src = np.asarray(source, dtype=np.int64)
    n, m = len(p), len(q)
    k = np.arange(m if closed else m - 1)
    a, b = src[k], src[(k + 1) % m]
    step = (b - a) % n if closed else b - a
    edge = step == 1  # offset edges that follow a source edge (not the bevel of a clip)
    d_src = p[(a + 1) % n] - p[a]
    d_off = q[(k + 1) % m] - q[k]
    folded = int(np.count_nonzero(edge & (np.einsum("ij,ij->i", d_src, d_off) < 0)))
    if not closed:
        return False, folded

    def area2(xy: np.ndarray) -> float:
        c = xy - xy.mean(axis=0)
        return float(np.dot(c[:, 0], np.roll(c[:, 1], -1)) - np.dot(np.roll(c[:, 0], -1), c[:, 1]))

    a0, a1 = area2(p), area2(q)
    ratio = a1 / a0 if a0 else 0.0
    inside_out = folded == int(np.count_nonzero(edge)) or (inward and not 0.0 < ratio < 1.0)
    return inside_out, folded


def _orientation(xy: np.ndarray) -> float:
    """+1 for a counter-clockwise closed polygon, -1 clockwise (shoelace signed area)."""
    centred = xy - xy.mean(axis=0)
    x, y = centred[:, 0], centred[:, 1]
    area2 = float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    extent = float(np.ptp(centred, axis=0).max())
    if not abs(area2) > 1e-12 * extent**2:
        raise ValueError(
            "a closed polyline with zero signed area has no outside to grow towards; offset "
            "it as an open polyline, or use offset.marching_squares"
        )
    return math.copysign(1.0, area2)
