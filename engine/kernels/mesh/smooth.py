"""Mesh smoothing on a sparse vertex adjacency: Laplacian and Taubin's lambda|mu.

The umbrella operator ``L v_i = mean(v_j, j ~ i) - v_i`` is one sparse matrix-vector
product (scipy.sparse CSR over the mesh's edges), applied to all vertices at once.
Laplacian smoothing steps ``v += lambda L v`` and shrinks a closed surface; Taubin's
(``lambda > 0`` then ``mu < -lambda`` each iteration, "A signal processing approach to fair
surface design", SIGGRAPH 1995) is a low-pass filter whose gain at the lowest frequencies,
``(1 - lambda k)(1 - mu k)`` for small ``k``, is slightly above 1: it does not shrink, but
it grows a closed surface a little each step (a clean icosphere of 2,562 vertices by
0.25 % in 10 steps and 2.5 % in 100, as trimesh's ``filter_taubin`` does). With
``keep_volume`` each closed part is then scaled about its centroid back to the volume it
started with after every step (Desbrun, Meyer, Schroeder & Barr, "Implicit fairing of
irregular meshes using diffusion and curvature flow", SIGGRAPH 1999, section 2.4: a
uniform scale by ``(V0 / V)^(1/3)``), which changes no shape, only its size.
Vertices on a boundary edge (or a non-manifold one) are held where they are, so an open
sheet keeps its outline and a closed mesh stays closed (no vertex or face is added or
removed: the connectivity is the input's).
"""

from __future__ import annotations

import numpy as np

from ..io.meshdata import fan_triangles
from .measure import next_corner, union_find

__all__ = ["held_vertices", "smooth", "umbrella", "VolumeKeeper"]


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
    keep_volume: bool = False,
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
        ``taubin`` (grows a closed surface slightly unless ``keep_volume``) or
        ``laplacian`` (shrinks).
    lamb, mu : float
        Step sizes: ``0 < lamb < 1``; Taubin's ``mu < -lamb`` (pass band
        ``1 / lamb + 1 / mu``: 0.5 and -0.53 give about 0.11).
    keep_volume : bool
        After every step, scale each closed part (no boundary or non-manifold edge, a
        volume not 0) about its centroid back to its starting volume
        (:class:`VolumeKeeper`); open parts are left as the filter makes them.
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
    keeper = VolumeKeeper(v, face_indices, face_offsets, held) if keep_volume else None
    for _ in range(iterations):
        for s in steps:
            step = w @ v
            step -= v
            step *= s if free is None else s * free
            v += step
        if keeper is not None:
            keeper.restore(v)
    return v


class VolumeKeeper:
    """Scales the closed parts of a mesh back to the volumes they had when it was made.

    A part is a set of faces joined through shared vertices; it is closed when none of its
    vertices is held (on an edge not shared by exactly two faces) and its volume is not 0.
    :meth:`restore` scales each closed part about its volume centroid (the centroid of the
    solid, from the signed tetrahedra of its fan triangles) by ``(V0 / V)^(1/3)``, all
    parts at once; the connectivity is fixed, so the fans and parts are found once.
    """

    def __init__(
        self, vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray, held
    ):
        fi = np.asarray(face_indices, dtype=np.int64)
        fo = np.asarray(face_offsets, dtype=np.int64)
        n = len(vertices)
        root, _ = union_find(n, fi, fi[next_corner(fo)])
        used = np.zeros(n, dtype=bool)
        used[fi] = True
        parts, self.part = np.unique(root, return_inverse=True)
        self.n_parts = parts.size
        self.tris = fan_triangles(fi, fo)
        self.tri_part = self.part[self.tris[:, 0]]
        open_part = np.zeros(self.n_parts, dtype=bool)
        open_part[self.part[np.asarray(held, dtype=bool) | ~used]] = True
        self.volume0, _ = self._measure(np.asarray(vertices, dtype=np.float64))
        size = float(np.ptp(np.asarray(vertices, dtype=np.float64)[used], axis=0).max())
        self.closed = ~open_part & (np.abs(self.volume0) > 1e-12 * size**3)

    def _measure(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each part's signed volume (parts,) and volume centroid (parts, 3)."""
        count = np.bincount(self.part, minlength=self.n_parts)
        # a point inside each part's box, so the tetrahedra are well conditioned
        origin = _sums(self.part, v, self.n_parts) / np.maximum(count, 1)[:, None]
        o = origin[self.tri_part]
        a, b, c = (v[self.tris[:, k]] - o for k in range(3))
        six = np.einsum("ij,ij->i", a, np.cross(b, c))  # 6 x the tetrahedron's volume
        volume = np.bincount(self.tri_part, six, self.n_parts) / 6.0
        # sum of volume x (tetrahedron's centroid - origin)
        moment = _sums(self.tri_part, six[:, None] * (a + b + c), self.n_parts) / 24.0
        centre = origin + np.divide(
            moment, volume[:, None], out=np.zeros_like(moment), where=volume[:, None] != 0
        )
        return volume, centre

    def restore(self, v: np.ndarray) -> None:
        """Scale the closed parts of ``v`` (n, 3), in place, back to their first volumes."""
        volume, centre = self._measure(v)
        ratio = np.divide(self.volume0, volume, out=np.ones_like(volume), where=volume != 0)
        kept = self.closed & (ratio > 0)
        at = np.flatnonzero(kept[self.part])  # the other parts' vertices stay bit for bit
        c = centre[self.part[at]]
        v[at] = c + (v[at] - c) * np.cbrt(ratio)[self.part[at], None]


def _sums(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """(n, 3) sums of the rows of ``values`` (m, 3) by ``index`` (m,)."""
    return np.stack([np.bincount(index, values[:, k], n) for k in range(3)], 1)
