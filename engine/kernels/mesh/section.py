"""Sections of meshes by a plane, and the outline of a mesh's shadow on a plane.

Both come out as the loops of a planar region, found by chaining oriented segments:

- :func:`slice_loops`: the plane ``z = h`` cuts each triangle that has corners on both
  sides (a corner counts as above when ``z > h``, below otherwise, so a vertex on the
  plane is never ambiguous: the same half-open rule as manifold3d's ``slice``, where the
  bottom face of a box is its section at the bottom and the top gives nothing). Each cut
  is a segment from the point on its triangle's edge that goes down through the plane to
  the point on the edge that goes up, which runs along ``z x n`` for the triangle's
  normal n: counter-clockwise around material, clockwise around holes, seen from +z. The
  point on an edge is computed once per edge, from its lower vertex id to its higher, so
  the two triangles of an edge meet in the same bits, and a segment's successor is the
  one that starts on the edge it ends on.
- :func:`shadow_loops`: the boundary, as a chain, of every face projected on the XY plane
  and counted +1 where it faces up and -1 where it faces down (reversed, so that it too
  runs counter-clockwise): edges between faces of one sign cancel, and what is left is a
  set of loops whose winding number at a point is the number of faces above or below it.
  Its nonzero fill is the shadow, the union of the projected faces (Clipper2's sweep,
  through manifold3d's ``CrossSection``).
- :func:`cycles`: the cycles of a successor permutation, each in order, by pointer jumping
  (Wyllie's list ranking, vectorized: log2 of the longest cycle rounds of gathers).
- :func:`region_of_loops`: loops to a valid region: by the even-odd rule of GEOS when that
  agrees with their winding numbers (their signed areas add up to the region's area, as
  they do for the section of a solid that does not intersect itself), else by Clipper2's
  nonzero fill (overlapping parts, faces that cross).
"""

from __future__ import annotations

import math

import numpy as np

from ..curves import regions as kregions
from .keys import sort_keys

__all__ = [
    "SliceIndex",
    "cycles",
    "nonzero_fill",
    "region_of_loops",
    "section_rings",
    "shadow_loops",
    "slice_loops",
]


def cycles(succ: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cycles of a permutation, each listed in order from its smallest element.

    Parameters
    ----------
    succ : (n,) int
        A permutation of ``range(n)``: element i is followed by ``succ[i]``.

    Returns
    -------
    order : (n,) int64
        The elements cycle after cycle, each cycle in successor order.
    offsets : (c + 1,) int64
        Cycle k is ``order[offsets[k]:offsets[k + 1]]``; cycles by their smallest element.
    """
    succ = np.asarray(succ, dtype=np.int64)
    n = len(succ)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(1, np.int64)
    # the smallest element of each cycle, by pointer jumping on (min so far, jump): once a
    # round changes nothing, no later round would (each window's minimum is settled)
    idx = np.arange(n)
    low = np.minimum(idx, succ)
    jump = succ
    while True:
        nxt_low = np.minimum(low, low.take(jump))
        if not (nxt_low < low).any():
            break
        low, jump = nxt_low, jump.take(jump)
    # cut each cycle before its smallest element and rank the paths (distance to the end)
    head = low == idx
    last = head.take(succ)  # i is followed by its cycle's head: the end of the path
    nxt = np.where(last, idx, succ)
    dist = (~last).astype(np.int64)
    while True:
        further = nxt.take(nxt)
        if not (further != nxt).any():
            break
        dist += dist.take(nxt)
        nxt = further
    # dist counts steps to the end; within a cycle of length L, position = L - 1 - dist
    cycle = low
    length = np.bincount(cycle, minlength=n)
    pos = length[cycle] - 1 - dist
    heads = np.flatnonzero(head)
    start = np.zeros(n, dtype=np.int64)
    sizes = length[heads]
    start[heads] = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    order = np.empty(n, dtype=np.int64)
    order[start[cycle] + pos] = np.arange(n)
    return order, np.concatenate([[0], np.cumsum(sizes)])


class SliceIndex:
    """The triangles of a mesh sorted for slicing along z: each plane finds the triangles
    it cuts without looking at the others.

    The z range is cut into ``buckets`` equal slabs and every triangle is listed in each
    slab its ``[zmin, zmax]`` reaches (one pass: a triangle spans few slabs); the plane
    ``z = h`` looks at the triangles listed in its slab only. Built once per mesh and
    axis, kept with the mesh, so a stack of sections (``repeat:``) or a slider pays for it
    once.
    """

    def __init__(self, z: np.ndarray, tri: np.ndarray):
        zt = z[tri]
        self.zmin, self.zmax = zt.min(axis=1), zt.max(axis=1)
        t = len(tri)
        self.lo = float(self.zmin.min()) if t else 0.0
        self.hi = float(self.zmax.max()) if t else 0.0
        self.buckets = max(1, min(t // 32, 1 << 16))
        width = (self.hi - self.lo) / self.buckets
        self.width = width if width > 0 else 1.0
        first = self._bucket(self.zmin)
        last = self._bucket(self.zmax)
        span = last - first + 1
        total = int(span.sum())
        ids = np.repeat(np.arange(t), span)
        bucket = np.repeat(first, span) + (
            np.arange(total) - np.repeat(np.cumsum(span) - span, span)
        )
        order, sb = sort_keys(bucket, self.buckets)
        self.ids = ids[order]
        self.starts = np.searchsorted(sb, np.arange(self.buckets + 1))

    def _bucket(self, z: np.ndarray) -> np.ndarray:
        b = np.floor((z - self.lo) / self.width).astype(np.int64)
        return np.clip(b, 0, self.buckets - 1)

    def cut(self, h: float) -> np.ndarray:
        """The triangles with ``zmin <= h < zmax`` (those with corners on both sides of
        the plane by the half-open rule), in increasing order."""
        if not self.lo <= h < self.hi:
            return np.zeros(0, np.int64)
        b = int(self._bucket(np.array([h]))[0])
        cand = self.ids[self.starts[b] : self.starts[b + 1]]
        keep = (self.zmin[cand] <= h) & (self.zmax[cand] > h)
        return np.sort(cand[keep])


def slice_loops(
    v: np.ndarray, tri: np.ndarray, h: float, cut: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, int]:
    """The section of triangles by the plane ``z = h`` as closed loops.

    Parameters
    ----------
    v : (n, 3) float
        Vertices (the plane is z = h; callers slicing along x or y permute the columns).
    tri : (t, 3) int
        Triangles, oriented outward.
    h : float
    cut : (k,) int, optional
        The triangles the plane cuts (:meth:`SliceIndex.cut`), if known.

    Returns
    -------
    xy : (m, 2) float
        Loop points, loop after loop, each without its closing point.
    offsets : (c + 1,) int64
    open_chains : int
        Segments that found no successor (an open or non-manifold mesh) and were left out.
    """
    z = v[:, 2]
    if cut is None:
        above = z > h
        na = above[tri].sum(axis=1)
        cut = np.flatnonzero((na > 0) & (na < 3))
    k = len(cut)
    if k == 0:
        return np.zeros((0, 2)), np.zeros(1, np.int64), 0
    t = tri[cut]
    flat = t.reshape(-1)
    above = z[flat] > h  # (indexing, not take: take would copy a strided column whole)
    code = above[0::3] + 2 * above[1::3] + 4 * above[2::3]  # which corners are above
    base = 3 * np.arange(k)
    # edge i runs from corner i to corner i + 1: the one going up ends the segment, the
    # one going down starts it
    up = base + _UP.take(code)
    down = base + _DOWN.take(code)
    ua, ub = flat.take(up), flat.take(_next_in_triangle(up))
    da, db = flat.take(down), flat.take(_next_in_triangle(down))
    n = len(v)
    end_key = np.minimum(ua, ub) * n + np.maximum(ua, ub)
    lo, hi = np.minimum(da, db), np.maximum(da, db)
    start_key = lo * n + hi
    succ, found = _match(start_key, end_key)
    open_chains = int(k - np.count_nonzero(found))
    if open_chains:  # drop the segments of chains that do not close
        succ, keep_seg = _closed_only(succ, found)
        lo, hi = lo[keep_seg], hi[keep_seg]
        if len(lo) == 0:
            return np.zeros((0, 2)), np.zeros(1, np.int64), open_chains
    order, offsets = cycles(succ)
    # the point on each segment's start edge, from its lower vertex to its higher
    lo, hi = lo.take(order), hi.take(order)
    zl = z[lo]
    s = (h - zl) / (z[hi] - zl)
    pl, ph = v[lo, :2], v[hi, :2]
    xy = pl + s[:, None] * (ph - pl)
    return _without_repeats(xy, offsets) + (open_chains,)


def _crossings() -> tuple[np.ndarray, np.ndarray]:
    """For each pattern of corners above the plane (bit i: corner i), the edge that goes
    up through it and the one that goes down (0 where the plane does not cut)."""
    up, down = np.zeros(8, np.int64), np.zeros(8, np.int64)
    for code in range(1, 7):  # the six patterns with corners on both sides
        ab = [(code >> i) & 1 for i in range(3)]
        up[code] = next(i for i in range(3) if not ab[i] and ab[(i + 1) % 3])
        down[code] = next(i for i in range(3) if ab[i] and not ab[(i + 1) % 3])
    return up, down


_UP, _DOWN = _crossings()


def _next_in_triangle(pos: np.ndarray) -> np.ndarray:
    """The flat position of the next corner of a triangle's corner (its last: its first)."""
    return pos + 1 - 3 * (pos % 3 == 2)


def _match(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Segment s is followed by one whose start key is s's end key; of equal keys (an edge
    on more than two faces) the j-th end meets the j-th start. Returns the successor of
    every segment and whether it has one."""
    k = len(start)
    so = np.argsort(start, kind="stable")
    eo = np.argsort(end, kind="stable")
    ss, se = start.take(so), end.take(eo)
    succ = np.empty(k, dtype=np.int64)
    if np.array_equal(ss, se):  # a closed mesh: every end meets a start
        succ[eo] = so
        return succ, np.ones(k, dtype=bool)
    rank = np.arange(k) - np.searchsorted(se, se, side="left")
    target = np.searchsorted(ss, se, side="left") + rank
    ok = target < k
    ok[ok] = ss[target[ok]] == se[ok]
    found = np.zeros(k, dtype=bool)
    found[eo[ok]] = True
    succ[eo] = np.where(ok, so.take(np.minimum(target, k - 1)), 0)
    return succ, found


def _argsorted(key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(key, kind="stable")
    return order, key[order]


def _closed_only(succ: np.ndarray, found: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Keep the segments on closed chains: follow successors from the dead ends and
    drop everything reachable backwards from one (a chain is a path, not a cycle)."""
    n = len(succ)
    nxt = np.where(found, succ, np.arange(n))
    # an element is on a path if jumping forward ever reaches a dead end
    dead = ~found
    reach = dead.copy()
    jump = nxt.copy()
    for _ in range(max(1, math.ceil(math.log2(max(n, 2)))) + 1):
        reach = reach | reach[jump]
        jump = jump[jump]
    keep = ~reach
    new = np.cumsum(keep) - 1
    return new[succ[keep]], keep


def _without_repeats(xy: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Loops without a point equal to the one before it (cyclically), and without loops
    left with fewer than 3 points."""
    m = len(xy)
    if m == 0:
        return xy, offsets
    loop = np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))
    prev = np.arange(m) - 1
    prev[offsets[:-1]] = offsets[1:] - 1
    same = (xy[:, 0] == xy[prev, 0]) & (xy[:, 1] == xy[prev, 1])
    if same.any():
        keep = ~same
        sizes = np.bincount(loop[keep], minlength=len(offsets) - 1)
        xy, loop = xy[keep], loop[keep]
    else:
        sizes = np.diff(offsets)
    good = sizes >= 3
    if not good.all():
        sel = good[loop]
        xy, sizes = xy[sel], sizes[good]
    return xy, np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)


def shadow_loops(v: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The boundary of the up-and-down counted projection of the triangles, as loops.

    Parameters
    ----------
    v : (n, 3) float
        Vertices, coincident ones merged (a soup's triangles share no edges otherwise).
    tri : (t, 3) int

    Returns
    -------
    xy : (m, 2) float
        Loop points, loop after loop, each without its closing point.
    offsets : (c + 1,) int64
    """
    p = v[tri]  # (t, 3, 3)
    e1, e2 = p[:, 1, :2] - p[:, 0, :2], p[:, 2, :2] - p[:, 0, :2]
    nz = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    sign = np.sign(nz).astype(np.int64)
    live = sign != 0
    t, sign = tri[live], sign[live]
    a = t.reshape(-1)
    b = np.roll(t, -1, axis=1).reshape(-1)
    s = np.repeat(sign, 3)
    n = len(v)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    along = np.where(a < b, s, -s)  # +1: the chain runs lo -> hi
    order, key = sort_keys(lo * n + hi, n * n) if n < 3_037_000_499 else _argsorted(lo * n + hi)
    first = np.ones(len(key), dtype=bool)
    first[1:] = key[1:] != key[:-1]
    starts = np.flatnonzero(first)
    net = np.add.reduceat(along[order], starts) if len(starts) else np.zeros(0, np.int64)
    keys = key[starts]
    mult = np.abs(net)
    keys, net, mult = keys[mult > 0], net[mult > 0], mult[mult > 0]
    if len(keys) == 0:
        return np.zeros((0, 2)), np.zeros(1, np.int64)
    ek = np.repeat(keys, mult)
    forward = np.repeat(net > 0, mult)
    u, w = ek // n, ek % n
    src = np.where(forward, u, w)
    dst = np.where(forward, w, u)
    # k-th edge into a vertex is followed by the k-th edge out of it (in-degree equals
    # out-degree at every vertex of a cycle; any pairing gives loops of the same windings)
    out_order = np.argsort(src, kind="stable")
    in_order = np.argsort(dst, kind="stable")
    succ = np.empty(len(src), dtype=np.int64)
    succ[in_order] = out_order
    cyc, offsets = cycles(succ)
    xy = v[src[cyc], :2]
    return _without_repeats(xy, offsets)


def _scale_power(xy: np.ndarray) -> float:
    """A power of two taking every coordinate within 2**32: Clipper2 (in manifold3d's
    ``CrossSection``) rounds to 1e-8 and refuses coordinates past about 1e10, so the
    loops go to it scaled up to use that range (exactly: a power of two), and back."""
    big = float(np.abs(xy).max()) if len(xy) else 1.0
    if big == 0.0:
        return 1.0
    return 2.0 ** math.floor(math.log2(2.0**32 / big))


def nonzero_fill(xy: np.ndarray, offsets: np.ndarray) -> list[np.ndarray]:
    """The region of points of nonzero winding number of the loops (Clipper2's union),
    as rings (outer counter-clockwise, holes clockwise) without their closing point."""
    import manifold3d

    f = _scale_power(xy)
    rings = [
        np.ascontiguousarray(xy[a:b] * f) for a, b in zip(offsets[:-1], offsets[1:], strict=True)
    ]
    polys = manifold3d.CrossSection(rings, manifold3d.FillRule.NonZero).to_polygons()
    return [np.asarray(p, dtype=np.float64) / f for p in polys if len(p) >= 3]


def region_of_loops(xy: np.ndarray, offsets: np.ndarray, fill: bool = False) -> tuple[object, bool]:
    """The valid region the loops bound by their winding numbers (nonzero); ``fill`` goes
    to the nonzero fill at once (loops known to overlap, as a shadow's do).

    Returns
    -------
    region : shapely (Multi)Polygon
    filled : bool
        Whether the loops disagreed with the even-odd rule (they overlap, or nest with
        the same orientation) and went through the nonzero fill.
    """
    rings = [xy[a:b] for a, b in zip(offsets[:-1].tolist(), offsets[1:].tolist(), strict=True)]
    if not rings:
        return kregions.even_odd_region([]), False
    if fill:
        return kregions.even_odd_region(nonzero_fill(xy, offsets)), True
    x, y = xy[:, 0], xy[:, 1]
    nxt = np.arange(1, len(xy) + 1)
    nxt[offsets[1:] - 1] = offsets[:-1]
    base = np.repeat(xy[offsets[:-1]], np.diff(offsets), axis=0)
    bx, by = x - base[:, 0], y - base[:, 1]
    twice = bx * by[nxt] - bx[nxt] * by
    signed = 0.5 * np.add.reduceat(twice, offsets[:-1])
    region = kregions.even_odd_region(rings)
    scale = float(np.abs(signed).sum())
    if abs(abs(float(signed.sum())) - float(region.area)) <= 1e-9 * max(scale, 1e-300):
        return region, False
    filled = nonzero_fill(xy, offsets)
    return kregions.even_odd_region(filled), True


def section_rings(
    xy: np.ndarray, offsets: np.ndarray, fill: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The loops as the rings of a valid region (:func:`region_of_loops`), each closed by
    its first point, outer ones counter-clockwise and holes clockwise.

    One loop that winds once around the centre of its box, every edge turning the same way
    about it, is simple (:func:`~formgraph.kernels.curves.regions._star_shaped`: a section
    of a convex part, the usual case) and is its own region: it is taken as it is, turned
    counter-clockwise, without GEOS.

    Returns
    -------
    coords : (N, 2) float
    offsets : (r + 1,) int64
    step : (N - 1,) float
        The length of each step (at a ring's end, the jump to the next ring's start).
    filled : bool
        See :func:`region_of_loops`.
    """
    if len(offsets) == 2 and not fill and len(xy) >= 3:
        ring = np.concatenate([xy, xy[:1]])
        x, y = ring[:, 0], ring[:, 1]
        box = np.array([x.min(), y.min(), x.max(), y.max()])
        if kregions._star_shaped(ring, box):
            twice = np.dot(x[:-1] - x[0], y[1:] - y[0]) - np.dot(x[1:] - x[0], y[:-1] - y[0])
            if twice < 0:
                ring = ring[::-1].copy()
            d = np.diff(ring, axis=0)
            step = np.sqrt(np.einsum("ij,ij->i", d, d))
            return ring, np.array([0, len(ring)], dtype=np.int64), step, False
    region, filled = region_of_loops(xy, offsets, fill)
    coords, off, _, step = kregions.rings_of(region, steps=True)
    return coords, off, step, filled
