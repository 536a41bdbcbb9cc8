"""Closed outlines for cutting: rounded rectangles and regular polygons, exact.

A rounded rectangle is one closed rational quadratic NURBS: each corner the quarter circle
of The NURBS Book's A7.1 (control points on the tangent lines, middle weight
``cos 45 deg = sqrt(2) / 2``), each straight side a quadratic piece with its middle control
point at the side's midpoint (weight 1: exactly straight), the pieces joined by double
knots so every side and corner is its own Bezier piece. Knots are the pieces' arc lengths,
so the parameter runs around the outline roughly at unit speed. Outlines run counter-
clockwise seen from +z (a region's outer boundary).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["regular_polygon", "rounded_rectangle"]

_HALF_SQRT2 = math.sqrt(0.5)


def _finite_point(values: object, what: str) -> np.ndarray:
    a = np.asarray(values, dtype=np.float64).reshape(-1)
    if a.size == 2:
        a = np.append(a, 0.0)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{what} must be a finite [x, y] or [x, y, z] point, got {values!r}")
    return a


def rounded_rectangle(
    size: object, center: object = (0.0, 0.0, 0.0), radius: float = 0.0
) -> tuple[np.ndarray, int, np.ndarray, np.ndarray | None]:
    """The closed outline of a ``width x height`` rectangle with circular corners.

    Parameters
    ----------
    size : (2,) float
        Width (along x) and height (along y), both positive.
    center : (2,) or (3,) float
        Centre of the rectangle (its z is the outline's plane).
    radius : float
        Corner radius, ``0 <= radius <= min(width, height) / 2``. 0 gives sharp corners
        (a degree-1 polygon of four sides); at ``min / 2`` the short sides vanish (a slot,
        or a circle when the rectangle is square).

    Returns
    -------
    control_points : (n, 3) float
    degree : int
        1 for sharp corners, else 2.
    knots : (n + degree + 1,) float
        Cumulative arc lengths of the pieces (clamped, double inner knots).
    weights : (n,) float, or None when sharp

    Raises
    ------
    ValueError
        A size that is not two positive numbers, or a radius out of range (the message
        gives the largest radius that fits).

    Example
    -------
    >>> cp, p, kn, w = rounded_rectangle([80, 30], radius=5)
    >>> p, len(cp)
    (2, 17)
    """
    s = np.asarray(size, dtype=np.float64).reshape(-1)
    if s.shape != (2,) or not np.all(np.isfinite(s)) or not np.all(s > 0):
        raise ValueError(f"size must be [width, height], both positive, got {size!r}")
    c = _finite_point(center, "center")
    w, h = float(s[0]), float(s[1])
    r = float(radius)
    largest = min(w, h) / 2
    if not math.isfinite(r) or r < 0 or r > largest * (1 + 1e-12):
        raise ValueError(
            f"the corner radius must be between 0 and half the shorter side ({largest:g}), "
            f"got {radius!r}"
        )
    r = min(r, largest)
    if not math.isfinite(2 * (w + h)):
        raise ValueError(f"size {w:g} x {h:g} is too large: its perimeter is not a finite number")
    x0, x1, y0, y1 = c[0] - w / 2, c[0] + w / 2, c[1] - h / 2, c[1] + h / 2
    if r == 0:
        cp = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]])
        chord = np.cumsum([0.0, w, h, w, h])
        knots = np.concatenate([[0.0], chord, [chord[-1]]])
        return np.column_stack([cp, np.full(5, c[2])]), 1, knots, None
    # counter-clockwise from the start of the bottom-right corner: corner, side, corner, ...
    corners = [
        ((x1 - r, y0), (x1, y0), (x1, y0 + r)),
        ((x1, y1 - r), (x1, y1), (x1 - r, y1)),
        ((x0 + r, y1), (x0, y1), (x0, y1 - r)),
        ((x0, y0 + r), (x0, y0), (x0 + r, y0)),
    ]
    sides = [h - 2 * r, w - 2 * r, h - 2 * r, w - 2 * r]
    points: list[tuple[float, float]] = [corners[0][0]]
    weights: list[float] = [1.0]
    lengths: list[float] = []
    arc = r * math.pi / 2
    for k in range(4):  # four corners and up to four sides: a fixed handful of pieces
        _, corner, end = corners[k]
        points += [corner, end]
        weights += [_HALF_SQRT2, 1.0]
        lengths.append(arc)
        nxt = corners[(k + 1) % 4][0]
        if sides[k] > 1e-12 * largest:  # a side of zero length is no piece
            points += [((end[0] + nxt[0]) / 2, (end[1] + nxt[1]) / 2), nxt]
            weights += [1.0, 1.0]
            lengths.append(sides[k])
    cp = np.array(points)
    cp[-1] = cp[0]  # closed exactly
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    knots = np.concatenate([[0.0] * 3, np.repeat(cum[1:-1], 2), [cum[-1]] * 3])
    return np.column_stack([cp, np.full(len(cp), c[2])]), 2, knots, np.array(weights)


def regular_polygon(
    sides: int, radius: float, center: object = (0.0, 0.0, 0.0), angle: float = 0.0
) -> np.ndarray:
    """The corners of a regular polygon, counter-clockwise, the first at ``angle`` degrees.

    Parameters
    ----------
    sides : int
        Number of sides, >= 3.
    radius : float
        Distance from the centre to each corner (the circumradius), > 0.
    center : (2,) or (3,) float
    angle : float
        Direction of the first corner, in degrees counter-clockwise from +x.

    Returns
    -------
    (sides, 3) float
        The corners, not repeating the first.
    """
    if isinstance(sides, bool) or int(sides) != sides or sides < 3:
        raise ValueError(f"a polygon needs at least 3 sides, got {sides!r}")
    r = float(radius)
    if not math.isfinite(r) or r <= 0:
        raise ValueError(f"radius must be a positive number, got {radius!r}")
    if not math.isfinite(float(angle)):
        raise ValueError(f"angle must be finite, got {angle!r}")
    c = _finite_point(center, "center")
    a = math.radians(float(angle)) + 2 * math.pi * np.arange(int(sides)) / int(sides)
    return np.column_stack([c[0] + r * np.cos(a), c[1] + r * np.sin(a), np.full(a.size, c[2])])
