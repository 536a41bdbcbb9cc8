"""Knot operations that keep the curve: knot insertion (Algorithm A5.1 of The NURBS Book)
and degree elevation.
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import SameAs
from formgraph.geometry import (
    NurbsCurve,
    NurbsSurface,
)
from formgraph.kernels import nurbs as K
from formgraph.nodes.nurbs._common import (
    as_tuple,
    curve_of,
    surface_of,
)


class Direction(str, Enum):
    """A parameter direction of a surface."""

    u = "u"  # across the rows of control points
    v = "v"  # along each row


@node("nurbs.insert_knot", version=2)
def insert_knot(
    curve: NurbsCurve | NurbsSurface,
    t: float,
    times: Annotated[int, Range(min=0)] = 1,
    direction: Direction = Direction.u,
    *,
    ctx: Context,
) -> Annotated[NurbsCurve | NurbsSurface, SameAs("curve")]:
    """The same curve (or surface) with the knot t inserted: one more control point per
    insertion, shape unchanged (Boehm's algorithm, A5.1; on a surface A5.3, in u or v).

    A knot's multiplicity may not exceed the degree. Useful before editing control points
    locally, or to split a curve. Given a surface, the knot goes into its u or v knot
    vector (``direction``), adding a row (u) or a column (v) of control points per
    insertion; the output is a surface then.

    Parameters
    ----------
    curve : NurbsCurve | NurbsSurface
        The curve, or a surface.
    t : float
        Parameter of the new knot, inside the domain (of the chosen direction).
    times : int
        How many times to insert it.
    direction : Direction
        For a surface: u (across the rows of control points) or v (along each row).
    """
    if isinstance(curve, NurbsSurface):
        cp = np.asarray(curve.control_points)
        nu, nv = cp.shape[:2]
        grown = (nu + times) * nv if direction is Direction.u else nu * (nv + times)
        ctx.guard(grown, "control points")
        w = np.asarray(curve.weights) if curve.rational else None
        args = (cp, curve.degree_u, curve.degree_v, curve.knots_u, curve.knots_v, w)
        try:
            return surface_of(K.insert_knot_surface(*args, t, times, direction.value))
        except ValueError as exc:
            raise InputError(_knot_port(exc), str(exc)) from None
    try:
        return curve_of(K.insert_knot(*as_tuple(curve), t, times))
    except ValueError as exc:
        raise InputError(_knot_port(exc), str(exc)) from None


def _knot_port(exc: ValueError) -> str:
    return "times" if "multiplicity" in str(exc) else "t"


@node("nurbs.elevate_degree", version=1)
def elevate_degree(
    curve: NurbsCurve,
    times: Annotated[int, Range(min=0)] = 1,
    *,
    ctx: Context,
) -> NurbsCurve:
    """The same curve with its degree raised by ``times``, shape and continuity unchanged.

    Each distinct knot gains ``times`` in multiplicity, so the control points grow in
    number; a closed (periodic) curve becomes clamped. Used to match degrees before
    lofting, or for exporters that want one degree. The degree is raised in one step
    (A5.9 generalized to any ``times``): a 1,000-point cubic raised by 29 takes a fraction
    of a second; the work (new control points x degree^2) counts against the budget.

    Parameters
    ----------
    curve : NurbsCurve
        The curve.
    times : int
        How many degrees to add.
    """
    if curve.degree + times > 32:
        raise InputError(
            "times", f"degree {curve.degree} + {times} is above 32, the most supported"
        )
    n_new = len(curve.control_points) * (times + 1) + len(np.unique(curve.knots)) * times
    ctx.guard(n_new, "control points")
    q = curve.degree + times
    # each new control point is a blossom of degree q: q^2 / 2 affine steps (one pass)
    ctx.guard(n_new * (q + 1) ** 2 // 2, "blossom steps (new control points x degree^2 / 2)")
    return curve_of(InputError.call("times", K.elevate_degree, *as_tuple(curve), times))
