"""``attr.distance`` and ``attr.transfer``: one geometry asked about another.

The distance from every point of a point set or a mesh to the nearest point of points,
curves, a mesh or a field, with that nearest point; and attributes carried from a source
geometry to the points of another (from the nearest point, or barycentric at the closest
point of a mesh). Both answer from :mod:`formgraph.kernels.geometry.proximity`, whose
closest point on a mesh is the one ``field.from_mesh`` uses.
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import SameAs
from formgraph.geometry import Curve, Field, Mesh, NurbsCurve, Points
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.curves import sampling
from formgraph.kernels.geometry import proximity
from formgraph.kernels.geometry.meshdist import fan_triangles
from formgraph.language.elements import VARIABLES

_TOLERANCE = 1e-5  # curves are sampled within this fraction of their extent by default
CLOSEST = "closest"


def _points_of(geometry: Points | Mesh) -> np.ndarray:
    return np.asarray(geometry.vertices if isinstance(geometry, Mesh) else geometry.xyz)


def _with_points(geometry: Points | Mesh, data: dict[str, Any]) -> Points | Mesh:
    """``geometry`` with point attributes ``data`` added (or replacing same-named ones)."""
    point_data = geometry.point_data
    for name, values in data.items():
        point_data = point_data.with_(name, values)
    if isinstance(geometry, Mesh):
        return geometry.with_data(point_data, geometry.face_data)
    return geometry.with_point_data(point_data)


def check_name(name: str, port: str = "name") -> None:
    """A new attribute's name: an identifier that no per-element variable shadows."""
    if not isinstance(name, str) or not name.isidentifier() or name.startswith("_"):
        raise InputError(port, f"{name!r} is not a name: letters, digits and _, not first _")
    if name in VARIABLES:
        raise InputError(
            port, f"{name!r} is a variable of per-element expressions; choose another name"
        )


def curve_segments(curves: list[Curve], tolerance: float | None, ctx: Context) -> np.ndarray:
    """(m, 2, 3) the segments of polylines within ``tolerance`` of ``curves`` (a degree-1
    NURBS exactly: its own corners); the chords are split at their parameter midpoints
    until each is within the tolerance (``sampling.refine_chords``)."""
    if tolerance is not None and not tolerance > 0:
        raise InputError("tolerance", f"the tolerance must be positive, got {tolerance}")
    lines: list[np.ndarray] = []
    total = 0

    def guard(n: int) -> None:
        ctx.guard(total + n, "curve samples")

    tol = tolerance
    if tol is None:
        boxes = [
            np.asarray(c.control_points) if isinstance(c, NurbsCurve) else c.sample(65)
            for c in curves
        ]
        every = np.concatenate(boxes)
        extent = float(np.ptp(every, axis=0).max()) if len(every) else 0.0
        tol = _TOLERANCE * (extent if extent > 0 else 1.0)
    for c in curves:  # one step per curve; its sampling is vectorized
        if isinstance(c, NurbsCurve) and c.degree == 1:
            p = np.asarray(c.control_points)
        else:
            t0, t1 = c.domain
            if isinstance(c, NurbsCurve):  # each knot span cut in 8 to start
                k = np.unique(np.asarray(c.knots))
                k = k[(k >= t0) & (k <= t1)]
                u = np.unique(np.linspace(k[:-1], k[1:], 9).ravel())
            else:
                u = np.linspace(t0, t1, 65)

            def at(uu: np.ndarray, c: Curve = c) -> np.ndarray:
                return np.asarray(c.evaluate(uu), dtype=np.float64).reshape(-1, 3)

            _, p = sampling.refine_chords(at, u, at(u), tol, guard)
        if len(p) < 2:
            continue
        guard(len(p))
        total += len(p)
        lines.append(np.stack([p[:-1], p[1:]], axis=1))
    return np.concatenate(lines) if lines else np.zeros((0, 2, 3))


@node("attr.distance", version=1)
def distance(
    geometry: Points | Mesh,
    to: Points | Curve | list[Curve] | Mesh | Field,
    name: str = "distance",
    signed: bool = False,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Annotated[Points | Mesh, SameAs("geometry")]:
    """The distance from every point to the nearest point of another geometry.

    Adds the point attributes ``name`` (the Euclidean distance) and ``closest`` (that
    nearest point, a vector), so an expression downstream can read how far each point is
    (``"=distance < 5"``) and where the nearest point is (``"=closest"``). Exact for points
    (a k-d tree), meshes (a bounding-volume hierarchy of the triangles: every triangle that
    could be nearer is looked at) and polylines; other curves are sampled within
    ``tolerance``; a field gives its own value (exact for a primitive or a mesh, a bound
    for a blend) and the point one gradient step away.

    Parameters
    ----------
    geometry : Points | Mesh
        The points that ask (a mesh's vertices).
    to : Points | Curve | list[Curve] | Mesh | Field
        What they ask about.
    name : str
        The distance attribute's name.
    signed : bool
        Negative inside: for a closed mesh (by the angle-weighted pseudonormal of the
        nearest feature) or a field. An open mesh's inside is where its winding number is
        above 1/2 (a warning says so); points and curves have no inside.
    tolerance : float | None
        How far the polyline of a curved curve may stray from it; none: 1e-5 of the
        curves' extent.

    Example
    -------
    ``near: {type: attr.distance, geometry: "@facade", to: "@attractor"}``
    """
    check_name(name)
    if name == CLOSEST:
        raise InputError(
            "name", f"'{CLOSEST}' is the attribute of the nearest point; choose another name"
        )
    q = _points_of(geometry)
    ctx.guard(len(q), "points")
    if signed and isinstance(to, (Points, Curve, list)):
        what = "points" if isinstance(to, Points) else "curves"
        raise InputError(
            "signed",
            f"{what} have no inside, so no signed distance; use signed: false, or ask a "
            "closed mesh or a field",
        )
    if isinstance(to, Field):
        extent = float(np.ptp(q, axis=0).max()) if len(q) else 0.0
        bounds = to.bounds
        if bounds is not None:
            extent = max(extent, float(np.max(bounds[1] - bounds[0])))
        found = proximity.to_field(q, to.evaluate, 1e-6 * (extent if extent > 0 else 1.0))
        if not signed:
            found = proximity.Closest(
                np.abs(found.distance), found.point, found.index, found.weights
            )
    elif isinstance(to, Points):
        if not len(to):
            raise InputError("to", "the point set is empty: there is no nearest point")
        found = proximity.to_points(q, to.xyz)
    elif isinstance(to, Mesh):
        if to.n_faces == 0:
            raise InputError("to", "the mesh has no faces: there is no nearest point")
        tri, _ = fan_triangles(to.face_indices, to.face_offsets)
        found, closed = proximity.to_triangles(q, to.vertices, tri, signed)
        if signed and not closed:
            ctx.warn(
                "to: the mesh is open (an edge is not shared by exactly two faces), so it "
                "has no inside of its own: the sign is by its winding number (inside where "
                "it is above 1/2); close it (mesh.cap) for an exact sign"
            )
    else:
        curves = to if isinstance(to, list) else [to]
        segments = curve_segments(curves, tolerance, ctx)
        if not len(segments):
            raise InputError("to", "there are no curves: there is no nearest point")
        found = proximity.to_segments(q, segments)
    if len(q) and not np.isfinite(found.distance).all():
        raise InputError("to", "the distance is not finite at some points (the field gives NaN)")
    return _with_points(geometry, {name: found.distance, CLOSEST: found.point})


@node("attr.transfer", version=1)
def transfer(
    geometry: Points | Mesh,
    source: Points | Mesh,
    names: str | list[str],
    *,
    ctx: Context,
) -> Annotated[Points | Mesh, SameAs("geometry")]:
    """Point attributes of another geometry carried to each point.

    From a Points source each point takes the values of the nearest source point; from a
    Mesh source, the values at its closest point of the mesh, interpolated from the corners
    of that triangle by barycentric weights (a polygon is fanned from its first corner), so
    an attribute linear over the source stays exactly linear. A same-named attribute of
    ``geometry`` is replaced.

    Parameters
    ----------
    geometry : Points | Mesh
        The points that receive (a mesh's vertices).
    source : Points | Mesh
        The geometry whose point attributes are read.
    names : str | list[str]
        The point attributes of ``source`` to carry.

    Example
    -------
    ``painted: {type: attr.transfer, geometry: "@scan", source: "@painted_proxy",
    names: [color]}``
    """
    wanted = [names] if isinstance(names, str) else list(names)
    if not wanted:
        raise InputError("names", "name at least one point attribute of the source")
    have = sorted(source.point_data)
    for n in wanted:
        if n not in source.point_data:
            listed = ", ".join(have) if have else "none"
            raise InputError(
                "names",
                f"the source has no point attribute {n!r} (its point attributes: {listed})",
            )
    q = _points_of(geometry)
    ctx.guard(len(q), "points")
    if isinstance(source, Mesh):
        if source.n_faces == 0:
            raise InputError("source", "the mesh has no faces to carry attributes from")
        tri, _ = fan_triangles(source.face_indices, source.face_offsets)
        found, _ = proximity.to_triangles(q, source.vertices, tri)
        rule = carry.barycentric(tri[found.index], found.weights)
    else:
        if not len(source):
            raise InputError("source", "the point set is empty: there is no nearest point")
        rule = carry.copy(proximity.to_points(q, source.xyz).index)
    return _with_points(geometry, {n: rule.apply(source.point_data[n]) for n in wanted})
