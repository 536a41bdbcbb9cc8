"""The region machinery of the cutting nodes (:mod:`formgraph.nodes.curves.regions`): closed curves
sampled into rings, the rings made regions (:mod:`formgraph.kernels.curves.regions`), and a
region's boundary made curves again — input curves the operation left whole as themselves,
the arcs it cut of exact curves as arcs (:mod:`formgraph.kernels.curves.arcs`), the rest
as chord-length polylines. Also the division of a curve at equal arc length that
``curves.divide`` and ``curves.resample`` share (:func:`even_parameters`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context
from formgraph.geometry import Curve, NurbsCurve, frozen_array
from formgraph.kernels import curves as kc
from formgraph.kernels.curves import arcs as karcs
from formgraph.kernels.curves import regions as kregions
from formgraph.kernels.curves import sampling as ksampling

__all__ = [
    "chord_knots",
    "closes",
    "divisions",
    "even_parameters",
    "make_region",
    "region_loops",
    "outline_curves",
    "region_rings",
    "sample_rings",
    "sampling_tolerance",
    "span_of",
]

_TOLERANCE = 1e-5  # default sampling tolerance of region booleans, relative to the extent
_FEW = 64  # up to this many outlines, their knots are made a ring at a time
_LARGEST = 1e150  # the largest extent whose areas (its square, times vertex counts) are finite


def span_of(curves: list[Curve]) -> float:
    """The largest side of the XY box around the curves (their control points when NURBS:
    the curve lies in their hull)."""
    pts = [
        c.control_points if isinstance(c, NurbsCurve) else np.asarray(c.sample(65)) for c in curves
    ]
    p = pts[0] if len(pts) == 1 else np.concatenate(pts)
    x, y = p[:, 0], p[:, 1]  # a column at a time (numpy's axis=0 min is slow)
    return float(max(x.max() - x.min(), y.max() - y.min()))


def closes(c: Curve) -> bool:
    """Whether a curve closes: a clamped NURBS ends on its first and last control points
    (no evaluation needed); any other curve is asked."""
    if isinstance(c, NurbsCurve):
        p, k = c.degree, c.knots
        if k[0] == k[p] and k[-1] == k[-1 - p]:
            first, last = c.control_points[0].tolist(), c.control_points[-1].tolist()
            scale = max(1.0, *map(abs, first), *map(abs, last))
            return math.dist(first, last) <= 1e-9 * scale
    return c.closed


def divisions(
    length: float, count: int | None, spacing: float | None, closed: bool, ctx: Context, verb: str
) -> int:
    """How many points divide a curve of ``length``: ``count``, or from ``spacing``; checked
    and charged to the budget. ``verb`` ("divide", "resample") words the errors."""
    if not math.isfinite(length):
        raise InputError(
            "curve",
            f"cannot {verb} a curve whose length is not finite (got {length}: coordinates "
            "too large to measure, or not numbers)",
        )
    if not length > 0.0:
        raise InputError("curve", f"cannot {verb} a curve of zero length")
    n = (
        count
        if count is not None
        else InputError.call("spacing", kc.resample_count, length, spacing, closed)
    )
    if closed and n < 3:
        raise InputError("count", f"{verb[:-1]}ing a closed curve needs count >= 3, got {n}")
    ctx.guard(n, "points")
    return int(n)


def even_parameters(
    curve: Curve, closed: bool, count: int | None, spacing: float | None, ctx: Context, verb: str
) -> np.ndarray:
    """Parameters at equal arc length along any curve (:func:`kc.even_arc_parameters`):
    quadrature on every knot span of a NURBS (in 16 pieces unless it is straight), on the
    ``samples`` intervals (at least 64) of any other curve."""
    if isinstance(curve, NurbsCurve):
        breaks = np.unique(curve.knots[curve.degree : len(curve.control_points) + 1])
        pieces = 1 if curve.degree == 1 else 16
    else:
        breaks, pieces = np.array(curve.domain), max(64, getattr(curve, "samples", 256))
    return kc.even_arc_parameters(
        curve.derivative,
        breaks,
        lambda length: divisions(length, count, spacing, closed, ctx, verb),
        closed,
        pieces,
    )


def sample_rings(
    curves: list[Curve], port: str, tol: float, ctx: Context, exact: bool = True
) -> tuple[list[np.ndarray], list[np.ndarray | None], list[karcs.Source | None]]:
    """Each closed curve sampled to ``tol`` in XY; (for curves that are not polylines) the
    same rings again, to recognize the curves a boolean leaves whole; and (for NURBS of
    degree >= 2, with ``exact``) the curve with its samples' parameters, to rebuild the
    arcs it cuts (a solid made of the region needs neither: ``exact=False``)."""
    rings: list[np.ndarray] = []
    sampled: list[np.ndarray | None] = []
    sources: list[karcs.Source | None] = [None] * len(curves)
    total = 0

    def guard(n: int) -> None:
        ctx.guard(total + n, "curve samples")

    # NURBS of degree >= 2 are sampled together, a batch per degree (one vectorized pass)
    batched: dict[int, np.ndarray] = {}
    by_degree: dict[int, list[int]] = {}
    tilted: list[int] = []
    for i, c in enumerate(curves):
        if not closes(c):
            raise InputError(
                port,
                f"curve {i} is open: a region is bounded by closed curves (close it, or "
                "offset it with offset.marching_squares to get a band around it)",
            )
        if isinstance(c, NurbsCurve) and c.degree >= 2:
            by_degree.setdefault(c.degree, []).append(i)
        z = np.asarray(c.control_points)[:, 2] if isinstance(c, NurbsCurve) else c.sample(65)[:, 2]
        if not np.count_nonzero(z):  # on z = 0, the usual case: one pass, not two
            continue
        lo, hi = float(z.min()), float(z.max())
        if hi - lo > 1e-9 * max(1.0, -lo, hi):
            tilted.append(i)
    if tilted:
        shown = ", ".join(str(i) for i in tilted[:10]) + (", ..." if len(tilted) > 10 else "")
        ctx.warn(
            f"{port}: curve(s) {shown} are not parallel to the XY plane: their projection "
            "onto it (z dropped) bounds the region"
        )
    for members in by_degree.values():
        batch = [
            (
                curves[i].control_points,
                curves[i].degree,
                curves[i].knots,
                curves[i].weights if curves[i].rational else None,
            )
            for i in members
        ]
        sampled_batch = InputError.call(
            port, ksampling.sample_closed_batch, batch, tol, guard, params=exact, validate=False
        )
        batched.update(zip(members, sampled_batch, strict=True))
    for i, c in enumerate(curves):  # one step per curve; its samples are vectorized
        poly = isinstance(c, NurbsCurve) and c.degree == 1
        if poly:
            # a polyline is its own sampling: its control points in XY, closed as they are
            # (repeats left in: GEOS takes them and leaves none; a ring of fewer than 3
            # distinct points is refused where the region is made, see make_region)
            ring = kregions.planar(c.control_points)
            guard(len(ring))
            total += len(ring)
            rings.append(ring)
            sampled.append(None)
            continue
        if i in batched and not exact:
            ring = batched[i]
        elif i in batched:
            ring, t = batched[i]
            x, y = ring[:, 0], ring[:, 1]
            keep = np.r_[True, (x[1:] != x[:-1]) | (y[1:] != y[:-1])]
            ring, t = ring[keep], t[keep]
            w = np.asarray(c.weights) if c.rational else None
            flat = _flat(c)
            sources[i] = karcs.Source(
                np.asarray(flat.control_points), c.degree, np.asarray(c.knots), w, ring, t
            )
        elif isinstance(c, NurbsCurve):
            w = np.asarray(c.weights) if c.rational else None
            ring = InputError.call(
                port,
                ksampling.sample_nurbs,
                c.control_points,
                c.degree,
                c.knots,
                w,
                tol,
                closed=True,
                guard=guard,
            )
        else:
            t0, t1 = c.domain
            u = np.linspace(t0, t1, max(65, getattr(c, "samples", 256) + 1))

            def at(uu: np.ndarray, c: Curve = c) -> np.ndarray:
                return np.asarray(c.evaluate(uu))[:, :2]

            _, ring = ksampling.refine_chords(at, u, at(u), tol, guard)
            ring = ring[:-1]
        ring = _distinct(ring)
        if len(ring) < 3:
            raise InputError(port, f"curve {i} encloses no area (fewer than 3 distinct points)")
        total += len(ring)
        rings.append(ring)
        sampled.append(ring)
    return rings, sampled, sources


def make_region(make: Any, rings: list[np.ndarray], port: str) -> Any:
    """``make(rings)``, a ring of fewer than 3 distinct points refused as its curve's error
    (a polyline's ring is checked here, by GEOS's simplicity test it needs anyway, not by
    a pass of its own over the points)."""
    try:
        return make(rings)
    except kregions.NoArea as exc:
        raise InputError(
            port, f"curve {exc.ring} encloses no area (fewer than 3 distinct points)"
        ) from None


def region_loops(
    curves: list[Curve], ctx: Context
) -> tuple[list[np.ndarray], list[Curve], np.ndarray]:
    """The even-odd region of closed curves (port ``curves``) for the nodes that work on its
    pieces (``layout.nest``, ``cam.*``): its rings in XY (closing point left out), its
    outlines as curves (exact where the input was; outer counter-clockwise, holes
    clockwise) in the same order, and which of them are holes (each piece is an outer
    ring and the holes after it)."""
    tol = sampling_tolerance(None, curves)
    rings, sampled, sources = sample_rings(curves, "curves", tol, ctx)
    shape = make_region(kregions.even_odd_region, rings, "curves")
    outline = outline_curves(shape, curves, sampled, sources, tol, ctx)
    coords, offsets, hole = kregions.rings_of(shape)
    loops = [coords[offsets[i] : offsets[i + 1] - 1] for i in range(len(offsets) - 1)]
    return loops, outline, hole


def region_rings(
    curves: list[Curve], tolerance: float | None, ctx: Context, port: str = "curves"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The even-odd region of closed curves in XY, as ``curves.boolean`` reads it, given
    back as its boundary rings: the solids made from outlines (``mesh.extrude``,
    ``mesh.revolve``) read their region here and nowhere else.

    Returns
    -------
    xy : (N, 2) float
        Every ring's points, ring after ring, each without its closing point; no point
        repeats the one before it.
    offsets : (r + 1,) int
        Ring i is ``xy[offsets[i]:offsets[i + 1]]``; a polygon's outer ring (counter-
        clockwise) comes before its holes (clockwise).
    hole : (r,) bool
    tol : float
        The sampling tolerance: ``tolerance``, or 1e-5 of the size of the region.

    Raises
    ------
    InputError
        On ``port``: no curves, an open curve, a curve that encloses nothing, or a region
        of no area (e.g. a curve given twice: by the even-odd rule the two cancel).
    """
    if isinstance(curves, Curve):
        curves = [curves]
    if not curves:
        raise InputError(port, "give closed curves bounding a region, got none")
    tol = sampling_tolerance(tolerance, curves, port)
    rings, _, _ = sample_rings(curves, port, tol, ctx, exact=False)
    region = make_region(kregions.even_odd_region, rings, port)
    coords, offsets, hole = kregions.rings_of(region)
    if len(offsets) < 2:
        raise InputError(
            port,
            f"the {len(curves)} curve(s) bound a region of no area (by the even-odd rule a "
            "curve given twice, or two that coincide, cancel out)",
        )
    # each ring without its closing point: ring i loses its last row
    r = len(offsets) - 1
    keep = np.ones(len(coords), dtype=bool)
    keep[offsets[1:] - 1] = False
    xy = coords[keep]
    if tolerance is None:  # (polylines were taken as they are: 1e-5 of the region's size)
        tol = _TOLERANCE * float(max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1])))
    return xy, offsets - np.arange(r + 1), hole, tol


def _distinct(ring: np.ndarray) -> np.ndarray:
    """A sampled ring (its closing point left out) without consecutive repeats, nor a
    repeat of its first point at its end."""
    x, y = ring[:, 0], ring[:, 1]
    repeat = (x[1:] == x[:-1]) & (y[1:] == y[:-1])
    r = ring if not repeat.any() else ring[np.r_[True, ~repeat]]
    if len(r) > 1 and np.array_equal(r[0], r[-1]):
        r = r[:-1]
    return r


def _reversed(c: NurbsCurve) -> NurbsCurve:
    """The same curve run the other way (control points, weights and knots mirrored)."""
    k = np.asarray(c.knots)
    w = np.asarray(c.weights)[::-1] if c.rational else None
    return NurbsCurve(np.asarray(c.control_points)[::-1], c.degree, k[0] + k[-1] - k[::-1], w)


def _flat(c: NurbsCurve) -> NurbsCurve:
    """The curve projected onto z = 0 (exact: projection is affine)."""
    cp = np.asarray(c.control_points)
    if not np.any(cp[:, 2]):
        return c
    w = np.asarray(c.weights) if c.rational else None
    return NurbsCurve(np.c_[cp[:, :2], np.zeros(len(cp))], c.degree, c.knots, w)


def outline_curves(
    region: Any,
    curves: list[Curve],
    sampled: list[np.ndarray | None],
    sources: list[karcs.Source | None],
    tol: float,
    ctx: Context,
) -> list[Curve]:
    """The region's boundary as closed curves; an input curve the operation left whole
    comes back as itself (exact), turned to the right direction, and the arcs of exact
    curves it cut come back as arcs of those curves (:mod:`formgraph.kernels.curves.arcs`)."""
    coords, offsets, _, step = kregions.rings_of(region, with_z=True, steps=True)
    if len(offsets) < 2:
        ctx.warn("the result is empty: the regions leave no area")
        return []
    if any(g is not None for g in sampled):
        out_rings = [coords[offsets[i] : offsets[i + 1] - 1, :2] for i in range(len(offsets) - 1)]
        matches = kregions.match_rings(out_rings, sampled)
    else:  # polylines only: nothing to keep exact
        matches = [None] * (len(offsets) - 1)
    xyz = frozen_array(coords)  # every outline's points: each curve's are a view of them
    knots = frozen_array(chord_knots(step, offsets))
    exact = [x for x in sources if x is not None]
    index = karcs.SampleIndex(exact) if exact else None
    result: list[Curve] = []
    for i, match in enumerate(matches):  # one step per outline
        a, b = offsets[i], offsets[i + 1]
        rebuilt = (
            karcs.exact_outline(coords[a : b - 1, :2], exact, index, tol)
            if index is not None and match is None
            else None
        )
        if match is not None:
            c = curves[match[0]]
            assert isinstance(c, NurbsCurve)
            result.append(_flat(c) if match[1] else _flat(_reversed(c)))
        elif rebuilt is not None:
            result.append(NurbsCurve(*rebuilt))
        else:
            # GEOS's points of finite input and their running length: valid by making
            result.append(NurbsCurve._of_valid(xyz[a:b], 1, knots[a + 2 * i : b + 2 * i + 2]))
    return result


def chord_knots(seg: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The knots of every closed ring as a polyline, in one array: ring i's running chord
    length with its first and last value doubled, at ``[offsets[i] + 2 i, offsets[i + 1] +
    2 i + 2)`` (so t is arc length along each outline). ``seg[j - 1]`` is the length of
    the step from point j - 1 to j (as :func:`.regions.rings_of` gives them)."""
    m, r = offsets[-1], len(offsets) - 1
    knots = np.zeros(m + 2 * r)
    if r <= _FEW:  # a ring at a time, without the scatter: [0, 0, running length, last again]
        for i, (a, b) in enumerate(zip(offsets[:-1].tolist(), offsets[1:].tolist(), strict=True)):
            np.cumsum(seg[a : b - 1], out=knots[a + 2 * i + 2 : b + 2 * i + 1])
            knots[b + 2 * i + 1] = knots[b + 2 * i]
        return knots
    # point j of ring i sits at j + 2 i + 1; the step into it (none into a ring's first
    # point, so each ring starts at 0 and its doubled ends repeat their neighbours)
    ring = np.repeat(np.arange(r), np.diff(offsets))
    inside = np.flatnonzero(ring[1:] == ring[:-1])
    knots[inside + 2 + 2 * ring[inside + 1]] = seg[inside]
    np.cumsum(knots, out=knots)
    knots -= np.repeat(knots[offsets[:-1] + 2 * np.arange(r)], np.diff(offsets) + 2)
    return knots


def sampling_tolerance(tolerance: float | None, curves: list[Curve], port: str = "curves") -> float:
    """The sampling tolerance: given (and checked), else 1e-5 of the curves' extent. Polylines
    are taken at their vertices, so when every curve is one no extent is needed."""
    polylines = all(isinstance(c, NurbsCurve) and c.degree == 1 for c in curves)
    if tolerance is None and polylines:
        return 1.0  # unused: nothing is sampled
    extent = span_of(curves)
    if not extent < _LARGEST:
        raise InputError(
            "curves" if port == "curves" else "a",
            f"the curves span {extent:.3g}: too large for a region boolean, whose areas "
            f"(squares of lengths) overflow double precision past {_LARGEST:.0e}; scale them "
            "down",
        )
    if tolerance is None:
        return _TOLERANCE * (extent if extent > 0 else 1.0)
    if not tolerance > 0:
        raise InputError("tolerance", f"the tolerance must be positive, got {tolerance}")
    if extent > 0 and tolerance < 1e-12 * extent:
        raise InputError(
            "tolerance",
            f"tolerance {tolerance:g} is below 1e-12 of the curves' size ({extent:g}): "
            "finer than double precision resolves",
        )
    return float(tolerance)
