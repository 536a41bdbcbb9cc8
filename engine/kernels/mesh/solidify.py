"""Thickening a surface into a closed shell, with angle-weighted vertex normals."""

from __future__ import annotations

import numpy as np

from .halfedge import build_halfedges
from .measure import next_corner
from .meshops import face_normals, reverse_faces

__all__ = ["planar_rim_directions", "solidify", "vertex_normals"]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]


def vertex_normals(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> np.ndarray:
    """(n, 3) unit vertex normals: face normals weighted by the corner angles.

    Thuermer & Wuethrich 1998, "Computing vertex normals from polygonal facets": each face
    adds its unit normal times its interior angle at the vertex, so the result does not
    depend on how the faces around a vertex are split. A vertex no face uses gets 0.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    nxt = next_corner(fo)
    prv = np.empty_like(nxt)
    prv[nxt] = np.arange(nxt.size)
    e1 = v[fi[nxt]] - v[fi]
    e0 = v[fi[prv]] - v[fi]
    angle = np.arctan2(np.linalg.norm(np.cross(e0, e1), axis=1), np.einsum("ij,ij->i", e0, e1))
    fn = face_normals(v, fi, fo)
    corner_n = fn[np.repeat(np.arange(fo.size - 1), np.diff(fo))] * angle[:, None]
    out = np.stack([np.bincount(fi, weights=corner_n[:, k], minlength=len(v)) for k in range(3)], 1)
    length = np.linalg.norm(out, axis=1, keepdims=True)
    return np.divide(out, length, out=np.zeros_like(out), where=length > 0)


def solidify(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    thickness: float | np.ndarray,
    offset: float = 0.0,
    planar_rims: bool = True,
) -> MeshArrays:
    """A closed shell around an oriented surface: two offset copies joined along the rims.

    Each vertex moves along its angle-weighted normal (:func:`vertex_normals`): the front
    copy by ``t (1 + offset) / 2``, the back copy by ``-t (1 - offset) / 2``, so offset -1
    puts the shell behind the surface, 0 centres it, 1 puts it in front. The back copy's
    faces are reversed, and every boundary edge ``a -> b`` gets the quad
    ``(b, a, a', b')`` joining the copies, so an orientable manifold surface, open or
    closed, gives a watertight shell whose faces look out of the material. The offset is a
    constant distance along the normals: a thickness above the surface's radius of curvature
    folds the back copy through itself.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
        An oriented manifold surface, possibly with boundary.
    thickness : float or (n,) float
        Wall thickness, > 0; one value per vertex for a varying wall.
    offset : float
        Where the wall sits relative to the surface, -1 .. 1.
    planar_rims : bool
        Keep each planar boundary loop in its plane (:func:`planar_rim_directions`): a
        shade whose bottom rim lies on z = 0 still stands on z = 0 when thickened.

    Returns
    -------
    vertices : (2 n, 3) float64
        Front copy, then back copy.
    face_indices, face_offsets
        Front faces, back faces (reversed), then one quad per boundary edge.

    Raises
    ------
    ValueError
        A thickness that is not > 0, an offset outside -1 .. 1, a mesh without faces.
    MeshTopologyError
        A non-manifold or inconsistently oriented surface.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    t = np.broadcast_to(np.asarray(thickness, dtype=np.float64), (len(v),))
    if not (np.isfinite(t).all() and (t > 0).all()):
        bad = int(np.argmax(~(np.isfinite(t) & (t > 0))))
        raise ValueError(f"thickness must be > 0, got {t[bad]:g} at vertex {bad}")
    if not -1.0 <= offset <= 1.0:
        raise ValueError(f"offset must be between -1 and 1, got {offset:g}")
    if fo.size < 2:
        raise ValueError("the surface has no faces to thicken")
    he = build_halfedges(fi, fo, len(v))
    n = vertex_normals(v, fi, fo)
    if planar_rims and he.boundary_halfedges.size:
        n = planar_rim_directions(v, he.boundary_edges, n)
    front = v + n * (t * (1.0 + offset) / 2.0)[:, None]
    back = v - n * (t * (1.0 - offset) / 2.0)[:, None]
    nv = len(v)
    b = he.boundary_halfedges
    a_, b_ = he.origin[b], he.vertex[b]
    rims = np.stack([b_, a_, a_ + nv, b_ + nv], axis=1).reshape(-1)
    out_fi = np.concatenate([fi, reverse_faces(fi, fo) + nv, rims])
    out_fo = np.concatenate([fo, fo[-1] + fo[1:], 2 * fo[-1] + np.arange(4, 4 * b.size + 1, 4)])
    return np.concatenate([front, back]), out_fi, out_fo


def planar_rim_directions(
    vertices: np.ndarray, boundary_edges: np.ndarray, normals: np.ndarray, tol: float = 1e-6
) -> np.ndarray:
    """Offset directions with the vertices of planar boundary loops kept in their plane.

    Each loop (a connected component of the boundary edges) gets its best-fit plane from
    the eigenvectors of its covariance (all loops at once, a batched ``eigh``); a loop whose
    vertices are within ``tol`` of its size from that plane is planar. Its vertices then
    move along their normal projected into the plane, scaled by ``1 / |projection|^2`` so
    the wall keeps its thickness measured along the surface normal. A loop whose surface
    meets the plane at less than 30 degrees (a flat sheet lying in its own rim's plane) is
    left alone: no in-plane move could make its wall.

    Parameters
    ----------
    vertices : (n, 3) float
    boundary_edges : (b, 2) int
        Boundary edges (from a half-edge structure).
    normals : (n, 3) float
        Unit vertex normals.

    Returns
    -------
    (n, 3) float: ``normals`` with the rim vertices' rows replaced.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    v = np.asarray(vertices, dtype=np.float64)
    e = np.asarray(boundary_edges, dtype=np.int64)
    rim = np.unique(e)
    local = np.searchsorted(rim, e)
    graph = coo_matrix((np.ones(len(e)), (local[:, 0], local[:, 1])), shape=(rim.size,) * 2)
    k, loop = connected_components(graph, directed=False)
    count = np.bincount(loop, minlength=k).astype(np.float64)
    p = v[rim]
    centre = np.stack([np.bincount(loop, p[:, i], k) for i in range(3)], 1) / count[:, None]
    d = p - centre[loop]
    cov = np.zeros((k, 3, 3))
    for i in range(3):
        for j in range(3):
            cov[:, i, j] = np.bincount(loop, d[:, i] * d[:, j], k)
    _, vecs = np.linalg.eigh(cov)
    plane = vecs[:, :, 0]  # the normal: the direction of least spread
    dev = np.abs(np.einsum("ij,ij->i", d, plane[loop]))
    size = np.zeros(k)
    np.maximum.at(size, loop, np.linalg.norm(d, axis=1))
    worst = np.zeros(k)
    np.maximum.at(worst, loop, dev)
    planar = (count >= 3) & (worst <= tol * np.maximum(size, 1e-300))
    nrm = np.asarray(normals, dtype=np.float64)[rim]
    pn = plane[loop]
    proj = nrm - np.einsum("ij,ij->i", nrm, pn)[:, None] * pn
    length2 = np.einsum("ij,ij->i", proj, proj)
    steep = length2 >= 0.25  # the surface within 60 degrees of the plane's normal
    ok_loop = np.ones(k, dtype=bool)
    np.logical_and.at(ok_loop, loop, steep)
    use = planar[loop] & ok_loop[loop]
    out = np.array(normals, dtype=np.float64)
    out[rim[use]] = proj[use] / length2[use, None]
    return out
