"""Exact NURBS from chains of drawing segments: lines, Béziers and elliptical arcs.

A drawing's path is a chain of pieces of different kinds. Each piece becomes a rational
Bézier in homogeneous coordinates — a line of degree 1, a quadratic or cubic Bézier as it
is, an elliptical arc as rational quadratics of at most 90 degrees each (The NURBS Book,
section 7.3: the middle point on the tangents' meeting point, weight ``cos(sweep / 2)``) —
and the chain one NURBS curve of the highest degree among them, lower pieces degree-raised
exactly (Farin, *Curves and Surfaces for CAGD*, section 6.1: ``Q_i = i/(p+1) P_{i-1} +
(1 - i/(p+1)) P_i``, done on the weighted points), joined at knots of full multiplicity. The
parameter runs 0..1 over each piece. No piece is approximated.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["Chain", "arc_pieces", "line_piece"]

CurveArrays = tuple[np.ndarray, int, np.ndarray, np.ndarray | None]


def line_piece(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """A line as a degree-1 homogeneous Bézier, (2, 4)."""
    return np.array([[*p0, 1.0], [*p1, 1.0]], dtype=np.float64)


def bezier_piece(points: np.ndarray) -> np.ndarray:
    """Control points (k, 3) of a polynomial Bézier as a homogeneous one, (k, 4)."""
    p = np.asarray(points, dtype=np.float64)
    return np.column_stack([p, np.ones(len(p))])


def arc_pieces(
    center: np.ndarray, a: np.ndarray, b: np.ndarray, t0: float, t1: float
) -> list[np.ndarray]:
    """The arc ``center + a cos t + b sin t`` for t from ``t0`` to ``t1`` (either way round),
    as rational quadratic Béziers of at most 90 degrees each, (3, 4) homogeneous.

    ``a`` and ``b`` are conjugate semi-diameters: any affine image of a circle (a skewed,
    scaled ellipse) is exact this way.
    """
    sweep = t1 - t0
    if not (math.isfinite(sweep) and np.isfinite(center).all() and np.isfinite(a).all()
            and np.isfinite(b).all()):  # fmt: skip
        raise ValueError(
            "an arc's centre, radii or angles are not finite numbers (too large for double "
            "precision, or not numbers at all)"
        )
    if sweep == 0:
        return []
    n = max(1, math.ceil(abs(sweep) / (math.pi / 2) - 1e-9))
    ts = t0 + sweep * np.arange(n + 1) / n
    half = sweep / n / 2
    mid = ts[:-1] + half
    w = math.cos(half)
    c, a, b = (np.asarray(x, dtype=np.float64) for x in (center, a, b))
    ends = c + np.outer(np.cos(ts), a) + np.outer(np.sin(ts), b)
    apex = c + (np.outer(np.cos(mid), a) + np.outer(np.sin(mid), b)) / w
    out = []
    for k in range(n):
        out.append(
            np.array([[*ends[k], 1.0], [*(apex[k] * w), w], [*ends[k + 1], 1.0]], dtype=np.float64)
        )
    return out


def bulge_arc(p0: np.ndarray, p1: np.ndarray, bulge: float) -> list[np.ndarray]:
    """The arc a DXF polyline's ``bulge`` puts between ``p0`` and ``p1`` (in their plane,
    z of p0): included angle ``4 atan(bulge)``, counter-clockwise for a positive bulge."""
    p0, p1 = np.asarray(p0, dtype=np.float64), np.asarray(p1, dtype=np.float64)
    chord = p1[:2] - p0[:2]
    length = float(np.hypot(*chord))
    if not math.isfinite(bulge):
        raise ValueError(f"a bulge of {bulge} is not a finite number")
    if length == 0 or bulge == 0:
        return [line_piece(p0, p1)]
    theta = 4.0 * math.atan(bulge)
    radius = length / (2.0 * math.sin(abs(theta) / 2.0))
    # the centre is on the chord's perpendicular bisector, (L/2)(1 - b^2)/(2b) to its left
    # (b = tan(theta/4)): left of the chord for a positive bulge under a half circle
    mid = (p0[:2] + p1[:2]) / 2
    normal = np.array([-chord[1], chord[0]]) / length
    c2 = mid + normal * (length / 2.0) * ((1 - bulge * bulge) / (2 * bulge))
    start = math.atan2(p0[1] - c2[1], p0[0] - c2[0])
    center = np.array([c2[0], c2[1], p0[2]])
    a = np.array([radius, 0.0, 0.0])
    b = np.array([0.0, radius, 0.0])
    return arc_pieces(center, a, b, start, start + theta)


class Chain:
    """Pieces gathered one after another, then joined into one NURBS curve."""

    def __init__(self) -> None:
        self.pieces: list[np.ndarray] = []

    def add(self, piece: np.ndarray | Sequence[np.ndarray]) -> None:
        if isinstance(piece, np.ndarray):
            self.pieces.append(piece)
        else:
            self.pieces.extend(piece)

    def __len__(self) -> int:
        return len(self.pieces)

    def curve(self) -> CurveArrays:
        """``(control_points (n, 3), degree, knots, weights or None)`` of the chain."""
        if not self.pieces:
            raise ValueError("an empty chain has no curve")
        p = max(len(q) - 1 for q in self.pieces)
        raised = [_elevate(q, p) for q in self.pieces]
        rows = [raised[0]] + [q[1:] for q in raised[1:]]
        pw = np.concatenate(rows)
        k = len(raised)
        inner = np.repeat(np.arange(1, k, dtype=np.float64), p)
        knots = np.concatenate([np.zeros(p + 1), inner, np.full(p + 1, float(k))])
        w = pw[:, 3]
        rational = not np.allclose(w, 1.0, rtol=0, atol=0)
        return pw[:, :3] / w[:, None], p, knots, (w.copy() if rational else None)


def _elevate(pw: np.ndarray, p: int) -> np.ndarray:
    """A homogeneous Bézier raised to degree ``p`` (exactly; the curve is unchanged)."""
    q = pw
    while len(q) - 1 < p:
        d = len(q) - 1
        i = np.arange(1, d + 1)[:, None] / (d + 1)
        inner = i * q[:-1] + (1 - i) * q[1:]
        q = np.concatenate([q[:1], inner, q[-1:]])
    return q
