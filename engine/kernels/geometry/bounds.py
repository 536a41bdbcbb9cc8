"""Axis-aligned bounding boxes of the geometry itself: of NURBS curves and surfaces from
their Bezier pieces' extrema, not their control points.

A NURBS with positive weights lies in the convex hull of its control points, so the box of
the control points is only an outer bound; a circle's control square sticks out 41 % past
it. The exact box is the extrema of each coordinate over the curve or surface:

- :func:`bezier_extremes`: branch and bound over Bezier pieces (The NURBS Book A5.6 / A5.7
  gives them: :func:`~formgraph.kernels.nurbs.decompose_bezier`,
  :func:`~formgraph.kernels.nurbs.decompose_bezier_surface`). For each of the six
  objectives (the largest and the smallest x, y, z) a piece's control values bound its
  values from above (the convex hull property, in homogeneous coordinates so rational
  pieces too), and its corner points are on the geometry, so they bound the extremum from
  below. Pieces whose upper bound cannot beat the best corner by more than ``eps`` are
  dropped; the rest are halved by de Casteljau's algorithm (a surface patch along the
  parameter whose control values bend most: halving a piece shrinks the gap between its
  control values and its values by four along that parameter) until none is left. The
  answer is a value taken on the geometry, within ``eps`` of the true extremum.
- :func:`sampled_extremes`: curves and surfaces given by expressions: a dense grid, then
  around the best sample of each objective ever finer grids (a zoom by 1/8 each round);
  exact up to what the first grid resolves.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["bezier_extremes", "sampled_extremes"]

_LEVELS = 80  # halvings at most (each shrinks a gap 4 times: far past double precision)
_PIECES = 1 << 18  # live pieces at most per objective; past it the bound is given as it is


def _split_curves(h: np.ndarray) -> np.ndarray:
    """Each Bezier piece (k, p + 1, d) halved at t = 1/2 (de Casteljau): (2 k, p + 1, d)."""
    p = h.shape[1] - 1
    left = np.empty_like(h)
    right = np.empty_like(h)
    q = h
    left[:, 0], right[:, p] = h[:, 0], h[:, p]
    for r in range(1, p + 1):  # degree steps, each over every piece at once
        q = 0.5 * (q[:, :-1] + q[:, 1:])
        left[:, r], right[:, p - r] = q[:, 0], q[:, -1]
    return np.concatenate([left, right])


def _split_patches(h: np.ndarray, along_u: np.ndarray) -> np.ndarray:
    """Patches (k, p + 1, q + 1, d) each halved along u or along v."""
    parts = []
    if along_u.any():
        a = h[along_u]
        k, p1, q1, d = a.shape
        s = _split_curves(a.transpose(0, 2, 1, 3).reshape(k * q1, p1, d))
        parts.append(s.reshape(2, k, q1, p1, d).transpose(0, 1, 3, 2, 4).reshape(2 * k, p1, q1, d))
    if (~along_u).any():
        a = h[~along_u]
        k, p1, q1, d = a.shape
        s = _split_curves(a.reshape(k * p1, q1, d))
        parts.append(s.reshape(2, k, p1, q1, d).reshape(2 * k, p1, q1, d))
    return np.concatenate(parts)


def _values(h: np.ndarray, axis: int, sense: float) -> np.ndarray:
    """``sense * x_axis / w`` of every homogeneous control point."""
    return sense * (h[..., axis] / h[..., 3])


def _corners(f: np.ndarray, surface: bool) -> np.ndarray:
    """The largest value at a corner of each piece (a point on the geometry)."""
    if surface:
        return np.maximum(
            np.maximum(f[:, 0, 0], f[:, 0, -1]), np.maximum(f[:, -1, 0], f[:, -1, -1])
        )
    return np.maximum(f[:, 0], f[:, -1])


def _bend(f: np.ndarray, axis: int) -> np.ndarray:
    """The largest second difference of the control values along one parameter."""
    if f.shape[axis] < 3:
        return np.zeros(len(f))
    d2 = np.diff(f, n=2, axis=axis)
    return np.abs(d2).reshape(len(f), -1).max(axis=1)


def bezier_extremes(hom: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """The box of Bezier curves or patches given by homogeneous control points.

    Parameters
    ----------
    hom : (k, p + 1, 4) or (k, p + 1, q + 1, 4) float
        Pieces of a curve or a surface, ``(w x, w y, w z, w)`` with w > 0.
    eps : float
        How far below the true extremum the answer may be (> 0).

    Returns
    -------
    lo, hi : (3,) float
        Each a coordinate of a point of the geometry, within ``eps`` of the extremum (the
        bound of the live pieces, an outer bound, if a piece budget ran out first).
    """
    h = np.asarray(hom, dtype=np.float64)
    surface = h.ndim == 4
    out = np.empty((2, 3))
    for axis in range(3):  # six objectives, each a vectorized search over its pieces
        for side, sense in ((1, 1.0), (0, -1.0)):
            live = h
            f = _values(live, axis, sense)
            best = float(_corners(f, surface).max())
            flat = f.reshape(len(f), -1)
            for _ in range(_LEVELS):
                ub = flat.max(axis=1)
                keep = ub > best + eps
                if not keep.any():
                    break
                if np.count_nonzero(keep) > _PIECES:
                    best = float(ub.max())  # an outer bound: never inside the geometry
                    break
                live, f = live[keep], f[keep]
                if surface:
                    live = _split_patches(live, _bend(f, 1) >= _bend(f, 2))
                else:
                    live = _split_curves(live)
                f = _values(live, axis, sense)
                best = max(best, float(_corners(f, surface).max()))
                flat = f.reshape(len(f), -1)
            out[side, axis] = sense * best
    return out[0], out[1]


def sampled_extremes(
    evaluate: Callable[[np.ndarray], np.ndarray],
    lo: np.ndarray,
    hi: np.ndarray,
    counts: tuple[int, ...],
    rounds: int = 12,
) -> tuple[np.ndarray, np.ndarray]:
    """The box of a curve (one parameter) or surface (two) known only by evaluation.

    A grid of ``counts`` points over ``[lo, hi]``, then for each of the six objectives a
    grid of 17 (or 17 x 17) points around its best sample, shrinking 8 times each round
    (all six in one evaluation per round).

    Parameters
    ----------
    evaluate : callable (m, d) params -> (m, 3) points
    lo, hi : (d,) float
        The parameter domain.
    counts : tuple of d ints
        The first grid.

    Returns
    -------
    lo, hi : (3,) float
    """
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    d = len(lo)
    axes = [np.linspace(lo[i], hi[i], counts[i]) for i in range(d)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, d)
    pts = evaluate(grid)
    step = (hi - lo) / (np.asarray(counts) - 1)
    best_t = np.empty((6, d))
    best_v = np.empty(6)
    for k in range(6):
        axis, sense = k // 2, (1.0 if k % 2 else -1.0)
        i = int(np.argmax(sense * pts[:, axis]))
        best_t[k], best_v[k] = grid[i], sense * pts[i, axis]
    local = np.linspace(-1.0, 1.0, 17)
    offs = np.stack(np.meshgrid(*([local] * d), indexing="ij"), axis=-1).reshape(-1, d)
    for _ in range(rounds):  # one evaluation of every objective's grid per round
        cand = np.clip(best_t[:, None, :] + offs[None] * step, lo, hi)  # (6, g, d)
        vals = evaluate(cand.reshape(-1, d)).reshape(6, len(offs), 3)
        for k in range(6):
            axis, sense = k // 2, (1.0 if k % 2 else -1.0)
            j = int(np.argmax(sense * vals[k, :, axis]))
            if sense * vals[k, j, axis] >= best_v[k]:
                best_t[k], best_v[k] = cand[k, j], sense * vals[k, j, axis]
        step = step / 8.0
    signs = np.array([-1.0, 1.0] * 3)
    ext = (best_v * signs).reshape(3, 2)
    return ext[:, 0], ext[:, 1]
