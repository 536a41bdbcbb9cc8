"""Discrete curvature of a triangle mesh per vertex: mean (cotangent Laplacian) and Gaussian
(angle defect), both per unit area.

Meyer, Desbrun, Schroeder & Barr, "Discrete differential-geometry operators for
triangulated 2-manifolds" (VisMath 2002, published 2003):

* the mixed area of each vertex: its Voronoi area in every non-obtuse triangle
  (``(|ab|^2 cot C + |ac|^2 cot B) / 8`` at corner a), and in an obtuse triangle half the
  triangle's area at the obtuse corner, a quarter at the other two. The mixed areas tile
  the surface (they sum to its area);
* the mean curvature normal ``K(x_i) = 1 / (2 A_i) sum_j (cot a_ij + cot b_ij) (x_i - x_j)``
  (the cotangent Laplacian, one sparse matrix over the edges), the mean curvature
  ``H = K . n / 2`` along the unit vertex normal (positive where the surface bends away
  from its normal, as a sphere with outward faces: 1/r);
* the Gaussian curvature ``(2 pi - sum of the corner angles at i) / A_i``, whose sum times
  the areas is the total angle defect: ``2 pi chi`` on a closed mesh (Gauss-Bonnet),
  exactly up to rounding.

A vertex on a boundary (an edge on one face, or more than two) has neither: its values
are 0 and it is reported.
"""

from __future__ import annotations

import numpy as np

__all__ = ["angles", "cotangent_laplacian", "curvatures", "mixed_areas"]


def _corners(vertices: np.ndarray, triangles: np.ndarray):
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    p = v[t]  # (m, 3 corners, 3)
    # the edge opposite each corner k runs from corner k+1 to k+2
    e = np.roll(p, -2, axis=1) - np.roll(p, -1, axis=1)
    return v, t, p, e


def angles(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(m, 3) the interior angle at each corner of each triangle (atan2: exact near 0, pi)."""
    _, _, p, _ = _corners(vertices, triangles)
    u = np.roll(p, -1, axis=1) - p  # corner k to k+1
    w = np.roll(p, -2, axis=1) - p  # corner k to k+2
    cross = np.linalg.norm(np.cross(u, w), axis=2)
    return np.arctan2(cross, np.einsum("mki,mki->mk", u, w))


def _cotangents(vertices: np.ndarray, triangles: np.ndarray):
    """(m, 3) cot of each corner's angle, (m,) twice each area, (m, 3) squared opposite edges."""
    _, _, p, e = _corners(vertices, triangles)
    u = np.roll(p, -1, axis=1) - p
    w = np.roll(p, -2, axis=1) - p
    double = np.linalg.norm(np.cross(u[:, 0], w[:, 0]), axis=1)
    dots = np.einsum("mki,mki->mk", u, w)
    cot = np.divide(dots, double[:, None], out=np.zeros_like(dots), where=double[:, None] > 0)
    return cot, double, np.einsum("mki,mki->mk", e, e)


def cotangent_laplacian(vertices: np.ndarray, triangles: np.ndarray):
    """The (n, n) CSR matrix ``L`` with ``(L x)_i = sum_j (cot a_ij + cot b_ij) / 2 (x_i -
    x_j)`` over the edges of ``triangles`` (t, 3) (a triangle without area adds nothing)."""
    from scipy import sparse

    v, t, _, _ = _corners(vertices, triangles)
    cot, _, _ = _cotangents(v, t)
    n = len(v)
    # corner k's cotangent weighs the edge opposite it: (k+1, k+2)
    i = np.roll(t, -1, axis=1).reshape(-1)
    j = np.roll(t, -2, axis=1).reshape(-1)
    w = 0.5 * cot.reshape(-1)
    off = sparse.coo_matrix((np.r_[-w, -w], (np.r_[i, j], np.r_[j, i])), shape=(n, n)).tocsr()
    return off - sparse.diags(np.asarray(off.sum(axis=1)).ravel())


def mixed_areas(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(n,) each vertex's mixed Voronoi area (Meyer et al. 2003, section 3.3)."""
    v, t, _, _ = _corners(vertices, triangles)
    cot, double, sq = _cotangents(v, t)
    area = 0.5 * double
    # Voronoi part at corner k: (|edge k,k+1|^2 cot(k+2) + |edge k,k+2|^2 cot(k+1)) / 8;
    # the edge k -> k+1 is opposite corner k+2, the edge k -> k+2 opposite corner k+1
    voronoi = (np.roll(sq, -2, axis=1) * np.roll(cot, -2, axis=1)) + (
        np.roll(sq, -1, axis=1) * np.roll(cot, -1, axis=1)
    )
    voronoi /= 8.0
    obtuse = cot < 0  # the angle at that corner is over 90 degrees
    any_obtuse = obtuse.any(axis=1, keepdims=True)
    part = np.where(any_obtuse, np.where(obtuse, 0.5, 0.25) * area[:, None], voronoi)
    return np.bincount(t.reshape(-1), part.reshape(-1), minlength=len(v))


def curvatures(
    vertices: np.ndarray, triangles: np.ndarray, normals: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean and Gaussian curvature at every vertex, per unit area.

    Parameters
    ----------
    vertices : (n, 3) float
    triangles : (t, 3) int
    normals : (n, 3) float
        Unit vertex normals (the sign of the mean curvature follows them).

    Returns
    -------
    mean, gaussian : (n,) float
        0 on boundary vertices and on vertices no triangle uses.
    boundary : (n,) bool
        The vertices on an edge that is not shared by exactly two triangles.
    """
    v, t, _, _ = _corners(vertices, triangles)
    n = len(v)
    area = mixed_areas(v, t)
    lap = cotangent_laplacian(v, t) @ v  # sum_j w_ij (x_i - x_j)
    mean_normal = np.divide(lap, area[:, None], out=np.zeros_like(lap), where=area[:, None] > 0)
    mean = 0.5 * np.einsum("ij,ij->i", mean_normal, np.asarray(normals, dtype=np.float64))
    angle_sum = np.bincount(t.reshape(-1), angles(v, t).reshape(-1), minlength=n)
    defect = 2.0 * np.pi - angle_sum
    gauss = np.divide(defect, area, out=np.zeros(n), where=area > 0)
    # edges used by other than two triangles mark their ends as boundary
    e = np.sort(np.stack([t, np.roll(t, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
    keys, uses = np.unique(e[:, 0] * n + e[:, 1], return_counts=True)
    odd = keys[uses != 2]
    boundary = np.zeros(n, dtype=bool)
    boundary[odd // n] = True
    boundary[odd % n] = True
    unused = np.bincount(t.reshape(-1), minlength=n) == 0
    off = boundary | unused
    mean[off] = 0.0
    gauss[off] = 0.0
    return mean, gauss, boundary
