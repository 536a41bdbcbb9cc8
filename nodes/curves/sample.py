"""Curves sampled and measured: ``curves.resample``, ``curves.divide`` (equal arc length,
with frames) and ``curves.measure``.
"""

from __future__ import annotations

from typing import Annotated, NamedTuple

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve, NurbsCurve, Points
from formgraph.kernels import curves as kc
from formgraph.kernels.curves import measure as kmeasure
from formgraph.kernels.curves import sampling as ksampling
from formgraph.kernels.curves.adaptive import refine_breaks
from formgraph.nodes import _outlines as _o
from formgraph.nodes.curves._common import control_polygon, polyline_curve


@node("curves.resample", version=2)
def resample(
    curve: Curve,
    count: Annotated[int | None, Range(min=2)] = None,
    spacing: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> NurbsCurve:
    """Points evenly spaced along the curve by arc length, joined as a polyline.

    Give ``count`` or ``spacing``. The points lie exactly on the curve: the arc length is
    integrated by Gauss-Legendre quadrature and inverted by Newton steps (a polyline is
    resampled along its straight segments). A closed curve stays closed, its first point
    not repeated in the count.

    Parameters
    ----------
    curve : Curve
        Any curve.
    count : int
        Number of points (open: both ends included; closed: >= 3).
    spacing : float
        Distance along the curve between points; rounded so it divides the length evenly.
    """
    if (count is None) == (spacing is None):
        raise InputError("count", "give exactly one of count and spacing")
    closed = curve.closed
    if isinstance(curve, NurbsCurve) and curve.degree == 1:
        p, _ = control_polygon(curve)
        length = InputError.call("curve", kc.polyline_length, p, closed)
        n = _o.divisions(length, count, spacing, closed, ctx, "resample")
        out = InputError.call("curve", kc.resample_polyline, p, count=n, closed=closed)
        return polyline_curve(out, closed=closed)

    t = _o.even_parameters(curve, closed, count, spacing, ctx, "resample")
    return polyline_curve(curve.evaluate(t), closed=closed)


class CurveMeasures(NamedTuple):
    length: float
    area: float
    closed: bool


def breaks_of(curve: Curve) -> np.ndarray:
    """The quadrature intervals of a curve: every knot span of a NURBS curve split in 8 (a
    polyline's spans whole); a parametric curve's ``samples`` intervals, split where needed
    until the length is good to 1e-12 of itself (its derivatives are exact)."""
    t0, t1 = curve.domain
    if isinstance(curve, NurbsCurve):
        knots = np.unique(curve.knots[(curve.knots >= t0) & (curve.knots <= t1)])
        split = 1 if curve.degree == 1 else 8
        steps = np.arange(split) / split
        inner = knots[:-1, None] + np.diff(knots)[:, None] * steps
        return np.append(inner.reshape(-1), knots[-1])
    breaks = np.linspace(t0, t1, max(2, getattr(curve, "samples", 256)) + 1)
    return refine_breaks(  # exact derivatives, so the quadrature alone limits it
        lambda t: np.linalg.norm(curve.derivative(t), axis=1), breaks, rtol=1e-12
    )


@node("curves.measure", version=2)
def measure(curve: Curve) -> CurveMeasures:
    """Length of a curve, the area it encloses if closed and planar, and whether it is closed.

    Gauss-Legendre quadrature (8 points) of the speed ``|C'(t)|`` and of the vector area
    ``1/2 C x C'`` on every knot span of a NURBS curve, each split in 8 (a parametric curve:
    its ``samples`` intervals, split where needed until the length is good to 1e-12 of
    itself, with the expressions' exact derivatives); the area is 0 for an open or
    non-planar curve.

    Parameters
    ----------
    curve : Curve
        Any curve.
    """
    closed = curve.closed
    length, area = kmeasure.length_and_area(
        curve.evaluate, curve.derivative, breaks_of(curve), closed
    )
    return CurveMeasures(length=length, area=area, closed=closed)


@node("curves.divide", version=2)
def divide(
    curve: Curve,
    count: Annotated[int | None, Range(min=2)] = None,
    spacing: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Points:
    """Points on a curve at equal arc length, with ``tangent`` and ``t`` point attributes.

    Give ``count`` or ``spacing``. The arc length is integrated by Gauss-Legendre
    quadrature on every knot span and inverted by safeguarded Newton steps, so the points
    lie exactly on the curve (a polyline: along its straight segments); an open curve gets
    both ends, a closed one its start and no repeat of it. ``tangent`` is the unit tangent
    (the direction of travel) and ``t`` the curve parameter of each point: copy parts onto
    the points aligned to the curve, or drive expressions by position along it.

    Parameters
    ----------
    curve : Curve
        Any curve.
    count : int
        Number of points (open: both ends included; closed: >= 3).
    spacing : float
        Distance along the curve between points; rounded so it divides the length evenly.

    Example
    -------
    ``studs: {type: curves.divide, curve: "@rim", spacing: 5}``
    """
    if (count is None) == (spacing is None):
        raise InputError("count", "give exactly one of count and spacing")
    closed = _o.closes(curve)
    k0, k1 = np.asarray(curve.knots)[[0, 1]] if isinstance(curve, NurbsCurve) else (0, 1)
    if isinstance(curve, NurbsCurve) and curve.degree == 1 and k0 == k1:  # clamped polyline
        cp = np.asarray(curve.control_points)
        length = float(np.sum(np.linalg.norm(np.diff(cp, axis=0), axis=1)))
        n = _o.divisions(length, count, spacing, closed, ctx, "divide")
        s = kc.even_lengths(length, n, closed)
        t, xyz, tangent, _ = ksampling.polyline_at_lengths(cp, curve.knots, s)
        return Points(xyz, point_data={"tangent": tangent, "t": t})
    t = _o.even_parameters(curve, closed, count, spacing, ctx, "divide")
    xyz = np.asarray(curve.evaluate(t))
    d = np.asarray(curve.derivative(t))
    norm = np.linalg.norm(d, axis=1)
    tangent = np.divide(d, norm[:, None], out=np.zeros_like(d), where=norm[:, None] > 0)
    return Points(xyz, point_data={"tangent": tangent, "t": t})
