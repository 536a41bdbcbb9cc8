"""Mesh smoothing on a sparse vertex adjacency: Laplacian and Taubin's lambda|mu.

The umbrella operator ``L v_i = mean(v_j, j ~ i) - v_i`` is one sparse matrix-vector
product (scipy.sparse CSR over the mesh's edges), applied to all vertices at once.
Laplacian smoothing steps ``v += lambda L v`` and shrinks a closed surface; Taubin's
(``lambda > 0`` then ``mu < -lambda`` each iteration, "A signal processing approach to fair
surface design", SIGGRAPH 1995) is a low-pass filter that keeps the volume to first order.
Vertices on a boundary edge (or a non-manifold one) are held where they are, so an open
sheet keeps its outline and a closed mesh stays closed (no vertex or face is added or
removed: the connectivity is the input's).
"""

from __future__ import annotations

import numpy as np

from .measure import next_corner

__all__ = ["held_vertices", "smooth", "umbrella"]


def _halfedges(face_indices: np.ndarray, face_offsets: np.ndarray):
    fi = np.asarray(face_indices, dtype=np.int64)
    return fi, fi[next_corner(face_offsets)]


def umbrella(n: int, face_indices: np.ndarray, face_offsets: np.ndarray):
    """The (n, n) CSR matrix averaging each vertex's edge neighbours (rows sum to 1; an
    isolated vertex's row is empty) and the (n, n) edge-use counts (2 on an interior edge)."""
    from scipy import sparse

    a, b = _halfedges(face_indices, face_offsets)
    uses = sparse.coo_matrix((np.ones(a.size), (a, b)), shape=(n, n)).tocsr()
    uses = uses + uses.T  # an edge of two faces counts 2, whatever its orientation
    adj = uses.copy()
    adj.data[:] = 1.0
    deg = np.asarray(adj.sum(axis=1)).ravel()
    inv = np.divide(1.0, deg, out=np.zeros(n), where=deg > 0)
    return sparse.diags(inv) @ adj, uses


def held_vertices(uses) -> np.ndarray:
    """(n,) bool: vertices on an edge not shared by exactly two faces."""
    coo = uses.tocoo()
    odd = coo.data != 2
    held = np.zeros(uses.shape[0], dtype=bool)
    held[coo.row[odd]] = True
    held[coo.col[odd]] = True
    return held


def smooth(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    iterations: int = 10,
    method: str = "taubin",
    lamb: float = 0.5,
    mu: float = -0.53,
) -> np.ndarray:
    """Smoothed vertex positions (n, 3) of a polygon mesh; boundary vertices held.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices, face_offsets
        The faces (any polygons).
    iterations : int
        Smoothing steps (a Taubin step is one lambda and one mu pass).
    method : str
        ``taubin`` (volume kept) or ``laplacian`` (shrinks).
    lamb, mu : float
        Step sizes: ``0 < lamb < 1``; Taubin's ``mu < -lamb`` (pass band
        ``1 / lamb + 1 / mu``: 0.5 and -0.53 give about 0.11).
    """
    v = np.array(vertices, dtype=np.float64)
    if method not in ("taubin", "laplacian"):
        raise ValueError(f"method must be taubin or laplacian, got {method!r}")
    if not len(v) or np.asarray(face_offsets).size < 2 or iterations == 0:
        return v
    w, uses = umbrella(len(v), face_indices, face_offsets)
    held = held_vertices(uses)
    free = None if not held.any() else (~held).astype(np.float64)[:, None]
    steps = (lamb, mu) if method == "taubin" else (lamb,)
    for _ in range(iterations):
        for s in steps:
            step = w @ v
            step -= v
            step *= s if free is None else s * free
            v += step
    return v
