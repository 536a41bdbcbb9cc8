"""Helpers shared by the ``nurbs`` nodes: curves and surfaces to and from the kernels'
tuples, and degrees capped by the number of control points.
"""

from __future__ import annotations

from enum import Enum

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context
from formgraph.geometry import (
    Curve,
    NurbsCurve,
    NurbsSurface,
    ParametricCurve,
)
from formgraph.kernels import nurbs as K

CurveTuple = tuple[np.ndarray, int, np.ndarray, "np.ndarray | None"]


class Parametrization(str, Enum):
    """Spacing of the parameters of interpolated points."""

    chord = "chord"  # proportional to the distance between points
    centripetal = "centripetal"  # to its square root: no loops or cusps on uneven data
    uniform = "uniform"  # equal steps


def as_tuple(curve: NurbsCurve) -> CurveTuple:
    w = curve.weights if curve.rational else None
    return (np.asarray(curve.control_points), curve.degree, np.asarray(curve.knots), w)


def curve_of(t: CurveTuple) -> NurbsCurve:
    return NurbsCurve(*t)


def surface_of(s: tuple) -> NurbsSurface:
    return NurbsSurface(*s)


def as_nurbs(curve: Curve, port: str, ctx: Context) -> CurveTuple:
    """A NURBS curve exactly; any other curve (e.g. a parametric one) as the cubic through
    its sample points (as many as it is drawn with), closed if it closes. The banded
    interpolation (:mod:`~formgraph.kernels.nurbs.banded`) costs O(samples)."""
    if isinstance(curve, NurbsCurve):
        return as_tuple(curve)
    samples = curve.samples if isinstance(curve, ParametricCurve) else 256
    closed = bool(curve.closed)
    # What the banded solve holds at once (kernels.nurbs.banded_entries), and the samples.
    n = max(samples, 4)
    entries = K.banded_entries(n, 4, 3, closed) + 8 * n
    ctx.guard(entries, f"entries of the interpolation system of input '{port}'")
    pts = np.asarray(curve.sample(n))
    return InputError.call(port, K.interpolate, pts[:-1] if closed else pts, 3, closed)


def capped_degree(degree: int, count: int, port: str, ctx: Context) -> int:
    if count < 2:
        raise InputError(port, f"a NURBS curve needs at least 2 control points, got {count}")
    if degree > count - 1:
        ctx.warn(f"degree {degree} needs {degree + 1} points, got {count}: using {count - 1}")
        return count - 1
    return degree
