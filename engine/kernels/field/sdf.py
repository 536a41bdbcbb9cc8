"""Signed distance functions on point arrays: primitives, smooth blends, TPMS sheets.

Every function takes points ``p`` of shape (n, 3) (or distances of shape (n,)) and returns
(n,) float64, negative inside; ``*_grid`` take the axes of lattices of points and
``*_lines`` points on a lattice's lines (:class:`Lines`), the same values from tables.
The primitives are exact Euclidean distances (Quilez's formulas, "Distance functions",
iquilezles.org); the blends are the polynomial smooth
minimum, whose gradient is a convex combination of its arguments' gradients, so a blend of
1-Lipschitz fields stays 1-Lipschitz (what the mesher's culling relies on).
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = [
    "box",
    "cylinder",
    "smooth_max",
    "smooth_min",
    "sphere",
    "torus",
    "tpms",
    "TPMS_KINDS",
]


def sphere(p: np.ndarray, radius: float, center: np.ndarray) -> np.ndarray:
    """Distance to a sphere: ``|p - c| - r``."""
    return np.linalg.norm(p - center, axis=1) - radius


def box(p: np.ndarray, size: np.ndarray, center: np.ndarray, radius: float = 0.0) -> np.ndarray:
    """Exact distance to an axis-aligned box of ``size``, its edges rounded by ``radius``.

    The rounded box is the box shrunk by ``radius`` then grown by it (a Minkowski sum with a
    ball), so its outside size stays ``size``; ``radius`` is clipped to half the smallest
    side.
    """
    half = np.asarray(size, dtype=np.float64) / 2.0
    r = float(min(max(radius, 0.0), half.min()))
    q = np.abs(p - center) - (half - r)
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    return outside + inside - r


def cylinder(p: np.ndarray, radius: float, height: float, center: np.ndarray) -> np.ndarray:
    """Exact distance to a capped cylinder along z (``height`` long, centred on ``center``)."""
    d = p - center
    q = np.stack([np.hypot(d[:, 0], d[:, 1]) - radius, np.abs(d[:, 2]) - height / 2.0], axis=1)
    return np.minimum(q.max(axis=1), 0.0) + np.linalg.norm(np.maximum(q, 0.0), axis=1)


def torus(p: np.ndarray, major: float, minor: float, center: np.ndarray) -> np.ndarray:
    """Exact distance to a torus round the z axis: ``|(rho - R, z)| - r``."""
    d = p - center
    return np.hypot(np.hypot(d[:, 0], d[:, 1]) - major, d[:, 2]) - minor


def smooth_min(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Polynomial smooth minimum of two distances (a union blended over ``k``).

    ``min(a, b) - h^2 k / 4`` with ``h = max(k - |a - b|, 0) / k``: equal to ``min`` where
    the two differ by more than ``k``, at most ``k / 4`` below it where they meet.
    """
    if k <= 0:
        return np.minimum(a, b)
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * (k / 4.0)


def smooth_max(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Polynomial smooth maximum (an intersection blended over ``k``): ``-smin(-a, -b)``."""
    if k <= 0:
        return np.maximum(a, b)
    return -smooth_min(-a, -b, k)


TPMS_KINDS = ("gyroid", "schwarz_p", "diamond")


def _tpms_value_gradient(kind: str, p: np.ndarray, period: float):
    """The implicit function of a TPMS of ``period`` and its gradient (in model units)."""
    w = 2.0 * np.pi / period
    x, y, z = (p * w).T
    sx, sy, sz = np.sin(x), np.sin(y), np.sin(z)
    cx, cy, cz = np.cos(x), np.cos(y), np.cos(z)
    if kind == "gyroid":  # sin x cos y + sin y cos z + sin z cos x
        f = sx * cy + sy * cz + sz * cx
        g = np.stack([cx * cy - sz * sx, cy * cz - sx * sy, cz * cx - sy * sz], axis=1)
    elif kind == "schwarz_p":  # cos x + cos y + cos z
        f = cx + cy + cz
        g = np.stack([-sx, -sy, -sz], axis=1)
    elif kind == "diamond":
        # sin x sin y sin z + sin x cos y cos z + cos x sin y cos z + cos x cos y sin z
        f = sx * sy * sz + sx * cy * cz + cx * sy * cz + cx * cy * sz
        g = np.stack(
            [
                cx * sy * sz + cx * cy * cz - sx * sy * cz - sx * cy * sz,
                sx * cy * sz - sx * sy * cz + cx * cy * cz - cx * sy * sz,
                sx * sy * cz - sx * cy * sz - cx * sy * sz + cx * cy * cz,
            ],
            axis=1,
        )
    else:
        raise ValueError(f"unknown TPMS kind {kind!r}; one of {', '.join(TPMS_KINDS)}")
    return f, g * w


def tpms(p: np.ndarray, kind: str, period: float, thickness: float) -> np.ndarray:
    """A triply periodic minimal surface thickened into a sheet of even wall ``thickness``.

    The implicit function ``f`` is divided by its gradient's length, which makes
    ``f / |grad f|`` the distance to the surface to first order (Taubin's distance
    approximation); the sheet is ``|f| / |grad f| - thickness / 2``, a wall ``thickness``
    thick in model units wherever the surface is flatter than the wall is thick. Far from
    the surface (where the gradient vanishes) the value is capped at a quarter period, so
    it stays finite and an overestimate of nothing that matters to the mesher.
    """
    f, g = _tpms_value_gradient(kind, p, period)
    gl = np.linalg.norm(g, axis=1)
    cap = period / 4.0
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(gl > 0, np.abs(f) / gl, cap)
    return np.minimum(d, cap) - thickness / 2.0


# ----------------------------------------------------------------- on lattices of points
#
# The same distances on a lattice of points given by its axes: ``axes`` is three arrays
# ``(n, a)``, ``(n, b)``, ``(n, c)`` of coordinates (n boxes), the result ``(a, b, c, n)``:
# the boxes' index innermost (see :func:`_outer`; ``formgraph.geometry.Field.evaluate_grid``
# gives them as (n, a, b, c)). Where a function is a sum or product of terms in one
# coordinate each, the terms are tables along the axes and the lattice is their outer sums
# and products: a TPMS costs six sines a box side instead of six a point.


def _outer(axes):
    """The axes (n, a), (n, b), (n, c) as broadcastable (a, 1, 1, n), (1, b, 1, n),
    (1, 1, c, n): the lattices' values are worked on as (a, b, c, n), the boxes' index
    innermost, so numpy's inner loops run over the n boxes, not over a short side."""
    x, y, z = (np.ascontiguousarray(v.T) for v in axes)
    return x[:, None, None, :], y[None, :, None, :], z[None, None, :, :]


def sphere_grid(axes, radius: float, center: np.ndarray) -> np.ndarray:
    """:func:`sphere` on a lattice: ``sqrt(dx^2 + dy^2 + dz^2) - r`` from squared tables."""
    x, y, z = _outer([a - c for a, c in zip(axes, center, strict=True)])
    return np.sqrt((x * x + y * y) + z * z) - radius


def box_grid(axes, size: np.ndarray, center: np.ndarray, radius: float = 0.0) -> np.ndarray:
    """:func:`box` on a lattice: the clipped offsets per axis are tables. On a lattice
    inside the shrunk box (every offset <= 0) the distance is the largest offset alone."""
    half = np.asarray(size, dtype=np.float64) / 2.0
    r = float(min(max(radius, 0.0), half.min()))
    q = [np.abs(a - c) - (h - r) for a, c, h in zip(axes, center, half, strict=True)]
    inner = np.logical_and.reduce([v.max(axis=1, initial=-np.inf) <= 0 for v in q])
    if inner.all():
        return _box_inner(q, r)
    if not inner.any():
        return _box_outer(q, r)
    out = np.empty((*(v.shape[1] for v in q), len(inner)))
    out[..., inner] = _box_inner([v[inner] for v in q], r)
    out[..., ~inner] = _box_outer([v[~inner] for v in q], r)
    return out


def _box_inner(q, r: float) -> np.ndarray:
    qx, qy, qz = _outer(q)
    out = np.maximum(np.maximum(qx, qy), qz)
    if r:
        out -= r
    return out


def _box_outer(q, r: float) -> np.ndarray:
    mx, my, mz = _outer([np.maximum(v, 0.0) for v in q])
    qx, qy, qz = _outer(q)
    outside = np.sqrt((mx * mx + my * my) + mz * mz)
    outside += np.minimum(np.maximum(np.maximum(qx, qy), qz), 0.0)
    outside -= r
    return outside


def tpms_grid(axes, kind: str, period: float, thickness: float) -> np.ndarray:
    """:func:`tpms` on a lattice: the implicit function and its gradient are sums of
    products of sines and cosines of one coordinate each, outer products of tables; the
    lattice-sized work is a few sums and the distance, done in place."""
    w = 2.0 * np.pi / period
    x, y, z = _outer([a * w for a in axes])
    sx, sy, sz = np.sin(x), np.sin(y), np.sin(z)
    cx, cy, cz = np.cos(x), np.cos(y), np.cos(z)
    if kind == "gyroid":
        # f / w from the tables of sin / w (f / |grad f| = (f / w) / |grad f / w|); every
        # lattice-sized array made once and worked on in place: a new one of that size
        # each operation costs a quarter of the work in fresh pages
        u = 1.0 / w
        f = (sx * u) * cy + (sy * u) * cz
        f += (sz * u) * cx
        g2 = np.subtract(cx * cy, sz * sx)
        g2 *= g2
        term = np.subtract(cy * cz, sx * sy)
        term *= term
        g2 += term
        np.subtract(cz * cx, sy * sz, out=term)
        term *= term
        g2 += term
    elif kind == "schwarz_p":
        f = ((cx + cy) + cz) / w
        g2 = (sx * sx + sy * sy) + sz * sz
    elif kind == "diamond":
        sysz, cycz, cysz, sycz = sy * sz, cy * cz, cy * sz, sy * cz
        f = ((sx * sysz + sx * cycz) + cx * sycz) + cx * cysz
        f /= w
        g2 = np.square(((cx * sysz + cx * cycz) - sx * sycz) - sx * cysz)
        g2 += np.square(((sx * cysz - sx * sycz) + cx * cycz) - cx * sysz)
        g2 += np.square(((sx * sycz - sx * cysz) - cx * sysz) + cx * cycz)
    else:
        raise ValueError(f"unknown TPMS kind {kind!r}; one of {', '.join(TPMS_KINDS)}")
    np.abs(f, out=f)
    with np.errstate(divide="ignore", invalid="ignore"):
        f /= np.sqrt(g2, out=g2)  # inf or NaN where the gradient vanishes: capped
    np.fmin(f, period / 4.0, out=f)
    f -= thickness / 2.0
    return f


# ------------------------------------------------------------ on the lines of a lattice


class Lines:
    """Points on the lines of a lattice: ``origin + (ijk + t e_axis) * step``, one per row
    of the integer ``ijk (n, 3)``, ``axis (n,)`` and ``t (n,)``. Two of each point's
    coordinates are lattice coordinates, so what depends on one coordinate (a sine) is a
    table there; only the coordinate along the line is new (a mesher's vertices on its
    cells' edges)."""

    def __init__(self, origin, step, ijk: np.ndarray, axis: np.ndarray, t: np.ndarray):
        self.origin = np.asarray(origin, dtype=np.float64).reshape(3)
        self.step = np.broadcast_to(np.asarray(step, dtype=np.float64), (3,))
        self.ijk, self.axis, self.t = ijk, axis, t

    def __len__(self) -> int:
        return len(self.t)

    def moved(self, translate: np.ndarray, scale: np.ndarray) -> Lines:
        """The same points in the frame ``(p - translate) / scale`` (per axis)."""
        o = (self.origin - translate) / scale
        return Lines(o, self.step / scale, self.ijk, self.axis, self.t)

    @functools.cached_property
    def _index(self):
        """The indices by axis ``(3, n)`` and where in that array each point moves (an
        ``ijk`` stored by columns, a transposed ``(3, n)`` array, is not copied)."""
        n = len(self)
        moving = self.axis * n
        moving += np.arange(n, dtype=moving.dtype)
        return np.ascontiguousarray(self.ijk.T), moving

    @functools.cached_property
    def _columns(self) -> np.ndarray:
        i, moving = self._index
        q = i.astype(np.float64)
        q.reshape(-1)[moving] += self.t
        q *= self.step[:, None]
        q += self.origin[:, None]
        return q

    def columns(self) -> list[np.ndarray]:
        """The points' coordinates, one array an axis."""
        return list(self._columns)

    def sincos(self, w: float):
        """``sin(w x_k)`` and ``cos(w x_k)`` for each axis: tables over the lattice's
        indices where the coordinate is the lattice's, evaluated where it moves."""
        i, moving = self._index
        if not len(self):
            return [np.zeros(0)] * 3, [np.zeros(0)] * 3
        lo, hi = i.min(axis=1), i.max(axis=1)
        start = np.concatenate([[0], np.cumsum(hi - lo + 1)])
        x = np.concatenate(
            [self.origin[k] + np.arange(lo[k], hi[k] + 1) * self.step[k] for k in range(3)]
        )
        at = i - (lo - start[:3]).astype(i.dtype)[:, None]
        x *= w
        s, c = np.take(np.sin(x), at), np.take(np.cos(x), at)
        m = np.take(self._columns, moving)
        m *= w
        s.reshape(-1)[moving] = np.sin(m)
        c.reshape(-1)[moving] = np.cos(m)
        return list(s), list(c)


def sphere_lines(lines: Lines, radius: float, center: np.ndarray) -> np.ndarray:
    """:func:`sphere` on :class:`Lines`."""
    x, y, z = (a - c for a, c in zip(lines.columns(), center, strict=True))
    return np.sqrt((x * x + y * y) + z * z) - radius


def box_lines(lines: Lines, size: np.ndarray, center: np.ndarray, radius: float = 0.0):
    """:func:`box` on :class:`Lines`, by columns."""
    half = np.asarray(size, dtype=np.float64) / 2.0
    r = float(min(max(radius, 0.0), half.min()))
    q = [np.abs(a - c) - (h - r) for a, c, h in zip(lines.columns(), center, half, strict=True)]
    out = np.maximum(np.maximum(q[0], q[1]), q[2])
    # inside the shrunk box (most points of a lattice cut by it) the largest offset is
    # the distance; outside it, the length of the clipped offsets
    far = np.flatnonzero(out > 0)
    if len(far):
        mx, my, mz = (np.maximum(v[far], 0.0) for v in q)
        out[far] = np.sqrt((mx * mx + my * my) + mz * mz)
    if r:
        out -= r
    return out


def tpms_lines(lines: Lines, kind: str, period: float, thickness: float) -> np.ndarray:
    """:func:`tpms` on :class:`Lines`: two sines a point instead of six."""
    w = 2.0 * np.pi / period
    (sx, sy, sz), (cx, cy, cz) = lines.sincos(w)
    if kind == "gyroid":  # in place: the lines of a mesher are many
        f = sx * cy
        f += sy * cz
        f += sz * cx
        g2 = np.square(cx * cy - sz * sx)
        g2 += np.square(cy * cz - sx * sy)
        g2 += np.square(cz * cx - sy * sz)
        np.abs(f, out=f)
        with np.errstate(divide="ignore", invalid="ignore"):
            f /= np.sqrt(g2, out=g2)  # inf or NaN where the gradient vanishes: capped
        f /= w
        np.fmin(f, period / 4.0, out=f)
        f -= thickness / 2.0
        return f
    elif kind == "schwarz_p":
        f = cx + cy + cz
        gx, gy, gz = -sx, -sy, -sz
    elif kind == "diamond":
        f = sx * sy * sz + sx * cy * cz + cx * sy * cz + cx * cy * sz
        gx = cx * sy * sz + cx * cy * cz - sx * sy * cz - sx * cy * sz
        gy = sx * cy * sz - sx * sy * cz + cx * cy * cz - cx * sy * sz
        gz = sx * sy * cz - sx * cy * sz - cx * sy * sz + cx * cy * cz
    else:
        raise ValueError(f"unknown TPMS kind {kind!r}; one of {', '.join(TPMS_KINDS)}")
    gl = np.sqrt((gx * gx + gy * gy) + gz * gz) * w
    cap = period / 4.0
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(gl > 0, np.abs(f) / gl, cap)
    return np.minimum(d, cap) - thickness / 2.0
