"""Field primitives: sphere, box, cylinder, torus, expressions and TPMS sheets.

A :class:`~formgraph.geometry.Field` is a signed distance function, negative inside, kept
as the recipe that built it; nothing is sampled until ``field.mesh`` (or a distance query)
asks.
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Expression, Variables, Vec3
from formgraph.geometry import Field
from formgraph.nodes.field._common import bounds_box, positive


@node("field.sphere", version=1)
def sphere(radius: Annotated[float, Range(min=0)], center: Vec3 = (0.0, 0.0, 0.0)) -> Field:
    """The exact signed distance to a sphere: ``|p - center| - radius``.

    Parameters
    ----------
    radius : float
        Radius, > 0.
    center : Vec3
        Centre.

    Example
    -------
    ``ball: {type: field.sphere, radius: 10}``
    """
    return Field.sphere(positive("radius", radius), center)


@node("field.box", version=1)
def box(
    size: Vec3, center: Vec3 = (0.0, 0.0, 0.0), radius: Annotated[float, Range(min=0)] = 0.0
) -> Field:
    """The exact signed distance to an axis-aligned box, its edges rounded by ``radius``.

    Parameters
    ----------
    size : Vec3
        Side lengths, each > 0 (the outside size, rounding included).
    center : Vec3
        Centre.
    radius : float
        Edge and corner rounding, 0 .. half the smallest side.
    """
    s = np.asarray(size, dtype=np.float64)
    if not (s > 0).all():
        raise InputError("size", f"every side must be > 0, got {s.tolist()}")
    if radius > s.min() / 2:
        raise InputError("radius", f"radius {radius:g} is more than half the smallest side")
    return Field.box(s, center, radius)


@node("field.cylinder", version=1)
def cylinder(
    radius: Annotated[float, Range(min=0)],
    height: Annotated[float, Range(min=0)],
    center: Vec3 = (0.0, 0.0, 0.0),
) -> Field:
    """The exact signed distance to a capped cylinder along z, centred on ``center``.

    Parameters
    ----------
    radius : float
        Radius, > 0.
    height : float
        Length along z, > 0.
    center : Vec3
        Centre.
    """
    return Field.cylinder(positive("radius", radius), positive("height", height), center)


@node("field.torus", version=1)
def torus(
    major: Annotated[float, Range(min=0)],
    minor: Annotated[float, Range(min=0)],
    center: Vec3 = (0.0, 0.0, 0.0),
) -> Field:
    """The exact signed distance to a torus round the z axis.

    Parameters
    ----------
    major : float
        Radius of the centre circle, > 0.
    minor : float
        Radius of the tube, > 0 (above ``major`` the torus has no hole).
    center : Vec3
        Centre.
    """
    return Field.torus(positive("major", major), positive("minor", minor), center)


@node("field.expression", version=1)
def expression(
    value: Annotated[Expression, Variables("x", "y", "z")],
    bounds: list[list[float]] | None = None,
    lipschitz: Annotated[float, Range(min=0)] = 1.0,
    *,
    ctx: Context,
) -> Field:
    """A field from an expression in ``x y z`` (and the graph params), negative inside.

    The mesher discards a cell when the value at its centre is farther from zero than
    ``lipschitz`` times its half-diagonal, so ``lipschitz`` must bound the gradient's length
    (1 for a true distance such as ``sqrt(x*x + y*y + z*z) - 1``); a smaller one is faster
    but may miss thin parts. ``field.mesh`` checks the bound against samples of the field
    and names this node's ``lipschitz`` when they contradict it.

    Parameters
    ----------
    value : Expression
        The field, e.g. ``"sqrt(x**2 + y**2) - 2 - 0.5 * sin(z)"``.
    bounds : list[list[float]] | None
        ``[[x0, y0, z0], [x1, y1, z1]]``, a box outside which the value is positive (so
        ``field.mesh`` needs none); none: unbounded.
    lipschitz : float
        A bound on the gradient's length, > 0.
    """
    box = bounds_box("bounds", bounds) if bounds is not None else None
    return Field.expression(value, box, positive("lipschitz", lipschitz), made_by=ctx.node)


class TPMSKind(str, Enum):
    """Which triply periodic minimal surface."""

    gyroid = "gyroid"  # sin x cos y + sin y cos z + sin z cos x
    schwarz_p = "schwarz_p"  # cos x + cos y + cos z
    diamond = "diamond"  # Schwarz D


@node("field.tpms", version=1)
def tpms(
    kind: TPMSKind = TPMSKind.gyroid,
    period: Annotated[float, Range(min=0)] = 10.0,
    thickness: Annotated[float, Range(min=0)] = 1.0,
) -> Field:
    """A triply periodic minimal surface thickened into a sheet: lattice infill.

    The surface's implicit function divided by its gradient's length is a distance to
    first order, so the sheet ``|f| / |grad f| - thickness / 2`` has an even wall of
    ``thickness`` in model units. Unbounded: intersect it with a solid (``field.intersection``)
    or give ``field.mesh`` bounds.

    Parameters
    ----------
    kind : TPMSKind
        ``gyroid`` (sin x cos y + sin y cos z + sin z cos x), ``schwarz_p`` (cos x + cos y +
        cos z) or ``diamond`` (Schwarz D).
    period : float
        The length of one unit cell, > 0.
    thickness : float
        The full wall thickness, > 0 (below half the period).

    Example
    -------
    ``infill: {type: field.tpms, kind: gyroid, period: 8, thickness: 0.8}``
    """
    positive("period", period)
    positive("thickness", thickness)
    if thickness >= period / 2:
        raise InputError("thickness", f"thickness {thickness:g} must be below half the period")
    return Field.tpms(TPMSKind(kind).value, period, thickness)
