"""Affine maps as arrays: batched Euler rotations, alignment rotations and frames.

Every function takes one value or one per copy and returns stacks of ``(n, 3, 3)``
matrices, so a transform of ``n`` copies is one ``einsum``.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def per_copy(value: Any, n: int, name: str, *, width: int = 3) -> np.ndarray:
    """``value`` broadcast to ``(n, width)``: one row for all copies, or exactly one per copy.

    A number is one row of ``width`` equal entries; a flat list of numbers is one number per
    copy (each spread over the row); rows of 2 get z = 0.

    Raises
    ------
    ValueError
        When the count is neither 1 nor ``n``, or a value is not finite.
    """
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        a = np.full((1, width), float(a))
    elif a.ndim == 1:
        a = np.repeat(a[:, None], width, axis=1)
    elif a.ndim == 2 and a.shape[1] == 2 and width == 3:
        a = np.concatenate([a, np.zeros((len(a), 1))], axis=1)
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name} must be one value or one per point, got shape {a.shape}")
    if len(a) not in (1, n):
        raise ValueError(f"{name} has {len(a)} values for {n} points; give one, or one per point")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite")
    return np.broadcast_to(a, (n, width))


def euler_matrices(degrees: np.ndarray) -> np.ndarray:
    """Rotations about the fixed x, then y, then z axes: ``Rz @ Ry @ Rx`` per row.

    Parameters
    ----------
    degrees : (n, 3) float
        Angles in degrees about x, y and z.

    Returns
    -------
    (n, 3, 3) float64
        The same matrices as :func:`formgraph.kernels.mesh.meshops.rotation_matrix`, row by
        row, built without a loop.
    """
    a = np.radians(np.asarray(degrees, dtype=np.float64).reshape(-1, 3))
    c, s = np.cos(a), np.sin(a)
    cx, cy, cz = c.T
    sx, sy, sz = s.T
    m = np.empty((len(a), 3, 3))
    # Rz @ Ry @ Rx written out (the ZYX product of the elementary rotations)
    m[:, 0, 0] = cz * cy
    m[:, 0, 1] = cz * sy * sx - sz * cx
    m[:, 0, 2] = cz * sy * cx + sz * sx
    m[:, 1, 0] = sz * cy
    m[:, 1, 1] = sz * sy * sx + cz * cx
    m[:, 1, 2] = sz * sy * cx - cz * sx
    m[:, 2, 0] = -sy
    m[:, 2, 1] = cy * sx
    m[:, 2, 2] = cy * cx
    return m


def align_z(directions: np.ndarray) -> np.ndarray:
    """The minimal rotations taking +z onto each direction (Rodrigues' formula).

    For a unit direction d with ``c = z . d`` and ``v = z x d``, ``R = I + [v]x +
    [v]x^2 / (1 + c)``. Near d = -z the factor ``1 / (1 + c)`` is computed as
    ``(1 - c) / (x^2 + y^2)``, which keeps full precision; for d = -z exactly (the
    formula's singular case) the half turn about x is used.

    Parameters
    ----------
    directions : (n, 3) float
        Non-zero directions (normalized here).

    Returns
    -------
    (n, 3, 3) float64

    Raises
    ------
    ValueError
        For a zero direction.
    """
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    length = np.linalg.norm(d, axis=1)
    if (length <= 1e-300).any():
        i = int(np.argmax(length <= 1e-300))
        raise ValueError(f"align direction {i} is zero; cannot orient a copy along it")
    # the horizontal unit direction (x, y) / rho, from the given components scaled by the
    # larger of them: dividing by a rounded subnormal rho (a direction a hair from -z)
    # would cost up to 30 bits and leave R visibly non-orthogonal
    big = np.maximum(np.abs(d[:, 0]), np.abs(d[:, 1]))
    hx = d[:, 0] / np.where(big > 0, big, 1.0)
    hy = d[:, 1] / np.where(big > 0, big, 1.0)
    hr = np.hypot(hx, hy)
    ux = hx / np.where(hr > 0, hr, 1.0)
    uy = hy / np.where(hr > 0, hr, 1.0)
    d = d / length[:, None]
    x, y, z = d.T
    c = z
    flip = (c < 0) & (big == 0)
    # [v]x^2 / (1 + c) needs x^2 k, x y k, y^2 k with k = 1 / (1 + c); for c < 0 they are
    # (x / rho)^2 (1 - c), ...: x^2 + y^2 itself can underflow to a subnormal whose
    # reciprocal overflows (then 0 * inf made NaN)
    below = c < 0
    root = np.sqrt(np.where(below, 1.0, 1.0 + c))
    sx = np.where(below, ux * np.sqrt(1.0 - c), x / root)
    sy = np.where(below, uy * np.sqrt(1.0 - c), y / root)
    # v = (-y, x, 0); [v]x^2 / (1 + c) written out
    m = np.empty((len(d), 3, 3))
    m[:, 0, 0] = 1.0 - sx * sx
    m[:, 0, 1] = -sx * sy
    m[:, 0, 2] = x
    m[:, 1, 0] = -sx * sy
    m[:, 1, 1] = 1.0 - sy * sy
    m[:, 1, 2] = y
    m[:, 2, 0] = -x
    m[:, 2, 1] = -y
    m[:, 2, 2] = c
    m[flip] = np.diag([1.0, -1.0, -1.0])
    return m


def frames(
    n: int, scale: Any = 1.0, rotate: Any = (0.0, 0.0, 0.0), align: Any = None
) -> np.ndarray:
    """The linear part of each copy's map: scale, then rotate (x, y, z), then align +z.

    Parameters
    ----------
    n : int
        Number of copies.
    scale : float, (n,), (1, 3) or (n, 3)
        One factor for all copies, one per copy, or rows of [sx, sy, sz] (one row for all
        copies, or one per copy); no factor may be 0.
    rotate : (3,) or (n, 3)
        Degrees about x, y, z.
    align : None, (3,) or (n, 3)
        Directions for each copy's +z (applied after the rotation).

    Returns
    -------
    (n, 3, 3) float64
    """
    if n == 0:
        return np.zeros((0, 3, 3))
    s = per_copy(scale, n, "scale")
    if (s == 0).any():
        raise ValueError("scale factors must be non-zero")
    r = per_copy(np.asarray(rotate, dtype=np.float64).reshape(-1, 3), n, "rotate")
    same_r = (r == r[0]).all()
    rot = np.broadcast_to(euler_matrices(r[:1]), (n, 3, 3)) if same_r else euler_matrices(r)
    m = rot * s[:, None, :]  # R @ diag(s): columns scaled
    if align is not None:
        a = per_copy(np.asarray(align, dtype=np.float64).reshape(-1, 3), n, "align")
        same_a = (a == a[0]).all()
        al = np.broadcast_to(align_z(a[:1]), (n, 3, 3)) if same_a else align_z(a)
        m = al @ m
    return np.ascontiguousarray(np.broadcast_to(m, (n, 3, 3)))


def about_center(
    linear: np.ndarray, center: np.ndarray, translate: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The map ``p -> L (p - c) + c + t`` as ``(L, offset)`` with ``p -> L p + offset``."""
    c = np.asarray(center, dtype=np.float64)
    return linear, c - linear @ c + np.asarray(translate, dtype=np.float64)


def apply(points: np.ndarray, linear: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """``points @ linear.T + offset`` for (..., 3) points and one (3, 3) map."""
    return np.asarray(points, dtype=np.float64) @ linear.T + offset
