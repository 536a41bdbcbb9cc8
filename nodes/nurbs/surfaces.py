"""Exact NURBS surfaces: from a control net, loft, extrusion, revolution and sweep, and
their tessellation into meshes.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Vec3
from formgraph.geometry import (
    Curve,
    Mesh,
    NurbsCurve,
    NurbsSurface,
    ParametricCurve,
    Points,
    Surface,
)
from formgraph.kernels import nurbs as K
from formgraph.nodes.nurbs._common import (
    as_nurbs,
    capped_degree,
    surface_of,
)


@node("nurbs.surface", version=1)
def surface(
    points: list[Points],
    degree_u: Annotated[int, Range(min=1)] = 3,
    degree_v: Annotated[int, Range(min=1)] = 3,
    knots_u: list[float] | None = None,
    knots_v: list[float] | None = None,
    weights: list[float] | list[list[float]] | None = None,
    *,
    ctx: Context,
) -> NurbsSurface:
    """A NURBS surface from a grid of control points: row i, point j is control point
    (i, j); u runs across the rows, v along each row.

    Without knots, a direction gets clamped uniform knots on [0, 1] (the surface's
    corners are the grid's corners), and its degree is lowered to the count - 1 when the
    grid is too small (with a warning).

    Parameters
    ----------
    points : list[Points]
        Rows of control points, all of the same length (at least 2 x 2).
    degree_u : int
        Degree across the rows.
    degree_v : int
        Degree along the rows.
    knots_u : list[float] | None
        Knot vector across the rows (rows + degree_u + 1 values).
    knots_v : list[float] | None
        Knot vector along the rows (row length + degree_v + 1 values).
    weights : list[float] | list[list[float]] | None
        One positive weight per control point: a grid shaped like ``points`` (a list of
        rows), or flat, row after row (rows x row length values).
    """
    sizes = [len(r) for r in points]
    if len(sizes) < 2:
        raise InputError("points", f"a surface needs at least 2 rows of points, got {len(sizes)}")
    for i, n in enumerate(sizes):
        if n != sizes[0]:
            raise InputError(
                "points",
                f"every row needs the same number of points: row 0 has {sizes[0]}, row {i} has {n}",
            )
    net = np.stack([r.xyz for r in points])
    nu, nv = net.shape[:2]
    ctx.guard(nu * nv, "control points")
    w = None if weights is None else _surface_weights(weights, nu, nv)
    ku = _surface_knots(knots_u, degree_u, nu, "u", ctx)
    kv = _surface_knots(knots_v, degree_v, nv, "v", ctx)
    return InputError.call("weights", NurbsSurface, net, ku[1], kv[1], ku[0], kv[0], w)


def _surface_weights(weights: list, nu: int, nv: int) -> np.ndarray:
    """Weights given as rows (shaped like the points) or flat, as an (nu, nv) array."""
    if weights and all(isinstance(r, list) for r in weights):
        sizes = [len(r) for r in weights]
        if len(sizes) != nu or any(n != nv for n in sizes):
            got = f"{len(sizes)} rows of " + (
                f"{sizes[0]}" if len(set(sizes)) == 1 else "/".join(map(str, sizes))
            )
            raise InputError(
                "weights",
                f"a grid of weights must be shaped like the points, {nu} rows of {nv}; got {got}",
            )
        return np.asarray(weights, dtype=np.float64)
    if len(weights) != nu * nv:
        raise InputError(
            "weights",
            f"one weight per control point is needed: {nu} x {nv} = {nu * nv}, got {len(weights)}",
        )
    return np.asarray(weights, dtype=np.float64).reshape(nu, nv)


def _surface_knots(
    knots: list[float] | None, degree: int, n: int, side: str, ctx: Context
) -> tuple[np.ndarray, int]:
    if knots is None:
        p = capped_degree(degree, n, f"degree_{side}", ctx)
        return K.clamped_uniform_knots(n, p), p
    kn = np.asarray(knots, dtype=np.float64)
    port = f"knots_{side}"
    try:
        K.validate_curve(np.zeros((n, 3)), degree, kn, None)
    except ValueError as exc:
        raise InputError(port, str(exc)) from None
    return kn, degree


@node("nurbs.loft", version=1)
def loft(
    curves: list[Curve],
    degree_v: Annotated[int, Range(min=1)] = 3,
    closed: bool = False,
    *,
    ctx: Context,
) -> NurbsSurface:
    """A surface through every curve, in order (skinning, The NURBS Book 10.3).

    The curves may differ in degree, knots, number of control points and rationality:
    they are made compatible first (shapes unchanged), then joined smoothly across. u
    runs along the curves (on [0, 1]), v across them. Curves that are not NURBS (e.g.
    parametric ones) enter as the cubic through their sample points.

    Parameters
    ----------
    curves : list[Curve]
        At least 2 curves (3 when closed), each running the same way.
    degree_v : int
        Degree across the curves, lowered to the number of curves - 1 (2 curves give a
        ruled surface).
    closed : bool
        Join the last curve smoothly back to the first.
    """
    tuples = [as_nurbs(c, "curves", ctx) for c in curves]
    ctx.guard(sum(len(t[0]) for t in tuples) * len(tuples), "control points")
    return surface_of(InputError.call("curves", K.loft, tuples, degree_v, closed))


@node("nurbs.extrude", version=1)
def extrude(curve: Curve, direction: Vec3 = (0.0, 0.0, 1.0), *, ctx: Context) -> NurbsSurface:
    """The curve moved along a straight direction, as a ruled surface (u along the curve,
    v from 0 at the curve to 1 at the moved copy).

    Parameters
    ----------
    curve : Curve
        The profile.
    direction : Vec3
        Direction and length of the extrusion.
    """
    return surface_of(
        InputError.call("direction", K.extrude, as_nurbs(curve, "curve", ctx), direction)
    )


@node("nurbs.revolve", version=1)
def revolve(
    curve: Curve,
    axis_point: Vec3 = (0.0, 0.0, 0.0),
    axis: Vec3 = (0.0, 0.0, 1.0),
    angle: float = 360.0,
    *,
    ctx: Context,
) -> NurbsSurface:
    """The exact surface of revolution of a profile curve about an axis (A8.1).

    u runs along the profile, v around the axis, counter-clockwise about it (right-hand
    rule; a negative angle turns the other way). Every profile point keeps its distance
    from the axis exactly. With u up the profile and v counter-clockwise, the surface
    normal (u x v) faces the axis: draw the profile downwards to face out.

    Parameters
    ----------
    curve : Curve
        The profile, typically in a plane through the axis.
    axis_point : Vec3
        A point on the axis.
    axis : Vec3
        Direction of the axis.
    angle : float
        Sweep angle in degrees, 0 < |angle| <= 360.
    """
    if not 0 < abs(angle) <= 360:
        raise InputError(
            "angle", f"angle must be more than 0 and at most 360 degrees, got {angle:g}"
        )
    prof = as_nurbs(curve, "curve", ctx)
    return surface_of(InputError.call("axis", K.revolve, prof, axis_point, axis, angle))


@node("nurbs.sweep", version=1)
def sweep(
    profile: Curve,
    path: Curve,
    stations: Annotated[int, Range(min=0)] = 0,
    *,
    ctx: Context,
) -> NurbsSurface:
    """A profile swept along a path, kept in rotation-minimizing frames (no flips or
    twists on helices and S-bends).

    The profile's XY plane is placed normal to the path at each station: its x axis along
    the frame's normal, its origin on the path (so draw it around [0, 0]). The placed
    copies are joined smoothly; a closed path gives a closed surface whose frames meet up.
    u runs along the profile, v along the path.

    Parameters
    ----------
    profile : Curve
        The cross-section, in its XY plane.
    path : Curve
        The path (any curve: NURBS, parametric, ...).
    stations : int
        Number of stations along the path; 0 picks them: a parametric path's samples, or
        16 per span of a NURBS path (between 32 and 1024).
    """
    if stations == 1:
        raise InputError("stations", "a sweep needs at least 2 stations (or 0 for automatic)")
    m = stations or _auto_stations(path)
    prof = as_nurbs(profile, "profile", ctx)
    ctx.guard(m * len(prof[0]), "control points")
    t0, t1 = path.domain
    t = np.linspace(t0, t1, m)
    pts = np.asarray(path.evaluate(t))
    tangents = np.asarray(path.derivative(t))
    # a cusp (zero derivative) takes the direction of the neighbouring chords instead
    length = np.linalg.norm(tangents, axis=1)
    weak = length <= 1e-12 * max(1.0, float(np.abs(pts).max()))
    if np.any(weak):
        chords = np.gradient(pts, axis=0)
        tangents = np.where(weak[:, None], chords, tangents)
    return surface_of(InputError.call("path", K.sweep, prof, pts, tangents))


def _auto_stations(path: Curve) -> int:
    if isinstance(path, ParametricCurve):
        return max(2, path.samples)
    if isinstance(path, NurbsCurve):
        spans = len(np.unique(path.knots[path.degree : len(path.control_points) + 1])) - 1
        return int(np.clip(16 * spans, 32, 1024))
    return 256


@node("nurbs.tessellate", version=3)
def tessellate(
    surface: Surface,
    u: Annotated[int, Range(min=1)] = 32,
    v: Annotated[int, Range(min=1)] = 32,
    *,
    ctx: Context,
) -> Mesh:
    """A quad mesh of the surface: u x v faces over its whole domain, evenly spaced in the
    parameters; seams of closed surfaces are joined (no duplicate vertices there).

    A row of the grid that sits at one point (a pole: a revolve whose profile ends on the
    axis, a sphere's tip) becomes one vertex, its quads triangles: no zero-area faces, and
    a revolve to the axis comes out closed there. Each vertex carries its surface
    parameters as the ``u`` and ``v`` point attributes.

    Parameters
    ----------
    surface : Surface
        Any surface (NURBS, parametric, ...).
    u : int
        Number of faces along u.
    v : int
        Number of faces along v.
    """
    ctx.guard((u + 1) * (v + 1), "vertices")
    return surface.tessellate(u, v, with_uv=True)
