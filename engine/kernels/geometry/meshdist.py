"""Distances to triangle meshes and polylines, and the generalized winding number.

* :func:`point_triangle_distance`: the exact Euclidean distance between points and
  triangles, pair by pair (the plane's foot where it falls inside the triangle, else the
  nearest of the three edges), degenerate triangles included.
* :class:`Nearest`: the distance from many points to the nearest of many primitives
  (triangles or segments), exact, with the closest point and its barycentric weights:
  a bounding-volume hierarchy walked point by point in compiled code
  (:mod:`formgraph.kernels.geometry.bvh`).
* :class:`SignedDistance`: the same, signed (negative inside) by the angle-weighted
  pseudonormal on a closed mesh, by the winding number on an open one.
* :class:`WindingNumber`: the generalized winding number of a triangle soup (Jacobson,
  Kavan & Sorkine-Hornung 2013), fast by a Barnes-Hut tree of area-vector dipoles (Barill,
  Dickson, Schmidt, Levin & Jacobson, "Fast winding numbers for soups and clouds", 2018):
  near clusters add their triangles' exact solid angles (Van Oosterom & Strackee 1983), far
  ones their dipole. It is 1 inside a closed outward mesh, 0 outside, and about that for a
  mesh with small holes, which is why :class:`SignedDistance` uses it on open meshes.
"""

from __future__ import annotations

import numpy as np

from .bvh import morton_codes

__all__ = [
    "Nearest",
    "fan_triangles",
    "SignedDistance",
    "WindingNumber",
    "point_segment_distance",
    "point_triangle_distance",
]

CHUNK = 8192  # winding-number points per batch: bounds the (point, node) pairs held at once


def fan_triangles(
    face_indices: np.ndarray, face_offsets: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(t, 3) the triangles of polygon faces, each fanned from its first corner (the faces
    of a closed mesh stay closed), and (t,) the face each triangle comes from."""
    fo = np.asarray(face_offsets, dtype=np.int64)
    fi = np.asarray(face_indices, dtype=np.int64)
    sizes = np.diff(fo)
    face = np.repeat(np.arange(len(sizes)), sizes - 2)
    k = np.arange(len(face)) - np.repeat(np.cumsum(sizes - 2) - (sizes - 2), sizes - 2)
    first = fo[:-1][face]
    return np.stack([fi[first], fi[first + k + 1], fi[first + k + 2]], axis=1), face


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distances from points ``p`` to segments ``a -> b`` (all (..., 3), broadcast)."""
    ab = b - a
    num = _dot(p - a, ab)
    den = np.broadcast_to(_dot(ab, ab), num.shape)
    t = np.clip(np.divide(num, den, out=np.zeros(num.shape), where=den > 0), 0, 1)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def _triangle_coefficients(d1, d2, aa, ab, bb, region: bool = False):
    """(v, w) of the point ``a + v (b - a) + w (c - a)`` of a triangle nearest to ``p``.

    Ericson, "Real-Time Collision Detection", 5.1.5: the Voronoi region of ``p`` (vertex,
    edge or face) from ``d1 = (b-a).(p-a)``, ``d2 = (c-a).(p-a)`` and the triangle's own
    ``aa = |b-a|^2``, ``ab = (b-a).(c-a)``, ``bb = |c-a|^2``; the first region that holds
    ``p`` wins, as in the book's sequence of tests. A degenerate triangle (no area) gets the
    nearest of its edges through the same tests, its face region being empty.
    """
    d3, d4 = d1 - aa, d2 - ab  # (b-a).(p-b), (c-a).(p-b)
    d5, d6 = d1 - ab, d2 - bb  # (b-a).(p-c), (c-a).(p-c)
    vc = d1 * d4 - d3 * d2
    vb = d5 * d2 - d1 * d6
    va = d3 * d6 - d5 * d4
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        den = va + vb + vc
        fv, fw = vb / den, vc / den
    regions = [
        (d1 <= 0) & (d2 <= 0),  # vertex a
        (d3 >= 0) & (d4 <= d3),  # vertex b
        (vc <= 0) & (d1 >= 0) & (d3 <= 0),  # edge ab
        (d6 >= 0) & (d5 <= d6),  # vertex c
        (vb <= 0) & (d2 >= 0) & (d6 <= 0),  # edge ac
        (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0),  # edge bc
    ]
    v = np.select(regions, [0.0, 1.0, t_ab, 0.0, 0.0, 1.0 - t_bc], fv)
    w = np.select(regions, [0.0, 0.0, 0.0, 1.0, t_ac, t_bc], fw)
    if region:  # 0 a, 1 b, 2 edge ab, 3 c, 4 edge ac, 5 edge bc, 6 the face
        return v, w, np.select(regions, [0, 1, 2, 3, 4, 5], 6)
    return v, w


def point_triangle_distance(p, a, b, c) -> np.ndarray:
    """Exact distances from points ``p`` to triangles ``(a, b, c)`` (all (..., 3))."""
    e1, e2, ap = b - a, c - a, p - a
    v, w = _triangle_coefficients(
        _dot(e1, ap), _dot(e2, ap), _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
    )
    bad = ~(np.isfinite(v) & np.isfinite(w))
    out = np.linalg.norm(ap - v[..., None] * e1 - w[..., None] * e2, axis=-1)
    if bad.any():  # a triangle degenerate to a point or with collinear corners
        pb, ab_, bb_, cb_ = (np.broadcast_to(x, out.shape + (3,))[bad] for x in (p, a, b, c))
        out[bad] = np.minimum(
            np.minimum(point_segment_distance(pb, ab_, bb_), point_segment_distance(pb, bb_, cb_)),
            point_segment_distance(pb, cb_, ab_),
        )
    return out


class _Hierarchy:
    """Primitives (m, k, 3) in Morton order of their centres, grouped in blocks.

    Level 0 holds leaves of ``LEAF`` consecutive primitives, level ``l`` nodes of ``FAN``
    consecutive nodes of level ``l - 1``, up to one root. Each node has its bounding box
    (``lo``, ``hi``); ``order`` maps sorted positions to the caller's primitive indices.
    """

    LEAF = 2  # small leaves: tight boxes prune far more pairs than they add (1.7x vs 8)
    FAN = 8

    def __init__(self, corners: np.ndarray):
        c = np.asarray(corners, dtype=np.float64)
        centre = c.mean(axis=1)
        lo, hi = centre.min(axis=0), centre.max(axis=0)
        scale = 1023.999 / max(float((hi - lo).max()), 1e-300)
        q = np.floor((centre - lo) * scale).astype(np.int64)
        self.order = np.argsort(morton_codes(q), kind="stable")
        self.corners = c[self.order]
        self.n = len(c)
        box_lo, box_hi = self.corners.min(axis=1), self.corners.max(axis=1)
        self.groups = []  # per level: the sorted primitives' node index
        self.boxes = []  # per level: (lo (n, 3), hi (n, 3))
        g = np.arange(self.n) // self.LEAF
        while True:
            n = int(g[-1]) + 1
            blo = np.full((n, 3), np.inf)
            bhi = np.full((n, 3), -np.inf)
            np.minimum.at(blo, g, box_lo)
            np.maximum.at(bhi, g, box_hi)
            self.groups.append(g)
            self.boxes.append((blo, bhi))
            if n == 1:
                break
            g = g // self.FAN

    def children(self, level: int, node: np.ndarray, pi: np.ndarray):
        """The (point, child) pairs below ``(pi, node)`` pairs of ``level`` (> 0)."""
        kids = node[:, None] * self.FAN + np.arange(self.FAN)[None, :]
        ok = kids < len(self.boxes[level - 1][0])
        return np.broadcast_to(pi[:, None], kids.shape)[ok], kids[ok]

    def leaf_items(self, node: np.ndarray, pi: np.ndarray):
        """The (point, sorted primitive) pairs below ``(pi, leaf)`` pairs."""
        items = node[:, None] * self.LEAF + np.arange(self.LEAF)[None, :]
        ok = items < self.n
        return np.broadcast_to(pi[:, None], items.shape)[ok], items[ok]


class Nearest:
    """Exact distance from points to the nearest of a set of primitives, the closest point
    and where it lies on its primitive.

    A bounding-volume hierarchy walked point by point in compiled code
    (:mod:`formgraph.kernels.geometry.bvh`): boxes and slabs bound each node's distance from
    below, the nearer child is opened first, and a node whose bound is not below the best
    distance so far is skipped, so the result is exact (Ericson's closest point on each
    triangle or segment looked at).

    Parameters
    ----------
    corners : (m, k, 3) float
        Each primitive's corners: k = 3 for triangles, k = 2 for segments.
    """

    def __init__(self, corners: np.ndarray):
        c = np.asarray(corners, dtype=np.float64)
        if c.ndim != 3 or c.shape[1] not in (2, 3) or c.shape[2] != 3 or not len(c):
            raise ValueError("need at least one triangle or segment")
        if not np.isfinite(c).all():
            raise ValueError("the corners are not all finite")
        from .bvh import Tree

        self.tree = Tree(c)
        self.a = np.ascontiguousarray(c[:, 0])
        self.e1 = c[:, 1] - c[:, 0]
        self.e2 = c[:, 2] - c[:, 0] if c.shape[1] == 3 else None
        self.aa = _dot(self.e1, self.e1)
        if self.e2 is not None:
            self.ab = _dot(self.e1, self.e2)
            self.bb = _dot(self.e2, self.e2)

    def locate(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(n,) distances from ``points`` (n, 3), (n,) the nearest primitive of each, and
        the closest point's (v, w) on it: ``a + v (b - a) + w (c - a)`` on a triangle,
        ``a + v (b - a)`` on a segment (w = 0)."""
        return self.tree.query(np.asarray(points, dtype=np.float64).reshape(-1, 3))

    def nearest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(n,) distances and (n,) the index of each point's nearest primitive."""
        d, prim, _, _ = self.locate(points)
        return d, prim

    def distance(self, points: np.ndarray) -> np.ndarray:
        """(n,) unsigned distances from ``points`` (n, 3) to the nearest primitive."""
        return self.locate(points)[0]

    def closest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(n, 3) the nearest point on the primitives to each of ``points``, and (n,) the
        primitive it lies on."""
        _, prim, v, w = self.locate(points)
        out = self.a[prim] + v[:, None] * self.e1[prim]
        if self.e2 is not None:
            out += w[:, None] * self.e2[prim]
        return out, prim


class SignedDistance:
    """Signed distance to a triangle mesh (``vertices`` (n, 3), ``triangles`` (m, 3)).

    The distance is :class:`Nearest`'s. The sign: on a closed mesh (every edge on two
    triangles), the angle-weighted pseudonormal of the nearest feature (face, edge or
    vertex: Baerentzen & Aanaes, "Signed distance computation using the angle weighted
    pseudonormal", 2005), exact and cheap; on an open mesh or a soup, the generalized
    winding number (:class:`WindingNumber`), which still has an inside where small holes
    leave the mesh slightly open.
    """

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray):
        v = np.asarray(vertices, dtype=np.float64)
        t = np.asarray(triangles, dtype=np.int64)
        self.nearest = Nearest(v[t])
        e = np.sort(np.stack([t, np.roll(t, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
        keys, edge, uses = np.unique(
            e[:, 0] * len(v) + e[:, 1], return_inverse=True, return_counts=True
        )
        self.closed = bool((uses == 2).all())
        self.winding = None if self.closed else WindingNumber(v[t])
        if not self.closed:
            return
        from ..mesh.solidify import vertex_normals

        fn = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
        fn /= np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-300)
        edge = edge.reshape(-1, 3)  # edges ab, bc, ca of each triangle
        en = np.stack(
            [np.bincount(edge.ravel(), np.repeat(fn[:, k], 3), len(keys)) for k in range(3)], 1
        )
        vn = vertex_normals(v, t.reshape(-1), np.arange(0, t.size + 1, 3))
        # per triangle, by region code: a, b, ab, c, ac, bc, face
        self.normals = np.stack(
            [
                vn[t[:, 0]],
                vn[t[:, 1]],
                en[edge[:, 0]],
                vn[t[:, 2]],
                en[edge[:, 2]],
                en[edge[:, 1]],
                fn,
            ],
            axis=1,
        )

    def locate(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(n,) signed distances from ``points`` (n, 3), the nearest triangle of each and
        the closest point's (v, w) on it (as :meth:`Nearest.locate`)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        d, prim, v, w = self.nearest.locate(p)
        return np.where(self.inside(p, prim), -d, d), prim, v, w

    def inside(self, points: np.ndarray, prim: np.ndarray) -> np.ndarray:
        """(n,) bool: whether each point is inside, given its nearest triangle ``prim``."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if not self.closed:
            return self.winding(p) > 0.5
        nr = self.nearest
        ap = p - nr.a[prim]
        e1, e2 = nr.e1[prim], nr.e2[prim]
        v, w, region = _triangle_coefficients(
            _dot(e1, ap), _dot(e2, ap), nr.aa[prim], nr.ab[prim], nr.bb[prim], region=True
        )
        ok = np.isfinite(v) & np.isfinite(w)
        v, w = np.where(ok, v, 0.0), np.where(ok, w, 0.0)
        away = ap - v[:, None] * e1 - w[:, None] * e2
        return _dot(away, self.normals[prim, region]) < 0

    def __call__(self, points: np.ndarray) -> np.ndarray:
        return self.locate(points)[0]


class WindingNumber:
    """Generalized winding number of triangles (``tri`` (m, 3, 3)), fast (Barnes-Hut).

    ``beta``: a cluster counts as far when the point is more than ``beta`` times its
    radius from its centre (Barill et al. use 2; the dipole's error falls as the square).
    """

    def __init__(self, tri: np.ndarray, beta: float = 2.0):
        self.tree = _Hierarchy(np.asarray(tri, dtype=np.float64))
        self.beta = beta
        t = self.tree.corners
        area_vec = 0.5 * np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        area = np.linalg.norm(area_vec, axis=1)
        tc = t.mean(axis=1)
        self.levels = []  # per level: centre, radius, dipole (sum of area vectors)
        for g, (blo, bhi) in zip(self.tree.groups, self.tree.boxes, strict=True):
            n = len(blo)
            w = np.bincount(g, weights=area, minlength=n)
            sw = np.stack([np.bincount(g, tc[:, k] * area, n) for k in range(3)], 1)
            heavy = (w > 0)[:, None]
            c = np.where(heavy, sw / np.where(heavy, w[:, None], 1.0), (blo + bhi) / 2)
            r = np.zeros(n)
            np.maximum.at(r, g, np.linalg.norm(t - c[g][:, None, :], axis=2).max(axis=1))
            dip = np.stack([np.bincount(g, area_vec[:, k], n) for k in range(3)], 1)
            self.levels.append((c, r, dip))

    def __call__(self, points: np.ndarray) -> np.ndarray:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        out = np.zeros(len(p))
        for s in range(0, len(p), CHUNK):
            out[s : s + CHUNK] = self._chunk(p[s : s + CHUNK])
        return out

    def _chunk(self, p: np.ndarray) -> np.ndarray:
        w = np.zeros(len(p))
        top = len(self.levels) - 1
        pi = np.arange(len(p))
        node = np.zeros(len(p), dtype=np.int64)
        for level in range(top, -1, -1):
            c, r, dip = self.levels[level]
            d = c[node] - p[pi]
            dist = np.linalg.norm(d, axis=1)
            far = dist > self.beta * r[node]
            if far.any():
                contrib = _dot(dip[node[far]], d[far]) / np.maximum(dist[far], 1e-300) ** 3
                w += np.bincount(pi[far], weights=contrib, minlength=len(p))
            pi, node = pi[~far], node[~far]
            if level == 0:
                break
            pi, node = self.tree.children(level, node, pi)
        # near leaves: every triangle's exact solid angle
        pi, item = self.tree.leaf_items(node, pi)
        t = self.tree.corners[item]
        a, b, cc = (t[:, k] - p[pi] for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, cc))
        num = _dot(a, np.cross(b, cc))
        den = la * lb * lc + _dot(a, b) * lc + _dot(a, cc) * lb + _dot(b, cc) * la
        w += np.bincount(pi, weights=2.0 * np.arctan2(num, den), minlength=len(p))
        return w / (4.0 * np.pi)
