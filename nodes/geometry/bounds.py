"""``geometry.bounds`` and ``geometry.fit``: the box of any geometry, and geometry scaled and
moved into a box (:mod:`formgraph.kernels.geometry.bounds`)."""

from __future__ import annotations

import math
from typing import Annotated, Any, NamedTuple

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import node
from formgraph.core.types import SameAs, Vec3
from formgraph.geometry import (
    Curve,
    Field,
    Geometry,
    Mesh,
    NurbsCurve,
    NurbsSurface,
    Points,
    Solid,
    Surface,
)
from formgraph.kernels import nurbs
from formgraph.kernels.geometry import bounds as kbounds
from formgraph.nodes.geometry.transform import transform_one

_RELATIVE = 1e-10  # how far inside the true box an extremum may be, relative to the size


def _homogeneous(cp: np.ndarray, w: np.ndarray | None) -> np.ndarray:
    return nurbs.homogeneous(cp, np.ones(cp.shape[:-1]) if w is None else w)


def _box_of(g: Geometry) -> np.ndarray | None:
    """(2, 3) lowest and highest corner of one geometry, or None when it has no points."""
    if isinstance(g, Points):
        p = g.xyz
    elif isinstance(g, Mesh):
        p = g.vertices
    elif isinstance(g, NurbsCurve):
        cp = g.control_points
        if g.degree == 1:  # a polyline: its points are its extremes
            return np.stack([cp.min(axis=0), cp.max(axis=0)])
        w = g.weights if g.rational else None
        seg, sw = nurbs.decompose_bezier(cp, g.degree, g.knots, w)
        return _exact(_homogeneous(seg, sw), cp)
    elif isinstance(g, NurbsSurface):
        cp = g.control_points
        w = g.weights if g.rational else None
        patches, pw = nurbs.decompose_bezier_surface(
            cp, g.degree_u, g.degree_v, g.knots_u, g.knots_v, w
        )
        return _exact(_homogeneous(patches, pw), cp.reshape(-1, 3))
    elif isinstance(g, Curve):
        t0, t1 = g.domain
        n = max(1025, 4 * getattr(g, "samples", 256) + 1)
        lo, hi = kbounds.sampled_extremes(
            lambda t: np.asarray(g.evaluate(t[:, 0])), np.array([t0]), np.array([t1]), (n,)
        )
        return np.stack([lo, hi])
    elif isinstance(g, Surface):
        (u0, u1), (v0, v1) = g.domain_u, g.domain_v
        lo, hi = kbounds.sampled_extremes(
            lambda t: np.asarray(g.evaluate(t[:, 0], t[:, 1])),
            np.array([u0, v0]),
            np.array([u1, v1]),
            (129, 129),
        )
        return np.stack([lo, hi])
    elif isinstance(g, Solid):  # from its surfaces (OCC's optimal box)
        return None if g.is_empty else np.array(g.bounds)
    elif isinstance(g, Field):
        raise InputError(
            "geometry",
            "a Field has no exact extent (it is a distance function, known only where it is "
            "sampled): mesh it with field.mesh first and take the bounds of the mesh",
        )
    else:
        raise InputError("geometry", f"cannot bound a {type(g).__name__}")
    if len(p) == 0:
        return None
    return np.stack([p.min(axis=0), p.max(axis=0)])


def _exact(hom: np.ndarray, cp: np.ndarray) -> np.ndarray:
    size = float(np.ptp(cp, axis=0).max())
    eps = _RELATIVE * size if size > 0 else 1e-300
    lo, hi = kbounds.bezier_extremes(hom, eps)
    return np.stack([lo, hi])


def box(geometry: Geometry | list[Geometry]) -> np.ndarray:
    """(2, 3) the box of one geometry or of a list, all together.

    Raises
    ------
    InputError
        On ``geometry``: nothing to bound (an empty list, or only empty geometry).
    """
    items = geometry if isinstance(geometry, list) else [geometry]
    if not items:
        raise InputError("geometry", "the list is empty: there is nothing to bound")
    boxes = [b for b in (_box_of(g) for g in items) if b is not None]
    if not boxes:
        raise InputError("geometry", "the geometry has no points: there is nothing to bound")
    stacked = np.stack(boxes)
    return np.stack([stacked[:, 0].min(axis=0), stacked[:, 1].max(axis=0)])


class Bounds(NamedTuple):
    min: Vec3
    max: Vec3
    size: Vec3
    center: Vec3


@node("geometry.bounds", version=1)
def bounds(geometry: Geometry | list[Geometry]) -> Bounds:
    """The axis-aligned box of any geometry, or of a list of geometries together.

    Outputs ``min``, ``max`` (its lowest and highest corner), ``size`` and ``center``.
    Points and meshes are bounded by their vertices. NURBS curves and surfaces are bounded
    by the curve or surface itself, not by their control points (which stick out: a
    circle turned 45 degrees by 41 %): each is split into its Bezier pieces and the extremes of each
    coordinate found by branch and bound over them (a piece's control points bound it,
    its corners lie on it; the pieces that could still hold an extreme are halved until
    none can), to 1e-10 of the size. Curves and surfaces given by expressions are sampled
    on a dense grid and refined around each extreme. Text is curves: its box is that of
    its outlines.

    Parameters
    ----------
    geometry : Geometry | list[Geometry]
        Points, curves, surfaces, meshes, or a list of them.

    Example
    -------
    ``box: {type: geometry.bounds, geometry: "@label"}`` then ``"@box.size"``
    """
    lo, hi = box(geometry)
    return Bounds(
        min=[float(x) for x in lo],  # type: ignore[arg-type]
        max=[float(x) for x in hi],  # type: ignore[arg-type]
        size=[float(x) for x in hi - lo],  # type: ignore[arg-type]
        center=[float(x) for x in (lo + hi) / 2],  # type: ignore[arg-type]
    )


def _fit_scale(extent: np.ndarray, size: np.ndarray, keep_aspect: bool) -> np.ndarray:
    """The scale of each axis that fits ``extent`` into ``size`` (0: any)."""
    asked = size > 0
    flat = asked & (extent <= 0)
    usable = asked & ~flat
    if not usable.any():
        what = "it is flat along every axis given a size" if flat.any() else "every size is 0"
        raise InputError(
            "size",
            f"nothing to fit: {what}; give a size > 0 for an axis along which the "
            "geometry has extent",
        )
    ratio = np.where(usable, size / np.where(usable, extent, 1.0), 1.0)
    if keep_aspect:
        return np.full(3, float(ratio[usable].min()))
    return ratio


@node("geometry.fit", version=1)
def fit(
    geometry: Geometry | list[Geometry],
    size: list[float],
    center: Vec3 = (0.0, 0.0, 0.0),
    keep_aspect: bool = True,
) -> Annotated[Geometry | list[Geometry], SameAs("geometry")]:
    """Geometry scaled and moved so its box fits the box ``size`` around ``center``.

    The box is :func:`geometry.bounds`' (of the geometry itself, a list all together). With
    ``keep_aspect`` one scale, the largest that fits every axis given a size; otherwise each
    axis given a size is scaled to it exactly and the others are left as they are. A size of
    0 means any (no limit on that axis); an axis along which the geometry is flat (text in
    the XY plane, given a z size) cannot be scaled and is not constrained. Then the box's
    centre goes to ``center``. The same type comes out (NURBS stay exact; see
    ``geometry.transform``).

    Parameters
    ----------
    geometry : Geometry | list[Geometry]
        What to fit: points, curves, surfaces, meshes, or a list of them (fitted together).
    size : list[float]
        The box: [width, height] or [width, height, depth]; 0 for any.
    center : Vec3
        Where the box's centre goes.
    keep_aspect : bool
        One scale for all axes (the largest that fits), or each axis to its size.

    Example
    -------
    ``label: {type: geometry.fit, geometry: "@text", size: [60, 12], center: [0, 0, 5]}``
    """
    values = [float(x) for x in size]
    if len(values) not in (2, 3):
        raise InputError("size", f"size is [width, height] or [width, height, depth], got {values}")
    for x in values:
        if not math.isfinite(x) or x < 0:
            raise InputError("size", f"a size must be a finite number >= 0 (0: any), got {x:g}")
    target = np.array((values + [0.0])[:3])
    lo, hi = box(geometry)
    extent = hi - lo
    scale = _fit_scale(extent, target, keep_aspect)
    middle = (lo + hi) / 2
    linear = np.diag(scale)
    offset = np.asarray(center, dtype=np.float64) - scale * middle
    items: list[Any] = geometry if isinstance(geometry, list) else [geometry]
    try:
        out = [transform_one(g, linear, offset) for g in items]
    except ValueError as exc:
        raise InputError("geometry", str(exc)) from None
    return out if isinstance(geometry, list) else out[0]
