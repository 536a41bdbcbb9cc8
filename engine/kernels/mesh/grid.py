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
    face_indices = quads.reshape(-1).astype(np.int64, copy=False)
    face_offsets = np.arange(0, face_indices.size + 1, 4, dtype=np.int64)
    return face_indices, face_offsets


def collapse_poles(
    points: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray, rtol: float = 1e-10
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge each degenerate grid row or column (a pole) into one vertex.

    A surface that reaches an axis (a revolve whose profile ends on it, a sphere's pole)
    has a whole row of the grid at one point; its quads would have zero-area corners. Each
    such row (or column) becomes a single vertex, the quads touching it become triangles,
    and faces left with fewer than 3 corners are dropped.

    Parameters
    ----------
    points : (nu, nv, 3) float
        The grid, row-major as in :func:`grid_faces`.
    face_indices, face_offsets
        Its faces from :func:`grid_faces`.
    rtol : float
        A row is a pole when all its points lie within ``rtol`` times the grid's largest
        coordinate (at least 1) of its first point.

    Returns
    -------
    vertices, face_indices, face_offsets
        Unchanged (vertices flattened) when there is no pole.
    """
    from .repair import compact, drop_collapsed

    pts = np.asarray(points, dtype=np.float64)
    nu, nv, _ = pts.shape
    flat = pts.reshape(-1, 3)
    tol = rtol * max(1.0, float(np.abs(pts).max(initial=0.0)))
    rows = np.abs(pts - pts[:, :1]).max(axis=(1, 2)) <= tol
    cols = np.abs(pts - pts[:1, :]).max(axis=(0, 2)) <= tol
    if not (rows.any() or cols.any()):
        return flat, face_indices, face_offsets
    ids = np.arange(nu * nv).reshape(nu, nv)
    ids[rows] = ids[rows][:, :1]
    ids[:, cols] = ids[:, cols][:1, :]
    fi, fo = drop_collapsed(ids.reshape(-1)[face_indices], face_offsets, nu * nv)
    return compact(flat, fi, fo)
