"""The connected parts of a mesh, and which closed parts lie inside others.

A part is a set of faces joined through shared edges once coincident vertices are merged
(so a triangle soup, every triangle with its own three vertices as STL holds it, falls into
the same parts as its welded mesh; two parts touching at one point stay two).

- :func:`face_parts`: the part of every face: coincident vertices merged by one sort of a
  hash of their coordinates (:func:`~.repair.exact_duplicates`), the faces on each edge
  joined (:func:`~.measure.edge_table`), components of that graph by scipy's
  ``connected_components`` (a linear-time traversal in C);
- :func:`split`: each part as its own compact mesh, every array of all parts made in one
  pass (the parts' faces and vertices gathered part after part, each part a slice);
- :func:`inside_counts`: for one point per closed part, how many other closed parts hold
  it, by the parity of a ray's crossings (Jordan's theorem), with ties on edges and
  vertices broken by a symbolic perturbation of the ray (Edelsbrunner & Muecke 1990,
  "Simulation of Simplicity"): each crossing is decided by signs computed once per edge
  in one direction, so a ray through an edge counts exactly one of its two triangles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..io.meshdata import fan_triangles
from .keys import sort_keys
from .measure import edge_table, face_vectors
from .repair import exact_duplicates

__all__ = ["Parts", "face_parts", "inside_counts", "split"]

_PAIRS = 1 << 20  # (triangle, point) pairs tested at once in inside_counts


@dataclass(frozen=True, eq=False)
class Parts:
    """The parts of a mesh, ordered largest first.

    Attributes
    ----------
    part : (n_faces,) int64
        The part of each face: 0 is the first in order.
    count : int
    closed : (count,) bool
        Every edge of the part lies on exactly two of its faces (watertight).
    volume : (count,) float
        Signed volume of each part (meaningful for closed ones; negative: facing inward).
    area : (count,) float
        Area of each part (of a warped face, its projection on its mean plane).
    merged : (n_vertices,) int64
        The merged vertex of every vertex (coincident vertices share one).
    first : (n_merged,) int64
        The first vertex of each merged vertex.
    """

    part: np.ndarray
    count: int
    closed: np.ndarray
    volume: np.ndarray
    area: np.ndarray
    merged: np.ndarray
    first: np.ndarray


def face_parts(vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray) -> Parts:
    """The connected parts, closed ones first by decreasing size (absolute volume), then
    the open ones by decreasing area.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int

    Returns
    -------
    Parts
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    n_faces = len(fo) - 1
    first, merged = exact_duplicates(v)
    if n_faces == 0:
        z = np.zeros(0)
        return Parts(np.zeros(0, np.int64), 0, z.astype(bool), z, z, merged, first)
    mfi = merged[fi]
    table = edge_table(mfi, fo, len(first))
    face_of_corner = np.repeat(np.arange(n_faces), np.diff(fo))
    faces = face_of_corner[table.order]  # faces run edge by edge
    run_end = np.cumsum(table.counts)
    same_edge = np.ones(len(faces) - 1, dtype=bool) if len(faces) > 1 else np.zeros(0, bool)
    same_edge[run_end[:-1] - 1] = False  # the last corner of a run and the next edge's first
    a, b = faces[:-1][same_edge], faces[1:][same_edge]
    graph = coo_matrix((np.ones(len(a), dtype=np.int8), (a, b)), shape=(n_faces, n_faces))
    count, label = connected_components(graph.tocsr(), directed=False)
    label = label.astype(np.int64)
    # a part is open where one of its edges is not on exactly two faces
    open_corner = np.repeat(table.counts != 2, table.counts)
    open_part = np.zeros(count, dtype=bool)
    open_part[label[faces[open_corner]]] = True
    volume, area = _sizes(v, fi, fo, label, count)
    # closed first by size, then open by area; ties by the order the parts first appear
    size = np.where(open_part, area, np.abs(volume))
    rank = np.lexsort((np.arange(count), -size, open_part))
    new = np.empty(count, dtype=np.int64)
    new[rank] = np.arange(count)
    return Parts(new[label], int(count), ~open_part[rank], volume[rank], area[rank], merged, first)


def _sizes(
    v: np.ndarray, fi: np.ndarray, fo: np.ndarray, label: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray]:
    """Each part's signed volume and area from one Newell vector per face: ``|n| / 2`` its
    area, ``(p - o) . n / 6`` the cone over it from the centre o of the box (p its first
    corner): exact for triangles and planar faces (a warped one counts as its projection
    on its mean plane, which is all the ordering of parts needs)."""
    n = face_vectors(v, fi, fo)
    first = v[fi[fo[:-1]]]
    o = 0.5 * (v.min(axis=0) + v.max(axis=0))
    cone = np.einsum("ij,ij->i", first - o, n) / 6.0
    half = 0.5 * np.sqrt(np.einsum("ij,ij->i", n, n))
    return np.bincount(label, cone, minlength=count), np.bincount(label, half, minlength=count)


def split(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray, parts: Parts
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """Each part as a compact mesh on the merged vertices, in the parts' order.

    Returns
    -------
    list of (vertices, face_indices, face_offsets, vertex_source, face_source)
        ``vertex_source`` the input vertex each part vertex comes from (the first of the
        coincident ones), ``face_source`` the input face of each part face; faces keep
        their input order within a part.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    n_faces = len(fo) - 1
    if n_faces == 0:
        return []
    order, _ = sort_keys(parts.part, parts.count)  # faces part after part, in input order
    sizes = np.diff(fo)[order]
    new_fo = np.zeros(n_faces + 1, dtype=np.int64)
    np.cumsum(sizes, out=new_fo[1:])
    corner = np.arange(new_fo[-1]) + np.repeat(fo[:-1][order] - new_fo[:-1], sizes)
    m = parts.merged[fi[corner]]
    corner_part = np.repeat(parts.part[order], sizes)
    n_merged = len(parts.first)
    key = corner_part * n_merged + m
    kord, skey = sort_keys(key, parts.count * n_merged)
    new_key = np.ones(len(skey), dtype=bool)
    new_key[1:] = skey[1:] != skey[:-1]
    vid = np.cumsum(new_key) - 1  # the part vertex of each sorted corner
    local = np.empty(len(key), dtype=np.int64)
    local[kord] = vid
    keys = skey[new_key]
    source = parts.first[keys % n_merged]
    key_part = keys // n_merged
    v_start = np.searchsorted(key_part, np.arange(parts.count + 1))
    f_start = np.searchsorted(parts.part[order], np.arange(parts.count + 1))
    out_v = v[source]
    out = []
    for p in range(parts.count):  # one step per part: its arrays are slices
        fa, fb = int(f_start[p]), int(f_start[p + 1])
        ca, cb = int(new_fo[fa]), int(new_fo[fb])
        va, vb = int(v_start[p]), int(v_start[p + 1])
        out.append(
            (
                out_v[va:vb],
                local[ca:cb] - va,
                new_fo[fa : fb + 1] - ca,
                source[va:vb],
                order[fa:fb],
            )
        )
    return out


def inside_counts(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    parts: Parts,
    which: np.ndarray,
) -> np.ndarray:
    """How many of the other closed parts hold a point of each part in ``which``.

    The point of a part is the centroid of its first triangle (on its surface, away from
    its edges). A ray from it along +x crosses another closed part's surface an odd
    number of times exactly when the point is inside that part. The crossings are counted
    on the exported triangles (each face fanned from its first corner): a triangle is
    crossed when the point's (y, z) lies inside the triangle's projection and its plane is
    ahead on the ray. The three edge tests use ``orient2d`` of each edge taken from its
    smaller merged vertex to its larger, so the triangles on either side of an edge agree
    on it bit for bit; a zero is decided as if the ray started at (y + e, z + e^2) for an
    infinitesimal e (Simulation of Simplicity): then no ray passes exactly through an
    edge or a vertex, and each crossing of the surface is counted once.

    Parameters
    ----------
    vertices, face_indices, face_offsets
        The mesh.
    parts : Parts
        Its :func:`face_parts`.
    which : (k,) int
        Closed parts to test.

    Returns
    -------
    (k,) int64
        For each, the number of other closed parts around its point.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    which = np.asarray(which, dtype=np.int64)
    out = np.zeros(len(which), dtype=np.int64)
    if len(which) == 0:
        return out
    mtri = fan_triangles(parts.merged[fi], fo)
    tri_part = np.repeat(parts.part, np.diff(fo) - 2)
    keep = parts.closed[tri_part]
    mtri, tri_part = mtri[keep], tri_part[keep]
    pos = v[parts.first]  # merged vertex positions
    # one point per tested part: the centroid of its first triangle
    first_tri = np.full(parts.count, -1, dtype=np.int64)
    first_tri[tri_part[::-1]] = np.arange(len(tri_part))[::-1]
    q = pos[mtri[first_tri[which]]].mean(axis=1)
    qorder = np.argsort(q[:, 1], kind="stable")
    qy = q[qorder, 1]
    corners = pos[mtri]  # (t, 3, 3)
    ylo, yhi = corners[:, :, 1].min(axis=1), corners[:, :, 1].max(axis=1)
    start = np.searchsorted(qy, ylo, side="left")
    stop = np.searchsorted(qy, yhi, side="right")
    counts = stop - start
    total = int(counts.sum())
    cum = np.cumsum(counts)
    cuts = np.searchsorted(cum, np.arange(_PAIRS, total, _PAIRS), side="left")
    bounds = np.unique(np.concatenate([[0], cuts, [len(counts)]]))
    hits = []
    for s, e in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):  # per chunk
        c = counts[s:e]
        t = np.repeat(np.arange(s, e), c)
        k = np.arange(len(t)) - np.repeat(np.cumsum(c) - c, c)
        j = qorder[start[t] + k]  # the tested point's index in `which`
        other = tri_part[t] != which[j]
        t, j = t[other], j[other]
        hit = _crossed(pos, mtri[t], q[j])
        hits.append(j[hit] * parts.count + tri_part[t[hit]])
    key, crossings = np.unique(np.concatenate(hits), return_counts=True)
    odd = key[crossings % 2 == 1]  # (point, part) pairs: the point is inside the part
    return np.bincount(odd // parts.count, minlength=len(which)).astype(np.int64)


def _orient(p: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Sign of orient2d(p, r, s) in (y, z), zeros decided by Simulation of Simplicity
    (s moved by (e, e^2)): -(r_z - p_z), else (r_y - p_y)."""
    dy, dz = r[:, 1] - p[:, 1], r[:, 2] - p[:, 2]
    det = dy * (s[:, 2] - p[:, 2]) - dz * (s[:, 1] - p[:, 1])
    sign = np.sign(det)
    zero = sign == 0
    if zero.any():
        sos = np.where(dz[zero] != 0, -np.sign(dz[zero]), np.sign(dy[zero]))
        sign[zero] = sos
    return sign


def _crossed(pos: np.ndarray, tri: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Whether the ray from each q along +x crosses its triangle (merged vertex ids)."""
    signs = []
    for i, k in ((0, 1), (1, 2), (2, 0)):  # each edge from its smaller vertex to its larger
        a, b = tri[:, i], tri[:, k]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        s = _orient(pos[lo], pos[hi], q)
        signs.append(np.where(a < b, s, -s))
    s0, s1, s2 = signs
    inside = (s0 == s1) & (s1 == s2) & (s0 != 0)
    a, b, c = pos[tri[:, 0]], pos[tri[:, 1]], pos[tri[:, 2]]
    n = np.cross(b - a, c - a)
    ahead = np.einsum("ij,ij->i", n, q - a)
    return inside & (ahead * n[:, 0] < 0)
