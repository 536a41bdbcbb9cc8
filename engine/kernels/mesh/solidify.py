"""Thickening a surface into a closed shell, with angle-weighted vertex normals."""

from __future__ import annotations

import numpy as np

from .halfedge import build_halfedges
from .measure import next_corner
from .meshops import face_normals, reverse_faces

__all__ = ["solidify", "vertex_normals"]

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
    front = v + n * (t * (1.0 + offset) / 2.0)[:, None]
    back = v - n * (t * (1.0 - offset) / 2.0)[:, None]
    nv = len(v)
    b = he.boundary_halfedges
    a_, b_ = he.origin[b], he.vertex[b]
    rims = np.stack([b_, a_, a_ + nv, b_ + nv], axis=1).reshape(-1)
    out_fi = np.concatenate([fi, reverse_faces(fi, fo) + nv, rims])
    out_fo = np.concatenate([fo, fo[-1] + fo[1:], 2 * fo[-1] + np.arange(4, 4 * b.size + 1, 4)])
    return np.concatenate([front, back]), out_fi, out_fo
