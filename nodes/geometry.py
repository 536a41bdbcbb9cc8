"""Geometry of any type: affine transforms, copies on points, and points sampled on surfaces.

``geometry.transform`` moves Points, every Curve, every Surface, a Mesh or a list of them
and gives back the same type: NURBS are mapped exactly through their control points (an
affine map commutes with the rational basis, The NURBS Book section 4.4, so the weights are
kept), parametric curves and surfaces stay parametric. The copy-to-points nodes build every
copy in one array operation (:mod:`formgraph.kernels.geometry.instancing`).
"""

from __future__ import annotations

from typing import Annotated, Any, NamedTuple

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import PerElement, SameAs, Vec3
from formgraph.geometry import (
    Curve,
    Geometry,
    Mesh,
    NurbsCurve,
    NurbsSurface,
    ParametricCurve,
    ParametricSurface,
    Points,
    Surface,
)
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.geometry import affine, instancing
from formgraph.kernels.mesh import meshops
from formgraph.language.elements import ElementValue, element_env


class _Shared:
    """The three coordinate callables of a parametric shape, evaluated once per input
    array and mapped: each transformed component reads the same result."""

    def __init__(self, fs: tuple[Any, Any, Any], linear: np.ndarray, offset: np.ndarray):
        self.fs, self.linear, self.offset = fs, linear, offset
        self._last: tuple[Any, np.ndarray] | None = None

    def __call__(self, **variables: Any) -> np.ndarray:
        args = tuple(variables.values())
        last = self._last
        if (
            last is not None
            and len(last[0]) == len(args)
            and all(a is b for a, b in zip(last[0], args, strict=True))
        ):
            return last[1]
        shape = np.broadcast_shapes(*(np.shape(a) for a in args))
        xyz = np.stack(
            [np.broadcast_to(np.asarray(f(**variables), np.float64), shape) for f in self.fs],
            axis=-1,
        )
        out = xyz @ self.linear.T + self.offset
        self._last = (args, out)  # holding the inputs keeps their ids from being reused
        return out


class _Component:
    """One coordinate of a transformed parametric shape, a callable like a bound expression.

    Its ``text`` is the component written as an expression of the original ones, and its
    ``params`` the originals' params, so its content hash is exact (cache keys, cutoff).
    """

    def __init__(self, shared: _Shared, row: int):
        self.shared, self.row = shared, row
        a, b = shared.linear[row], shared.offset[row]
        texts = [getattr(f, "text", "?") for f in shared.fs]
        terms = [f"{float(a[i])!r} * ({texts[i]})" for i in range(3) if a[i] != 0]
        self.text = " + ".join(terms + [repr(float(b))]) if terms else repr(float(b))
        params: dict[str, Any] = {}
        for f in shared.fs:
            params.update(getattr(f, "params", None) or {})
        self.params = params

    def __call__(self, **variables: Any) -> np.ndarray:
        return self.shared(**variables)[..., self.row]


def _mapped(fs: tuple[Any, Any, Any], linear: np.ndarray, offset: np.ndarray) -> list[Any]:
    shared = _Shared(fs, linear, offset)
    return [_Component(shared, i) for i in range(3)]


def transform_one(g: Geometry, linear: np.ndarray, offset: np.ndarray) -> Geometry:
    """``g`` under ``p -> linear @ p + offset``, the same type as ``g``.

    Raises
    ------
    ValueError
        For a geometry type it does not know.
    """
    if isinstance(g, Points):
        return Points(affine.apply(g.xyz, linear, offset), carry.turn(g.point_data, linear))
    if isinstance(g, NurbsCurve):
        w = g.weights if g.rational else None
        return NurbsCurve(affine.apply(g.control_points, linear, offset), g.degree, g.knots, w)
    if isinstance(g, NurbsSurface):
        w = g.weights if g.rational else None
        cp = affine.apply(g.control_points, linear, offset)
        return NurbsSurface(cp, g.degree_u, g.degree_v, g.knots_u, g.knots_v, w)
    if isinstance(g, ParametricCurve):
        fx, fy, fz = _mapped((g.fx, g.fy, g.fz), linear, offset)
        return ParametricCurve(fx, fy, fz, g.domain, g.samples)
    if isinstance(g, ParametricSurface):
        fx, fy, fz = _mapped((g.fx, g.fy, g.fz), linear, offset)
        return ParametricSurface(fx, fy, fz, g.domain_u, g.domain_v)
    if isinstance(g, Mesh):
        fi = g.face_indices
        if np.linalg.det(linear) < 0:
            fi = meshops.reverse_faces(fi, g.face_offsets)
        return Mesh(
            affine.apply(g.vertices, linear, offset),
            fi,
            g.face_offsets,
            carry.turn(g.point_data, linear),
            carry.turn(g.face_data, linear),
        )
    raise ValueError(f"cannot transform a {type(g).__name__}")


def _map(scale: Any, rotate: Any, translate: Any, center: Any) -> tuple[np.ndarray, np.ndarray]:
    s = np.asarray(scale, dtype=np.float64)
    try:
        linear = affine.frames(1, s.reshape(1, 3) if s.ndim else s, np.reshape(rotate, (1, 3)))[0]
    except ValueError as exc:
        raise InputError("scale", str(exc)) from None
    return affine.about_center(linear, center, translate)


@node("geometry.transform", version=1)
def transform(
    geometry: Geometry | list[Geometry],
    translate: Vec3 = (0.0, 0.0, 0.0),
    rotate: Vec3 = (0.0, 0.0, 0.0),
    scale: float | Vec3 = 1.0,
    center: Vec3 = (0.0, 0.0, 0.0),
) -> Annotated[Geometry | list[Geometry], SameAs("geometry")]:
    """Scale, then rotate, then translate any geometry (or list); the same type comes out.

    The map is ``p -> R S (p - center) + center + translate`` with ``R`` the rotation about
    the fixed x, then y, then z axes (degrees), as ``mesh.transform``. NURBS curves and
    surfaces are exact: their control points move and their weights are kept (an affine map
    of a NURBS is the NURBS of the mapped control points, The NURBS Book 4.4). Parametric
    curves and surfaces stay parametric. A mirroring scale reverses mesh faces so they keep
    facing outward.

    Parameters
    ----------
    geometry : Geometry | list[Geometry]
        Points, a curve, a surface, a mesh, or a list of them.
    translate : Vec3
        Offset added last.
    rotate : Vec3
        Degrees about the fixed x, y and z axes, applied in that order.
    scale : float | Vec3
        One factor or [sx, sy, sz]; none may be 0.
    center : Vec3
        The fixed point of the scale and the rotation.

    Example
    -------
    ``tilted: {type: geometry.transform, geometry: "@ring", rotate: [30, 0, 0]}``
    """
    linear, offset = _map(scale, rotate, translate, center)
    items = geometry if isinstance(geometry, list) else [geometry]
    out = [transform_one(g, linear, offset) for g in items]
    return out if isinstance(geometry, list) else out[0]


def _per_point(points: Points, **inputs: Any) -> dict[str, Any]:
    """The inputs written as per-element expressions, evaluated over every point at once."""
    out = dict(inputs)
    env = None
    for port, value in inputs.items():
        if isinstance(value, ElementValue):
            env = element_env(points, "point", value.names) if env is None else env
            try:
                out[port] = value.evaluate(env, len(points), "points")
            except ValueError as exc:
                raise InputError(port, str(exc)) from None
            a = out[port]
            vector = a.ndim == 2 and a.shape[1] == 3
            if not vector and (port != "scale" or a.ndim != 1):
                want = "[x, y, z]" if port == "align" else "[rx, ry, rz]"
                example = '"=normal"' if port == "align" else '[0, 0, "=360 * rand(i)"]'
                if port == "scale":
                    want, example = "one factor or [sx, sy, sz]", '"=0.5 + rand(i)"'
                got = a.shape[1] if a.ndim == 2 else 1
                raise InputError(
                    port,
                    f"{value.text} gives {got} number(s) per point; {port} needs {want} per "
                    f"point, e.g. {example}",
                )
    return out


def _frames(n: int, scale: Any, rotate: Any, align: Any) -> np.ndarray:
    try:
        return affine.frames(
            n,
            scale,
            np.asarray(rotate, np.float64).reshape(-1, 3),
            None if align is None else np.asarray(align, np.float64).reshape(-1, 3),
        )
    except ValueError as exc:
        msg = str(exc)
        raise InputError(next((p for p in ("rotate", "align") if p in msg), "scale"), msg) from None


Scale = Annotated[float | list[float] | list[Vec3], PerElement("points")]
Rotate = Annotated[Vec3 | list[Vec3], PerElement("points")]
Align = Annotated[Vec3 | list[Vec3] | None, PerElement("points")]


@node("mesh.copy_to_points", version=1)
def mesh_copy_to_points(
    mesh: Mesh,
    points: Points,
    scale: Scale = 1.0,
    rotate: Rotate = (0.0, 0.0, 0.0),
    align: Align = None,
    *,
    ctx: Context,
) -> Mesh:
    """A copy of the mesh on every point, all copies in one mesh (one array operation).

    Copy k is the mesh scaled, rotated (degrees about x, y, z), turned so its +z points
    along ``align[k]`` (the minimal rotation, Rodrigues' formula), then moved to point k.
    The mesh's origin lands on the point. Copies follow the points' order; a mirroring
    scale reverses that copy's faces.

    ``scale``, ``rotate`` and ``align`` may be expressions evaluated per point, over the
    point's ``x y z``, ``i``, ``count``, its attributes and the params:
    ``scale: "=0.5 + rand(i)"``, ``rotate: [0, 0, "=360 * rand(i, 1)"]``, ``align: "=normal"``.
    Attributes: each copy keeps the part's (a ``normal`` turned with the copy), the point's
    attributes go onto its copy's vertices, and a ``copy`` point attribute holds each
    vertex's copy index.

    Parameters
    ----------
    mesh : Mesh
        The part to copy, modelled about its origin.
    points : Points
        Where the copies go.
    scale : float | list[float] | list[Vec3]
        One factor for all copies, one factor per point, or rows [sx, sy, sz] (one row
        for all, e.g. [[1, 1, 2]], or one per point).
    rotate : Vec3 | list[Vec3]
        Degrees about x, y, z: one [rx, ry, rz] for all, or one per point.
    align : Vec3 | list[Vec3] | None
        A direction for each copy's +z (e.g. surface normals), one or one per point; None
        keeps the orientation.

    Example
    -------
    ``windows: {type: mesh.copy_to_points, mesh: "@frame", points: "@grid.points",
    align: "@grid.normals"}``
    """
    n = len(points)
    ctx.guard(n * mesh.n_faces, "faces")
    ctx.guard(n * mesh.n_vertices * 3, "coordinates")
    per = _per_point(points, scale=scale, rotate=rotate, align=align)
    linear = _frames(n, per["scale"], per["rotate"], per["align"])
    mirrored = np.linalg.det(linear) < 0
    rev = meshops.reverse_faces(mesh.face_indices, mesh.face_offsets) if mirrored.any() else None
    v, fi, fo = instancing.copy_mesh(
        mesh.vertices, mesh.face_indices, mesh.face_offsets, linear, points.xyz, rev
    )
    if not np.isfinite(v).all():
        raise InputError("points", "the copies' coordinates overflow (not finite)")
    # the part's attributes on every copy (a normal turned with it), the point's
    # attributes on its copy's vertices, and ``copy``: the index of each vertex's copy
    m, f = mesh.n_vertices, mesh.n_faces
    which_v = np.repeat(np.arange(n), m)
    tile_v = carry.copy(np.tile(np.arange(m), n))
    point_data = carry.turn(carry.carried(mesh, point=tile_v)["point_data"], linear, which_v)
    point_data.update(carry.carried(points, point=carry.copy(which_v))["point_data"])
    point_data["copy"] = which_v.astype(np.float64)
    tile_f = carry.copy(np.tile(np.arange(f), n))
    face_data = carry.turn(
        carry.carried(mesh, face=tile_f)["face_data"], linear, np.repeat(np.arange(n), f)
    )
    return Mesh.trusted(v, fi, fo, point_data, face_data)


@node("curves.copy_to_points", version=1)
def curves_copy_to_points(
    curve: Curve,
    points: Points,
    scale: Scale = 1.0,
    rotate: Rotate = (0.0, 0.0, 0.0),
    align: Align = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """A copy of the curve on every point, as a list (NURBS copies stay exact).

    The copies are placed as by ``mesh.copy_to_points``: scale, rotate (degrees about x, y,
    z), turn +z along ``align``, move the origin to the point; each of the three may be a
    per-point expression (``scale: "=1 + 0.5 * noise(x, y)"``). A NURBS curve's control
    points for every copy are one array operation; weights are kept.

    Parameters
    ----------
    curve : Curve
        The curve to copy, modelled about its origin.
    points : Points
        Where the copies go.
    scale : float | list[float] | list[Vec3]
        One factor for all, one per point, or rows [sx, sy, sz].
    rotate : Vec3 | list[Vec3]
        Degrees about x, y, z: one for all, or one per point.
    align : Vec3 | list[Vec3] | None
        A direction for each copy's +z, one or one per point; None keeps the orientation.
    """
    n = len(points)
    per = _per_point(points, scale=scale, rotate=rotate, align=align)
    linear = _frames(n, per["scale"], per["rotate"], per["align"])
    offsets = points.xyz
    if isinstance(curve, NurbsCurve):
        ctx.guard(n * len(curve.control_points) * 3, "coordinates")
        cps = instancing.copy_points(curve.control_points, linear, offsets)
        w = curve.weights if curve.rational else None
        return [NurbsCurve(cp, curve.degree, curve.knots, w) for cp in cps]
    ctx.guard(n, "curves")
    return [transform_one(curve, linear[k], offsets[k]) for k in range(n)]


class Samples(NamedTuple):
    points: Points
    normals: list[Vec3]


@node("geometry.sample_surface", version=2)
def sample_surface(
    surface: Surface,
    u: Annotated[int, Range(min=1)] = 8,
    v: Annotated[int, Range(min=1)] = 8,
    *,
    ctx: Context,
) -> Samples:
    """Points at the centres of a u x v grid of cells over a surface, with unit normals.

    Cell (i, j) is centred at parameters ``u0 + (i + 1/2) (u1 - u0) / u`` and likewise in
    v; points run along v first (row i holds v points). The points carry ``normal``,
    ``u`` and ``v`` point attributes (so ``align: "=normal"`` works). Normals are ``S_u x S_v``
    normalized: exact derivatives on a NURBS surface (The NURBS Book A3.6) and on a
    parametric one (its expressions differentiated; central differences only for noise).

    Parameters
    ----------
    surface : Surface
        Any surface.
    u : int
        Cells along u.
    v : int
        Cells along v.
    """
    ctx.guard(u * v, "points")
    (u0, u1), (v0, v1) = surface.domain_u, surface.domain_v
    uu = u0 + (np.arange(u) + 0.5) * (u1 - u0) / u
    vv = v0 + (np.arange(v) + 0.5) * (v1 - v0) / v
    gu, gv = (a.reshape(-1) for a in np.meshgrid(uu, vv, indexing="ij"))
    xyz = np.asarray(surface.evaluate(gu, gv), dtype=np.float64).reshape(-1, 3)
    normals = np.asarray(surface.normals(gu, gv), dtype=np.float64).reshape(-1, 3)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    if (length <= 1e-300).any():
        ctx.warn("the surface is degenerate at some samples; their normal is +z")
    normals = np.where(length > 1e-300, normals / np.where(length > 0, length, 1), [0, 0, 1.0])
    # the points carry their normal and their surface parameters as attributes too
    return Samples(Points(xyz, {"normal": normals, "u": gu, "v": gv}), normals)
