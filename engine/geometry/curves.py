"""Curves: the protocol, exact NURBS curves and curves from expressions."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .base import (
    Geometry,
    _expression_fingerprint,
    as_xyz,
    frozen_array,
    storable,
)

__all__ = ["Curve", "NurbsCurve", "ParametricCurve"]


class Curve(Geometry):
    """The curve protocol: ``domain``, ``evaluate(t)``, ``derivative(t, order)``, ``sample(n)``."""

    domain: tuple[float, float]

    def evaluate(self, t: Any) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def sample(self, n: int) -> np.ndarray:
        """``n`` points at parameters evenly spaced over the domain, ``(n, 3)``."""
        if n < 2:
            raise ValueError(f"sampling a curve needs at least 2 points, got {n}")
        return self.evaluate(np.linspace(self.domain[0], self.domain[1], n))

    @property
    def closed(self) -> bool:
        a, b = self.evaluate(np.array(self.domain))
        scale = max(1.0, float(np.abs(self.sample(9)).max()))
        return bool(np.linalg.norm(a - b) <= 1e-9 * scale)

    def display_points(self) -> np.ndarray:
        """A polyline fine enough to draw this curve."""
        return self.sample(256)

    def to_pyvista(self) -> Any:
        import pyvista as pv

        return pv.lines_from_points(np.array(self.display_points()))


@storable
@dataclass(frozen=True, eq=False, init=False)
class NurbsCurve(Curve):
    """A NURBS curve, the exact curve type: polylines, Beziers, Catmull-Rom and circles.

    Parameters
    ----------
    control_points : (n, 3) or (n, 2) float
    degree : int
    knots : (n + degree + 1,) float, non-decreasing
    weights : (n,) float, positive; None for a non-rational curve (all ones)

    Evaluation is The NURBS Book's A2.1-A2.3 and A4.1-A4.2, vectorized over parameters
    (:mod:`formgraph.kernels.nurbs`).
    """

    control_points: np.ndarray
    degree: int
    knots: np.ndarray
    weights: np.ndarray
    rational: bool = field(default=False)

    def __init__(self, control_points: Any, degree: int, knots: Any, weights: Any = None):
        from ..kernels import nurbs

        cp = as_xyz(control_points, "control_points")
        kn = frozen_array(knots)
        w = None if weights is None else frozen_array(weights)
        nurbs.validate_curve(cp, int(degree), kn, w)
        rational = w is not None and not np.all(w == w[0])
        object.__setattr__(self, "control_points", cp)
        object.__setattr__(self, "degree", int(degree))
        object.__setattr__(self, "knots", kn)
        object.__setattr__(self, "weights", w if w is not None else frozen_array(np.ones(len(cp))))
        object.__setattr__(self, "rational", bool(rational))

    @classmethod
    def _of_valid(
        cls,
        control_points: np.ndarray,
        degree: int,
        knots: np.ndarray,
        ones: np.ndarray | None = None,
    ) -> NurbsCurve:
        """A non-rational curve of frozen arrays a kernel built valid (finite (n, 3) points,
        non-decreasing knots of the right count): made without checking them again. For
        kernels that make many or long curves, e.g. the outlines of a region boolean;
        ``ones``, a frozen array of ones as long as the control points, lets many curves
        share one buffer of weights (each a view of it)."""
        from .base import is_frozen

        assert is_frozen(control_points) and is_frozen(knots)
        if ones is None:
            ones = frozen_array(np.ones(len(control_points)))
        assert len(ones) == len(control_points) and is_frozen(ones)
        curve = object.__new__(cls)
        object.__setattr__(curve, "control_points", control_points)
        object.__setattr__(curve, "degree", int(degree))
        object.__setattr__(curve, "knots", knots)
        object.__setattr__(curve, "weights", ones)
        object.__setattr__(curve, "rational", False)
        return curve

    @classmethod
    def polyline(cls, points: Any, closed: bool = False) -> NurbsCurve:
        """The degree-1 curve through ``points``; ``closed`` joins the last to the first.

        The parameter is the cumulative chord length, so t is arc length along it.
        """
        p = as_xyz(points)
        if len(p) < 2:
            raise ValueError(f"a polyline needs at least 2 points, got {len(p)}")
        if closed and not np.array_equal(p[0], p[-1]):
            p = np.vstack([p, p[:1]])
        # a repeated point (or one so close that the running length does not grow) adds no
        # segment; dropping it keeps the shape and the knots valid
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        keep = np.concatenate([[True], np.diff(chord) > 0])
        p, chord = p[keep], chord[keep]
        if len(p) < 2:
            raise ValueError("a polyline needs at least two distinct points")
        knots = np.concatenate([[chord[0]], chord, [chord[-1]]])
        return cls(p, 1, knots)

    @property
    def closed(self) -> bool:
        """Whether the curve ends where it starts. A clamped curve ends on its first and
        last control points, so those are compared (relative to the control points' size,
        the hull the curve lies in) without evaluating anything; others are evaluated."""
        p, k = self.degree, self.knots
        if k[0] == k[p] and k[-1] == k[-1 - p]:
            cp = self.control_points
            scale = max(1.0, float(np.abs(cp).max()))
            return bool(np.linalg.norm(cp[0] - cp[-1]) <= 1e-9 * scale)
        return super().closed

    @property
    def domain(self) -> tuple[float, float]:  # type: ignore[override]
        p = self.degree
        return float(self.knots[p]), float(self.knots[len(self.control_points)])

    def _w(self) -> np.ndarray | None:
        return self.weights if self.rational else None

    def evaluate(self, t: Any) -> np.ndarray:
        from ..kernels import nurbs

        return nurbs.curve_evaluate(self.control_points, self.degree, self.knots, self._w(), t)

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        from ..kernels import nurbs

        scalar = np.ndim(t) == 0
        d = nurbs.curve_derivatives(
            self.control_points, self.degree, self.knots, self._w(), np.atleast_1d(t), order
        )[order]
        return d[0] if scalar else d

    def display_points(self) -> np.ndarray:
        if self.degree == 1:
            return self.control_points
        spans = max(1, len(np.unique(self.knots)) - 1)
        return self.sample(min(4096, max(64, 16 * spans)))

    def __repr__(self) -> str:
        kind = "rational " if self.rational else ""
        return f"NurbsCurve({kind}degree={self.degree}, n={len(self.control_points)})"

    def state(self) -> dict[str, Any]:
        return {
            "control_points": self.control_points,
            "degree": self.degree,
            "knots": self.knots,
            "weights": self.weights,
        }


@dataclass(frozen=True, eq=False)
class ParametricCurve(Curve):
    """A curve given by expressions ``x(t), y(t), z(t)`` over ``domain``.

    ``fx, fy, fz`` are callables taking ``t=array``; ``samples`` is how finely it is drawn
    and sampled by default. Derivatives are exact for expressions (forward-mode
    differentiation of their syntax tree), central differences for other callables.
    """

    fx: Callable[..., Any]
    fy: Callable[..., Any]
    fz: Callable[..., Any]
    domain: tuple[float, float] = (0.0, 1.0)  # type: ignore[assignment]
    samples: int = 256

    def evaluate(self, t: Any) -> np.ndarray:
        scalar = np.ndim(t) == 0
        tt = np.atleast_1d(np.asarray(t, dtype=np.float64))
        cols = [
            np.broadcast_to(np.asarray(f(t=tt), dtype=np.float64), tt.shape)
            for f in (self.fx, self.fy, self.fz)
        ]
        xyz = np.stack(cols, axis=-1)
        bad = ~np.isfinite(xyz).all(axis=-1)
        if bad.any():
            i = int(np.argmax(bad))
            axis = "xyz"[int(np.argmax(~np.isfinite(xyz[i])))]
            text = getattr((self.fx, self.fy, self.fz)["xyz".index(axis)], "text", axis)
            raise ValueError(f"{axis} = {text!r} is not finite at t = {tt[i]:.6g}")
        return xyz[0] if scalar else xyz

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        """The first or second derivative, exact: the expressions are differentiated
        (forward mode over their syntax tree); by central differences only for what has no
        derivative there (``noise``) or callables that are not expressions."""
        if order not in (1, 2):
            raise ValueError(f"derivative order {order} is not supported on a parametric curve")
        exact = self._exact(t, order)
        if exact is not None:
            return exact
        t0, t1 = self.domain
        h = (t1 - t0) * 1e-5
        tt = np.clip(np.asarray(t, dtype=np.float64), t0 + order * h, t1 - order * h)
        if order == 1:
            return (self.evaluate(tt + h) - self.evaluate(tt - h)) / (2 * h)
        return (self.evaluate(tt + h) - 2 * self.evaluate(tt) + self.evaluate(tt - h)) / h**2

    def _exact(self, t: Any, order: int) -> np.ndarray | None:
        fs = (self.fx, self.fy, self.fz)
        if not all(hasattr(f, "taylor") for f in fs):
            return None
        tt = np.asarray(t, dtype=np.float64)
        try:
            cols = [f.taylor("t", t=tt)[order] for f in fs]  # type: ignore[attr-defined]
        except ValueError:  # NotDifferentiable
            return None
        return np.stack([np.broadcast_to(c, tt.shape) for c in cols], axis=-1)

    def display_points(self) -> np.ndarray:
        return self.sample(max(2, self.samples))

    def __repr__(self) -> str:
        return f"ParametricCurve(domain={self.domain})"

    def fingerprint(self) -> Any:
        return {
            "f": [_expression_fingerprint(f) for f in (self.fx, self.fy, self.fz)],
            "domain": list(self.domain),
            "samples": self.samples,
        }

    @property
    def nbytes(self) -> int:
        return 256
