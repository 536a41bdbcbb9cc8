"""Copies of a point set or a mesh under many affine maps, as one array operation.

``n`` copies of ``m`` vertices are one batched ``matmul`` of the ``(m, 3)`` vertices with the
``(n, 3, 3)`` maps (several times faster than ``einsum`` here); the faces of every copy are
the original index array shifted by ``k * m``, built by broadcasting. Copies whose map
mirrors (negative determinant) get their faces reversed, so every copy keeps facing outward.
"""

from __future__ import annotations

import numpy as np


def copy_points(points: np.ndarray, linear: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Every point under every map.

    Parameters
    ----------
    points : (m, 3) float
    linear : (n, 3, 3) float
    offsets : (n, 3) float
        Copy ``k`` is ``points @ linear[k].T + offsets[k]``.

    Returns
    -------
    (n, m, 3) float64
    """
    p = np.asarray(points, dtype=np.float64)
    out = np.matmul(p[None], np.asarray(linear, dtype=np.float64).transpose(0, 2, 1))
    out += np.asarray(offsets, dtype=np.float64)[:, None, :]
    return out


def copy_mesh(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    linear: np.ndarray,
    offsets: np.ndarray,
    reversed_indices: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One mesh holding a copy of the input per map, copies in order.

    Parameters
    ----------
    vertices : (m, 3) float
    face_indices : (k,) int
    face_offsets : (f + 1,) int
    linear : (n, 3, 3) float
    offsets : (n, 3) float
    reversed_indices : (k,) int, optional
        ``face_indices`` with every face reversed, used for the copies whose map mirrors
        (computed by the caller, who knows the face layout); required when any does.

    Returns
    -------
    vertices : (n * m, 3) float64
    face_indices : (n * k,) int64
    face_offsets : (n * f + 1,) int64
    """
    n, m = len(linear), len(vertices)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    v = copy_points(vertices, linear, offsets).reshape(n * m, 3)
    base = np.broadcast_to(fi, (n, len(fi)))
    mirrored = np.linalg.det(linear) < 0
    if mirrored.any():
        if reversed_indices is None:
            raise ValueError("a mirroring map needs the reversed faces")
        base = np.where(mirrored[:, None], np.asarray(reversed_indices, np.int64), base)
    indices = (base + (np.arange(n, dtype=np.int64) * m)[:, None]).reshape(-1)
    tails = (fo[1:][None, :] + (np.arange(n, dtype=np.int64) * len(fi))[:, None]).reshape(-1)
    return v, indices, np.concatenate([np.zeros(1, dtype=np.int64), tails])
