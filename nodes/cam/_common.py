"""What the tool-path nodes share: the region read from closed curves (as every region node
reads it, :mod:`formgraph.nodes._outlines`), the checks of the tool and the depth, the
exact offset of arc chains matched to the offset kernel's loops, and the passes at depth.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely

from formgraph.core.errors import InputError
from formgraph.core.registry import Context
from formgraph.geometry import Curve, NurbsCurve
from formgraph.kernels.cam import arcs as karcs
from formgraph.kernels.cam import paths as kpaths
from formgraph.kernels.curves import sampling as ksampling
from formgraph.nodes import _outlines as _o
from formgraph.nodes.geometry.transform import transform_one
from formgraph.nodes.offset.marching_squares import _loop_curve

_ACCURACY = 1e-4  # default accuracy of the paths, as a share of the drawing's size


def region(
    curves: list[Curve], ctx: Context
) -> tuple[list[np.ndarray], list[Curve], np.ndarray, float]:
    """The even-odd region of the curves: its rings (XY), its outlines (exact where the
    input was; outer counter-clockwise, holes clockwise), which outlines are holes, and
    the paths' default accuracy."""
    if isinstance(curves, Curve):
        curves = [curves]
    if not curves:
        raise InputError("curves", "give the closed curves of the region to cut, got none")
    loops, outline, hole = _o.region_loops(curves, ctx)
    return loops, outline, hole, _ACCURACY * _o.span_of(curves)


def tool_radius(diameter: float) -> float:
    if not (math.isfinite(diameter) and diameter > 0):
        raise InputError("tool_diameter", f"the tool's diameter must be positive, got {diameter}")
    return 0.5 * diameter


def pass_depths(depth: float, step_down: float | None) -> np.ndarray:
    try:
        return kpaths.depths(depth, step_down)
    except ValueError as exc:
        raise InputError("step_down" if "step down" in str(exc) else "depth", str(exc)) from None


def accuracy(tolerance: float | None, default: float) -> float:
    if tolerance is None:
        return default
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise InputError("tolerance", f"the tolerance must be positive, got {tolerance}")
    return float(tolerance)


def exact_loops(
    loops: Sequence[np.ndarray], outline: Sequence[Curve], distance: float, tol: float
) -> list[Curve]:
    """The loops as curves at z = 0: an outline that is a polygon or a chain of arcs and
    straight pieces and whose exact offset by ``distance`` (:func:`_exact_offset`) is one
    of the loops (every point of each within 4 ``tol`` of the other, by GEOS's prepared
    distance tests) replaces it, so circles stay circles and corners rounded by the
    offset are arcs; the others stay polylines."""
    exact: list[tuple[NurbsCurve, np.ndarray]] = []
    for c in outline:  # one step per outline: its offset, if it has an exact one
        curve = _exact_offset(c, distance)
        if curve is not None:
            exact.append((curve, _chords(curve, tol)))
    out: list[Curve] = []
    for lp in loops:  # one step per loop: its exact twin, if any
        twin = None
        for j, (_, fine) in enumerate(exact):
            if _same_loop(lp, fine, 4 * tol):
                twin = j
                break
        if twin is None:
            out.append(_loop_curve(lp))
        else:
            out.append(exact.pop(twin)[0])
    return out


def _chords(curve: NurbsCurve, tol: float) -> np.ndarray:
    """Points along a chain of arcs and straight pieces in Bezier form, closing point left
    out: a straight piece's ends, an arc's chords within ``tol`` of it (a sweep of 2 h in
    steps of 2 acos(1 - tol / R), twice over for the parametrization's unevenness)."""
    cp = np.asarray(curve.control_points)[:, :2]
    if curve.degree == 1:  # a polygon (an offset with no arc): its corners
        return cp[:-1]
    w = np.asarray(curve.weights) if curve.rational else np.ones(len(cp))
    p0, p2 = cp[0:-1:2], cp[2::2]
    wm = w[1::2] / np.sqrt(w[0:-1:2] * w[2::2])
    half = np.arccos(np.clip(wm, -1.0, 1.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = np.hypot(*(p2 - p0).T) / (2 * np.sin(half))
        step = 2 * np.arccos(np.clip(1 - tol / radius, -1.0, 1.0))
        n = np.where(half > 1e-12, np.ceil(4 * half / step), 1)
    n = np.clip(np.nan_to_num(n, nan=1.0), 1, 256).astype(np.int64)
    spans = np.unique(np.asarray(curve.knots))
    piece = np.repeat(np.arange(len(n)), n)
    frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    t = spans[piece] + (spans[piece + 1] - spans[piece]) * frac
    return np.asarray(curve.evaluate(t))[:, :2]


def _same_loop(loop: np.ndarray, fine: np.ndarray, within: float) -> bool:
    """Whether two closed point loops lie within ``within`` of each other both ways: the
    bounds first, then every vertex and chord middle of each against the other (GEOS's
    prepared distance test, indexed: n log m, not the n m of a discrete Hausdorff)."""
    lo, hi = loop.min(axis=0), loop.max(axis=0)
    if np.abs(lo - fine.min(axis=0)).max() > within or np.abs(hi - fine.max(axis=0)).max() > within:
        return False
    for a, b in ((loop, fine), (fine, loop)):  # each way: a's points near b's ring
        ring = shapely.LinearRing(b)
        shapely.prepare(ring)
        mid = 0.5 * (a + np.roll(a, -1, axis=0))
        if not shapely.dwithin(ring, shapely.points(np.r_[a, mid]), within).all():
            return False
    return True


def _exact_offset(c: Curve, distance: float) -> NurbsCurve | None:
    """The exact offset of an outline that is a polygon or a chain of arcs and straight
    pieces: the same knots where its pieces meet tangentially
    (:func:`~formgraph.kernels.cam.arcs.offset_chain`), else with round joins at its
    corners (:func:`~formgraph.kernels.cam.arcs.offset_loop`); None for any other curve."""
    if not isinstance(c, NurbsCurve) or distance == 0:
        return None
    if c.degree == 1:
        cp, knots, w = karcs.polygon_chain(np.asarray(c.control_points)[:-1])
    elif c.degree == 2 and c.rational:
        cp, knots, w = np.asarray(c.control_points), np.asarray(c.knots), np.asarray(c.weights)
        moved = karcs.offset_chain(cp, knots, w, distance)
        if moved is not None:
            return NurbsCurve(moved, 2, knots, w)
    else:
        return None
    got = karcs.offset_loop(cp, knots, w, distance)
    if got is None:
        return None
    if np.all(got[2] == 1):  # no arc anywhere: a polygon, its corners cut sharp
        return _loop_curve(got[0][0:-1:2, :2])
    return NurbsCurve(got[0], 2, got[1], got[2])


def polyline_points(c: Curve, tol: float, ctx: Context) -> np.ndarray:
    """A closed loop's points in XY within ``tol`` of it, the first repeated at the end
    (a polygon's own corners; any other NURBS by the drawing sampler)."""
    if isinstance(c, NurbsCurve):
        cp = np.asarray(c.control_points)
        if c.degree == 1:
            return cp[:, :2]
        w = np.asarray(c.weights) if c.rational else None
        pts = ksampling.sample_nurbs(
            cp, c.degree, c.knots, w, tol, closed=True, guard=lambda n: ctx.guard(n, "points")
        )
        return np.r_[pts, pts[:1]][:, :2]
    pts = np.asarray(c.sample(max(65, getattr(c, "samples", 256) + 1)))[:, :2]
    return pts


def at_depths(curves: Sequence[Curve], zs: np.ndarray, ctx: Context) -> list[Curve]:
    """Each curve (at z = 0) once per depth, each loop through all its depths in turn."""
    ctx.guard(len(curves) * len(zs), "tool-path passes")
    eye = np.eye(3)
    return [transform_one(c, eye, np.array([0.0, 0.0, z])) for c in curves for z in zs.tolist()]
