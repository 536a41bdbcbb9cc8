"""Thickening a surface into a closed shell, with angle-weighted vertex normals."""

from __future__ import annotations

import numpy as np

from .halfedge import build_halfedges
from .measure import next_corner
from .meshops import face_normals, reverse_faces

__all__ = [
    "behind_beds",
    "planar_rim_directions",
    "planar_rim_moves",
    "solidify",
    "vertex_normals",
]

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
    n = normals = vertex_normals(v, fi, fo)
    planes = np.zeros((0, 4))
    if planar_rims and he.boundary_halfedges.size:
        n, planes = planar_rim_moves(v, he.boundary_edges, normals)
    front = v + n * (t * (1.0 + offset) / 2.0)[:, None]
    back = v - n * (t * (1.0 - offset) / 2.0)[:, None]
    if len(planes):
        front, back = (behind_beds(v, normals, copy, planes) for copy in (front, back))
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
    """Offset directions with the vertices of planar boundary loops kept in their plane
    (:func:`planar_rim_moves`, its directions alone)."""
    return planar_rim_moves(vertices, boundary_edges, normals, tol)[0]


def planar_rim_moves(
    vertices: np.ndarray, boundary_edges: np.ndarray, normals: np.ndarray, tol: float = 1e-6
) -> tuple[np.ndarray, np.ndarray]:
    """Offset directions with the vertices of planar boundary loops kept in their plane,
    and those planes.

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
    directions : (n, 3) float
        ``normals`` with the rim vertices' rows replaced.
    planes : (p, 4) float
        The planes of the loops kept in them: unit normal, offset (``n . x = c``).
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
    kept = np.unique(loop[use])
    planes = np.column_stack([plane[kept], np.einsum("ij,ij->i", plane[kept], centre[kept])])
    return out, planes


def behind_beds(
    vertices: np.ndarray,
    normals: np.ndarray,
    moved: np.ndarray,
    planes: np.ndarray,
    rise: float = 0.5,
    tol: float = 1e-9,
) -> np.ndarray:
    """An offset copy kept behind every rim plane that bounds the surface (a bed), without
    folds.

    A planar rim keeps its vertices in its plane, but the next rings of an offset wall move
    along their normals, which near the rim of a flaring wall point through the plane: a
    shade stood on a ring of vertices below the bed, and the section showed the wall folding
    back. A plane counts as a bed when the whole surface lies on one side of it (to ``tol``
    of its size). The wall cut by the plane starts where the offset surface meets it (the
    rim's moved vertex); the vertices of the offset copy that fell behind the bed, or too
    near it, slide within their tangent plane (which is the offset surface's, to first
    order: the wall keeps its thickness) away from the bed, to ``rise`` times their
    vertex's own height above it. Heights along the wall then grow with the surface's
    (``max`` of two growing functions), so the copy neither crosses the bed nor folds back;
    vertices far from it keep their place. Where the surface is nearly parallel to the bed
    (within 15 degrees) a vertex that crossed it stops where its move meets it.

    Parameters
    ----------
    vertices : (n, 3) float
        The surface.
    normals : (n, 3) float
        Its unit vertex normals (the offset surface's tangent planes).
    moved : (n, 3) float
        Each vertex moved (an offset copy).
    planes : (p, 4) float
        Unit normals and offsets of the rim planes (:func:`planar_rim_moves`).
    rise : float
        The height above the bed, as a share of the vertex's own, that a moved vertex at
        least keeps (0 < rise < 1).

    Returns
    -------
    (n, 3) float: ``moved``, with the vertices near a bed slid away from it.
    """
    v = np.asarray(vertices, dtype=np.float64)
    nrm = np.asarray(normals, dtype=np.float64)
    out = np.array(moved, dtype=np.float64)
    eps = tol * max(float(np.ptp(v, axis=0).max()), 1e-300)
    for plane in np.asarray(planes, dtype=np.float64).reshape(-1, 4):
        up, level = -plane[:3], -plane[3]  # height: up . x - level, >= 0 on the surface
        height = v @ up - level
        if height.min() < -eps:  # the surface is on the other side, or on both
            if height.max() > eps:
                continue  # the plane bounds nothing
            up, level, height = -up, -level, -height
        raise_by = np.maximum(rise * height, 0.0) - (out @ up - level)
        low = np.flatnonzero(raise_by > eps)
        if not low.size:
            continue
        # the steepest way up within each vertex's tangent plane, and its climb per length
        slope = up - np.einsum("ij,j->i", nrm[low], up)[:, None] * nrm[low]
        climb2 = np.einsum("ij,ij->i", slope, slope)
        steep = climb2 >= np.sin(np.radians(15.0)) ** 2
        i = low[steep]
        out[i] += slope[steep] * (raise_by[i] / climb2[steep])[:, None]
        # nearly parallel to the bed: a vertex that crossed it stops where its move meets it
        j = low[~steep]
        below = (out[j] @ up - level) < 0
        j, step = j[below], out[j[below]] - v[j[below]]
        out[j] = v[j] + step * (height[j] / -(step @ up))[:, None]
    return out
