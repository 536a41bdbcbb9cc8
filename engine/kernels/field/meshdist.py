"""Distances to triangle meshes and polylines, and the generalized winding number.

* :func:`point_triangle_distance`: the exact Euclidean distance between points and
  triangles, pair by pair (the plane's foot where it falls inside the triangle, else the
  nearest of the three edges), degenerate triangles included.
* :class:`Nearest`: the distance from many points to the nearest of many primitives
  (triangles or segments), exact: each primitive's disc (or ball) bounds its distance
  from below, so only candidates whose bound beats the best distance so far get an exact
  one; the candidates come from scipy's cKDTree, first the primitive with the nearest
  centre, then clusters of neighbouring primitives (one cube of a grid each) bounded by
  thin cylinders along the surface, nearest first, until no cluster left can hold a
  nearer primitive. All points go through each pass at once.
* :class:`WindingNumber`: the generalized winding number of a triangle soup (Jacobson,
  Kavan & Sorkine-Hornung 2013), fast by a Barnes-Hut tree of area-vector dipoles (Barill,
  Dickson, Schmidt, Levin & Jacobson, "Fast winding numbers for soups and clouds", 2018):
  near clusters add their triangles' exact solid angles (Van Oosterom & Strackee 1983), far
  ones their dipole. It is 1 inside a closed outward mesh, 0 outside, and about that for a
  mesh with small holes, which is why the sign of :func:`mesh_distance` uses it.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "Nearest",
    "WindingNumber",
    "point_segment_distance",
    "point_triangle_distance",
]

CHUNK = 8192  # winding-number points per batch: bounds the (point, node) pairs held at once


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def _segment_foot(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The points of segments ``a -> b`` nearest to ``p`` (all (n, 3))."""
    ab = b - a
    num, den = _dot(p - a, ab), _dot(ab, ab)
    t = np.clip(np.divide(num, den, out=np.zeros(num.shape), where=den > 0), 0, 1)
    return a + t[..., None] * ab


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
        self.order = np.argsort(_morton(q), kind="stable")
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


class _Class:
    """Primitives of about one size (radii within :attr:`Nearest.SPREAD`), and clusters.

    ``tree`` is a k-d tree of the primitives' centres. A cluster holds the primitives
    whose centres fall in one cube of a grid (sized for about ``CLUSTER`` of them where
    the surface crosses a cube, so every cluster is compact); ``ctree`` is a k-d tree of
    the clusters' middles, and each cluster has a bounding cylinder: a slab of
    half-thickness ``thick`` across the unit ``axis`` (its primitives' mean normal) cut
    by the ball of radius ``reach`` round ``middle``. The primitives are stored cluster
    by cluster (``start``, ``count``), each as one row of ``disc``: centre, unit normal
    (0 for a segment or a sliver) and radius.
    """

    CLUSTER = 12

    def __init__(self, idx, centre, normal, radius, corners, area):
        from scipy.spatial import cKDTree

        q = centre[idx]
        cube = float(np.sqrt(self.CLUSTER * max(area[idx].mean(), 0.0)))
        cube = max(cube, 1e-6 * float(np.ptp(q, axis=0).max()), 1e-300)
        ijk = np.floor((q - q.min(axis=0)) / cube).astype(np.int64)
        dims = ijk.max(axis=0) + 1
        key = (ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]
        _, g, count = np.unique(key, return_inverse=True, return_counts=True)
        g = g.reshape(-1)
        o = np.argsort(g, kind="stable")
        idx, g = idx[o], g[o]
        self.idx = idx
        self.disc = np.ascontiguousarray(np.column_stack([centre[idx], normal[idx], radius[idx]]))
        self.r_max = float(radius[idx].max())
        self.tree = cKDTree(centre[idx])
        n = len(count)
        self.n_clusters = n
        self.count = count
        self.start = np.cumsum(count) - count
        c = corners[idx]  # (m, k, 3)
        blo = np.full((n, 3), np.inf)
        bhi = np.full((n, 3), -np.inf)
        np.minimum.at(blo, g, c.min(axis=1))
        np.maximum.at(bhi, g, c.max(axis=1))
        middle = (blo + bhi) / 2.0
        rel = c - middle[g][:, None, :]
        reach = np.zeros(n)
        np.maximum.at(reach, g, np.linalg.norm(rel, axis=2).max(axis=1))
        w = area[idx]
        axis = np.stack([np.bincount(g, normal[idx, k] * w, n) for k in range(3)], 1)
        la = np.linalg.norm(axis, axis=1, keepdims=True)
        axis = np.where(la > 0, axis / np.maximum(la, 1e-300), 0.0)
        thick = np.zeros(n)
        np.maximum.at(thick, g, np.abs(np.einsum("mki,mi->mk", rel, axis[g])).max(axis=1))
        self.cyl = np.ascontiguousarray(np.column_stack([middle, axis, thick, reach]))
        self.reach_max = float(reach.max())
        self.ctree = cKDTree(middle)


def _disc_bound2(q: np.ndarray, disc: np.ndarray, dist2: np.ndarray | None = None) -> np.ndarray:
    """Squared lower bounds of the distance from points ``q`` (..., 3) to the primitives of
    rows ``disc`` (..., 7): each lies in the disc of its radius round its centre, in the
    plane of its normal (the ball, where the normal is 0)."""
    diff = q - disc[..., :3]
    h = np.abs(_dot(diff, disc[..., 3:6]))
    if dist2 is None:
        dist2 = _dot(diff, diff)
    rho = np.sqrt(np.maximum(dist2 - h * h, 0.0))
    return h * h + np.maximum(rho - disc[..., 6], 0.0) ** 2


def _cylinder_bound2(q: np.ndarray, cyl: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """Squared lower bounds of the distance from points ``q`` (..., 3) to clusters of rows
    ``cyl`` (..., 8): the slab ``|axis . (x - middle)| <= thick`` within ``reach`` of
    the middle, ``dist`` from it."""
    h = np.abs(_dot(q - cyl[..., :3], cyl[..., 3:6]))
    rho = np.sqrt(np.maximum(dist * dist - h * h, 0.0))
    return np.maximum(h - cyl[..., 6], 0.0) ** 2 + np.maximum(rho - cyl[..., 7], 0.0) ** 2


class Nearest:
    """Exact distance from points to the nearest of a set of primitives.

    Every primitive lies in the disc of its circumradius round its centre, in its plane
    (a segment or a sliver: in the ball), which bounds its distance from below; only
    candidates whose bound is below the best exact distance so far get their exact
    distance (Ericson's closest point). On scipy's cKDTree: the primitive with the
    nearest centre gives each point its first bound; then clusters of neighbouring
    primitives (one cube of a grid each), bounded by cylinders (thin slabs along the
    surface, tight across it, where balls are weak), are taken nearest first, four times
    more each pass, until the nearest cluster not looked at is farther than the best
    distance plus the largest cluster radius: every primitive left is then farther still.
    So that one huge triangle among small ones loosens no bound, the primitives are split
    by size into classes whose radii differ by less than 4x, each with its own trees.

    Parameters
    ----------
    corners : (m, k, 3) float
        Each primitive's corners: k = 3 for triangles, k = 2 for segments.
    """

    K_CLUSTERS = 24  # the first pass's clusters: enough for most points near a surface
    PAIRS = 1 << 19  # (point, candidate) pairs held at once
    SPREAD = 4.0

    def __init__(self, corners: np.ndarray):
        c = np.asarray(corners, dtype=np.float64)
        if c.ndim != 3 or c.shape[1] not in (2, 3) or c.shape[2] != 3 or not len(c):
            raise ValueError("need at least one triangle or segment")
        if not np.isfinite(c).all():
            raise ValueError("the corners are not all finite")
        self.a = np.ascontiguousarray(c[:, 0])
        self.e1 = c[:, 1] - c[:, 0]
        self.e2 = c[:, 2] - c[:, 0] if c.shape[1] == 3 else None
        self.aa = _dot(self.e1, self.e1)
        centre = c.mean(axis=1)
        radius = np.linalg.norm(c - centre[:, None, :], axis=2).max(axis=1)
        if self.e2 is not None:
            self.ab = _dot(self.e1, self.e2)
            self.bb = _dot(self.e2, self.e2)
            n = np.cross(self.e1, self.e2)
            ln = np.linalg.norm(n, axis=1, keepdims=True)
            area = 0.5 * ln[:, 0]
            # a sliver's normal is noise: its bound falls back to the ball's
            normal = np.where(ln > 1e-6 * radius[:, None] ** 2, n / np.maximum(ln, 1e-300), 0.0)
        else:
            area = radius**2
            normal = np.zeros_like(centre)
        parts = [self.a, self.e1] + ([self.aa[:, None]] if self.e2 is None else [self.e2])
        if self.e2 is not None:
            parts += [self.aa[:, None], self.ab[:, None], self.bb[:, None]]
        self.rows = np.ascontiguousarray(np.hstack(parts))
        order = np.argsort(-radius, kind="stable")
        rs = radius[order]
        self.classes: list[_Class] = []
        s = 0
        while s < len(order):
            e = s + int(np.searchsorted(-rs[s:], -rs[s] / self.SPREAD, side="right"))
            e = max(e, s + 1) if rs[s] > 0 else len(order)
            self.classes.append(_Class(order[s:e], centre, normal, radius, c, area))
            s = e
        # the class with most primitives first: it gives most points their bound
        self.classes.sort(key=lambda cl: -len(cl.idx))

    def _exact(self, p: np.ndarray, prim: np.ndarray) -> np.ndarray:
        """Distances from points ``p`` (n, 3) to primitives ``prim`` (n,) -> (n,)."""
        row = np.take(self.rows, prim, axis=0)  # one gather: a, e1, (e2), aa, (ab, bb)
        ap = p - row[:, 0:3]
        e1 = row[:, 3:6]
        d1 = _dot(e1, ap)
        if self.e2 is None:
            aa = row[:, 6]
            t = np.clip(np.divide(d1, aa, out=np.zeros_like(d1), where=aa > 0), 0.0, 1.0)
            return np.linalg.norm(ap - t[:, None] * e1, axis=1)
        e2 = row[:, 6:9]
        v, w = _triangle_coefficients(d1, _dot(e2, ap), row[:, 9], row[:, 10], row[:, 11])
        bad = ~(np.isfinite(v) & np.isfinite(w))
        out = np.linalg.norm(ap - v[:, None] * e1 - w[:, None] * e2, axis=1)
        if bad.any():
            a = row[bad, 0:3]
            out[bad] = point_triangle_distance(p[bad], a, a + e1[bad], a + e2[bad])
        return out

    def distance(self, points: np.ndarray) -> np.ndarray:
        """(n,) unsigned distances from ``points`` (n, 3) to the nearest primitive."""
        return self.nearest(points)[0]

    def closest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(n, 3) the nearest point on the primitives to each of ``points``, and (n,) the
        primitive it lies on."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        _, prim = self.nearest(p)
        row = self.rows[prim]
        ap = p - row[:, 0:3]
        e1 = row[:, 3:6]
        if self.e2 is None:
            aa = row[:, 6]
            d1 = _dot(e1, ap)
            t = np.clip(np.divide(d1, aa, out=np.zeros_like(d1), where=aa > 0), 0.0, 1.0)
            return row[:, 0:3] + t[:, None] * e1, prim
        e2 = row[:, 6:9]
        v, w = _triangle_coefficients(_dot(e1, ap), _dot(e2, ap), row[:, 9], row[:, 10], row[:, 11])
        out = row[:, 0:3] + v[:, None] * e1 + w[:, None] * e2
        bad = ~(np.isfinite(v) & np.isfinite(w))
        if bad.any():  # a degenerate triangle: the nearest point of its three edges
            a = row[bad, 0:3]
            ends = [(a, a + e1[bad]), (a + e1[bad], a + e2[bad]), (a + e2[bad], a)]
            feet = np.stack([_segment_foot(p[bad], s, e) for s, e in ends], axis=1)
            k = np.argmin(np.linalg.norm(feet - p[bad, None], axis=2), axis=1)
            out[bad] = feet[np.arange(len(k)), k]
        return out, prim

    def nearest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(n,) distances and (n,) the index of each point's nearest primitive."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        best = np.full(len(p), np.inf)
        prim = np.zeros(len(p), dtype=np.int64)
        for cl in self.classes:
            _, near = cl.tree.query(p, k=1)
            near = cl.idx[near]
            d = self._exact(p, near)
            win = d < best
            best[win], prim[win] = d[win], near[win]
        for cl in self.classes:
            todo = np.arange(len(p))
            k0, k1 = 0, min(self.K_CLUSTERS, cl.n_clusters)
            while len(todo):
                step = max(1, self.PAIRS // ((k1 - k0) * cl.CLUSTER))
                todo = np.concatenate(
                    [
                        self._clusters(cl, p, todo[s : s + step], k0, k1, best, prim)
                        for s in range(0, len(todo), step)
                    ]
                )
                k0, k1 = k1, min(4 * k1, cl.n_clusters)
        return best, prim

    def _open(self, cl: _Class, q, r, clusters, n_items, b, prim, pts) -> None:
        """Every primitive of clusters ``clusters`` for points ``q[r]``: the exact distance
        of those whose disc bound beats ``b`` (updated in place, with ``prim[pts]``)."""
        r = np.repeat(r, n_items)
        skip = np.cumsum(n_items) - n_items
        item = np.arange(len(r)) + np.repeat(cl.start[clusters] - skip, n_items)
        qr = np.take(q, r, axis=0)
        keep = _disc_bound2(qr, np.take(cl.disc, item, axis=0)) < b[r] ** 2
        r, cand, qr = r[keep], cl.idx[item[keep]], qr[keep]
        if not len(r):
            return
        d = self._exact(qr, cand)
        o = np.lexsort((d, r))
        head = o[np.r_[True, r[o][1:] != r[o][:-1]]]
        rr, dd = r[head], d[head]
        better = dd < b[rr]
        b[rr[better]] = dd[better]
        prim[pts[rr[better]]] = cand[head][better]

    def _clusters(self, cl: _Class, p, pts, k0: int, k1: int, best, prim) -> np.ndarray:
        """Clusters ``k0 + 1 .. k1`` nearest to points ``pts``: the exact distances of their
        primitives that may beat the best (updated in place); return the points whose
        nearest primitive may still lie in a cluster farther out."""
        q = p[pts]
        b = best[pts]
        dc, ic = cl.ctree.query(q, k=np.arange(k0 + 1, k1 + 1))
        lb2 = _cylinder_bound2(q[:, None, :], np.take(cl.cyl, ic, axis=0), dc)
        r, col = np.nonzero(lb2 < (b * b)[:, None])
        open_ = ic[r, col]
        n_items = cl.count[open_]
        # the open clusters' primitives, a bounded number of pairs at a time
        cut = np.searchsorted(np.cumsum(n_items), np.arange(self.PAIRS, n_items.sum(), self.PAIRS))
        for rs, os_, ns in zip(*(np.split(x, cut) for x in (r, open_, n_items)), strict=True):
            self._open(cl, q, rs, os_, ns, b, prim, pts)
        best[pts] = b
        done = (k1 >= cl.n_clusters) | (dc[:, -1] - cl.reach_max >= b)
        return pts[~done]


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

    def __call__(self, points: np.ndarray) -> np.ndarray:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        d, prim = self.nearest.nearest(p)
        if not self.closed:
            return np.where(self.winding(p) > 0.5, -d, d)
        nr = self.nearest
        ap = p - nr.a[prim]
        e1, e2 = nr.e1[prim], nr.e2[prim]
        v, w, region = _triangle_coefficients(
            _dot(e1, ap), _dot(e2, ap), nr.aa[prim], nr.ab[prim], nr.bb[prim], region=True
        )
        ok = np.isfinite(v) & np.isfinite(w)
        v, w = np.where(ok, v, 0.0), np.where(ok, w, 0.0)
        away = ap - v[:, None] * e1 - w[:, None] * e2
        side = _dot(away, self.normals[prim, region])
        return np.where(side < 0, -d, d)


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


def _morton(q: np.ndarray) -> np.ndarray:
    """Morton (Z-order) codes of 10-bit integer coordinates (n, 3) -> (n,) int64."""
    code = np.zeros(len(q), dtype=np.int64)
    for bit in range(10):
        for k in range(3):
            code |= ((q[:, k] >> bit) & 1) << (3 * bit + k)
    return code
