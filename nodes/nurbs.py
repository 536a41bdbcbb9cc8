"""NURBS nodes: exact curves and surfaces (circles, arcs, interpolation, knot operations,
loft, extrusion, revolution, sweep) and their tessellation.

Each node adapts a kernel of :mod:`formgraph.kernels.nurbs` (The NURBS Book's algorithms,
vectorized); a kernel's ``ValueError`` is reported against the input it is about.
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import SameAs, Vec3
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

CurveTuple = tuple[np.ndarray, int, np.ndarray, "np.ndarray | None"]


class Parametrization(str, Enum):
    """Spacing of the parameters of interpolated points."""

    chord = "chord"  # proportional to the distance between points
    centripetal = "centripetal"  # to its square root: no loops or cusps on uneven data
    uniform = "uniform"  # equal steps


def _tuple(curve: NurbsCurve) -> CurveTuple:
    w = curve.weights if curve.rational else None
    return (np.asarray(curve.control_points), curve.degree, np.asarray(curve.knots), w)


def _curve(t: CurveTuple) -> NurbsCurve:
    return NurbsCurve(*t)


def _surface(s: tuple) -> NurbsSurface:
    return NurbsSurface(*s)


def _as_nurbs(curve: Curve, port: str, ctx: Context) -> CurveTuple:
    """A NURBS curve exactly; any other curve (e.g. a parametric one) as the cubic through
    its sample points (as many as it is drawn with), closed if it closes. The banded
    interpolation (:mod:`~formgraph.kernels.nurbs.banded`) costs O(samples)."""
    if isinstance(curve, NurbsCurve):
        return _tuple(curve)
    samples = curve.samples if isinstance(curve, ParametricCurve) else 256
    closed = bool(curve.closed)
    # What the banded solve holds at once (kernels.nurbs.banded_entries), and the samples.
    n = max(samples, 4)
    entries = K.banded_entries(n, 4, 3, closed) + 8 * n
    ctx.guard(entries, f"entries of the interpolation system of input '{port}'")
    pts = np.asarray(curve.sample(n))
    return InputError.call(port, K.interpolate, pts[:-1] if closed else pts, 3, closed)


def _capped_degree(degree: int, count: int, port: str, ctx: Context) -> int:
    if count < 2:
        raise InputError(port, f"a NURBS curve needs at least 2 control points, got {count}")
    if degree > count - 1:
        ctx.warn(f"degree {degree} needs {degree + 1} points, got {count}: using {count - 1}")
        return count - 1
    return degree


# -------------------------------------------------------------------------------- curves


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
        p = _capped_degree(degree, len(cp), "degree", ctx)
        ctrl, kn, _ = K.periodic_curve(cp, p)
        ww = None if w is None else np.concatenate([w, w[:p]])
        return InputError.call("weights", NurbsCurve, ctrl, p, kn, ww)
    if knots is None:
        p = _capped_degree(degree, len(cp), "degree", ctx)
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
    return _curve(InputError.call("radius", K.circle, radius, center, _nonzero(normal, "normal")))


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
    return _curve(
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
    return _curve(
        InputError.call("points", K.interpolate, pts, degree, closed, parametrization.value)
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
            return _surface(K.insert_knot_surface(*args, t, times, direction.value))
        except ValueError as exc:
            raise InputError(_knot_port(exc), str(exc)) from None
    try:
        return _curve(K.insert_knot(*_tuple(curve), t, times))
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
    return _curve(InputError.call("times", K.elevate_degree, *_tuple(curve), times))


# ------------------------------------------------------------------------------ surfaces


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
        p = _capped_degree(degree, n, f"degree_{side}", ctx)
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
    tuples = [_as_nurbs(c, "curves", ctx) for c in curves]
    ctx.guard(sum(len(t[0]) for t in tuples) * len(tuples), "control points")
    return _surface(InputError.call("curves", K.loft, tuples, degree_v, closed))


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
    return _surface(
        InputError.call("direction", K.extrude, _as_nurbs(curve, "curve", ctx), direction)
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
    prof = _as_nurbs(curve, "curve", ctx)
    return _surface(InputError.call("axis", K.revolve, prof, axis_point, axis, angle))


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
    prof = _as_nurbs(profile, "profile", ctx)
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
    return _surface(InputError.call("path", K.sweep, prof, pts, tangents))


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
