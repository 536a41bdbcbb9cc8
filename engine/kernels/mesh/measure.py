"""Measures of polygon meshes and the edge table behind the solid checks, vectorized.

- :func:`edge_table`: every undirected edge with the number of faces on it and whether two
  of them run it the same way (one sort of the edge keys);
- :func:`union_find`: connected components of a graph given by edge lists, optionally with
  a parity per edge (two-colouring, used to orient faces), by hooking and pointer jumping;
- :func:`face_areas`, :func:`signed_volume`, :func:`solid_report`: area of the exported fan,
  volume by the divergence theorem over the fan triangles of each face;
- :func:`flat_open_parts`: how many connected parts are flat open sheets (which a cap
  would only double).

A mesh is ``vertices (n, 3)``, ``face_indices (m,)`` and ``face_offsets (n_faces + 1,)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..io.meshdata import fan_triangles
from .keys import sort_keys
from .memo import by_faces

__all__ = [
    "COLUMN_CORNERS",
    "EdgeTable",
    "FanColumns",
    "SolidReport",
    "edge_table",
    "face_areas",
    "face_vectors",
    "flat_open_parts",
    "is_closed_oriented",
    "next_corner",
    "signed_volume",
    "solid_report",
    "union_find",
]


def next_corner(face_offsets: np.ndarray) -> np.ndarray:
    """(m,) int64: the corner after each corner in its face (the last wraps to the first)."""
    fo = np.asarray(face_offsets, dtype=np.int64)
    nxt = np.arange(1, int(fo[-1]) + 1, dtype=np.int64)
    nxt[fo[1:] - 1] = fo[:-1]
    return nxt


@dataclass(frozen=True, eq=False)
class EdgeTable:
    """Undirected edges of a face list.

    Attributes
    ----------
    order : (m,) int64
        Corners (half-edges ``face_indices[h] -> face_indices[next[h]]``) sorted by edge.
    starts : (n_edges,) int64
        Where each edge's run of corners starts in ``order``.
    counts : (n_edges,) int64
        Faces on each edge: 1 boundary, 2 interior, more non-manifold.
    vertices : (n_edges, 2) int64
        The two ends of each edge, smaller first.
    same_way : (n_edges,) bool
        Two of its faces run the edge in the same direction (orientations disagree).
    """

    order: np.ndarray
    starts: np.ndarray
    counts: np.ndarray
    vertices: np.ndarray
    same_way: np.ndarray

    @property
    def n_edges(self) -> int:
        return int(self.counts.size)


def edge_table(face_indices: np.ndarray, face_offsets: np.ndarray, n_vertices: int) -> EdgeTable:
    """Group the half-edges of all faces by undirected edge (one sort, O(m log m)).

    Parameters
    ----------
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
    n_vertices : int

    Returns
    -------
    EdgeTable
    """
    fi = np.asarray(face_indices, dtype=np.int64)
    a, b = fi, fi[next_corner(face_offsets)]
    nv = max(int(n_vertices), 1)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    # the direction is the last bit, so equal neighbours in the sort run an edge the same way
    key = (lo * nv + hi) * 2 + (a > b)
    order, skey = sort_keys(key, 2 * nv * nv)
    edge = skey >> 1
    first = np.r_[edge.size > 0, edge[1:] != edge[:-1]] if edge.size else np.zeros(0, bool)
    starts = np.flatnonzero(first)
    counts = np.diff(np.r_[starts, edge.size])
    same = np.zeros(edge.size, dtype=bool)
    if edge.size > 1:
        same[1:] = skey[1:] == skey[:-1]
    edge_id = np.cumsum(first) - 1
    same_way = np.zeros(starts.size, dtype=bool)
    same_way[edge_id[same]] = True
    ends = edge[starts] if starts.size else np.zeros(0, np.int64)
    return EdgeTable(order, starts, counts, np.stack([ends // nv, ends % nv], axis=1), same_way)


def union_find(
    n: int, a: np.ndarray, b: np.ndarray, parity: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Connected components of ``n`` elements joined by edges ``a[k] -- b[k]``.

    Parallel hooking with pointer jumping (Shiloach & Vishkin 1982, in the deterministic
    "hook the larger root under the smaller" form): each round every tree whose root has an
    edge to a smaller root is hung below one such root, then paths are halved until every
    element points at its root. Every round hooks at least one root and drops the edges that
    already lie inside a component, so it ends; mesh graphs settle in a few rounds.

    With ``parity`` (one bool per edge: "the two ends differ") each element also gets a
    parity relative to its root, such that tree edges satisfy ``p[a] ^ p[b] == parity``; an
    edge that does not (a cycle of odd parity, e.g. around a Moebius strip) is left for the
    caller to find.

    Parameters
    ----------
    n : int
    a, b : (k,) int
    parity : (k,) bool, optional

    Returns
    -------
    root : (n,) int64
        The smallest element of each element's component.
    relative : (n,) bool
        Parity of each element relative to its root (all False without ``parity``).
    """
    parent = np.arange(n, dtype=np.int64)
    rel = np.zeros(n, dtype=bool)
    a = np.asarray(a, dtype=np.int64)
    b = np.asarray(b, dtype=np.int64)
    w = np.zeros(a.size, dtype=bool) if parity is None else np.asarray(parity, dtype=bool)
    while True:
        _compress(parent, rel)
        ra, rb = parent[a], parent[b]
        live = ra != rb
        if not live.any():
            return parent, rel
        a, b, w = a[live], b[live], w[live]
        ra, rb = ra[live], rb[live]
        x = rel[a] ^ rel[b] ^ w
        hi, lo = np.maximum(ra, rb), np.minimum(ra, rb)
        # one edge per hooked root, so parent and parity come from the same edge
        roots, pick = np.unique(hi, return_index=True)
        parent[roots] = lo[pick]
        rel[roots] = x[pick]


def _compress(parent: np.ndarray, rel: np.ndarray) -> None:
    """Pointer jumping until every element points at its root, accumulating parities."""
    todo = np.flatnonzero(parent[parent] != parent)
    while todo.size:
        p = parent[todo]
        rel[todo] ^= rel[p]
        parent[todo] = parent[p]
        todo = todo[parent[parent[todo]] != parent[todo]]


def face_vectors(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> np.ndarray:
    """(n_faces, 3) Newell vectors: twice the area times the unit normal of each face.

    Exact for planar polygons (Newell's method, Sutherland et al. 1974); for a warped face
    the area of its projection on the best-fit plane.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    if fo.size < 2:
        return np.zeros((0, 3))
    n_faces = fo.size - 1
    if fi.size == 3 * n_faces and fo[-1] == fi.size and (np.diff(fo) == 3).all():
        return _triangle_vectors(v, fi.reshape(-1, 3))
    columns = FanColumns.of(v, fi, fo)
    if columns is not None:
        return columns.newell().T
    # about the first corner of each face, for conditioning far from the origin
    base = np.repeat(v[fi[fo[:-1]]], np.diff(fo), axis=0)
    p = v[fi] - base
    q = v[fi[next_corner(fo)]] - base
    return np.add.reduceat(np.cross(p, q), fo[:-1], axis=0)


def _triangle_vectors(v: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Newell vectors of triangles: ``(b - a) x (c - a)``, the same as the polygon formula
    for three corners, on one contiguous array per coordinate (no per-corner repeat, no
    reduceat, no (m, 3) cross product with its short last axis)."""
    cols = [np.ascontiguousarray(v[:, k]) for k in range(3)]
    a = [np.take(c, tri[:, 0]) for c in cols]
    e1 = [np.take(c, tri[:, 1]) - ak for c, ak in zip(cols, a, strict=True)]
    e2 = [np.take(c, tri[:, 2]) - ak for c, ak in zip(cols, a, strict=True)]
    out = np.empty((tri.shape[0], 3))
    out[:, 0] = e1[1] * e2[2] - e1[2] * e2[1]
    out[:, 1] = e1[2] * e2[0] - e1[0] * e2[2]
    out[:, 2] = e1[0] * e2[1] - e1[1] * e2[0]
    return out


def face_areas(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> np.ndarray:
    """(n_faces,) area of each face as exported: the fan of triangles from its first corner.

    STL, OBJ-triangles and the booleans write a polygon as the fan ``(a, b, c), (a, c, d),
    ...``; a warped quad's fan has more area than its projection on the best-fit plane
    (Newell's vector, :func:`face_vectors`), so the area is the sum of the fan triangles'
    areas. Each counts with the sign of its agreement with the face's Newell normal, so a
    planar concave face -- whose fan folds over itself -- still measures its exact area.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    if fo.size < 2:
        return np.zeros(0)
    sizes = np.diff(fo)
    if fi.size == 3 * sizes.size and fo[-1] == fi.size and (sizes == 3).all():
        n = _triangle_vectors(v, fi.reshape(-1, 3))  # a triangle is its own fan
        x, y, z = n[:, 0], n[:, 1], n[:, 2]
        return 0.5 * np.sqrt(x * x + y * y + z * z)
    columns = FanColumns.of(v, fi, fo)
    if columns is not None:
        return columns.areas()
    base = np.repeat(v[fi[fo[:-1]]], sizes, axis=0)
    cross = np.cross(v[fi] - base, v[fi[next_corner(fo)]] - base)  # fan triangles, doubled
    newell = np.add.reduceat(cross, fo[:-1], axis=0)
    along = np.einsum("ij,ij->i", cross, np.repeat(newell, sizes, axis=0))
    signed = np.where(along < 0, -1.0, 1.0) * np.linalg.norm(cross, axis=1)
    return 0.5 * np.add.reduceat(signed, fo[:-1])


def signed_volume(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    origin: np.ndarray | None = None,
) -> np.ndarray:
    """(n_faces,) signed volume of the cone from ``origin`` over each face's fan triangles.

    Summed over a closed, outward mesh this is its volume (divergence theorem); the total
    does not depend on ``origin``, which defaults to the bounding-box centre to keep the sum
    well conditioned. ``origin`` may also be ``(n_faces, 3)``, one point per face.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    n_faces = fo.size - 1
    if n_faces == 0:
        return np.zeros(0)
    columns = None
    if not (fi.size == 3 * n_faces and fo[-1] == fi.size and (np.diff(fo) == 3).all()):
        columns = FanColumns.of(v, fi, fo)
    if origin is None:
        if columns is not None:  # the same corners, so the same box
            origin = 0.5 * (columns.xyz.min(axis=(1, 2)) + columns.xyz.max(axis=(1, 2)))
        else:
            used = v[fi]
            origin = 0.5 * (used.min(axis=0) + used.max(axis=0))
    origin = np.asarray(origin, dtype=np.float64)
    if columns is not None:
        return columns.volumes(origin)
    if fi.size == 3 * n_faces and fo[-1] == fi.size and (np.diff(fo) == 3).all():
        # Triangles: one cone each, on contiguous coordinate columns (no fan, no bincount).
        tri = fi.reshape(-1, 3)
        o = [origin[:, k] if origin.ndim == 2 else origin[k] for k in range(3)]
        cols = [np.ascontiguousarray(v[:, k]) for k in range(3)]
        p = [[np.take(cols[k], tri[:, c]) - o[k] for k in range(3)] for c in range(3)]
        (x0, y0, z0), (x1, y1, z1), (x2, y2, z2) = p
        det = x0 * (y1 * z2 - z1 * y2) + y0 * (z1 * x2 - x1 * z2) + z0 * (x1 * y2 - y1 * x2)
        return det / 6.0
    tris = fan_triangles(fi, fo)
    face = np.repeat(np.arange(n_faces), np.diff(fo) - 2)
    o = origin[face] if origin.ndim == 2 else origin
    p0, p1, p2 = v[tris[:, 0]] - o, v[tris[:, 1]] - o, v[tris[:, 2]] - o
    det = np.einsum("ij,ij->i", p0, np.cross(p1, p2)) / 6.0
    return np.bincount(face, weights=det, minlength=n_faces)


#: faces of up to this many corners take the column path (:class:`FanColumns`); beyond it
#: numpy's sums over a face switch to pairwise blocks, which the columns would not follow
COLUMN_CORNERS = 8


class FanColumns:
    """The corners of every face gathered once, one contiguous row per coordinate and
    corner, for the measures of the fan triangles ``(a, b, c), (a, c, d), ...``.

    A face with fewer corners than the widest (``K``) repeats its last corner; the extra
    fan triangles it gets, ``(a, z, z)``, have an exactly zero cross product, so they add
    exact zeros. Every sum over a face then runs in the order of the per-corner path
    (``reduceat`` and ``bincount`` over the corners, whose first and last terms are the zero
    crosses of the corner at ``a``), and the measures come out the same to the bit, for
    quads and triangles together, without the ``(m, 3)`` cross products with their short
    last axis, the repeats and the reductions of that path. Faces of more than
    :data:`COLUMN_CORNERS` corners are left to it (:meth:`of` gives None).

    Attributes
    ----------
    xyz : (3, K, n_faces) float64
        ``xyz[c, k, f]``: coordinate ``c`` of corner ``k`` of face ``f``.
    sizes : (n_faces,) int64
        Corners of each face.
    """

    def __init__(self, xyz: np.ndarray, sizes: np.ndarray):
        self.xyz = xyz
        self.sizes = sizes

    @classmethod
    def of(cls, v: np.ndarray, fi: np.ndarray, fo: np.ndarray) -> FanColumns | None:
        """The columns of a mesh whose faces have at most :data:`COLUMN_CORNERS` corners."""
        corners = by_faces("fan corners", fi, fo, len(v), lambda: _corner_table(fi, fo))
        if corners is None:
            return None
        ids, sizes = corners
        return cls(np.ascontiguousarray(v.T).take(ids, axis=1), sizes)

    def _fan(self, p: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Cross products ``p[:, j] x p[:, j + 1]`` for j = 1 .. K-2 (componentwise as
        :func:`numpy.cross` computes them)."""
        out = []
        for j in range(1, p.shape[1] - 1):
            (a0, a1, a2), (b0, b1, b2) = p[:, j], p[:, j + 1]
            out.append((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))
        return out

    def _edges(self) -> np.ndarray:
        x = self.xyz
        return x - x[:, :1]  # (the first column, zeros, is never used)

    def newell(self) -> np.ndarray:
        """(3, n_faces) Newell vectors (twice the area times the unit normal)."""
        return _total(self._fan(self._edges()))

    def areas(self) -> np.ndarray:
        """(n_faces,) area of each face's fan, each triangle signed by its agreement with
        the Newell normal (see :func:`face_areas`)."""
        crosses = self._fan(self._edges())
        n0, n1, n2 = _total(crosses)
        signed = []
        for t0, t1, t2 in crosses:
            along = (t0 * n0 + t2 * n2) + t1 * n1  # the order numpy's einsum sums in
            signed.append(np.where(along < 0, -1.0, 1.0) * np.sqrt(t0 * t0 + t1 * t1 + t2 * t2))
        return 0.5 * _sum(signed)

    def volumes(self, origin: np.ndarray, overwrite: bool = False) -> np.ndarray:
        """(n_faces,) signed volume of the cone from ``origin`` ((3,), or (n_faces, 3))
        over each face's fan triangles (see :func:`signed_volume`); ``overwrite`` moves the
        corners to the origin in place (no copy of the columns; they are not used again)."""
        o = (origin[:, None] if origin.ndim == 1 else origin.T)[:, None, :]
        p = np.subtract(self.xyz, o, out=self.xyz) if overwrite else self.xyz - o
        x0, y0, z0 = p[:, 0]
        dets = [((x0 * c0 + z0 * c2) + y0 * c1) / 6.0 for c0, c1, c2 in self._fan(p)]
        return _sum(dets)

    def corner_sums(self) -> list[np.ndarray]:
        """The sums of each face's corners' coordinates (3 arrays of n_faces), added in
        corner order; the repeated corners of short faces add exact zeros."""
        x = self.xyz
        sums = [x[c, 0] + x[c, 1] + x[c, 2] for c in range(3)]
        for k in range(3, x.shape[1]):
            real = k < self.sizes
            for c in range(3):
                sums[c] += np.where(real, x[c, k], 0.0)
        return sums


def _corner_table(fi: np.ndarray, fo: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(K, n_faces) vertex ids (row k: corner k of every face, a short face repeating its
    last corner) and the faces' sizes; None if a face has more than COLUMN_CORNERS."""
    sizes = np.diff(fo)
    if sizes.size == 0 or fo[-1] != fi.size:
        return None
    k = int(sizes.max())
    if k > COLUMN_CORNERS or int(sizes.min()) < 3:
        return None
    pos = np.minimum(fo[:-1] + np.arange(k)[:, None], fo[1:] - 1)
    return fi[pos], sizes


def _sum(terms: list[np.ndarray]) -> np.ndarray:
    """Terms added one after another (the order of a per-face ``reduceat``)."""
    out = terms[0].copy()
    for t in terms[1:]:
        out += t
    return out


def _total(crosses: list[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> np.ndarray:
    return np.stack([_sum([t[c] for t in crosses]) for c in range(3)])


@dataclass(frozen=True)
class SolidReport:
    """Whether a mesh bounds a solid, and if not, where it fails."""

    open_edges: int
    nonmanifold_edges: int
    misoriented_edges: int
    example: tuple[int, int] | None  # one offending edge (vertex ids), if any

    @property
    def is_watertight(self) -> bool:
        return self.open_edges == 0 and self.nonmanifold_edges == 0

    @property
    def is_solid(self) -> bool:
        return self.is_watertight and self.misoriented_edges == 0

    def problems(self) -> str:
        """The defects as a phrase: '128 open edges, 2 non-manifold edges'."""
        parts = [
            f"{n} {what} edge{'s' if n != 1 else ''}"
            for n, what in (
                (self.open_edges, "open"),
                (self.nonmanifold_edges, "non-manifold"),
                (self.misoriented_edges, "inconsistently oriented"),
            )
            if n
        ]
        return ", ".join(parts)


def is_closed_oriented(face_indices: np.ndarray, face_offsets: np.ndarray, n_vertices: int) -> bool:
    """Every edge on exactly two faces that run it in opposite directions.

    The fast form of ``solid_report(...).is_solid``: one sort of the directed edge keys
    (no indices), after which a closed, consistently oriented manifold reads as pairs
    ``(edge, forward), (edge, backward)`` with every pair a different edge.
    """
    fi = np.asarray(face_indices, dtype=np.int64)
    if fi.size == 0 or fi.size % 2:
        return False
    a, b = fi, fi[next_corner(face_offsets)]
    nv = max(int(n_vertices), 1)
    key = np.sort((np.minimum(a, b) * nv + np.maximum(a, b)) * 2 + (a > b)).reshape(-1, 2)
    edge = key >> 1
    return bool(
        np.all(edge[:, 0] == edge[:, 1])
        and np.all((key[:, 0] & 1) == 0)
        and np.all((key[:, 1] & 1) == 1)
        and np.all(edge[1:, 0] != edge[:-1, 0])
    )


def solid_report(
    face_indices: np.ndarray, face_offsets: np.ndarray, n_vertices: int
) -> SolidReport:
    """Count open, non-manifold and misoriented edges (see :func:`edge_table`)."""
    t = edge_table(face_indices, face_offsets, n_vertices)
    bad = (t.counts != 2) | t.same_way
    example = tuple(int(x) for x in t.vertices[np.argmax(bad)]) if bad.any() else None
    return SolidReport(
        open_edges=int(np.count_nonzero(t.counts == 1)),
        nonmanifold_edges=int(np.count_nonzero(t.counts > 2)),
        misoriented_edges=int(np.count_nonzero(t.same_way & (t.counts == 2))),
        example=example,  # type: ignore[arg-type]
    )


def flat_open_parts(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    planar_tolerance: float = 1e-6,
) -> int:
    """How many connected parts are flat open sheets (all in one plane, with a boundary).

    Capping such a part fills its outline in its own plane: the cap lies on the sheet, and
    the result is a two-sided shell of zero volume, doubled and usually non-manifold, which
    no slicer can print. Parts are joined by shared vertices (a parallel union-find); each
    one's plane is the least-squares plane of its vertices (the smallest eigenvector of their
    covariance, batched), and it is flat when every vertex lies within ``planar_tolerance``
    of the part's bounding-box diagonal from that plane.

    Returns
    -------
    int
        The number of flat parts that have at least one boundary edge.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    if fi.size == 0:
        return 0
    used, part, count, starts = by_faces(
        "sheets", fi, fo, len(v), lambda: _vertex_parts(fi, fo, len(v))
    )
    n_parts = count.size
    # the used vertices run part by part, each part in vertex order (so every sum over a
    # part adds what a sum in vertex order adds, in the same order)
    p = np.ascontiguousarray(v.T).take(used, axis=1)
    mean = [np.bincount(part, p[k], n_parts) / count for k in range(3)]
    d = [p[k] - mean[k].take(part) for k in range(3)]
    cov = np.zeros((n_parts, 3, 3))
    for a in range(3):
        for b in range(a, 3):
            cov[:, a, b] = cov[:, b, a] = np.bincount(part, d[a] * d[b], n_parts)
    normal = np.linalg.eigh(cov)[1][:, :, 0]  # eigenvalues ascending: the plane's normal
    n0, n1, n2 = (normal[:, k].take(part) for k in range(3))
    far = np.maximum.reduceat(np.abs((d[0] * n0 + d[2] * n2) + d[1] * n1), starts)
    extent = np.maximum.reduceat(p, starts, axis=1) - np.minimum.reduceat(p, starts, axis=1)
    flat = far <= planar_tolerance * np.linalg.norm(extent.T, axis=1)
    if not flat.any():  # (the common case: no edge table needed to say which are open)
        return 0
    has_open = by_faces("sheets open", fi, fo, len(v), lambda: _open_parts(fi, fo, len(v)))
    return int(np.count_nonzero(flat & has_open))


def _vertex_parts(fi: np.ndarray, fo: np.ndarray, n_vertices: int) -> tuple:
    """The used vertices sorted by the part they join (by shared vertices; parts numbered
    by their smallest vertex, vertices in order within a part), each one's part, the
    vertices per part and where each part's run starts.

    The parts are scipy's connected components of the vertex graph of the faces' edges
    (compiled: twice as fast as our vectorized union-find here, and the same partition)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    edges = coo_matrix(
        (np.ones(fi.size, np.int8), (fi, fi[next_corner(fo)])), shape=(n_vertices, n_vertices)
    )
    _, label = connected_components(edges.tocsr(), directed=False)
    used = np.zeros(n_vertices, dtype=bool)
    used[fi] = True
    parts, part = np.unique(label[used], return_inverse=True)
    order = np.argsort(part, kind="stable")
    count = np.bincount(part, minlength=parts.size)
    starts = np.concatenate([[0], np.cumsum(count)[:-1]])
    return np.flatnonzero(used)[order], part[order], count, starts


def _open_parts(fi: np.ndarray, fo: np.ndarray, n_vertices: int) -> np.ndarray:
    """Which parts (numbered as :func:`_vertex_parts` numbers them) have a boundary edge."""
    used, part, count, _ = by_faces(
        "sheets", fi, fo, n_vertices, lambda: _vertex_parts(fi, fo, n_vertices)
    )
    part_of = np.zeros(n_vertices, dtype=np.int64)
    part_of[used] = part
    t = edge_table(fi, fo, n_vertices)
    has_open = np.zeros(count.size, dtype=bool)
    has_open[part_of[t.vertices[t.counts == 1, 0]]] = True
    return has_open
