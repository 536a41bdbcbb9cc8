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
    """The loops as curves at z = 0: an outline that is a chain of arcs and straight pieces
    and whose exact offset by ``distance`` (:func:`formgraph.kernels.cam.arcs.offset_chain`)
    is one of the loops (within the accuracy, by GEOS's Hausdorff distance) replaces it,
    so circles stay circles; the others stay polylines."""
    exact: list[tuple[NurbsCurve, shapely.Geometry]] = []
    for c in outline:  # one step per outline: its offset, if it has an exact one
        if not (isinstance(c, NurbsCurve) and c.degree == 2 and c.rational):
            continue
        cp = karcs.offset_chain(c.control_points, c.knots, c.weights, distance)
        if cp is None:
            continue
        curve = NurbsCurve(cp, 2, c.knots, c.weights)
        pieces = (len(cp) - 1) // 2  # 64 samples a piece: within 1e-4 of an arc's radius
        fine = np.asarray(curve.sample(64 * pieces + 1))[:-1, :2]
        exact.append((curve, shapely.LinearRing(fine)))
    out: list[Curve] = []
    for lp in loops:  # one step per loop: its exact twin, if any
        ring = shapely.LinearRing(lp)
        twin = None
        for j, (_, sampled) in enumerate(exact):
            if shapely.hausdorff_distance(ring, sampled, densify=0.25) <= 4 * tol:
                twin = j
                break
        if twin is None:
            out.append(_loop_curve(lp))
        else:
            out.append(exact.pop(twin)[0])
    return out


def at_depths(curves: Sequence[Curve], zs: np.ndarray, ctx: Context) -> list[Curve]:
    """Each curve (at z = 0) once per depth, each loop through all its depths in turn."""
    ctx.guard(len(curves) * len(zs), "tool-path passes")
    eye = np.eye(3)
    return [transform_one(c, eye, np.array([0.0, 0.0, z])) for c in curves for z in zs.tolist()]
