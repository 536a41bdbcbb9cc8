"""The levels of Catmull-Clark subdivision: connectivity in closed form, rules as matrices.

A level's connectivity (:class:`Level`) is built from the half-edges once; every later
level is all quads and follows from the one before by index arithmetic (no sorting, no
search). The rules of a level are linear in the vertices, so they are two sparse matrices
(:meth:`Level.stencil`) applied to all the vertices' columns at once: x, y, z and any
point attributes in one product, a column more costing a small part of the level.

Indices are int32 while the last level's counts fit (half the memory to write and read of
int64, which is most of a level's time), int64 beyond.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .halfedge import HalfEdges

__all__ = ["Level", "index_type"]


def index_type(largest: int) -> type:
    """int32 when every index and count up to ``largest`` fits, else int64."""
    return np.int32 if largest < 2**31 - 1 else np.int64


def _csr(data: np.ndarray, indices: np.ndarray, indptr: np.ndarray, shape: tuple) -> Any:
    from scipy.sparse import csr_matrix

    # indices and indptr of one integer type: scipy takes them as they are, unchecked
    return csr_matrix((data, indices, indptr), shape=shape, copy=False)


@dataclass
class Level:
    """Connectivity of one level, as much as the Catmull-Clark rules need.

    Half-edge ``h`` is corner ``h`` of the flat face list ``face_indices``; ``edge`` is its
    undirected edge. ``edge_vertices`` are the two ends of each edge (not sorted after the
    first level) and ``edge_halfedges`` its two half-edges, the one leaving
    ``edge_vertices[e, 0]`` first (a boundary edge: its one half-edge twice). ``around``
    lists the half-edges leaving each vertex, vertex after vertex, those of vertex ``v``
    from ``around_offsets[v]`` on. ``face``, ``prev`` and ``next`` (the half-edge's face and
    its neighbours in it) are kept for the first level only: on all-quad levels they
    follow from ``h`` (:meth:`faces_of`, :meth:`nexts_of`).
    """

    face_indices: np.ndarray
    face_offsets: np.ndarray
    edge: np.ndarray
    edge_vertices: np.ndarray
    edge_halfedges: np.ndarray
    around: np.ndarray
    around_offsets: np.ndarray
    face: np.ndarray | None = None
    prev: np.ndarray | None = None
    next: np.ndarray | None = None

    @classmethod
    def from_halfedges(cls, he: HalfEdges, itype: type) -> Level:
        h = np.arange(he.n_halfedges)
        one = (he.twin < 0) | (h < he.twin)  # each edge once
        e, h, t = he.edge[one], h[one], he.twin[one]
        t = np.where(t < 0, h, t)
        first = he.origin[h] == he.edge_vertices[e, 0]  # h leaves the edge's first end
        edge_halfedges = np.empty((he.n_edges, 2), dtype=itype)
        edge_halfedges[e, 0] = np.where(first, h, t)
        edge_halfedges[e, 1] = np.where(first, t, h)
        around_offsets = np.zeros(he.n_vertices + 1, dtype=itype)
        np.cumsum(np.bincount(he.origin, minlength=he.n_vertices), out=around_offsets[1:])
        sizes = he.face_sizes
        quads = bool(sizes.size and (sizes == 4).all())
        return cls(
            face_indices=he.origin.astype(itype),
            face_offsets=he.face_offsets.astype(itype),
            edge=he.edge.astype(itype),
            edge_vertices=he.edge_vertices.astype(itype),
            edge_halfedges=edge_halfedges,
            around=np.argsort(he.origin).astype(itype),  # any order within a vertex
            around_offsets=around_offsets,
            face=None if quads else he.face.astype(itype),
            prev=None if quads else he.prev.astype(itype),
            next=None if quads else he.next.astype(itype),
        )

    # on all-quad levels (face = None) corner h is corner h % 4 of quad h // 4

    def faces_of(self, h: np.ndarray) -> np.ndarray:
        return h >> 2 if self.face is None else self.face[h]

    def nexts_of(self, h: np.ndarray) -> np.ndarray:
        if self.next is not None:
            return self.next[h]
        out = h + 1
        out &= 3
        out |= h & ~3  # the same quad's corner after
        return out

    def prevs(self) -> np.ndarray:
        """Every half-edge's previous one in its face."""
        if self.prev is not None:
            return self.prev
        out = np.arange(-1, self.face_indices.size - 1, dtype=self.face_indices.dtype)
        out[::4] += 4
        return out

    def stencil(
        self, n: int, edge_weight: np.ndarray | None, spare: int = 0
    ) -> tuple[Any, Any, np.ndarray]:
        """The level's rules as sparse matrices.

        Returns ``faces`` (F, n), the face points from the vertices; ``points``
        (n + E + F + spare, n + F), all new points from the vertices followed by the face
        points, except that a vertex point lacks its own vertex's share and the face
        points (and ``spare`` rows after them, room for the next level's face points) are
        left zero: the share and the face points are added apart, with no product; and
        ``scale`` (n,), what the vertex rows are to be multiplied by. ``edge_weight`` (E,)
        blends each edge point towards the midpoint of its ends (1 on a boundary, a
        crease's sharpness on a crease).
        """
        fi, fo = self.face_indices, self.face_offsets
        ev, eh = self.edge_vertices, self.edge_halfedges
        itype = fi.dtype.type
        m, n_edges, n_faces = fi.size, ev.shape[0], fo.size - 1
        nnz = 2 * m + 4 * n_edges
        data = np.full(nnz, 0.25)
        if self.face is None:  # a quad's point: a quarter of each corner (as the ring's entries)
            faces = _csr(data[:m], fi, fo, (n_faces, n))
        else:
            sizes = np.diff(fo)
            faces = _csr(np.repeat(1.0 / sizes, sizes), fi, fo, (n_faces, n))
        indices = np.empty(nnz, dtype=itype)

        # vertex points, smooth rule (Q + 2R + (n - 3) S) / n with n the valence
        # = (sum of face points + sum of edge neighbours) / n^2 + (n - 2) / n * S: per
        # half-edge leaving the vertex its face's point and its other end (a boundary
        # vertex misses a neighbour; the boundary rule replaces it). The entries are 1/4
        # like the rest, the 4 / n^2 is the rows' scale.
        out = self.around
        ring = indices[: 2 * m].reshape(m, 2)
        ring[:, 0] = self.faces_of(out)
        ring[:, 0] += n
        ring[:, 1] = fi[self.nexts_of(out)]
        k = np.diff(self.around_offsets)
        scale = 4.0 / np.maximum(k, 1) ** 2
        # edge points: (v0 + v1 + f0 + f1) / 4, blended towards (v0 + v1) / 2
        cols = indices[2 * m :].reshape(n_edges, 4)
        cols[:, :2] = ev
        cols[:, 2:] = self.faces_of(eh)
        cols[:, 2:] += n
        if edge_weight is not None:
            ew = data[2 * m :].reshape(n_edges, 4)
            ew[:, :2] = (0.25 + 0.25 * edge_weight)[:, None]
            ew[:, 2:] = (0.25 - 0.25 * edge_weight)[:, None]
        rows = n + n_edges + n_faces + spare
        indptr = np.empty(rows + 1, dtype=itype)
        np.multiply(self.around_offsets, 2, out=indptr[: n + 1])
        indptr[n : n + n_edges + 1] = np.arange(2 * m, nnz + 1, 4, dtype=itype)
        indptr[n + n_edges :] = nnz  # the face points and the spare rows: no entries
        points = _csr(data, indices, indptr, (rows, n + n_faces))
        return faces, points, scale

    def quads(self, n: int, dtype: type) -> np.ndarray:
        """The next level's faces (m, 4): quad ``h`` = (vertex, edge point, face point,
        edge point) of half-edge ``h``, the points numbered ``n`` vertices, then one edge
        point per edge, then one face point per face."""
        fi, edge = self.face_indices, self.edge
        m, n_edges = fi.size, self.edge_vertices.shape[0]
        quad = np.empty((m, 4), dtype=dtype)
        quad[:, 0] = fi
        np.add(edge, n, out=quad[:, 1])
        if self.face is None:
            np.right_shift(np.arange(m, dtype=dtype), 2, out=quad[:, 2])
            quad[:, 2] += n + n_edges
            q = quad.reshape(-1, 4, 4)  # quad h's previous edge: the edge of h - 1 in its quad
            q[:, 1:, 3] = q[:, :3, 1]
            q[:, 0, 3] = q[:, 3, 1]
        else:
            np.add(self.face, n + n_edges, out=quad[:, 2])
            np.add(edge[self.prev], n, out=quad[:, 3])
        return quad

    def refined(self, n: int) -> Level:
        """The connectivity of the next level (all quads, see :meth:`quads`)."""
        fi, edge, ev, eh = self.face_indices, self.edge, self.edge_vertices, self.edge_halfedges
        itype = fi.dtype.type
        n_edges, m = ev.shape[0], fi.size
        quad = self.quads(n, itype)
        prev = self.prevs()
        h4 = np.arange(0, 4 * m, 4, dtype=itype)
        # edges: old edge e splits into 2e (at ev[e, 0]) and 2e + 1 (at ev[e, 1]); the
        # edge from the edge point of h to the face point is 2E + h
        side = fi == ev[edge, 1]
        new_edge = np.empty((m, 4), dtype=itype)
        np.multiply(edge, 2, out=new_edge[:, 0])
        new_edge[:, 0] += side
        new_edge[:, 1] = np.arange(2 * n_edges, 2 * n_edges + m, dtype=itype)
        np.add(prev, 2 * n_edges, out=new_edge[:, 2])
        pe = edge[prev]
        np.multiply(pe, 2, out=new_edge[:, 3])
        new_edge[:, 3] += fi == ev[pe, 1]
        new_ev = np.empty((2 * n_edges + m, 2), dtype=itype)
        new_ev[: 2 * n_edges, 0] = ev.ravel()
        new_ev[: 2 * n_edges, 1] = np.repeat(np.arange(n, n + n_edges, dtype=itype), 2)
        new_ev[2 * n_edges :] = quad[:, 1:3]
        # the corners on each split edge: corner 0 of the quad of the half-edge leaving its
        # end (4h), corner 3 of the quad after the one arriving there (4 next(h) + 3)
        leave = 4 * eh
        arrive = 4 * self.nexts_of(eh) + 3
        new_eh = np.empty((2 * n_edges + m, 2), dtype=itype)
        split = new_eh[: 2 * n_edges].reshape(n_edges, 2, 2)  # [e, child, slot]
        split[:, :, 0] = leave
        split[:, :, 1] = arrive[:, ::-1]
        lone = np.flatnonzero(eh[:, 0] == eh[:, 1])
        if lone.size:  # a boundary edge's one half-edge h: its corner 0 on the child at
            # its origin, the next quad's corner 3 on the other child
            at_first = fi[eh[lone, 0]] == ev[lone, 0]
            a, b = leave[lone, 0], arrive[lone, 0]
            split[lone, 0] = np.where(at_first, a, b)[:, None]
            split[lone, 1] = np.where(at_first, b, a)[:, None]
        # the edge 2E + h: corner 1 of quad h (leaving the edge point), corner 2 of the
        # quad after it (leaving the face point)
        new_eh[2 * n_edges :, 0] = h4 + 1
        new_eh[2 * n_edges :, 1] = 4 * self.nexts_of(np.arange(m, dtype=itype)) + 2
        # the corners at each new point: at a vertex its own corners, at an edge point
        # corner 1 of each of its half-edges' quads and corner 3 of the quads after them,
        # at a face point corner 2 of each of the face's quads
        at_edge = np.empty((n_edges, 2, 2), dtype=itype)
        np.add(leave, 1, out=at_edge[:, :, 0])
        at_edge[:, :, 1] = arrive
        n_side = np.full(n_edges, 4, dtype=itype)
        if lone.size:
            keep = np.ones((n_edges, 2), dtype=bool)
            keep[lone, 1] = False
            at_edge = at_edge[keep]
            n_side[lone] = 2
        around_offsets = np.empty(n + n_edges + self.face_offsets.size, dtype=itype)
        around_offsets[: n + 1] = self.around_offsets
        np.cumsum(n_side, out=around_offsets[n + 1 : n + n_edges + 1])
        around_offsets[n + 1 : n + n_edges + 1] += m
        np.add(self.face_offsets[1:], 3 * m, out=around_offsets[n + n_edges + 1 :])
        return Level(
            face_indices=quad.reshape(-1),
            face_offsets=np.arange(0, 4 * m + 1, 4, dtype=itype),
            edge=new_edge.reshape(-1),
            edge_vertices=new_ev,
            edge_halfedges=new_eh,
            around=np.concatenate([4 * self.around, at_edge.reshape(-1), h4 + 2]),
            around_offsets=around_offsets,
        )
