"""Polygon mesh operations on flat arrays: build, check, triangulate, merge, transform.

A mesh is ``vertices`` (n, 3) float64, ``face_indices`` (m,) int64 (all faces concatenated,
counter-clockwise seen from outside) and ``face_offsets`` (n_faces + 1,) int64.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .halfedge import HalfEdges, build_halfedges
from .measure import face_vectors
from .polygon import WorkLimitError, large_face, triangulate_polygon  # noqa: F401 (re-exported)

_BATCH_UP_TO = 32  # concave faces up to this size are clipped together (O(k^3) each)
_ALONE_UP_TO = 8  # larger faces of one size, up to this many: each on its own

__all__ = [
    "box",
    "dihedral_angles",
    "face_normals",
    "faces_from_lists",
    "merge",
    "reverse_faces",
    "rotation_matrix",
    "transform",
    "triangulate",
    "triangulate_polygon",
    "validate_faces",
]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]


def _vec3(value: float | Sequence[float] | np.ndarray, name: str) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(3, float(a))
    if a.shape == (2,):
        a = np.append(a, 0.0)
    if a.shape != (3,) or not np.isfinite(a).all():
        raise ValueError(f"{name} must be a number or 3 finite numbers, got {value!r}")
    return a


def validate_faces(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> MeshArrays:
    """Check a mesh and return it as fresh float64 / int64 arrays.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int

    Returns
    -------
    vertices : (n, 3) float64
    face_indices : (m,) int64
    face_offsets : (n_faces + 1,) int64

    Raises
    ------
    ValueError
        Vertices that are not finite (n, 3) coordinates.
    MeshTopologyError
        Bad indices, faces under 3 vertices or repeating one, an edge on more than two
        faces, or neighbouring faces whose orientations disagree (a ValueError too).
    """
    v = np.array(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must be an (n, 3) array, got shape {v.shape}")
    bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
    if bad.size:
        raise ValueError(f"vertex {int(bad[0])} is not finite: {v[bad[0]].tolist()}")
    he = build_halfedges(face_indices, face_offsets, v.shape[0])
    return v, np.array(he.origin), np.array(he.face_offsets)


def faces_from_lists(faces: Sequence[Sequence[int]]) -> tuple[np.ndarray, np.ndarray]:
    """Flat ``(face_indices, face_offsets)`` from a list of faces (lists of vertex indices).

    Raises
    ------
    ValueError
        A face that is not a list of whole numbers.
    """
    flat: list[np.ndarray] = []
    for f, face in enumerate(faces):
        a = np.asarray(face) if isinstance(face, (list, tuple, np.ndarray)) else np.asarray(None)
        ok = a.ndim == 1 and a.dtype.kind in "iu"
        if a.ndim == 1 and a.dtype.kind == "f":
            ok = bool(np.isfinite(a).all() and (a == np.round(a)).all())
        if not ok:
            raise ValueError(f"face {f} must be a list of vertex indices, got {face!r}")
        flat.append(a.astype(np.int64))
    sizes = np.array([a.size for a in flat], dtype=np.int64)
    offsets = np.zeros(sizes.size + 1, dtype=np.int64)
    np.cumsum(sizes, out=offsets[1:])
    indices = np.concatenate(flat) if flat else np.zeros(0, dtype=np.int64)
    return indices, offsets


def box(
    size: float | Sequence[float] = 1.0, center: Sequence[float] = (0.0, 0.0, 0.0)
) -> MeshArrays:
    """An axis-aligned box: 8 vertices, 6 quads facing outward.

    Parameters
    ----------
    size : float or (3,) float
        Edge lengths along x, y, z (a number for a cube); each > 0.
    center : (3,) float
        Centre of the box.

    Returns
    -------
    vertices : (8, 3) float64
        Vertex ``i`` is the corner with x, y, z high for bits 0, 1, 2 of ``i``.
    face_indices : (24,) int64
    face_offsets : (7,) int64
        Faces -z, +z, -y, +y, -x, +x.
    """
    s = _vec3(size, "size")
    c = _vec3(center, "center")
    if (s <= 0).any():
        raise ValueError(f"box size must be > 0 along every axis, got {s.tolist()}")
    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1
    vertices = c + (bits - 0.5) * s
    faces = np.array(
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]],
        dtype=np.int64,
    )
    return vertices, faces.reshape(-1), np.arange(0, 25, 4, dtype=np.int64)


def merge(meshes: Sequence[MeshArrays]) -> MeshArrays:
    """Concatenate meshes into one (vertices appended, indices shifted; nothing welded).

    Parameters
    ----------
    meshes : sequence of (vertices, face_indices, face_offsets)

    Returns
    -------
    vertices : (sum n, 3) float64
    face_indices : (sum m,) int64
    face_offsets : (sum n_faces + 1,) int64
    """
    if not meshes:
        return np.zeros((0, 3)), np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64)
    n = np.array([len(v) for v, _, _ in meshes], dtype=np.int64)
    m = np.array([len(fi) for _, fi, _ in meshes], dtype=np.int64)
    v_shift = np.concatenate([[0], np.cumsum(n)[:-1]])
    i_shift = np.concatenate([[0], np.cumsum(m)[:-1]])
    vertices = np.concatenate([np.asarray(v, dtype=np.float64) for v, _, _ in meshes])
    indices = np.concatenate(
        [np.asarray(fi, dtype=np.int64) + s for (_, fi, _), s in zip(meshes, v_shift, strict=True)]
    )
    tails = [
        np.asarray(fo, dtype=np.int64)[1:] + s
        for (_, _, fo), s in zip(meshes, i_shift, strict=True)
    ]
    offsets = np.concatenate([np.zeros(1, dtype=np.int64), *tails])
    return vertices, indices, offsets


def rotation_matrix(rotate_deg_xyz: Sequence[float]) -> np.ndarray:
    """(3, 3) rotation about x, then y, then z (fixed axes, degrees): ``Rz @ Ry @ Rx``."""
    ax, ay, az = np.radians(_vec3(rotate_deg_xyz, "rotate"))
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def transform(
    vertices: np.ndarray,
    translate: Sequence[float] = (0.0, 0.0, 0.0),
    rotate_deg_xyz: Sequence[float] = (0.0, 0.0, 0.0),
    scale: float | Sequence[float] = 1.0,
) -> np.ndarray:
    """Scale, then rotate about x, y, z in that order (degrees, fixed axes), then translate.

    Parameters
    ----------
    vertices : (n, 3) float
    translate : (3,) float
    rotate_deg_xyz : (3,) float
        Angles in degrees about the x, y and z axes, applied in that order.
    scale : float or (3,) float
        Uniform or per-axis scale; no factor may be 0. A negative product of factors
        mirrors the mesh: reverse its faces (:func:`reverse_faces`) to keep them outward.

    Returns
    -------
    (n, 3) float64
    """
    v = np.asarray(vertices, dtype=np.float64)
    s = _vec3(scale, "scale")
    if (s == 0).any():
        raise ValueError(f"scale factors must be non-zero, got {s.tolist()}")
    m = rotation_matrix(rotate_deg_xyz) * s  # columns scaled: R @ diag(s)
    return v @ m.T + _vec3(translate, "translate")


def reverse_faces(face_indices: np.ndarray, face_offsets: np.ndarray) -> np.ndarray:
    """Flip every face's orientation, keeping its first vertex first.

    Returns
    -------
    (m,) int64
        ``[a, b, c, d]`` becomes ``[a, d, c, b]``.
    """
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    sizes = np.diff(fo)
    start = np.repeat(fo[:-1], sizes)
    j = np.arange(fi.size) - start
    return fi[start + (np.repeat(sizes, sizes) - j) % np.repeat(sizes, sizes)]


def face_normals(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> np.ndarray:
    """Unit face normals by Newell's method (exact for planar faces, robust for warped ones).

    Returns
    -------
    (n_faces, 3) float64
        Zero for a face of zero area.
    """
    n = face_vectors(vertices, face_indices, face_offsets)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def dihedral_angles(vertices: np.ndarray, he: HalfEdges) -> np.ndarray:
    """Angle in degrees between the normals of the two faces at each edge.

    Returns
    -------
    (n_edges,) float64
        0 for a flat edge, up to 180 for a folded one; 0 on boundary edges.
    """
    normals = face_normals(vertices, he.origin, he.face_offsets)
    h = np.flatnonzero(he.twin > np.arange(he.n_halfedges))
    cos = np.einsum("ij,ij->i", normals[he.face[h]], normals[he.face[he.twin[h]]])
    out = np.zeros(he.n_edges)
    out[he.edge[h]] = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    return out


def _newell_normals(p: np.ndarray) -> np.ndarray:
    """(m, 3) area-weighted normals of polygons (m, k, 3) by Newell's method."""
    q = np.roll(p, -1, axis=1)
    return np.cross(p, q).sum(axis=1)


def _side(u: np.ndarray, w: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(m, r, r) cross products (w - u) x (q - u): candidate corner on axis 1, point on axis 2."""
    d = (w - u)[:, :, None, :]
    e = q[:, None, :, :] - u[:, :, None, :]
    return d[..., 0] * e[..., 1] - d[..., 1] * e[..., 0]


def _ear_clip(xy: np.ndarray) -> np.ndarray:
    """Triangles (m, k - 2, 3) of local corner indices for simple polygons xy (m, k, 2), CCW.

    Ear clipping (Meisters 1975), vectorized over the polygons: each round removes one ear
    per polygon -- a convex corner whose triangle holds no other remaining corner. A
    polygon with no ear left (degenerate or self-intersecting) loses its most convex corner.
    """
    m, k, _ = xy.shape
    rows = np.arange(m)[:, None]
    rem = np.broadcast_to(np.arange(k), (m, k)).copy()
    scale = np.abs(xy).max(initial=1.0)
    eps = 1e-12 * scale * scale
    tris = []
    for r in range(k, 3, -1):
        p = xy[rows, rem]  # (m, r, 2)
        a, c = np.roll(p, 1, axis=1), np.roll(p, -1, axis=1)
        turn = (p[..., 0] - a[..., 0]) * (c[..., 1] - p[..., 1]) - (p[..., 1] - a[..., 1]) * (
            c[..., 0] - p[..., 0]
        )

        inside = (_side(a, p, p) >= -eps) & (_side(p, c, p) >= -eps) & (_side(c, a, p) >= -eps)
        j = np.arange(r)
        own = (j[None, :] == j[:, None]) | (j[None, :] == (j[:, None] - 1) % r)
        own |= j[None, :] == (j[:, None] + 1) % r
        inside &= ~own[None]
        ear = (turn > eps) & ~inside.any(axis=2)
        pick = np.where(ear.any(axis=1), ear.argmax(axis=1), turn.argmax(axis=1))
        tris.append(
            np.stack(
                [
                    rem[rows[:, 0], (pick - 1) % r],
                    rem[rows[:, 0], pick],
                    rem[rows[:, 0], (pick + 1) % r],
                ],
                axis=1,
            )
        )
        keep = j[None, :] != pick[:, None]
        rem = rem[keep].reshape(m, r - 1)
    tris.append(rem)
    return np.stack(tris, axis=1)


def triangulate(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    max_tests: int | None = None,
) -> MeshArrays:
    """Split every face into triangles, keeping its orientation and the face order.

    A convex face becomes a fan from its first corner; a concave one is ear-clipped in the
    plane of its Newell normal. Faces are processed in groups of equal size: small concave
    faces all at once, larger ones (over 32 corners) one by one with the O(k^2)-at-worst
    clipper of :func:`~.polygon.triangulate_polygon`.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int

    Returns
    -------
    vertices : (n, 3) float64
        Unchanged.
    face_indices : (3 * (m - 2 n_faces),) int64
        The triangles of face 0, then of face 1, ... (a mesh of triangles only: its own
        arrays, not copied).
    face_offsets : (m - 2 n_faces + 1,) int64

    Raises
    ------
    WorkLimitError
        When a large concave face needs more than ``max_tests`` triangle-corner tests, or
        the small concave faces of one size together (k^3 each) would.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    sizes = np.diff(fo)
    if sizes.size and sizes.min() == 3 == sizes.max():  # triangles already: as they are
        return v, fi, fo
    n_tri = sizes - 2
    tri_off = np.zeros(sizes.size + 1, dtype=np.int64)
    np.cumsum(n_tri, out=tri_off[1:])
    out = np.empty((tri_off[-1], 3), dtype=np.int64)
    for k in np.unique(sizes):
        k = int(k)
        faces = np.flatnonzero(sizes == k)
        corners = fi[fo[faces][:, None] + np.arange(k)]  # (f, k)
        if k == 3:
            out[tri_off[faces]] = corners
            continue
        if k > _BATCH_UP_TO and faces.size <= _ALONE_UP_TO:
            # a few large faces (a polygon made a face): each tested and clipped in its
            # own plane, made once (the batched test below costs a face's clipping again)
            for f, start in zip(corners, tri_off[faces].tolist(), strict=True):
                # (np.take: a fancy index of rows is 4x slower on (k, 3))
                out[start : start + k - 2] = f[large_face(np.take(v, f, axis=0), max_tests)]
            continue
        local = np.broadcast_to(
            np.stack([np.zeros(k - 2, dtype=np.int64), np.arange(1, k - 1), np.arange(2, k)], 1),
            (faces.size, k - 2, 3),
        ).copy()
        p = v[corners]
        normal = _newell_normals(p)
        edge_in = p - np.roll(p, 1, axis=1)
        edge_out = np.roll(p, -1, axis=1) - p
        turn = np.einsum("fkd,fd->fk", np.cross(edge_in, edge_out), normal)
        tol = 1e-12 * (np.einsum("fd,fd->f", normal, normal) + 1e-300)
        concave = np.flatnonzero((turn < -tol[:, None]).any(axis=1))
        if concave.size and k > _BATCH_UP_TO:
            for f in concave:  # one large polygon at a time, each vectorized inside
                local[f] = triangulate_polygon(p[f], max_tests)
        elif concave.size:
            work = concave.size * k**3  # the batched clipper tests every corner, every round
            if max_tests is not None and work > max_tests:
                raise WorkLimitError(work, max_tests)
            nrm = normal[concave] / np.linalg.norm(normal[concave], axis=1, keepdims=True)
            helper = np.where(np.abs(nrm[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
            u = np.cross(nrm, helper)
            u /= np.linalg.norm(u, axis=1, keepdims=True)
            w = np.cross(nrm, u)
            q = p[concave] - p[concave].mean(axis=1, keepdims=True)
            xy = np.stack([np.einsum("fkd,fd->fk", q, u), np.einsum("fkd,fd->fk", q, w)], -1)
            local[concave] = _ear_clip(xy)
        rows = np.arange(faces.size)[:, None, None]
        tri_rows = tri_off[faces][:, None] + np.arange(k - 2)
        out[tri_rows] = corners[rows, local]
    return v, out.reshape(-1), np.arange(0, out.size + 1, 3, dtype=np.int64)
