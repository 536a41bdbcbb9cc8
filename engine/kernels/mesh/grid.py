"""Quad faces of a structured grid of points (shared by tessellation and surfaces.grid)."""

from __future__ import annotations

import numpy as np


def grid_faces(
    nu: int, nv: int, closed_u: bool = False, closed_v: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Quads of an ``(nu, nv)`` grid of vertices stored row-major (vertex ``i*nv + j``).

    Parameters
    ----------
    nu, nv : int
        Grid size; each must be >= 2 (>= 3 in a closed direction).
    closed_u, closed_v : bool
        Wrap the last row (column) back to the first.

    Returns
    -------
    face_indices : (4 * n_faces,) int64
        Flat vertex indices, counter-clockwise when u runs along +x and v along +y.
    face_offsets : (n_faces + 1,) int64

    Example
    -------
    >>> fi, fo = grid_faces(2, 2)
    >>> fi.tolist(), fo.tolist()
    ([0, 2, 3, 1], [0, 4])
    """
    if nu < 2 or nv < 2:
        raise ValueError(f"a grid needs at least 2 x 2 points, got {nu} x {nv}")
    iu = np.arange(nu if closed_u else nu - 1)
    iv = np.arange(nv if closed_v else nv - 1)
    i0, j0 = np.meshgrid(iu, iv, indexing="ij")
    i1 = (i0 + 1) % nu
    j1 = (j0 + 1) % nv
    quads = np.stack([i0 * nv + j0, i1 * nv + j0, i1 * nv + j1, i0 * nv + j1], axis=-1)
    face_indices = quads.reshape(-1).astype(np.int64)
    face_offsets = np.arange(0, face_indices.size + 1, 4, dtype=np.int64)
    return face_indices, face_offsets
