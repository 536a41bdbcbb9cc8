"""``geometry.transform``: affine maps of Points, every Curve, every Surface, a Mesh or a list.

NURBS are mapped exactly through their control points (an affine map commutes with the
rational basis, The NURBS Book section 4.4, so the weights are kept); parametric curves and
surfaces stay parametric. :func:`transform_one` is shared with the copy-to-points nodes.
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import node
from formgraph.core.types import SameAs, Vec3
from formgraph.geometry import (
    Geometry,
    Mesh,
    NurbsCurve,
    NurbsSurface,
    ParametricCurve,
    ParametricSurface,
    Points,
    Solid,
)
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.geometry import affine
from formgraph.kernels.mesh import meshops


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
    if isinstance(g, Solid):  # exact: a motion moves it, a scale maps its geometry
        return g.transformed(linear, offset)
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
