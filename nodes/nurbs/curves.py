"""Exact NURBS curves: from control points, circles, arcs and interpolation through points.

Each node adapts a kernel of :mod:`formgraph.kernels.nurbs` (The NURBS Book's algorithms,
vectorized); a kernel's ``ValueError`` is reported against the input it is about.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Vec3
from formgraph.geometry import (
    NurbsCurve,
    Points,
)
from formgraph.kernels import nurbs as K
from formgraph.nodes.nurbs._common import (
    Parametrization,
    capped_degree,
    curve_of,
)


@node("nurbs.curve", version=1)
def curve(
    points: Points,
    degree: Annotated[int, Range(min=1)] = 3,
    knots: list[float] | None = None,
    weights: list[float] | None = None,
    closed: bool = False,
    *,
    ctx: Context,
) -> NurbsCurve:
    """A NURBS curve from its control points (the curve follows them, it does not pass
    through them; see nurbs.interpolate).

    Without knots, an open curve gets clamped uniform knots (it starts at the first point
    and ends at the last) on [0, 1]; a closed curve wraps its control polygon periodically
    and closes smoothly. With fewer than degree + 1 points the degree is lowered (with a
    warning).

    Parameters
    ----------
    points : Points
        Control points, in order.
    degree : int
        Polynomial degree (1 = the control polygon itself, 3 = cubic).
    knots : list[float] | None
        Explicit knot vector, non-decreasing, of length points + degree + 1 (open only).
    weights : list[float] | None
        One positive weight per control point (a rational curve); default all 1.
    closed : bool
        Periodic: the curve closes smoothly around the control polygon.

    Example
    -------
    ``c: {type: nurbs.curve, points: [[0, 0], [1, 2], [3, 2], [4, 0]], degree: 3}``
    """
    cp = points.xyz
    w = None if weights is None else np.asarray(weights, dtype=np.float64)
    if w is not None and len(w) != len(cp):
        raise InputError(
            "weights", f"one weight per control point is needed: {len(cp)} points, {len(w)} weights"
        )
    if closed:
        if knots is not None:
            raise InputError(
                "knots", "a closed curve makes its own periodic knots; leave knots out"
            )
        if len(cp) > 1 and np.array_equal(cp[0], cp[-1]):
            cp, w = cp[:-1], None if w is None else w[:-1]
        if len(cp) < 3:
            raise InputError("points", f"a closed curve needs at least 3 points, got {len(cp)}")
        p = capped_degree(degree, len(cp), "degree", ctx)
        ctrl, kn, _ = K.periodic_curve(cp, p)
        ww = None if w is None else np.concatenate([w, w[:p]])
        return InputError.call("weights", NurbsCurve, ctrl, p, kn, ww)
    if knots is None:
        p = capped_degree(degree, len(cp), "degree", ctx)
        return InputError.call("weights", NurbsCurve, cp, p, K.clamped_uniform_knots(len(cp), p), w)
    kn = np.asarray(knots, dtype=np.float64)
    try:
        K.validate_curve(cp, degree, kn, None)
    except ValueError as exc:
        msg = str(exc)
        port = (
            "knots"
            if msg.startswith("knot")
            else "degree"
            if msg.startswith("degree")
            else "points"
        )
        raise InputError(port, msg) from None
    return InputError.call("weights", NurbsCurve, cp, degree, kn, w)


@node("nurbs.circle", version=1)
def circle(
    radius: float = 1.0,
    center: Vec3 = (0.0, 0.0, 0.0),
    normal: Vec3 = (0.0, 0.0, 1.0),
) -> NurbsCurve:
    """An exact circle: the rational quadratic with 9 control points, parameter on [0, 1].

    It starts on the plane's x axis and runs counter-clockwise around the normal; for the
    default normal +z that is +x, then +y. (The plane's x axis follows the DXF arbitrary
    axis rule, so exported circles agree.)

    Parameters
    ----------
    radius : float
        Radius (> 0).
    center : Vec3
        Centre.
    normal : Vec3
        Normal of the circle's plane (non-zero).
    """
    return curve_of(InputError.call("radius", K.circle, radius, center, _nonzero(normal, "normal")))


@node("nurbs.arc", version=1)
def arc(
    radius: float,
    start: float,
    end: float,
    center: Vec3 = (0.0, 0.0, 0.0),
    normal: Vec3 = (0.0, 0.0, 1.0),
) -> NurbsCurve:
    """An exact circular arc (rational quadratic pieces of at most 90 degrees).

    Angles in degrees, counter-clockwise around the normal from the plane's x axis (+x
    for the default normal); an end below the start runs clockwise.

    Parameters
    ----------
    radius : float
        Radius (> 0).
    start : float
        Start angle in degrees.
    end : float
        End angle in degrees, 0 < |end - start| <= 360.
    center : Vec3
        Centre.
    normal : Vec3
        Normal of the arc's plane.
    """
    if not 0 < abs(end - start) <= 360:
        raise InputError(
            "end",
            f"an arc must sweep more than 0 and at most 360 degrees, got {start:g} to {end:g}",
        )
    return curve_of(
        InputError.call("radius", K.arc, radius, start, end, center, _nonzero(normal, "normal"))
    )


def _nonzero(v: np.ndarray, port: str) -> np.ndarray:
    if not np.any(v):
        raise InputError(port, f"{port} must be a non-zero vector, got [0, 0, 0]")
    return v


@node("nurbs.interpolate", version=1)
def interpolate(
    points: Points,
    degree: Annotated[int, Range(min=1)] = 3,
    closed: bool = False,
    parametrization: Parametrization = Parametrization.chord,
    *,
    ctx: Context,
) -> NurbsCurve:
    """A smooth curve through every point, in order (global interpolation, A9.1).

    Open curves start at the first point and end at the last (parameter 0 and 1); closed
    curves close smoothly, without a corner at the first point. The degree is lowered to
    points - 1 when there are too few points (with a warning).

    Parameters
    ----------
    points : Points
        Points to pass through; consecutive points must differ.
    degree : int
        Degree of the curve.
    closed : bool
        Close the curve smoothly (a repeated last point is ignored).
    parametrization : Parametrization
        Parameter spacing: chord, centripetal or uniform.
    """
    pts = points.xyz
    count = len(pts) - (1 if closed and len(pts) > 1 and np.array_equal(pts[0], pts[-1]) else 0)
    if degree > count - 1 >= 1:
        ctx.warn(f"degree {degree} needs {degree + 1} points, got {count}: using {count - 1}")
    # what the banded solve holds at once (kernels.nurbs.banded_entries)
    width = min(degree, max(count - 1, 1)) + 1
    ctx.guard(K.banded_entries(count, width, 3, closed), "entries of the interpolation system")
    return curve_of(
        InputError.call("points", K.interpolate, pts, degree, closed, parametrization.value)
    )
