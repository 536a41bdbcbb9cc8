"""Half-edge connectivity of a polygon mesh, built vectorized from flat face arrays.

A mesh is stored flat: ``face_indices`` lists the vertices of every face one after the
other, and face ``f`` is ``face_indices[face_offsets[f]:face_offsets[f + 1]]``, listed
counter-clockwise seen from outside. Half-edge ``h`` is corner ``h`` of that flat list: it
starts at ``face_indices[h]`` and runs to the next vertex of the same face, so the half-edges
of a face are contiguous and a face's own corner order is kept.

Twins are matched by sorting the undirected edge keys (O(n log n)); the same sort finds the
topological defects a half-edge structure cannot represent: an edge on more than two faces
(non-manifold), or two faces that run a shared edge the same way (inconsistent orientation).
Ordered neighbourhoods (the faces around a vertex, the boundary loops) come from list
ranking by pointer jumping (Wyllie 1979), O(n log k) for rings of at most k elements, so
nothing walks the mesh one element at a time.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .keys import sort_keys

__all__ = [
    "Fans",
    "HalfEdges",
    "MeshTopologyError",
    "boundary_loops",
    "build_halfedges",
    "check_faces",
]


class MeshTopologyError(ValueError):
    """The faces do not describe an oriented 2-manifold polygon mesh (with boundary)."""


def _readonly(*arrays: np.ndarray) -> None:
    for a in arrays:
        a.flags.writeable = False


def _listing(values: np.ndarray, limit: int = 8) -> str:
    items = [str(int(v)) for v in values[:limit]]
    if values.size > limit:
        items.append("...")
    return "[" + ", ".join(items) + "]"


def check_faces(
    face_indices: np.ndarray, face_offsets: np.ndarray, n_vertices: int
) -> tuple[np.ndarray, np.ndarray]:
    """Check the flat face arrays and return them as int64 (no topology checks).

    Parameters
    ----------
    face_indices : (m,) int
        Vertex indices of all faces, concatenated.
    face_offsets : (n_faces + 1,) int
        Start of each face in ``face_indices``, then ``m``.
    n_vertices : int
        Number of vertices the indices refer to.

    Returns
    -------
    face_indices : (m,) int64
    face_offsets : (n_faces + 1,) int64

    Raises
    ------
    MeshTopologyError
        Arrays that are not 1-d integers, offsets that do not run from 0 to ``m`` without
        decreasing, faces with fewer than 3 vertices or a repeated vertex, indices outside
        ``0 .. n_vertices - 1``; the message names the first offending face.
    """
    fi = np.asarray(face_indices)
    fo = np.asarray(face_offsets)
    for name, a in (("face_indices", fi), ("face_offsets", fo)):
        if a.ndim != 1:
            raise MeshTopologyError(f"{name} must be a flat array, got shape {a.shape}")
        if a.size and not np.issubdtype(a.dtype, np.integer):
            raise MeshTopologyError(f"{name} must hold integers, got {a.dtype}")
    fi = fi.astype(np.int64, copy=False)
    fo = fo.astype(np.int64, copy=False)
    if fo.size == 0 or fo[0] != 0 or fo[-1] != fi.size:
        raise MeshTopologyError(
            f"face_offsets must start at 0 and end at len(face_indices) = {fi.size}, "
            f"got {_listing(fo[:1])[:-1]} ... {int(fo[-1]) if fo.size else 'nothing'}]"
        )
    sizes = np.diff(fo)
    bad = np.flatnonzero(sizes < 3)
    if bad.size:
        f = int(bad[0])
        raise MeshTopologyError(f"face {f} has {int(sizes[f])} vertices; a face needs at least 3")
    bad = np.flatnonzero((fi < 0) | (fi >= n_vertices))
    if bad.size:
        h = int(bad[0])
        f = int(np.searchsorted(fo, h, side="right") - 1)
        raise MeshTopologyError(
            f"face {f} refers to vertex {int(fi[h])}, but the mesh has {n_vertices} vertices "
            f"(indices 0 .. {n_vertices - 1})"
        )
    if fi.size == 3 * sizes.size:  # triangles: a repeat is two equal corners, no sort
        t = fi.reshape(-1, 3)
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        if not ((a == b) | (b == c) | (a == c)).any():
            return fi, fo
    face = np.repeat(np.arange(sizes.size, dtype=np.int64), sizes)
    key = np.sort(face * max(n_vertices, 1) + fi)
    dup = np.flatnonzero(key[1:] == key[:-1])
    if dup.size:
        f = int(key[dup[0]] // max(n_vertices, 1))
        v = int(key[dup[0]] % max(n_vertices, 1))
        raise MeshTopologyError(
            f"face {f} visits vertex {v} twice ({_listing(fi[fo[f] : fo[f + 1]])}); "
            "a face lists each of its vertices once"
        )
    return fi, fo


@dataclass(frozen=True, eq=False)
class Fans:
    """The half-edges leaving each vertex, ordered counter-clockwise around it.

    A manifold vertex has one fan: closed (a cycle) inside the mesh, open on the boundary,
    where it starts at the vertex's outgoing boundary half-edge. A non-manifold vertex
    (two sheets touching at a point) has one fan per sheet.

    Attributes
    ----------
    halfedges : (n_halfedges,) int64
        Outgoing half-edges, fan after fan, fans sorted by vertex.
    offsets : (n_fans + 1,) int64
        Fan ``i`` is ``halfedges[offsets[i]:offsets[i + 1]]``.
    vertex : (n_fans,) int64
        The vertex of each fan.
    closed : (n_fans,) bool
        True for a fan that goes all the way round (an interior vertex).
    """

    halfedges: np.ndarray
    offsets: np.ndarray
    vertex: np.ndarray
    closed: np.ndarray

    @property
    def sizes(self) -> np.ndarray:
        return np.diff(self.offsets)


@dataclass(frozen=True, eq=False)
class HalfEdges:
    """Half-edge connectivity of a polygon mesh; every array is read-only.

    Half-edge ``h`` is corner ``h`` of the flat face list: it leaves ``origin[h]`` and ends
    at ``vertex[h]``, with its face on the left.

    Attributes
    ----------
    origin, vertex : (n_halfedges,) int64
        Start and end vertex.
    twin : (n_halfedges,) int64
        The opposite half-edge in the neighbouring face, -1 on a boundary edge.
    next, prev : (n_halfedges,) int64
        The following / preceding half-edge of the same face.
    face : (n_halfedges,) int64
        The face on the left.
    edge : (n_halfedges,) int64
        Undirected edge id (both half-edges of an interior edge share it).
    edge_vertices : (n_edges, 2) int64
        The two ends of each edge, smaller index first; edges sorted by that pair.
    vertex_halfedge : (n_vertices,) int64
        One outgoing half-edge per vertex, a boundary one where there is one; -1 for a
        vertex that no face uses.
    face_halfedge : (n_faces,) int64
        The first half-edge of each face (its first corner).
    """

    origin: np.ndarray
    vertex: np.ndarray
    twin: np.ndarray
    next: np.ndarray
    prev: np.ndarray
    face: np.ndarray
    edge: np.ndarray
    edge_vertices: np.ndarray
    vertex_halfedge: np.ndarray
    face_halfedge: np.ndarray
    face_offsets: np.ndarray

    # -- sizes -------------------------------------------------------------------------

    @property
    def n_halfedges(self) -> int:
        return int(self.origin.size)

    @property
    def n_vertices(self) -> int:
        return int(self.vertex_halfedge.size)

    @property
    def n_faces(self) -> int:
        return int(self.face_halfedge.size)

    @property
    def n_edges(self) -> int:
        return int(self.edge_vertices.shape[0])

    @property
    def face_sizes(self) -> np.ndarray:
        """(n_faces,) int64: number of vertices of each face."""
        return np.diff(self.face_offsets)

    @property
    def euler_characteristic(self) -> int:
        """V - E + F (vertices that no face uses count too)."""
        return self.n_vertices - self.n_edges + self.n_faces

    # -- boundary ----------------------------------------------------------------------

    @cached_property
    def is_boundary(self) -> np.ndarray:
        """(n_halfedges,) bool: the half-edge has no twin."""
        out = self.twin < 0
        _readonly(out)
        return out

    @cached_property
    def boundary_halfedges(self) -> np.ndarray:
        """(n_boundary,) int64: half-edges without a twin, in half-edge order."""
        out = np.flatnonzero(self.is_boundary)
        _readonly(out)
        return out

    @property
    def boundary_edges(self) -> np.ndarray:
        """(n_boundary, 2) int64: boundary edges as (start, end), the face on the left."""
        b = self.boundary_halfedges
        return np.stack([self.origin[b], self.vertex[b]], axis=1)

    @property
    def is_closed(self) -> bool:
        return self.boundary_halfedges.size == 0

    @cached_property
    def is_boundary_vertex(self) -> np.ndarray:
        """(n_vertices,) bool: the vertex is on at least one boundary edge."""
        out = np.zeros(self.n_vertices, dtype=bool)
        out[self.origin[self.boundary_halfedges]] = True
        _readonly(out)
        return out

    @cached_property
    def valence(self) -> np.ndarray:
        """(n_vertices,) int64: number of edges at each vertex."""
        n = self.n_vertices
        out = np.bincount(self.origin, minlength=n) + np.bincount(
            self.vertex[self.boundary_halfedges], minlength=n
        )
        _readonly(out)
        return out

    # -- ordered neighbourhoods --------------------------------------------------------

    @cached_property
    def fans(self) -> Fans:
        """The outgoing half-edges of every vertex, counter-clockwise (see :class:`Fans`).

        The successor of ``h`` around its origin is ``twin[prev[h]]``; an open fan starts at
        a boundary half-edge and ends where that twin is missing.
        """
        has_twin = self.twin[self.prev] >= 0
        succ = np.where(has_twin, self.twin[self.prev], -1)
        counts = np.bincount(self.origin, minlength=self.n_vertices)
        tail, dist, closed = rank_links(succ, int(counts.max(initial=1)))
        order = np.lexsort((-dist, tail, self.origin))
        first = np.ones(order.size, dtype=bool)
        first[1:] = tail[order[1:]] != tail[order[:-1]]
        starts = np.flatnonzero(first)
        fans = Fans(
            halfedges=order,
            offsets=np.append(starts, order.size),
            vertex=self.origin[order[starts]],
            closed=closed[order[starts]],
        )
        _readonly(fans.halfedges, fans.offsets, fans.vertex, fans.closed)
        return fans

    @cached_property
    def is_manifold_vertex(self) -> np.ndarray:
        """(n_vertices,) bool: at most one fan of faces meets at the vertex."""
        out = np.bincount(self.fans.vertex, minlength=self.n_vertices) <= 1
        _readonly(out)
        return out

    def faces_around_vertex(self) -> tuple[np.ndarray, np.ndarray]:
        """Faces at each vertex, counter-clockwise (from the boundary on a boundary vertex).

        Returns
        -------
        offsets : (n_vertices + 1,) int64
        faces : (n_halfedges,) int64
            Faces of vertex ``v`` are ``faces[offsets[v]:offsets[v + 1]]``.
        """
        fans = self.fans
        offsets = np.zeros(self.n_vertices + 1, dtype=np.int64)
        np.cumsum(np.bincount(self.origin, minlength=self.n_vertices), out=offsets[1:])
        return offsets, self.face[fans.halfedges]

    def boundary_loops(self) -> list[np.ndarray]:
        """Boundary loops as vertex cycles, each running with the mesh on its left.

        Returns
        -------
        list of (k,) int64
            One array per loop, sorted by the loop's smallest half-edge; empty when closed.
        """
        b = self.boundary_halfedges
        if b.size == 0:
            return []
        fans = self.fans
        open_ = np.flatnonzero(~fans.closed)
        heads = fans.halfedges[fans.offsets[open_]]
        tails = fans.halfedges[fans.offsets[open_ + 1] - 1]
        compact = np.full(self.n_halfedges, -1, dtype=np.int64)
        compact[b] = np.arange(b.size)
        succ = np.full(b.size, -1, dtype=np.int64)
        # the boundary edge coming into a fan's vertex is the one before its last half-edge
        succ[compact[self.prev[tails]]] = compact[heads]
        tail, dist, _ = rank_links(succ, b.size)
        order = np.lexsort((-dist, tail))
        cut = np.flatnonzero(tail[order[1:]] != tail[order[:-1]]) + 1
        return [self.origin[b[loop]] for loop in np.split(order, cut)]


def rank_links(succ: np.ndarray, max_len: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Order disjoint chains and cycles given by successor links (list ranking).

    Pointer jumping (Wyllie 1979): each round every element looks twice as far ahead, so
    ``ceil(log2(max_len)) + 1`` vectorized rounds settle every chain of at most ``max_len``
    elements. Cycles are cut just before their smallest element, which becomes their head.

    Parameters
    ----------
    succ : (m,) int64
        Successor of each element, -1 at the end of a chain; every element has at most one
        predecessor.
    max_len : int
        Upper bound on the length of any chain or cycle.

    Returns
    -------
    tail : (m,) int64
        Last element of each element's chain (a group id).
    dist : (m,) int64
        Steps from the element to that tail; sorting by ``(tail, -dist)`` orders each group.
    closed : (m,) bool
        The element lies on a cycle.
    """
    m = succ.size
    rounds = int(np.ceil(np.log2(max(max_len, 2)))) + 1
    ids = np.arange(m, dtype=np.int64)
    jump = succ.copy()
    low = ids.copy()
    for _ in range(rounds):
        idx = np.flatnonzero(jump >= 0)
        if idx.size == 0:
            break
        j = jump[idx]
        low[idx] = np.minimum(low[idx], low[j])
        jump[idx] = jump[j]
    closed = jump >= 0
    cut = succ.copy()
    cut[closed & (succ == low)] = -1
    jump = cut.copy()
    dist = (cut >= 0).astype(np.int64)
    tail = np.where(cut >= 0, cut, ids)
    for _ in range(rounds):
        idx = np.flatnonzero(jump >= 0)
        if idx.size == 0:
            break
        j = jump[idx]
        dist[idx] += dist[j]
        tail[idx] = tail[j]
        jump[idx] = jump[j]
    return tail, dist, closed


def build_halfedges(
    face_indices: np.ndarray, face_offsets: np.ndarray, n_vertices: int
) -> HalfEdges:
    """Half-edge connectivity of a polygon mesh from its flat face arrays.

    Parameters
    ----------
    face_indices : (m,) int
        Vertex indices of all faces, concatenated, each face counter-clockwise.
    face_offsets : (n_faces + 1,) int
        Start of each face in ``face_indices``, then ``m``.
    n_vertices : int
        Number of vertices.

    Returns
    -------
    HalfEdges
        ``m`` half-edges, half-edge ``h`` being corner ``h`` of the flat face list.

    Raises
    ------
    MeshTopologyError
        Bad indices or faces (see :func:`check_faces`), an edge shared by more than two
        faces, or two faces running a shared edge the same way; the message names the
        first offending face or edge.

    Example
    -------
    >>> he = build_halfedges([0, 1, 2, 0, 2, 3], [0, 3, 6], 4)
    >>> he.twin.tolist(), he.euler_characteristic
    ([-1, -1, 3, 2, -1, -1], 1)
    """
    fi, fo = check_faces(face_indices, face_offsets, n_vertices)
    n_faces = fo.size - 1
    m = fi.size
    sizes = np.diff(fo)
    pos = np.arange(m, dtype=np.int64)
    nxt = pos + 1
    nxt[fo[1:] - 1] = fo[:-1]
    prv = pos - 1
    prv[fo[:-1]] = fo[1:] - 1
    face = np.repeat(np.arange(n_faces, dtype=np.int64), sizes)
    origin = fi
    dest = fi[nxt]

    lo = np.minimum(origin, dest)
    hi = np.maximum(origin, dest)
    key = lo * max(n_vertices, 1) + hi
    # stable: within an edge, faces in order
    order, skey = sort_keys(key, max(n_vertices, 1) ** 2)
    first = np.ones(m, dtype=bool)
    first[1:] = skey[1:] != skey[:-1]
    starts = np.flatnonzero(first)
    count = np.diff(np.append(starts, m))

    if (count > 2).any():
        bad = starts[count > 2]
        g = bad[np.argmin(order[bad])]  # the edge met first in face order
        k = int(count[np.searchsorted(starts, g)])
        hs = order[g : g + k]
        a, b = int(lo[hs[0]]), int(hi[hs[0]])
        raise MeshTopologyError(
            f"edge ({a}, {b}) is shared by {k} faces {_listing(face[hs])}; a manifold mesh "
            "has at most two faces on an edge (non-manifold edge)"
        )
    pair = starts[count == 2]
    h0 = order[pair]
    h1 = order[pair + 1]
    same = origin[h0] == origin[h1]
    if same.any():
        i = np.flatnonzero(same)
        i = i[np.argmin(h0[i])]
        a, b, f0, f1 = origin[h0[i]], dest[h0[i]], face[h0[i]], face[h1[i]]
        raise MeshTopologyError(
            f"faces {f0} and {f1} both run edge {a} -> {b} the same way; neighbouring faces "
            "must list a shared edge in opposite directions (inconsistent orientation)"
        )
    twin = np.full(m, -1, dtype=np.int64)
    twin[h0] = h1
    twin[h1] = h0
    edge = np.empty(m, dtype=np.int64)
    edge[order] = np.cumsum(first) - 1
    edge_vertices = np.stack([lo[order[starts]], hi[order[starts]]], axis=1)

    vertex_halfedge = np.full(n_vertices, -1, dtype=np.int64)
    vertex_halfedge[origin[::-1]] = pos[::-1]
    boundary = np.flatnonzero(twin < 0)
    vertex_halfedge[origin[boundary]] = boundary

    he = HalfEdges(
        origin=np.array(fi),  # a copy: never freeze the caller's array
        vertex=dest,
        twin=twin,
        next=nxt,
        prev=prv,
        face=face,
        edge=edge,
        edge_vertices=edge_vertices,
        vertex_halfedge=vertex_halfedge,
        face_halfedge=np.array(fo[:-1]),
        face_offsets=np.array(fo),
    )
    _readonly(
        he.origin,
        he.vertex,
        he.twin,
        he.next,
        he.prev,
        he.face,
        he.edge,
        he.edge_vertices,
        he.vertex_halfedge,
        he.face_halfedge,
        he.face_offsets,
    )
    return he


def boundary_loops(
    face_indices: np.ndarray, face_offsets: np.ndarray, n_vertices: int
) -> list[np.ndarray]:
    """The boundary loops of a mesh, as ``build_halfedges(...).boundary_loops()`` gives them.

    The same checks and the same loops, from one sort of the edges: where no vertex has two
    boundary edges leaving it, a boundary edge's successor is simply the boundary edge that
    leaves its end, so the fans around every vertex (a list ranking of all half-edges) are
    not needed; only a mesh with such a pinched vertex builds them.

    Returns
    -------
    list of (k,) int64
        Vertex cycles, each running with the mesh on its left; empty when closed.

    Raises
    ------
    MeshTopologyError
        As :func:`build_halfedges`.
    """
    fi, fo = check_faces(face_indices, face_offsets, n_vertices)
    m = fi.size
    nv = max(n_vertices, 1)
    nxt = np.arange(1, m + 1, dtype=np.int64)
    nxt[fo[1:] - 1] = fo[:-1]
    dest = fi[nxt]
    order, skey = sort_keys(np.minimum(fi, dest) * nv + np.maximum(fi, dest), nv * nv)
    first = np.ones(m, dtype=bool)
    first[1:] = skey[1:] != skey[:-1]
    starts = np.flatnonzero(first)
    count = np.diff(np.append(starts, m))
    pair = starts[count == 2]
    if (count > 2).any() or (fi[order[pair]] == fi[order[pair + 1]]).any():
        build_halfedges(fi, fo, n_vertices)  # raises, naming the first offending edge
    b = np.sort(order[starts[count == 1]])  # boundary half-edges, in half-edge order
    if b.size == 0:
        return []
    origin = fi[b]
    if np.bincount(origin, minlength=nv).max() > 1:
        return build_halfedges(fi, fo, n_vertices).boundary_loops()
    leaving = np.full(nv, -1, dtype=np.int64)
    leaving[origin] = np.arange(b.size)
    tail, dist, _ = rank_links(leaving[dest[b]], b.size)
    order = np.lexsort((-dist, tail))
    cut = np.flatnonzero(tail[order[1:]] != tail[order[:-1]]) + 1
    return [origin[loop] for loop in np.split(order, cut)]
