"""Triangulation of one simple polygon by ear clipping, in rounds over independent ears.

Ear clipping (G. H. Meisters, "Polygons have ears", Amer. Math. Monthly 82, 1975) cuts off
one convex corner at a time whose triangle holds no other corner. Done naively (test every
corner against every corner, one ear per step) it costs O(n^3); this version is the
standard O(n^2)-at-worst one (D. Eberly, "Triangulation by ear clipping", Geometric
Tools, 2002) made vectorized:

- only reflex corners can lie inside an ear's triangle (if any corner does, a reflex one
  does), and a reflex corner never becomes reflex again once convex, so the candidates are
  the reflex corners, kept sorted by x: each triangle is tested only against those inside
  its x range (a ragged gather, ``searchsorted`` plus ``repeat``);
- clipping an ear changes the ear status of its two neighbours only, so each round clips
  every other ear of each run of ears at once (no two adjacent) and re-tests just the
  neighbours. A star loses all its tips in the first round, and a convex remainder half
  its corners per round.

The work (triangle-corner tests) is counted and refused past ``max_tests`` before it is
done, so a hostile polygon cannot take minutes.

Simple polygons go to mapbox_earcut first (the C++ port of Mapbox's earcut: ear clipping
with a z-order index of the corners, the well-kept library for exactly this; 10-20x faster
than the rounds here, measured in ``bench/bench_mesh.py``) when its worst case, ``k^2 / 2``
tests, is within ``max_tests``. Its answer is checked by :func:`tiling` (``k - 2``
triangles, none flipped, whose edges pair up with the loop's: a proof that they cover it
once, in one sort); where it is not a tiling -- a loop that touches or crosses itself, for
which earcut drops or overlaps triangles -- the rounds here decide. The check is needed:
earcut does not promise a tiling (its README: "acceptable results for practical data"),
and whether a loop is simple is not known before.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "WorkLimitError",
    "large_face",
    "polygon_plane",
    "tiling",
    "triangulate_plane",
    "triangulate_polygon",
]

_CHUNK = 1 << 21  # triangle-corner pairs tested at once (bounds the memory of a round)


class WorkLimitError(ValueError):
    """More triangle-corner tests than allowed; ``work`` is how many were needed so far."""

    def __init__(self, work: int, limit: int):
        super().__init__(
            f"ear clipping needs more than {limit:,} triangle-corner tests ({work:,} so far)"
        )
        self.work = work
        self.limit = limit


def polygon_plane(points: np.ndarray) -> np.ndarray:
    """Coordinates (k, 2) of a polygon loop in its own plane, counter-clockwise.

    ``(k, 2)`` input that runs clockwise is mirrored; ``(k, 3)`` input is projected on the
    plane of its Newell normal, seen from the side the normal points to (so the loop runs
    counter-clockwise there). Centred on the mean corner.

    The Newell normal ``sum_i q_i x q_(i+1)`` is read off the 3 x 3 matrix
    ``S = q^T q_next`` (its antisymmetric part: ``n_x = S_yz - S_zy`` ...): one product
    instead of k cross products.
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"a polygon must be a (k, 2) or (k, 3) array of corners, got {p.shape}")
    if not np.isfinite(p).all():
        raise ValueError("polygon corners must be finite")
    # (a product with ones: numpy's mean along the short axis of a (k, 3) array is ten
    # times slower than the rest of this function)
    q = p - np.ones(len(p)) @ p / max(len(p), 1)
    s = q.T @ _following(q)
    if p.shape[1] == 2:
        return q * np.array([-1.0, 1.0]) if s[0, 1] - s[1, 0] < 0 else q
    n = (s[1, 2] - s[2, 1], s[2, 0] - s[0, 2], s[0, 1] - s[1, 0])
    length = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
    if length == 0:
        return q[:, :2]  # no area at all: any projection (the fan fallback handles it)
    n = (n[0] / length, n[1] / length, n[2] / length)
    # u: the x axis (the y axis if n is near x) made square to n, w = n x u: a loop in a
    # plane z = c keeps its own x and y (mirrored in y if it faces -z): mapbox_earcut took
    # 13% longer on the bench's 10,000-corner star turned a quarter, as the old choice of
    # u turned it. 3-vectors written out: np.cross costs 20 us a call.
    if abs(n[0]) < 0.9:
        u = (1.0 - n[0] * n[0], -n[0] * n[1], -n[0] * n[2])
    else:
        u = (-n[1] * n[0], 1.0 - n[1] * n[1], -n[1] * n[2])
    lu = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
    u = (u[0] / lu, u[1] / lu, u[2] / lu)
    w = (n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0])
    return q @ np.array([u, w]).T


def _following(a: np.ndarray) -> np.ndarray:
    """The rows of ``a`` one on, the first after the last (``np.roll(a, -1, axis=0)``
    without its generality's cost, which on a face of 1,200 corners is most of the work)."""
    out = np.empty_like(a)
    out[:-1] = a[1:]
    out[-1] = a[0]
    return out


def triangulate_polygon(points: np.ndarray, max_tests: int | None = None) -> np.ndarray:
    """Triangles (k - 2, 3) of corner indices for a simple polygon given as a loop.

    Parameters
    ----------
    points : (k, 2) or (k, 3) float
        The corners in order (k >= 3), without repeating the first at the end. A 3-D loop
        is triangulated in the plane of its Newell normal.
    max_tests : int, optional
        Refuse (:class:`WorkLimitError`) once more triangle-corner tests than this would
        be needed; the worst case is about k^2 / 2.

    Returns
    -------
    (k - 2, 3) int64
        Each triangle runs the same way round as the loop. A polygon that is not simple
        (self-touching, or with no area) still gets k - 2 triangles: where no ear is left,
        the most convex corner is cut off.

    Example
    -------
    >>> triangulate_polygon([[0, 0], [2, 0], [2, 2], [1, 1], [0, 2]]).shape
    (3, 3)
    """
    return triangulate_plane(polygon_plane(points), max_tests)


def large_face(points: np.ndarray, max_tests: int | None = None) -> np.ndarray:
    """Triangles (k - 2, 3) of one face (k, 3) of a mesh: a fan from its first corner when
    it is convex (or has no area), else :func:`triangulate_plane` of its plane coordinates,
    which are made once for both tests (``meshops.triangulate``'s path for faces of more
    than 32 corners)."""
    xy = polygon_plane(points)
    k = len(xy)
    edge = _following(xy) - xy  # the edge out of each corner
    ahead = _following(edge)  # the edge out of the next corner
    turn = edge[:, 0] * ahead[:, 1] - edge[:, 1] * ahead[:, 0]  # > 0: the next turns left
    # twice the area: the sum of the cross products of corner and edge out (the shoelace)
    twice_area = float(xy[:, 0] @ edge[:, 1] - xy[:, 1] @ edge[:, 0])
    # the tolerance of the Newell test, |n|^2 * 1e-12, in the plane: |n| = twice the area
    if twice_area <= 0 or turn.min() >= -1e-12 * twice_area:
        j = np.arange(1, k - 1)
        return np.stack([np.zeros(k - 2, dtype=np.int64), j, j + 1], axis=1)
    return triangulate_plane(xy, max_tests)


def triangulate_plane(xy: np.ndarray, max_tests: int | None = None) -> np.ndarray:
    """:func:`triangulate_polygon` of a loop already in its plane, counter-clockwise (what
    :func:`polygon_plane` returns)."""
    k = len(xy)
    if k < 3:
        raise ValueError(f"a polygon needs at least 3 corners, got {k}")
    if k > 3 and (max_tests is None or k * k // 2 <= max_tests):
        tris = _earcut(xy)
        if tris is not None:
            return tris
    return _ear_clip_rounds(xy, max_tests)


def _earcut(xy: np.ndarray) -> np.ndarray | None:
    """mapbox_earcut's triangles of a counter-clockwise loop, if they tile it (else None)."""
    import mapbox_earcut

    k = len(xy)
    ends = np.array([k], dtype=np.uint32)
    flat = mapbox_earcut.triangulate_float64(np.ascontiguousarray(xy), ends)
    return tiling(xy, ends, flat)


def tiling(xy: np.ndarray, ends: np.ndarray, triangles: np.ndarray) -> np.ndarray | None:
    """``triangles`` (t, 3), counter-clockwise, if they tile the region bounded by the
    rings ``xy`` (ring i ends at ``ends[i]``; outer ring counter-clockwise, holes
    clockwise), else None: how an answer of mapbox_earcut is checked before it is used.

    They tile it when (1) there are ``n + 2 h - 2`` of them (n corners, h holes), (2) none
    is turned clockwise (beyond 1e-9 of the total area: collinear corners make slivers),
    and (3) the directed edges of the triangles with the rings' edges reversed added pair
    up exactly: every edge once each way, none twice the same way. (3) says that the
    boundary of the triangles, as a chain, is the rings; with (2) every point is then
    covered as many times as the rings wind about it, once inside a region whose rings
    do not cross or touch (the winding number of a 2-chain's boundary), so the triangles
    cover it without gap or overlap. One sort of ``3 t + n`` keys: no per-edge search.

    Parameters
    ----------
    xy : (n, 2) float
    ends : (rings,) int
        Where each ring ends in ``xy``; the last is ``n``.
    triangles : (3 t,) or (t, 3) int
        Indices into ``xy`` (earcut's flat answer), either winding.

    Returns
    -------
    (t, 3) int64 or None
    """
    n = len(xy)
    tri = np.asarray(triangles).reshape(-1, 3).astype(np.int64)
    if len(tri) != n + 2 * (len(ends) - 1) - 2 or n < 3 or tri.min() < 0 or tri.max() >= n:
        return None
    x, y = xy[:, 0], xy[:, 1]
    xa, ya = x[tri[:, 0]], y[tri[:, 0]]
    area = (x[tri[:, 1]] - xa) * (y[tri[:, 2]] - ya) - (y[tri[:, 1]] - ya) * (x[tri[:, 2]] - xa)
    if area.sum() < 0:  # earcut's own winding: made the rings'
        tri, area = tri[:, ::-1], -area
    if area.min() < -1e-9 * float(area.sum()):
        return None
    last = np.asarray(ends, dtype=np.int64) - 1  # each ring's last corner
    if last[-1] != n - 1:
        return None
    first = np.zeros_like(last)
    first[1:] = last[:-1] + 1
    # an edge a -> b's key: its pair {a, b} twice over, plus 1 for the way b > a ... a
    # triangle's three (the next corner of each: its columns turned by one) ...
    nxt = np.empty_like(tri)
    nxt[:, :2] = tri[:, 1:]
    nxt[:, 2] = tri[:, 0]
    way = tri > nxt
    edge = np.minimum(tri, nxt)
    edge *= n
    edge += np.maximum(tri, nxt)
    edge *= 2
    edge += way
    # ... and each ring edge reversed, i + 1 -> i (last -> first at its end): in closed form
    kind = np.int32 if 2 * n * n < 2**31 else np.int64  # (half the time to sort)
    key = np.empty(edge.size + n, dtype=kind)
    key[: edge.size] = edge.reshape(-1)
    ring = key[edge.size :]
    ring[:] = np.arange(3, 2 * n * (n + 1), 2 * (n + 1), dtype=kind)[:n]
    ring[last] = 2 * (first * n + last)
    key.sort()
    # paired exactly: the sorted keys go (2 e, 2 e + 1), (2 e', 2 e' + 1), ... (sorted,
    # so no pair can repeat: the next pair starts past 2 e + 1)
    pairs = key.reshape(-1, 2)  # (3 t + n = 4 n + 6 h - 6: even)
    if np.any(pairs[:, 0] & 1) or np.any(pairs[:, 1] - pairs[:, 0] != 1):
        return None
    return tri


def _turns(xy: np.ndarray, a: np.ndarray, v: np.ndarray, c: np.ndarray) -> np.ndarray:
    pa, pv, pc = xy[a], xy[v], xy[c]
    return (pv[:, 0] - pa[:, 0]) * (pc[:, 1] - pv[:, 1]) - (pv[:, 1] - pa[:, 1]) * (
        pc[:, 0] - pv[:, 0]
    )


class _Clipper:
    """State of one ear clipping: the corners left (in loop order) and the reflex ones."""

    def __init__(self, xy: np.ndarray, max_tests: int | None):
        self.xy = xy
        k = len(xy)
        scale = float(np.abs(xy).max(initial=1.0)) or 1.0
        self.eps = 1e-12 * scale * scale
        self.ring = np.arange(k)
        self.turn = _turns(xy, np.roll(self.ring, 1), self.ring, np.roll(self.ring, -1))
        self.alive = np.ones(k, dtype=bool)
        reflex = np.flatnonzero(self.turn <= self.eps)
        order = np.argsort(xy[reflex, 0], kind="stable")
        self.rid = reflex[order]  # ever-reflex corners, by x
        self.rx = xy[self.rid, 0]
        self.work = 0
        self.max_tests = max_tests

    def ears(self, pos: np.ndarray) -> np.ndarray:
        """Whether the corners at ring positions ``pos`` are ears now."""
        r = len(self.ring)
        a, v, c = self.ring[(pos - 1) % r], self.ring[pos], self.ring[(pos + 1) % r]
        ok = self.turn[v] > self.eps
        idx = np.flatnonzero(ok)
        if idx.size == 0 or self.rid.size == 0:
            return ok
        ta, tv, tc = a[idx], v[idx], c[idx]
        xs = self.xy[np.stack([ta, tv, tc]), 0]
        lo = np.searchsorted(self.rx, xs.min(axis=0), side="left")
        hi = np.searchsorted(self.rx, xs.max(axis=0), side="right")
        counts = hi - lo
        total = int(counts.sum())
        self.work += total
        if self.max_tests is not None and self.work > self.max_tests:
            raise WorkLimitError(self.work, self.max_tests)
        blocked = np.zeros(idx.size, dtype=bool)
        ends = np.cumsum(counts)
        start = 0
        while start < idx.size:  # chunks of at most _CHUNK pairs (one round's tests)
            stop = max(start + 1, int(np.searchsorted(ends, ends[start] - counts[start] + _CHUNK)))
            sl = slice(start, stop)
            blocked[sl] = self._blocked(ta[sl], tv[sl], tc[sl], lo[sl], counts[sl])
            start = stop
        ok[idx[blocked]] = False
        return ok

    def _blocked(self, a, v, c, lo, counts) -> np.ndarray:
        n = counts.sum()
        tri = np.repeat(np.arange(len(a)), counts)
        first = np.repeat(np.cumsum(counts) - counts, counts)
        q = self.rid[np.repeat(lo, counts) + np.arange(n) - first]
        live = self.alive[q] & (self.turn[q] <= self.eps)
        live &= (q != a[tri]) & (q != v[tri]) & (q != c[tri])
        tri, q = tri[live], q[live]
        pa, pv, pc, pq = self.xy[a[tri]], self.xy[v[tri]], self.xy[c[tri]], self.xy[q]

        def side(u: np.ndarray, w: np.ndarray) -> np.ndarray:
            return (w[:, 0] - u[:, 0]) * (pq[:, 1] - u[:, 1]) - (w[:, 1] - u[:, 1]) * (
                pq[:, 0] - u[:, 0]
            )

        inside = (side(pa, pv) >= -self.eps) & (side(pv, pc) >= -self.eps)
        inside &= side(pc, pa) >= -self.eps
        return np.bincount(tri[inside], minlength=len(a)) > 0

    def clip(self, chosen: np.ndarray) -> np.ndarray:
        """Cut off the corners at the chosen ring positions; their triangles (c, 3)."""
        r = len(self.ring)
        pos = np.flatnonzero(chosen)
        tris = np.stack(
            [self.ring[(pos - 1) % r], self.ring[pos], self.ring[(pos + 1) % r]], axis=1
        )
        self.alive[self.ring[pos]] = False
        touched = np.zeros(r, dtype=bool)
        touched[(pos - 1) % r] = True
        touched[(pos + 1) % r] = True
        touched &= ~chosen
        self.ring = self.ring[~chosen]
        return tris, np.flatnonzero(touched[~chosen])

    def retune(self, pos: np.ndarray) -> None:
        """New turns at the given ring positions; drop candidates that are no longer reflex."""
        r = len(self.ring)
        v = self.ring[pos]
        self.turn[v] = _turns(self.xy, self.ring[(pos - 1) % r], v, self.ring[(pos + 1) % r])
        keep = self.alive[self.rid] & (self.turn[self.rid] <= self.eps)
        if 2 * np.count_nonzero(keep) < keep.size:  # compact now and then: O(n) overall
            self.rid, self.rx = self.rid[keep], self.rx[keep]


def _ear_clip_rounds(xy: np.ndarray, max_tests: int | None) -> np.ndarray:
    st = _Clipper(xy, max_tests)
    ear = st.ears(np.arange(len(xy)))
    out = []
    while len(st.ring) > 3:  # rounds: ~log n for stars and convex parts, n at worst
        r = len(st.ring)
        if ear.any():
            chosen = _every_other(ear)
            if chosen.sum() > r - 3:
                chosen[np.flatnonzero(chosen)[r - 3 :]] = False
        else:  # no ear (not a simple polygon): the most convex corner goes
            chosen = np.zeros(r, dtype=bool)
            chosen[int(np.argmax(st.turn[st.ring]))] = True
        tris, touched = st.clip(chosen)
        out.append(tris)
        ear = ear[~chosen]
        st.retune(touched)
        ear[touched] = st.ears(touched)
    out.append(st.ring[None, :])
    return np.concatenate(out).astype(np.int64)


def _every_other(flags: np.ndarray) -> np.ndarray:
    """Every other True of each run of consecutive Trues (cyclic): no two chosen adjacent."""
    r = len(flags)
    if flags.all():
        chosen = np.zeros(r, dtype=bool)
        chosen[0 : r - (r % 2) : 2] = True
        return chosen
    # rotate so that position 0 is False: no run wraps around
    shift = int(np.argmin(flags))
    f = np.roll(flags, -shift)
    idx = np.arange(r)
    starts = np.where(f & ~np.roll(f, 1), idx, 0)
    run_start = np.maximum.accumulate(starts)
    chosen = f & ((idx - run_start) % 2 == 0)
    return np.roll(chosen, shift)
