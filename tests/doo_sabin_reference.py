"""The Doo-Sabin corner rule as the kernel computed it before its sparse form: per face
size, the circulant matrix of weights (``doo_sabin_weights``) applied by einsum to the
face's corners; the boundary Chaikin points and the kept corners as before. A reference for
the tests and the bench row; the connectivity is the kernel's (unchanged)."""

from __future__ import annotations

import numpy as np

from formgraph.kernels.mesh.halfedge import HalfEdges
from formgraph.kernels.mesh.subdivision import doo_sabin_weights


def doo_sabin_points(v: np.ndarray, he: HalfEdges) -> np.ndarray:
    """The new points of one Doo-Sabin level: a corner point per half-edge, two Chaikin
    points per boundary edge, then the kept corners (the kernel's order)."""
    fi, fo = he.origin, he.face_offsets
    sizes = he.face_sizes
    d = v.shape[1]
    corner = np.empty((fi.size, d))
    for k in np.unique(sizes):
        faces = np.flatnonzero(sizes == k)
        idx = fo[faces][:, None] + np.arange(k)
        corner[idx] = np.einsum("ij,fjd->fid", doo_sabin_weights(int(k)), v[fi[idx]])
    b = he.boundary_halfedges
    a_b, z_b = v[he.origin[b]], v[he.vertex[b]]
    chaikin = np.stack([0.75 * a_b + 0.25 * z_b, 0.25 * a_b + 0.75 * z_b], axis=1).reshape(-1, d)
    fans = he.fans
    corner_fan = ~fans.closed & (fans.sizes == 1) & he.is_manifold_vertex[fans.vertex]
    return np.concatenate([corner, chaikin, v[fans.vertex[corner_fan]]])
