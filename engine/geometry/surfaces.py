"""Surfaces: the protocol, NURBS surfaces and surfaces from expressions."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..kernels.mesh import grid as _grid
from .base import (
    Geometry,
    _expression_fingerprint,
    frozen_array,
    storable,
)
from .mesh import Mesh

__all__ = ["NurbsSurface", "ParametricSurface", "Surface"]


class Surface(Geometry):
    """The surface protocol: ``domain_u``, ``domain_v``, ``evaluate(u, v)``, ``tessellate``."""

    domain_u: tuple[float, float]
    domain_v: tuple[float, float]

    def evaluate(self, u: Any, v: Any) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    def evaluate_grid(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Points at every (u[i], v[j]): ``(len(u), len(v), 3)``."""
        return self.evaluate(u[:, None], v[None, :])

    def tessellate(self, nu: int = 32, nv: int = 32, with_uv: bool = False) -> Mesh:
        """A quad mesh of ``nu x nv`` faces over the whole domain (seams closed up);
        ``with_uv`` adds each vertex's parameters as ``u`` and ``v`` point attributes."""
        if nu < 1 or nv < 1:
            raise ValueError(f"tessellation needs at least 1 x 1 faces, got {nu} x {nv}")
        u = np.linspace(*self.domain_u, nu + 1)
        v = np.linspace(*self.domain_v, nv + 1)
        pts = self.evaluate_grid(u, v)
        closed_u = nu > 1 and bool(np.allclose(pts[0], pts[-1], atol=1e-10 * _scale(pts)))
        closed_v = nv > 1 and bool(np.allclose(pts[:, 0], pts[:, -1], atol=1e-10 * _scale(pts)))
        if closed_u:
            pts = pts[:-1]
        if closed_v:
            pts = pts[:, :-1]
        fi, fo = _grid.grid_faces(pts.shape[0], pts.shape[1], closed_u, closed_v)
        vertices, fi, fo = _grid.collapse_poles(pts, fi, fo)
        if not with_uv:
            return Mesh(vertices, fi, fo)
        from ..kernels.attributes.propagate import by_position

        gu, gv = np.meshgrid(u[: pts.shape[0]], v[: pts.shape[1]], indexing="ij")
        if len(vertices) == pts.shape[0] * pts.shape[1]:
            source = np.arange(len(vertices))  # no pole: the grid's own points, in order
        else:
            source = by_position(pts.reshape(-1, 3), vertices)  # a pole keeps its row's first
        return Mesh(vertices, fi, fo, {"u": gu.reshape(-1)[source], "v": gv.reshape(-1)[source]})

    def to_pyvista(self) -> Any:
        return self.tessellate(64, 64).to_pyvista()


def _scale(pts: np.ndarray) -> float:
    return max(1.0, float(np.abs(pts).max()))


@storable
@dataclass(frozen=True, eq=False, init=False)
class NurbsSurface(Surface):
    """A tensor-product NURBS surface; ``control_points`` is ``(nu, nv, 3)``, u first."""

    control_points: np.ndarray
    degree_u: int
    degree_v: int
    knots_u: np.ndarray
    knots_v: np.ndarray
    weights: np.ndarray
    rational: bool = field(default=False)

    def __init__(
        self,
        control_points: Any,
        degree_u: int,
        degree_v: int,
        knots_u: Any,
        knots_v: Any,
        weights: Any = None,
    ):
        from ..kernels import nurbs

        cp = frozen_array(control_points)
        if cp.ndim != 3 or cp.shape[2] not in (2, 3):
            raise ValueError(
                f"surface control points must be rows of [x, y, z] points (nu, nv, 3), got "
                f"shape {cp.shape}"
            )
        if cp.shape[2] == 2:
            cp = frozen_array(np.concatenate([cp, np.zeros(cp.shape[:2] + (1,))], axis=2))
        ku, kv = frozen_array(knots_u), frozen_array(knots_v)
        w = None if weights is None else frozen_array(weights)
        nurbs.validate_surface(cp, int(degree_u), int(degree_v), ku, kv, w)
        rational = w is not None and not np.all(w == w.flat[0])
        object.__setattr__(self, "control_points", cp)
        object.__setattr__(self, "degree_u", int(degree_u))
        object.__setattr__(self, "degree_v", int(degree_v))
        object.__setattr__(self, "knots_u", ku)
        object.__setattr__(self, "knots_v", kv)
        object.__setattr__(
            self, "weights", w if w is not None else frozen_array(np.ones(cp.shape[:2]))
        )
        object.__setattr__(self, "rational", bool(rational))

    def _args(self) -> tuple[Any, ...]:
        w = self.weights if self.rational else None
        return (self.control_points, self.degree_u, self.degree_v, self.knots_u, self.knots_v, w)

    @property
    def domain_u(self) -> tuple[float, float]:  # type: ignore[override]
        return float(self.knots_u[self.degree_u]), float(self.knots_u[self.control_points.shape[0]])

    @property
    def domain_v(self) -> tuple[float, float]:  # type: ignore[override]
        return float(self.knots_v[self.degree_v]), float(self.knots_v[self.control_points.shape[1]])

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        from ..kernels import nurbs

        return nurbs.surface_evaluate(*self._args(), u, v)

    def evaluate_grid(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        from ..kernels import nurbs

        return nurbs.surface_evaluate_grid(*self._args(), np.asarray(u), np.asarray(v))

    def normals(self, u: Any, v: Any) -> np.ndarray:
        from ..kernels import nurbs

        return nurbs.surface_normals(*self._args(), u, v)

    def __repr__(self) -> str:
        nu, nv, _ = self.control_points.shape
        return f"NurbsSurface(degree=({self.degree_u}, {self.degree_v}), n=({nu}, {nv}))"

    def state(self) -> dict[str, Any]:
        return {
            "control_points": self.control_points,
            "degree_u": self.degree_u,
            "degree_v": self.degree_v,
            "knots_u": self.knots_u,
            "knots_v": self.knots_v,
            "weights": self.weights,
        }


@dataclass(frozen=True, eq=False)
class ParametricSurface(Surface):
    """A surface given by expressions ``x(u, v), y(u, v), z(u, v)``."""

    fx: Callable[..., Any]
    fy: Callable[..., Any]
    fz: Callable[..., Any]
    domain_u: tuple[float, float] = (0.0, 1.0)  # type: ignore[assignment]
    domain_v: tuple[float, float] = (0.0, 1.0)  # type: ignore[assignment]

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        uu, vv = np.broadcast_arrays(np.asarray(u, np.float64), np.asarray(v, np.float64))
        cols = [
            np.broadcast_to(np.asarray(f(u=uu, v=vv), np.float64), uu.shape)
            for f in (self.fx, self.fy, self.fz)
        ]
        xyz = np.stack(cols, axis=-1)
        bad = ~np.isfinite(xyz).all(axis=-1)
        if bad.any():
            idx = np.unravel_index(int(np.argmax(bad)), bad.shape)
            axis = int(np.argmax(~np.isfinite(xyz[idx])))
            text = getattr((self.fx, self.fy, self.fz)[axis], "text", "xyz"[axis])
            raise ValueError(
                f"{'xyz'[axis]} = {text!r} is not finite at u = {uu[idx]:.6g}, v = {vv[idx]:.6g}"
            )
        return xyz

    def partials(self, u: Any, v: Any) -> tuple[np.ndarray, np.ndarray]:
        """``S_u`` and ``S_v`` at (u, v): exact for expressions (forward-mode differentiation
        of their syntax tree), central differences otherwise (``noise``, plain callables)."""
        uu, vv = np.broadcast_arrays(np.asarray(u, np.float64), np.asarray(v, np.float64))
        fs = (self.fx, self.fy, self.fz)
        if all(hasattr(f, "taylor") for f in fs):
            try:
                su = [f.taylor("u", u=uu, v=vv)[1] for f in fs]  # type: ignore[attr-defined]
                sv = [f.taylor("v", u=uu, v=vv)[1] for f in fs]  # type: ignore[attr-defined]
                return np.stack(su, axis=-1), np.stack(sv, axis=-1)
            except ValueError:  # NotDifferentiable: differences below
                pass
        (u0, u1), (v0, v1) = self.domain_u, self.domain_v
        hu, hv = (u1 - u0) * 1e-5, (v1 - v0) * 1e-5
        su_fd = (self.evaluate(uu + hu, vv) - self.evaluate(uu - hu, vv)) / (2 * hu)
        sv_fd = (self.evaluate(uu, vv + hv) - self.evaluate(uu, vv - hv)) / (2 * hv)
        return su_fd, sv_fd

    def normals(self, u: Any, v: Any) -> np.ndarray:
        """``S_u x S_v`` at (u, v), not normalized (as NurbsSurface.normals)."""
        su, sv = self.partials(u, v)
        return np.cross(su, sv)

    def __repr__(self) -> str:
        return f"ParametricSurface(u={self.domain_u}, v={self.domain_v})"

    def fingerprint(self) -> Any:
        return {
            "f": [_expression_fingerprint(f) for f in (self.fx, self.fy, self.fz)],
            "domain": [list(self.domain_u), list(self.domain_v)],
        }

    @property
    def nbytes(self) -> int:
        return 256
