"""Exact distance from points to a set of line segments, and the even-odd inside test.

`SegmentTree` is a bounding-volume hierarchy of capsules (a segment's axis grown by a
radius) over runs of consecutive segments: for curve samples these capsules are thin, so
a nearest-segment query prunes almost everything at every level. Queries run breadth
first for all points at once (one numpy pass per visited level over the surviving
(point, node) pairs; levels are visited in jumps that keep about a thousand pairs a pass,
so a query of a few points makes few numpy calls), with branch-and-bound: a node is
dropped when its capsule's lower bound exceeds the best upper bound found so far, as in
the nearest-neighbour search of Roussopoulos, Kelley & Vincent (SIGMOD 1995). A query
may also carry a band ``[lo, hi]``: the distance is exact inside it, and outside it only
certified to be below ``lo`` or above ``hi`` -- which is all a contour at one level needs,
and far cheaper.

`RowParity` answers the even-odd (crossing number) test for the points of a grid:
the crossings of every closed segment with every grid row are computed once, and a point
is inside when an odd number of them lie to its left on its row (the half-open rule of
Haines, "Point in polygon strategies", Graphics Gems IV, 1994, so vertices on a row are
counted once).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Nearest", "RowParity", "SegmentTree", "WorkLimit", "point_segment"]


class WorkLimit(ValueError):
    """The queries of a `SegmentTree` tested more (point, node) pairs than its ``max_pairs``."""


_PAIRS = 1024  # (point, node) pairs a query tests per visited level, about


def point_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance from points to segments, pairwise (broadcasting over leading axes).

    Parameters
    ----------
    p, a, b : (..., 2) float
        Points and segment ends (a segment may have zero length).

    Returns
    -------
    dist : (...) float
    t : (...) float
        Parameter of the nearest point ``a + t (b - a)``, in [0, 1].
    """
    ux, uy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    dx, dy = p[..., 0] - a[..., 0], p[..., 1] - a[..., 1]
    den = ux * ux + uy * uy
    num = dx * ux + dy * uy
    t = np.clip(np.divide(num, den, out=np.zeros_like(num), where=den > 0), 0.0, 1.0)
    ex, ey = dx - t * ux, dy - t * uy
    return np.sqrt(ex * ex + ey * ey), t


@dataclass(frozen=True)
class Nearest:
    """Result of `SegmentTree.query`.

    Attributes
    ----------
    dist : (q,) float
        Exact distance where ``exact``; otherwise a value certified on the same side of
        the band as the true distance (below ``lo`` or above ``hi``).
    exact : (q,) bool
    segment : (q,) int64
        Index of a nearest segment where exact, else -1.
    t : (q,) float
        Parameter of the nearest point on that segment.
    """

    dist: np.ndarray
    exact: np.ndarray
    segment: np.ndarray
    t: np.ndarray


class SegmentTree:
    """Capsule hierarchy over segments ``a[k] -> b[k]`` kept in their given order.

    Parameters
    ----------
    a, b : (n, 2) float
        Segment ends, n >= 1. Consecutive segments should be close (curve order) for
        tight capsules; any order is correct.
    leaf : int
        Segments per leaf, tested by brute force.
    max_pairs : int, optional
        A bound on the work of all queries together: the (point, node) pairs they test
        (`WorkLimit` once passed). None: no bound.
    """

    def __init__(
        self, a: np.ndarray, b: np.ndarray, leaf: int = 4, max_pairs: int | None = None
    ) -> None:
        a = np.asarray(a, dtype=float)
        b = np.asarray(b, dtype=float)
        n = a.shape[0]
        if n == 0:
            raise ValueError("a segment tree needs at least one segment")
        self.a, self.b, self.n, self.leaf = a, b, n, leaf
        # Long segments are cut into pieces for the hierarchy (results still name the whole
        # segment): a capsule over a few long segments that do not follow each other (a
        # messy input, as random points joined up) is as fat as the input, so every query
        # would test every leaf; capsules over pieces of at most 1/64 of the extent stay thin.
        pa, pb, self._owner, self._start, self._scale_t = _pieces(a, b)
        n_pieces = pa.shape[0]
        n_leaves = -(-n_pieces // leaf)
        depth = max(0, int(np.ceil(np.log2(n_leaves))))
        width = 2**depth
        pad = n_leaves * leaf - n_pieces
        pa = np.concatenate([pa, np.repeat(pa[-1:], pad, axis=0)])
        pb = np.concatenate([pb, np.repeat(pb[-1:], pad, axis=0)])
        self._n_pieces = n_pieces
        self.depth = depth
        self.pairs = 0  # (point, node) pairs tested by every query so far: the work done
        self.last_pairs = 0
        self.max_pairs = max_pairs

        # Leaf capsules: axis from the first segment's start to the last one's end, radius
        # the farthest segment end from that axis (a capsule is convex, so it then holds
        # every segment whole). The axis ends are on it; in a chain (each segment starting
        # where the one before ends, as a polyline's do) the other ends are the starts, so
        # only those are measured. Strided coordinate views, squared distances until the
        # one square root of the maximum.
        axa = pa[0::leaf]
        axb = pb[leaf - 1 :: leaf]
        ax, ay, bx, by = axa[:, 0], axa[:, 1], axb[:, 0], axb[:, 1]
        ux, uy = bx - ax, by - ay
        len2 = ux * ux + uy * uy
        inv = np.divide(1.0, len2, out=np.zeros_like(len2), where=len2 > 0)
        chain = np.array_equal(pa[1:n_pieces], pb[: n_pieces - 1])
        ends = [pa[k::leaf] for k in range(1, leaf)]
        if not chain:
            ends += [pb[k::leaf] for k in range(leaf - 1)]
        d2 = np.zeros(n_leaves)
        for e in ends:
            dx, dy = e[:, 0] - ax, e[:, 1] - ay
            t = dx * ux
            t += dy * uy
            t *= inv
            np.minimum(np.maximum(t, 0.0, out=t), 1.0, out=t)
            dx -= t * ux
            dy -= t * uy
            dx *= dx
            dy *= dy
            dx += dy
            np.maximum(d2, dx, out=d2)
        rad = np.sqrt(d2)
        # Missing leaves copy the last real axis (a true curve point keeps the upper bound
        # valid) with radius -inf, so their lower bound is +inf and they are never entered.
        extra = width - n_leaves
        axa = np.concatenate([axa, np.repeat(axa[-1:], extra, axis=0)])
        axb = np.concatenate([axb, np.repeat(axb[-1:], extra, axis=0)])
        rad = np.concatenate([rad, np.full(extra, -np.inf)])
        levels = [(axa[:, 0], axa[:, 1], axb[:, 0], axb[:, 1], rad)]
        # Parents: axis from the left child's start to the right child's end (the left
        # child's end if the right one is missing); a radius that holds both child capsules
        # (distance to a segment is convex, so a child's axis ends bound its whole axis; the
        # left child's start lies on the parent's axis).
        while levels[-1][0].shape[0] > 1:
            ax, ay, bx, by, r = levels[-1]
            lax, lay, lbx, lby, lr = ax[0::2], ay[0::2], bx[0::2], by[0::2], r[0::2]
            rax, ray, rbx, rby, rr = ax[1::2], ay[1::2], bx[1::2], by[1::2], r[1::2]
            missing = np.isneginf(rr)
            pbx, pby = np.where(missing, lbx, rbx), np.where(missing, lby, rby)
            d = np.sqrt(
                _dist2(np.stack([lbx, rax, rbx]), np.stack([lby, ray, rby]), lax, lay, pbx, pby)
            )
            right = rr + np.maximum(d[1], d[2])
            levels.append((lax, lay, pbx, pby, np.maximum(lr + d[0], right)))
        # Per level, contiguous node fields (gathered one by one, which numpy does far
        # faster than rows): start x, y, axis vector x, y, 1 / |axis|^2 (0 if none), radius;
        # computed for all levels at once. The radius carries a hair of slack, as does the
        # bound in `query` (the node holding the bound's own point must never be lost to
        # rounding); a missing node's is NaN, which no test passes.
        levels = levels[::-1]
        bounds = np.cumsum([0] + [lv[0].shape[0] for lv in levels]).tolist()
        ax, ay, bx, by, rad = (np.concatenate([lv[k] for lv in levels]) for k in range(5))
        rad = np.where(np.isneginf(rad), np.nan, rad * (1 + 1e-12))
        # Absolute slack of the pruning test: a point ON the segments (distance 0, as a grid
        # sample on an input vertex is) has a bound of 0 and a flat capsule of radius 0, so
        # a relative slack alone loses its node to the rounding of the axis distance, of
        # the order of the machine epsilon times the coordinates.
        self._scale = float(max(np.abs(a).max(), np.abs(b).max()))
        fields = _fields(ax, ay, bx, by) + (rad,)
        self._levels = [
            tuple(f[lo:hi] for f in fields) for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)
        ]
        self._segs = _fields(pa[:, 0], pa[:, 1], pb[:, 0], pb[:, 1])
        self._grid = None

    def query(
        self,
        points: np.ndarray,
        lo: np.ndarray | float = 0.0,
        hi: np.ndarray | float = np.inf,
        upper: np.ndarray | None = None,
    ) -> Nearest:
        """Distance from each point to the nearest segment.

        Parameters
        ----------
        points : (q, 2) float
        lo, hi : float or (q,) float
            Band in which the distance must be exact; outside it the result is only
            certified to lie below ``lo`` or above ``hi``. Defaults: exact everywhere.
        upper : (q,) float, optional
            Known upper bounds of the distances (the distance to some point of the
            segments; inf where none): a tight one prunes the search from the start.

        Returns
        -------
        Nearest
        """
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        q = p.shape[0]
        if q == 0:
            empty = np.zeros(0)
            return Nearest(empty, np.zeros(0, dtype=bool), np.zeros(0, dtype=np.int64), empty)
        lo, hi = (np.asarray(v, dtype=float) for v in (lo, hi))
        lo = np.full(q, lo) if lo.ndim == 0 else np.broadcast_to(lo, (q,))
        hi = np.full(q, hi) if hi.ndim == 0 else np.broadcast_to(hi, (q,))
        if upper is not None:
            upper = np.asarray(upper, float)
        # The (point, node) pairs of one pass are held at once: in chunks of points, sized
        # from the pairs the chunk before needed per point, they stay near _MAX_PAIRS.
        chunk = q if q <= _FIRST_CHUNK else _FIRST_CHUNK
        if chunk == q:
            return self._query(p, lo, hi, upper)
        parts = []
        start = 0
        while start < q:
            stop = min(q, start + chunk)
            part = self._query(
                p[start:stop],
                lo[start:stop],
                hi[start:stop],
                None if upper is None else upper[start:stop],
            )
            parts.append(part)
            per_point = max(self.last_pairs / (stop - start), 1.0)
            chunk = int(min(max(_MAX_PAIRS / per_point, 256), 8 * chunk))
            start = stop
        return Nearest(*(np.concatenate([getattr(r, f) for r in parts]) for f in _NEAREST))

    def index_reach(self, reach: float) -> None:
        """Index the tree's nodes of one level in a grid of buckets for queries that need
        nothing farther than ``reach`` (a band's top, or a known upper bound, at most
        ``reach``): such a query starts at that level with the nodes of each point's bucket
        in one pass, instead of descending from the root in several.

        Each node goes into every bucket within ``reach`` of its capsule, so one bucket
        lists every node a point in it can need. The level is the coarsest whose nodes are
        mostly no longer than a bucket (side ``reach``); no index is made if the buckets
        would outnumber the segments by far (a reach tiny next to the input).
        """
        self._grid = None
        if not (np.isfinite(reach) and reach > 0) or self.depth < 2:
            return
        a, b = self.a, self.b
        lo = np.array([min(a[:, k].min(), b[:, k].min()) for k in range(2)]) - 2 * reach
        hi = np.array([max(a[:, k].max(), b[:, k].max()) for k in range(2)]) + 2 * reach
        shape = np.ceil((hi - lo) / reach).astype(np.int64)
        if shape.prod() > max(4096, 8 * self.n):
            return
        level = 0
        for k in range(self.depth, 0, -1):
            ax, ay, ux, uy, _, rad = self._levels[k]
            size = np.nanmedian(np.hypot(ux, uy) + 2 * rad)
            if size > reach:
                break
            level = k
        if level == 0:
            return
        ax, ay, ux, uy, _, rad = self._levels[level]
        real = np.flatnonzero(np.isfinite(rad))
        ax, ay, ux, uy, rad = ax[real], ay[real], ux[real], uy[real], rad[real]
        grow = rad + reach * (1 + 1e-9) + 1e-12 * self._scale
        i0 = np.floor((np.minimum(ax, ax + ux) - grow - lo[0]) / reach).astype(np.int64)
        i1 = np.floor((np.maximum(ax, ax + ux) + grow - lo[0]) / reach).astype(np.int64)
        j0 = np.floor((np.minimum(ay, ay + uy) - grow - lo[1]) / reach).astype(np.int64)
        j1 = np.floor((np.maximum(ay, ay + uy) + grow - lo[1]) / reach).astype(np.int64)
        i0, j0 = np.maximum(i0, 0), np.maximum(j0, 0)
        i1, j1 = np.minimum(i1, shape[0] - 1), np.minimum(j1, shape[1] - 1)
        wide, tall = i1 - i0 + 1, j1 - j0 + 1
        count = wide * tall
        owner = np.repeat(np.arange(real.size), count)
        k = np.arange(owner.size) - np.repeat(np.cumsum(count) - count, count)
        di, dj = np.divmod(k, tall[owner])
        bucket = (j0[owner] + dj) * shape[0] + i0[owner] + di
        order = np.argsort(bucket, kind="stable")
        offsets = np.zeros(shape.prod() + 2, dtype=np.int64)  # (last: an empty bucket)
        np.cumsum(np.bincount(bucket, minlength=shape.prod() + 1), out=offsets[1:])
        self._grid = (lo, float(reach), shape, level, offsets, real[owner[order]])

    def _grid_start(self, px, py, best2, hi2):
        """``(level, qi, node)`` of the first pass from the bucket index (`index_reach`), or
        None if there is none or some point needs farther than its reach."""
        if self._grid is None:
            return None
        lo, reach, shape, level, offsets, nodes = self._grid
        if not np.minimum(best2, hi2).max() <= reach * reach:
            return None
        i = np.floor((px - lo[0]) / reach)
        j = np.floor((py - lo[1]) / reach)
        outside = (i < 0) | (i >= shape[0]) | (j < 0) | (j >= shape[1])
        key = np.where(outside, shape.prod(), j * shape[0] + i).astype(np.int64)
        first = offsets.take(key)
        count = offsets.take(key + 1) - first
        qi = np.arange(px.size).repeat(count)
        shift = first - (np.cumsum(count) - count)
        node = nodes.take(np.arange(qi.size) + shift.take(qi))
        return level, qi, node

    def _charge(self, pairs: int) -> None:
        self.pairs += pairs
        if self.max_pairs is not None and self.pairs > self.max_pairs:
            raise WorkLimit(
                f"the distance queries would test more than {self.max_pairs:,} (point, segment) "
                f"pairs against the {self.n:,} input segments (each sample near the result "
                "tests the segments within its reach: many when the input criss-crosses or "
                "the distance is large next to it); use a larger cell, fewer or cleaner "
                "curves, or a larger budget"
            )

    def _query(
        self, p: np.ndarray, lo: np.ndarray, hi: np.ndarray, upper: np.ndarray | None
    ) -> Nearest:
        """`query` of one chunk of points (``lo``, ``hi``: one value a point). Sets
        ``last_pairs``, the most (point, node) pairs one pass held, and adds every pair
        tested to ``pairs``."""
        q = p.shape[0]
        px, py = np.ascontiguousarray(p[:, 0]), np.ascontiguousarray(p[:, 1])
        peak = 0
        slack = 1e-12 * max(self._scale, float(np.abs(px).max()), float(np.abs(py).max()))
        hi2 = np.square(np.maximum(hi, 0.0))
        lo2 = np.where(lo > 0, np.square(lo), -1.0)
        # Squared distance to the nearest curve point seen.
        best2 = np.full(q, np.inf) if upper is None else np.square(upper)
        # Levels are visited in jumps that keep about _PAIRS (point, node) pairs per visit:
        # few points start deep and skip levels (numpy calls cost more than the few more
        # capsules tested), many go two levels a step.
        start = self._grid_start(px, py, best2, hi2)
        if start is None:
            level = min(self.depth, max(0, int(np.log2(max(_PAIRS // q, 1)))))
            qi = np.arange(q).repeat(2**level)
            node = _fan_out(np.zeros(q, dtype=np.int64), 2**level)
        else:
            level, qi, node = start
        while True:
            ax, ay, ux, uy, inv, rad = self._levels[level]
            peak = max(peak, qi.size)
            self._charge(qi.size)
            nux, nuy = ux.take(node), uy.take(node)
            dx = px.take(qi)
            dx -= ax.take(node)
            dy = py.take(qi)
            dy -= ay.take(node)
            t = dx * nux
            t += dy * nuy
            t *= inv.take(node)
            np.minimum(np.maximum(t, 0.0, out=t), 1.0, out=t)
            # The axis start is a curve point: an upper bound. (Its end is the next node's
            # start, so it adds little.)
            if level >= self.depth - 3:
                d2 = dx * dx
                d2 += dy * dy
                np.minimum.at(best2, qi, d2)
            nux *= t
            dx -= nux
            nuy *= t
            dy -= nuy
            dx *= dx
            dy *= dy
            dx += dy  # squared distance to the capsule's axis
            # Drop a node whose capsule is farther than the best upper bound (or the band's
            # top), and every node of a point already certified below the band (NaN).
            cut = np.sqrt(np.minimum(best2, hi2))
            cut *= 1 + 1e-12
            cut[best2 < lo2] = np.nan
            thr = cut.take(qi)
            thr += rad.take(node)
            thr += slack
            thr *= thr
            keep = (dx <= thr).nonzero()[0]
            qi, node = qi.take(keep), node.take(keep)
            if level == self.depth or qi.size == 0:
                break
            jump = int(np.log2(max(_PAIRS // max(qi.size, 1), 1)))
            jump = min(self.depth - level, max(jump, 2))
            fan = 2**jump
            level += jump
            qi = qi.repeat(fan)
            node = _fan_out(node, fan)

        # Leaves: brute force over their segments.
        seg = _fan_out(node, self.leaf)
        self.last_pairs = max(peak, seg.size)
        self._charge(seg.size)
        qs = qi.repeat(self.leaf)
        ax, ay, ux, uy, inv = self._segs
        dx = px.take(qs)
        dx -= ax.take(seg)
        dy = py.take(qs)
        dy -= ay.take(seg)
        nux, nuy = ux.take(seg), uy.take(seg)
        t = dx * nux
        t += dy * nuy
        t *= inv.take(seg)
        np.minimum(np.maximum(t, 0.0, out=t), 1.0, out=t)
        nux *= t
        dx -= nux
        nuy *= t
        dy -= nuy
        dx *= dx
        dy *= dy
        dx += dy
        d2 = dx
        dist2 = np.full(q, np.inf)
        np.minimum.at(dist2, qs, d2)
        hit = (d2 == dist2.take(qs)).nonzero()[0]
        segment = np.full(q, -1, dtype=np.int64)
        param = np.zeros(q)
        # Ties give several hits per point; any one of them is a nearest segment.
        at = qs.take(hit)
        piece = np.minimum(seg.take(hit), self._n_pieces - 1)
        if self._owner is None:
            segment[at] = piece
            param[at] = t.take(hit)
        else:  # a piece's parameter on its whole segment
            segment[at] = self._owner.take(piece)
            param[at] = np.minimum(
                self._start.take(piece) + t.take(hit) * self._scale_t.take(piece), 1.0
            )
        dist = np.sqrt(dist2)
        found = dist2 < np.inf
        exact = found & (dist <= hi)
        if found.all():
            out = dist
        else:
            best = np.sqrt(best2)
            out = np.where(found, dist, best)
            far = ~found & ~(best2 < lo2)
            out[far] = np.maximum(best[far], np.nextafter(hi[far], np.inf))
        segment[~exact] = -1
        return Nearest(out, exact, segment, param)


_FIRST_CHUNK = 8192  # points in a query's first chunk
_MAX_PAIRS = 1 << 21  # (point, node) pairs a query's chunk should hold at once, about
_NEAREST = ("dist", "exact", "segment", "t")
_PIECES = 64  # a segment is cut into pieces of at most 1/_PIECES of the input's extent
_MAX_PIECES = 1 << 20  # ... while the pieces stay fewer than this (or than 4 per segment)


def _pieces(a: np.ndarray, b: np.ndarray):
    """Segments ``a -> b`` cut into pieces of at most ``extent / _PIECES`` (fewer cuts if
    there would be too many), in Morton order of their midpoints (the order of a messy input
    says nothing about where its segments are; a tree over that order has fat capsules).

    Returns the pieces' ends, and per piece its segment, and where on it the piece starts and
    how much of it the piece spans (as segment parameters); the last three are ``None`` if
    no segment is cut (the segments are then their own pieces, in their given order).
    """
    n = a.shape[0]
    ux, uy = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    length = np.sqrt(ux * ux + uy * uy)
    extent = max(float(np.ptp(a[:, 0])), float(np.ptp(a[:, 1])), float(length.max()))
    if extent == 0:
        return a, b, None, None, None
    longest = extent / _PIECES
    total = float(length.sum())
    budget = max(4 * n, _MAX_PIECES)
    if total / longest > budget:
        longest = total / budget
    count = np.maximum(np.ceil(length / longest), 1).astype(np.int64)
    if (count == 1).all():
        return a, b, None, None, None
    first = np.cumsum(count) - count
    owner = np.repeat(np.arange(n), count)
    k = np.arange(owner.size) - first[owner]
    m = count[owner].astype(float)
    start, span = k / m, 1.0 / m
    ao, bo = a[owner], b[owner]
    pa = ao + (bo - ao) * start[:, None]
    pb = ao + (bo - ao) * (start + span)[:, None]
    pa[first] = a  # whole segments' own ends, exactly
    pb[first + count - 1] = b
    order = np.argsort(_morton((pa + pb) / 2), kind="stable")
    return pa[order], pb[order], owner[order], start[order], span[order]


def _morton(p: np.ndarray) -> np.ndarray:
    """Z-order keys of points: coordinates quantized to 16 bits, bits interleaved."""
    lo = p.min(axis=0)
    size = float((p.max(axis=0) - lo).max()) or 1.0
    q = ((p - lo) * (65535.0 / size)).astype(np.uint64)

    def spread(v: np.ndarray) -> np.ndarray:
        v = (v | (v << np.uint64(8))) & np.uint64(0x00FF00FF)
        v = (v | (v << np.uint64(4))) & np.uint64(0x0F0F0F0F)
        v = (v | (v << np.uint64(2))) & np.uint64(0x33333333)
        return (v | (v << np.uint64(1))) & np.uint64(0x55555555)

    return spread(q[:, 0]) | (spread(q[:, 1]) << np.uint64(1))


_PATTERNS: dict[int, np.ndarray] = {}  # 0, 1, ..., fan - 1 repeated, per fan (grown as needed)


def _fan_out(node: np.ndarray, fan: int) -> np.ndarray:
    """The children ``node * fan + k``, ``k < fan``, of every node, flattened node by node.

    (A repeat plus a slice of a stored ``0, 1, ..., fan - 1`` pattern: numpy's broadcast
    ``add.outer`` crawls over a short last axis.)
    """
    out = (node * fan).repeat(fan)
    pattern = _PATTERNS.get(fan)
    if pattern is None or pattern.size < out.size:
        pattern = np.tile(np.arange(fan), max(2 * out.size // fan, 4096))
        _PATTERNS[fan] = pattern
    out += pattern[: out.size]
    return out


def _dist2(
    ex: np.ndarray, ey: np.ndarray, ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray
) -> np.ndarray:
    """Squared distances (k, m) from points ``(ex[i, j], ey[i, j])`` to the segments
    ``(ax[j], ay[j]) -> (bx[j], by[j])``: segments along the last axis, so numpy's inner
    loops run over all of them (a short last axis would make them crawl)."""
    ux, uy = bx - ax, by - ay
    len2 = ux * ux + uy * uy
    inv = np.divide(1.0, len2, out=np.zeros_like(len2), where=len2 > 0)
    dx, dy = ex - ax, ey - ay
    t = dx * ux
    t += dy * uy
    t *= inv
    np.minimum(np.maximum(t, 0.0, out=t), 1.0, out=t)
    dx -= t * ux
    dy -= t * uy
    dx *= dx
    dy *= dy
    dx += dy
    return dx


def _fields(ax, ay, bx, by) -> tuple[np.ndarray, ...]:
    """Contiguous ``(ax, ay, ux, uy, 1 / |u|^2)`` of segments ``a -> b`` (``u = b - a``),
    from their coordinate columns."""
    ux, uy = bx - ax, by - ay
    len2 = ux * ux + uy * uy
    inv = np.divide(1.0, len2, out=np.zeros_like(len2), where=len2 > 0)
    return np.ascontiguousarray(ax), np.ascontiguousarray(ay), ux, uy, inv


class RowParity:
    """Even-odd inside test for the points of a regular grid.

    Parameters
    ----------
    a, b : (n, 2) float
        Ends of the closed curves' segments (open curves bound nothing; leave them out).
    origin : (2,) float
        Position of grid sample ``(0, 0)``; sample ``(i, j)`` is at
        ``origin + (j * cell, i * cell)``.
    cell : float
    ny, nx : int
        Number of grid rows and columns.
    """

    def __init__(
        self, a: np.ndarray, b: np.ndarray, origin: np.ndarray, cell: float, ny: int, nx: int
    ) -> None:
        # Rows crossed by a segment: those with y in [ymin, ymax), in row units.
        ya = (a[:, 1] - origin[1]) / cell
        yb = (b[:, 1] - origin[1]) / cell
        r0 = np.ceil(np.minimum(ya, yb)).astype(np.int64)
        r1 = np.ceil(np.maximum(ya, yb)).astype(np.int64)
        r0 = np.clip(r0, 0, ny)
        r1 = np.clip(r1, 0, ny)
        count = np.maximum(r1 - r0, 0)
        seg = np.repeat(np.arange(a.shape[0]), count)
        start = np.cumsum(count) - count
        row = r0[seg] + np.arange(seg.size) - np.repeat(start, count)
        xa = (a[seg, 0] - origin[0]) / cell
        xb = (b[seg, 0] - origin[0]) / cell
        s = (row - ya[seg]) / (yb[seg] - ya[seg])
        col = xa + s * (xb - xa)
        # Keys row * width + col sort by row, then column; width keeps rows apart.
        self._width = float(2 * (np.ceil(max(np.abs(col).max(initial=0.0), nx)) + 2))
        self._keys = np.sort(row * self._width + col)

    def inside(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """True where grid sample ``(i, j)`` is inside by the even-odd rule.

        Parameters
        ----------
        i, j : (m,) int
            Row and column of each sample.

        Returns
        -------
        (m,) bool
        """
        base = np.searchsorted(self._keys, i * self._width - self._width / 2)
        upto = np.searchsorted(self._keys, i * self._width + j)
        return (upto - base) % 2 == 1
