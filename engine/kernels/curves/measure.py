"""Length and enclosed area of a curve by Gauss-Legendre quadrature between breakpoints."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["gauss_nodes", "length_and_area"]


def gauss_nodes(breaks: np.ndarray, order: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on every interval between sorted ``breaks``.

    An ``order``-point rule is exact for polynomials of degree ``2 order - 1`` on each
    interval, so a NURBS curve's polynomial pieces (between its knots) integrate cleanly.

    Returns
    -------
    t, w : (order * (len(breaks) - 1),) float64
    """
    b = np.asarray(breaks, dtype=np.float64)
    x, w = np.polynomial.legendre.leggauss(order)
    half = 0.5 * np.diff(b)[:, None]
    mid = 0.5 * (b[1:] + b[:-1])[:, None]
    return (mid + half * x).reshape(-1), (half * w).reshape(-1)


def length_and_area(
    evaluate: Callable[[np.ndarray], np.ndarray],
    derivative: Callable[[np.ndarray], np.ndarray],
    breaks: np.ndarray,
    closed: bool,
    order: int = 8,
    planar_tolerance: float = 1e-9,
) -> tuple[float, float]:
    """Arc length, and for a closed planar curve the area it encloses.

    Length is the integral of ``|C'(t)|``; the area is the length of the vector area
    ``1/2 * integral of C(t) x C'(t) dt`` (the shoelace formula in the curve's own plane),
    reported when every quadrature point lies within ``planar_tolerance`` (relative to the
    curve's size) of the plane through the centroid normal to that vector; else 0.

    Parameters
    ----------
    evaluate, derivative : callables of (k,) parameters -> (k, 3) points / tangents
    breaks : (s + 1,) float
        Sorted parameters, the domain's ends first and last (knots, or a fine even split).
    closed : bool
        Whether the curve returns to its start (no area otherwise).

    Returns
    -------
    length, area : float
    """
    t, w = gauss_nodes(breaks, order)
    d = np.asarray(derivative(t), dtype=np.float64)
    length = float(np.sum(w * np.linalg.norm(d, axis=1)))
    if not closed:
        return length, 0.0
    p = np.asarray(evaluate(t), dtype=np.float64)
    c = p.mean(axis=0)
    vec = 0.5 * np.sum(w[:, None] * np.cross(p - c, d), axis=0)
    area = float(np.linalg.norm(vec))
    if area == 0.0:
        return length, 0.0
    size = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
    off_plane = np.abs((p - c) @ (vec / area)).max()
    return length, area if off_plane <= planar_tolerance * max(size, 1e-300) else 0.0
