"""Subdivision surfaces on flat polygon meshes: Catmull-Clark and Doo-Sabin.

Both schemes come from the same 1978 issue of Computer-Aided Design:

- E. Catmull, J. Clark, "Recursively generated B-spline surfaces on arbitrary topological
  meshes", CAD 10(6), 350-355 -- generalises uniform bicubic B-splines;
- D. Doo, M. Sabin, "Behaviour of recursive division surfaces near extraordinary points",
  CAD 10(6), 356-360 -- generalises uniform biquadratic B-splines.

Each level's rules are sparse matrices applied to all the vertices' columns at once (x, y,
z and point attributes), built by gathers over the half-edges (no Python loop per face,
edge or vertex). Catmull-Clark builds the half-edge structure once; the connectivity of
every later level follows in closed form from the previous one. Doo-Sabin builds the
half-edges of each level's output.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .catmull_clark_levels import Level, _csr, index_type
from .halfedge import HalfEdges, build_halfedges

__all__ = [
    "catmull_clark",
    "catmull_clark_counts",
    "catmull_clark_face_parents",
    "doo_sabin",
    "doo_sabin_counts",
    "doo_sabin_weights",
]


def _as_vertices(vertices: np.ndarray) -> np.ndarray:
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] < 3:
        raise ValueError(f"vertices must be an (n, 3) array, got shape {v.shape}")
    if not np.isfinite(v).all():
        i = int(np.flatnonzero(~np.isfinite(v).all(axis=1))[0])
        raise ValueError(f"vertex {i} is not finite: {v[i].tolist()}")
    return v


def _check_levels(levels: int) -> int:
    if isinstance(levels, bool) or int(levels) != levels or levels < 0:
        raise ValueError(f"levels must be a whole number >= 0, got {levels!r}")
    return int(levels)


def _halfedges_of(
    face_indices: np.ndarray, face_offsets: np.ndarray, n: int, given: HalfEdges | None
) -> HalfEdges:
    if given is None:
        return build_halfedges(face_indices, face_offsets, n)
    if given.n_vertices != n or given.n_halfedges != np.size(face_indices):
        raise ValueError(
            f"the half-edges given are of {given.n_vertices} vertices and "
            f"{given.n_halfedges} corners, the mesh has {n} and {np.size(face_indices)}"
        )
    return given


def _scatter(index: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    """Sum the rows of ``values`` (m, d) into ``size`` bins: one bincount per column."""
    columns = np.ascontiguousarray(values.T)  # bincount reads each column contiguously
    out = np.empty((values.shape[1], size))
    for k in range(values.shape[1]):
        out[k] = np.bincount(index, columns[k], minlength=size)
    return out.T


# --------------------------------------------------------------------------------------
# Catmull-Clark
# --------------------------------------------------------------------------------------


def _edge_sharpness(
    he: HalfEdges, creases: np.ndarray | None, sharpness: np.ndarray | float | None
) -> np.ndarray | None:
    """Sharpness per edge, or None when nothing is creased."""
    if creases is None:
        if sharpness is not None:
            raise ValueError("sharpness was given without creases")
        return None
    c = np.asarray(creases)
    if c.size == 0:
        return None
    s = np.zeros(he.n_edges)
    if c.ndim != 2 or c.shape[1] != 2 or not np.issubdtype(c.dtype, np.integer):
        raise ValueError(f"creases must be an (k, 2) array of vertex pairs, got shape {c.shape}")
    val = np.broadcast_to(np.inf if sharpness is None else np.asarray(sharpness, float), len(c))
    if (val < 0).any() or np.isnan(val).any():
        raise ValueError("crease sharpness must be >= 0 (inf for an infinitely sharp crease)")
    n = max(he.n_vertices, 1)
    lo, hi = np.minimum(c[:, 0], c[:, 1]), np.maximum(c[:, 0], c[:, 1])
    ekey = he.edge_vertices[:, 0] * n + he.edge_vertices[:, 1]
    ckey = lo * n + hi
    i = np.minimum(np.searchsorted(ekey, ckey), ekey.size - 1)
    missing = np.flatnonzero((ekey.size == 0) | (ekey[i] != ckey) | (lo < 0) | (hi >= n))
    if missing.size:
        a, b = c[missing[0]]
        raise ValueError(f"crease ({a}, {b}) is not an edge of the mesh")
    s[i] = np.maximum(s[i], val)
    return s


def _catmull_clark_step(
    x: np.ndarray, n: int, lv: Level, sharp: np.ndarray | None, last: bool
) -> tuple[np.ndarray, int, Level | np.ndarray, np.ndarray | None]:
    """One level on the ``n`` vertices ``x[:n]`` (d columns, C order), ``x`` having room
    for the level's face points after them. Returns the same for the next level (the new
    points, room for the next face points after them unless ``last``, and their count),
    the next level's connectivity (on the ``last`` level only its quads, (F', 4) int64)
    and the edges' sharpness there.

    Every rule is linear in the vertices, so a level is two sparse products
    (:meth:`Level.stencil`): the face points from the vertices, then every new point from
    the vertices and the face points. They read each vertex's d columns (x, y, z and the
    point attributes) together, so a column more costs a small part of a level; the sharp
    rules touch few vertices and are applied after, on their rows.
    """
    v = x[:n]
    ev, eh = lv.edge_vertices, lv.edge_halfedges
    n_edges, n_faces = ev.shape[0], lv.face_offsets.size - 1
    boundary_edge = eh[:, 0] == eh[:, 1]
    creased = np.zeros(n_edges, dtype=bool) if sharp is None else sharp > 0
    edge_weight = None
    if boundary_edge.any() or creased.any():
        # a boundary edge point is the midpoint; a crease's blends the smooth one and the
        # midpoint by its sharpness (semi-sharp creases, DeRose et al. 1998)
        edge_weight = boundary_edge.astype(np.float64)
        if sharp is not None:
            np.maximum(edge_weight, np.minimum(sharp, 1.0), out=edge_weight)
    spare = 0 if last else lv.face_indices.size  # the next level has a face per corner
    faces, points, scale = lv.stencil(n, edge_weight, spare)
    x[n : n + n_faces] = faces @ v
    new = points @ x  # vertex points, edge points, face points and spare rows (zero)
    n_new = n + n_edges + n_faces
    new[n + n_edges : n_new] = x[n : n + n_faces]
    k = np.diff(lv.around_offsets)
    keep = np.where(k > 0, (k - 2.0) / np.maximum(k, 1), 1.0)  # unused vertices: carried
    vp = new[:n]
    vp *= scale[:, None]
    hard = None
    # sharp rules: a vertex on two sharp edges (boundary or crease) follows the cubic
    # B-spline curve rule 1/8, 6/8, 1/8; on more than two, or a boundary corner in a single
    # face (valence 2), it stays put
    sharp_edge = boundary_edge | creased
    if sharp_edge.any():
        se = np.flatnonzero(sharp_edge)
        ends = ev[se].ravel()
        n_sharp = np.bincount(ends, minlength=n)
        s_e = np.inf if sharp is None else np.where(boundary_edge[se], np.inf, sharp[se])
        s_e = np.broadcast_to(np.minimum(s_e, 1e300), se.shape)
        s_v = np.bincount(ends, np.repeat(s_e, 2), minlength=n)
        s_v /= np.maximum(n_sharp, 1)  # vertex sharpness: mean over its sharp edges
        crease_v = n_sharp == 2
        on_boundary = np.bincount(ev[boundary_edge].ravel(), minlength=n) > 0
        s_v[on_boundary] = 1.0  # the smooth rule does not hold on a boundary
        s_v = np.minimum(s_v, 1.0)
        corner_v = (n_sharp > 2) | (crease_v & on_boundary & (k == 1))
        crease_v &= ~corner_v
        hard = np.flatnonzero(crease_v | corner_v)
        if hard.size:
            other = ev[se][:, ::-1].ravel()  # each sharp edge's other end, at both ends
            nb = _scatter(ends, v[other], n)
            target = v[hard]
            on_crease = crease_v[hard]
            target[on_crease] = 0.125 * nb[hard[on_crease]] + 0.75 * target[on_crease]
            w = s_v[hard][:, None]
    v *= keep[:, None]  # the level's own copy of its vertices, spent after this
    vp += v
    if hard is not None and hard.size:
        vp[hard] = (1.0 - w) * vp[hard] + w * target
    if last:
        return new, n_new, lv.quads(n, np.int64), None
    nxt = lv.refined(n)
    if sharp is None or not (sharp > 1.0).any():
        return new, n_new, nxt, None
    later = np.concatenate([np.repeat(np.maximum(sharp - 1.0, 0.0), 2), np.zeros(spare)])
    return new, n_new, nxt, later


def catmull_clark(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    levels: int = 1,
    creases: np.ndarray | None = None,
    sharpness: np.ndarray | float | None = None,
    halfedges: HalfEdges | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Catmull-Clark subdivision of a polygon mesh (Catmull & Clark 1978).

    Per level, on any polygons (after one level every face is a quad):

    - face point: the centroid of the face;
    - edge point: ``(v0 + v1 + f0 + f1) / 4``, the ends and the two face points;
    - vertex point: ``(Q + 2R + (n - 3) S) / n`` with ``n`` the valence, ``Q`` the mean of
      the adjacent face points, ``R`` the mean of the incident edge midpoints, ``S`` the
      vertex;
    - open boundaries follow the cubic B-spline curve rule: a boundary edge point is the
      midpoint, a boundary vertex moves to ``1/8 a + 6/8 S + 1/8 b`` with ``a``, ``b`` its
      boundary neighbours, and a corner (a boundary vertex in a single face, valence 2) or
      a vertex on more than two boundary edges (non-manifold) stays where it is.

    Each face of ``k`` corners becomes ``k`` quads (vertex, edge point, face point, edge
    point), so ``F' = sum of face sizes``; ``V' = V + E + F``; the Euler characteristic is
    kept.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
        The mesh, faces counter-clockwise seen from outside.
    levels : int
        Number of subdivision steps (0 returns a copy).
    creases : (k, 2) int, optional
        Edges (vertex pairs) to keep sharp. A crease edge uses the boundary rules: its edge
        point is the midpoint; a vertex on two creases follows the crease as a cubic
        B-spline curve, a vertex on three or more stays put (a dart, on one, stays smooth).
    sharpness : float or (k,) float, optional
        Sharpness of each crease, ``inf`` by default. Semi-sharp creases (DeRose, Kass &
        Truong 1998, "Subdivision surfaces in character animation"): an edge of sharpness
        ``s`` uses the sharp rules for ``floor(s)`` levels, blends sharp and smooth by the
        fractional part on the next, and is smooth afterwards; a vertex takes the mean
        sharpness of its sharp edges.
    halfedges : HalfEdges, optional
        The half-edges of these faces when the caller has them already (a ``Mesh``'s
        ``halfedges``): not built a second time.

    vertices may carry extra columns beyond x, y, z (point attributes): every rule is
    linear in the vertices, so they follow exactly the same stencils (a linear attribute
    stays linear). The face each output face lies in is
    :func:`catmull_clark_face_parents`.

    Returns
    -------
    vertices : (n', 3) float64
        The original vertices' new positions first (same indices), then one edge point per
        edge, then one face point per face (with the extra columns, when given).
    face_indices : (4 * n_faces',) int64
    face_offsets : (n_faces' + 1,) int64
        All quads.

    Raises
    ------
    MeshTopologyError
        When the faces are not an oriented manifold (see ``build_halfedges``).
    ValueError
        Bad vertex array, levels or creases.

    Example
    -------
    >>> v, fi, fo = catmull_clark(np.eye(3), [0, 1, 2], [0, 3])
    >>> v.shape, fo.size - 1
    ((7, 3), 3)
    """
    v = _as_vertices(vertices)
    levels = _check_levels(levels)
    he = _halfedges_of(face_indices, face_offsets, v.shape[0], halfedges)
    sharp = _edge_sharpness(he, creases, sharpness)
    if levels == 0:
        return v.copy(), np.array(he.origin), np.array(he.face_offsets)
    v_last, _, _ = catmull_clark_counts(
        he.n_vertices, he.n_edges, he.n_faces, he.n_halfedges, levels
    )[-1]
    lv = Level.from_halfedges(he, index_type(4**levels * he.n_halfedges + v_last))
    # rows (the stencils read a vertex's columns together), room for the face points after
    x = np.empty((v.shape[0] + he.n_faces, v.shape[1]))
    x[: v.shape[0]] = v
    n = v.shape[0]
    for level in range(levels):
        x, n, lv, sharp = _catmull_clark_step(x, n, lv, sharp, last=level == levels - 1)
    quads = lv.reshape(-1)
    return x, quads, np.arange(0, quads.size + 1, 4, dtype=np.int64)


def catmull_clark_face_parents(face_offsets: np.ndarray, levels: int) -> np.ndarray:
    """The input face each output face of ``levels`` Catmull-Clark steps lies in.

    Level one turns face ``f`` of ``k`` corners into ``k`` consecutive quads (one per
    corner, in face order); each later level turns every quad into four consecutive quads.
    """
    fo = np.asarray(face_offsets, dtype=np.int64)
    parents = np.arange(fo.size - 1, dtype=np.int64)
    if _check_levels(levels) == 0:
        return parents
    parents = np.repeat(parents, np.diff(fo))
    return np.repeat(parents, 4 ** (levels - 1))


def catmull_clark_counts(
    n_vertices: int, n_edges: int, n_faces: int, n_halfedges: int, levels: int
) -> list[tuple[int, int, int]]:
    """(vertices, edges, faces) after each of ``levels`` Catmull-Clark steps, in closed form.

    ``V' = V + E + F``, ``E' = 2E + H``, ``F' = H`` and ``H' = 4H``, with ``H`` the sum of
    the face sizes.
    """
    out = []
    v, e, f, h = n_vertices, n_edges, n_faces, n_halfedges
    for _ in range(_check_levels(levels)):
        v, e, f, h = v + e + f, 2 * e + h, h, 4 * h
        out.append((v, e, f))
    return out


# --------------------------------------------------------------------------------------
# Doo-Sabin
# --------------------------------------------------------------------------------------


def doo_sabin_weights(k: int) -> np.ndarray:
    """Doo-Sabin weights of a ``k``-sided face: ``a0 = 1/4 + 5/(4k)``,
    ``ai = (3 + 2 cos(2 pi i / k)) / (4k)``; they sum to 1.

    Returns
    -------
    (k, k) float64
        Circulant matrix: row ``i`` gives the new point of corner ``i`` from the corners.
    """
    i = np.arange(k)
    a = (3.0 + 2.0 * np.cos(2.0 * np.pi * i / k)) / (4.0 * k)
    a[0] = 0.25 + 5.0 / (4.0 * k)
    return a[(i[None, :] - i[:, None]) % k]


def _doo_sabin_points(he: HalfEdges, n: int, kept: np.ndarray) -> tuple[Any, Any]:
    """The new points of a Doo-Sabin level as two sparse products: ``sums @ v`` gives each
    face's sums ``S = sum v_j``, ``C = sum cos(t_j) v_j``, ``D = sum sin(t_j) v_j`` over its
    corners (``t_j = 2 pi j / k``), and ``points @ [v; S; C; D]`` every new point.

    The corner rule ``sum_j a_|i-j| v_j`` with ``a_i = (3 + 2 cos t_i) / (4k)`` (and 1/4
    more on ``a_0``) is, as ``cos(t_i - t_j) = cos t_i cos t_j + sin t_i sin t_j``,
    ``v_i / 4 + (3 S + 2 cos t_i C + 2 sin t_i D) / (4k)``: four entries a corner whatever
    the face's size (the circulant's k would be k^2). The boundary Chaikin points
    (3/4, 1/4 and 1/4, 3/4 of each boundary edge) and the ``kept`` corners are rows of the
    same product.
    """
    fi, fo, face = he.origin, he.face_offsets, he.face
    m, n_faces = fi.size, fo.size - 1
    sizes = he.face_sizes
    k = sizes[face]
    b = he.boundary_halfedges
    nb = b.size
    itype = index_type(n + 3 * n_faces + 9 * m)  # every index and entry count

    # cos t and sin t of every corner, looked up in one table of every face size present
    present = np.flatnonzero(np.bincount(sizes))
    start = np.zeros(present[-1] + 1 if present.size else 1, dtype=np.int64)
    start[present] = np.cumsum(present) - present
    of_k = np.repeat(present, present)
    angle = (np.arange(of_k.size) - start[of_k]) * (2.0 * np.pi) / of_k
    at = np.arange(m) - fo[face]
    at += start[k]

    data = np.empty(3 * m)
    data[:m] = 1.0
    np.take(np.cos(angle), at, out=data[m : 2 * m])
    np.take(np.sin(angle), at, out=data[2 * m :])
    indices = np.empty(3 * m, dtype=itype)
    indices.reshape(3, m)[:] = fi
    indptr = np.empty(3 * n_faces + 1, dtype=itype)
    indptr[: n_faces + 1] = fo
    np.add(fo[1:], m, out=indptr[n_faces + 1 : 2 * n_faces + 1])
    np.add(fo[1:], 2 * m, out=indptr[2 * n_faces + 1 :])
    sums = _csr(data, indices, indptr, (3 * n_faces, n))

    nnz = 4 * m + 4 * nb + kept.size
    rows = m + 2 * nb + kept.size
    weight, column = np.empty(nnz), np.empty(nnz, dtype=itype)
    w, c = weight[: 4 * m].reshape(m, 4), column[: 4 * m].reshape(m, 4)
    c[:, 0] = fi  # v_i, then S, C and D of its face
    np.add(face, n, out=c[:, 1])
    np.add(c[:, 1], n_faces, out=c[:, 2])
    np.add(c[:, 2], n_faces, out=c[:, 3])
    w[:, 0] = 0.25
    inv = 0.5 / k
    np.multiply(inv, 1.5, out=w[:, 1])
    np.multiply(data[m : 2 * m], inv, out=w[:, 2])
    np.multiply(data[2 * m :], inv, out=w[:, 3])
    # the Chaikin points: (a, b) twice per boundary edge a -> b
    ends = column[4 * m : 4 * m + 4 * nb].reshape(nb, 2, 2)
    ends[:, :, 0] = he.origin[b, None]
    ends[:, :, 1] = he.vertex[b, None]
    weight[4 * m : 4 * m + 4 * nb].reshape(nb, 4)[:] = [0.75, 0.25, 0.25, 0.75]
    column[4 * m + 4 * nb :] = kept
    weight[4 * m + 4 * nb :] = 1.0
    indptr = np.empty(rows + 1, dtype=itype)
    indptr[: m + 1] = np.arange(0, 4 * m + 1, 4, dtype=itype)
    indptr[m : m + 2 * nb + 1] = np.arange(4 * m, 4 * m + 4 * nb + 1, 2, dtype=itype)
    indptr[m + 2 * nb :] = np.arange(4 * m + 4 * nb, nnz + 1, dtype=itype)
    points = _csr(weight, column, indptr, (rows, n + 3 * n_faces))
    return sums, points


def _doo_sabin_step(
    v: np.ndarray, he: HalfEdges, fvals: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    m = he.origin.size
    sizes = he.face_sizes
    b = he.boundary_halfedges
    nb = b.size
    c_first = np.full(m, -1, dtype=np.int64)  # new id of the Chaikin point near origin(h)
    c_first[b] = m + 2 * np.arange(nb)

    fans = he.fans
    fan_size = fans.sizes
    fan_open = ~fans.closed
    corner_fan = fan_open & (fan_size == 1) & he.is_manifold_vertex[fans.vertex]
    kept = fans.vertex[corner_fan]
    # the new points (one per corner, two per boundary edge, the kept corners), all the
    # vertices' columns (x, y, z and point attributes) in each product
    sums, points = _doo_sabin_points(he, v.shape[0], kept)
    x = np.empty((v.shape[0] + sums.shape[0], v.shape[1]))
    x[: v.shape[0]] = v
    x[v.shape[0] :] = sums @ v
    new_v = points @ x

    # F-faces: the corner points of each face, in the face's order
    parts = [np.arange(m, dtype=np.int64)]
    part_sizes = [sizes]
    # E-faces: one quad per interior edge (h < twin) and per boundary edge
    h = np.flatnonzero(he.twin > np.arange(m))
    t = he.twin[h]
    parts.append(np.stack([he.next[t], t, he.next[h], h], axis=1).reshape(-1))
    parts.append(np.stack([c_first[b], c_first[b] + 1, he.next[b], b], axis=1).reshape(-1))
    part_sizes.append(np.full(h.size + nb, 4, dtype=np.int64))
    # V-faces: the corner points around each vertex, counter-clockwise; an open fan is
    # closed by the Chaikin points on its two boundary edges (and a corner by the vertex)
    out_size = fan_size + 2 * fan_open + corner_fan
    # an interior vertex of valence 2 would give a 2-gon: leave it out (the two E-faces at
    # the vertex then share that edge directly)
    out_size[fans.closed & (fan_size == 2)] = 0
    out_off = np.zeros(fan_size.size + 1, dtype=np.int64)
    np.cumsum(out_size, out=out_off[1:])
    vface = np.empty(out_off[-1], dtype=np.int64)
    fan_of = np.repeat(np.arange(fan_size.size), fan_size)
    rank = np.arange(m) - fans.offsets[fan_of]
    placed = out_size[fan_of] > 0
    vface[(out_off[fan_of] + fan_open[fan_of] + rank)[placed]] = fans.halfedges[placed]
    op = np.flatnonzero(fan_open)
    head = fans.halfedges[fans.offsets[op]]
    tail = fans.halfedges[fans.offsets[op + 1] - 1]
    vface[out_off[op]] = c_first[head]
    vface[out_off[op] + 1 + fan_size[op]] = c_first[he.prev[tail]] + 1
    cf = np.flatnonzero(corner_fan)
    vface[out_off[cf] + 3] = m + 2 * nb + np.arange(cf.size)
    parts.append(vface)
    part_sizes.append(out_size[out_size > 0])

    face_indices = np.concatenate(parts)
    all_sizes = np.concatenate(part_sizes)
    face_offsets = np.zeros(all_sizes.size + 1, dtype=np.int64)
    np.cumsum(all_sizes, out=face_offsets[1:])
    new_f = None
    if fvals is not None:
        # F-faces keep their face's values, E-faces take the mean of the faces on their
        # edge, V-faces the mean of the faces around their vertex: one sparse product
        face, n_faces = he.face, sizes.size
        n_fan = fan_size[out_size > 0]  # the faces around each V-face's vertex
        n_inner = 2 * h.size
        rows = np.concatenate(  # each face's own, each edge's two faces, each fan's faces
            [np.arange(n_faces), np.stack([face[h], face[t]], 1).reshape(-1), face[b]]
            + [face[fans.halfedges[placed]]]
        )
        weights = np.concatenate(
            [np.ones(n_faces), np.full(n_inner, 0.5), np.ones(nb), np.repeat(1.0 / n_fan, n_fan)]
        )
        starts = np.concatenate(
            [
                np.arange(n_faces),
                n_faces + np.arange(0, n_inner, 2),
                n_faces + n_inner + np.arange(nb + 1),
                n_faces + n_inner + nb + np.cumsum(n_fan),
            ]
        )
        spread = _csr(weights, rows, starts, (all_sizes.size, n_faces))
        new_f = spread @ fvals
    return new_v, face_indices, face_offsets, new_f


def doo_sabin(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    levels: int = 1,
    face_values: np.ndarray | None = None,
    halfedges: HalfEdges | None = None,
) -> tuple[np.ndarray, ...]:
    """Doo-Sabin subdivision of a polygon mesh (Doo & Sabin 1978).

    Per level, every corner ``i`` of every ``k``-sided face gets a new point
    ``sum_j a_|i-j| v_j`` with ``a0 = 1/4 + 5/(4k)``, ``ai = (3 + 2 cos(2 pi i/k)) / (4k)``
    (:func:`doo_sabin_weights`), and the new mesh has

    - an F-face per face: its new corner points (a shrunken copy, ``k`` sides);
    - an E-face per interior edge: the quad of the four corner points at its ends;
    - a V-face per interior vertex: the corner points around it (``valence`` sides; none
      for an interior vertex of valence 2).

    Boundaries: each boundary edge ``a -> b`` gets two new points ``3/4 a + 1/4 b`` and
    ``1/4 a + 3/4 b`` (Chaikin's corner cutting, the boundary case of the same quadratic
    B-spline scheme) and its E-face is the quad of those two points and the two corner
    points beside it; a boundary vertex's V-face is its corner points closed by the Chaikin
    points on its two boundary edges. So each boundary polygon is refined by Chaikin's rule
    and converges to its uniform quadratic B-spline, except that a corner (a boundary vertex
    in a single face, valence 2) is kept in its V-face and stays put, as Catmull-Clark
    keeps it.

    Two sheets that touch at a vertex (a non-manifold vertex) get a V-face each and come
    apart, so the output is always manifold.

    Counts per level: ``V' = H + 2B + C`` (``H`` the sum of face sizes, ``B`` boundary edges,
    ``C`` corners), ``F' = F + E + V`` (vertices used by faces, less interior ones of
    valence 2).

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
        The mesh, faces counter-clockwise seen from outside.
    levels : int
        Number of subdivision steps (0 returns a copy).
    halfedges : HalfEdges, optional
        The half-edges of these faces when the caller has them already (a ``Mesh``'s
        ``halfedges``): not built a second time.

    Each level is two sparse products over all the vertices' columns (see
    :func:`_doo_sabin_points`): the corner rule in its cosine form costs four entries a
    corner whatever the face's size, so a face of thousands of corners costs what as many
    quads do.

    vertices may carry extra columns beyond x, y, z (point attributes): they follow the
    same weights. ``face_values`` (n_faces, c), when given, follow the faces: an F-face keeps
    its face's values, an E-face gets the mean of the faces on its edge, a V-face the mean
    of the faces around its vertex; they are returned fourth.

    Returns
    -------
    vertices : (n', 3) float64
        Corner points (one per half-edge of the input, in face order), then the boundary
        Chaikin points (two per boundary edge), then the kept corners.
    face_indices : (m',) int64
    face_offsets : (n_faces' + 1,) int64
        F-faces, then E-faces (interior, then boundary), then V-faces.
    face_values : (n_faces', c) float64
        Only when ``face_values`` is given.

    Raises
    ------
    MeshTopologyError
        When the faces are not an oriented manifold (see ``build_halfedges``).
    """
    v = _as_vertices(vertices)
    levels = _check_levels(levels)
    he = _halfedges_of(face_indices, face_offsets, v.shape[0], halfedges)
    fv = (
        None if face_values is None else np.asarray(face_values, np.float64).reshape(he.n_faces, -1)
    )
    if levels == 0:
        out = v.copy(), np.array(he.origin), np.array(he.face_offsets)
        return out if fv is None else (*out, fv.copy())
    v, fi, fo, fv = _doo_sabin_step(v, he, fv)
    for _ in range(levels - 1):
        v, fi, fo, fv = _doo_sabin_step(v, build_halfedges(fi, fo, v.shape[0]), fv)
    return (v, fi, fo) if face_values is None else (v, fi, fo, fv)


def doo_sabin_counts(he: HalfEdges, levels: int) -> list[tuple[int, int, int]]:
    """(vertices, edges, faces) after each of ``levels`` Doo-Sabin steps, in closed form.

    With ``H`` half-edges, ``B`` boundary edges, ``C`` kept corners, ``P`` vertex fans and
    ``D`` interior vertices of valence 2 (no V-face): ``V' = H + 2B + C``,
    ``F' = F + E + P - D``, ``H' = 2H + 4E + 2B + C - 2D``, ``B' = 2B + C``,
    ``E' = (H' + B') / 2``; after the first level every vertex is manifold, used and of
    valence 3 or more, so ``P = V`` and ``D = 0``, and the corners stay corners.
    """
    fans = he.fans
    two = int((fans.closed & (fans.sizes == 2)).sum())
    corners = int((~fans.closed & (fans.sizes == 1) & he.is_manifold_vertex[fans.vertex]).sum())
    n_fans = int(fans.vertex.size) - two
    v, e, f, h = he.n_vertices, he.n_edges, he.n_faces, he.n_halfedges
    b = int(he.boundary_halfedges.size)
    out = []
    for _ in range(_check_levels(levels)):
        v, f, h, b = (
            h + 2 * b + corners,
            f + e + n_fans,
            2 * h + 4 * e + 2 * b + corners - 2 * two,
            2 * b + corners,
        )
        e = (h + b) // 2
        n_fans, two = v, 0
        out.append((v, e, f))
    return out
