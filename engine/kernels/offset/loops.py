"""Closed loops stored flat for vectorized work, and their clean-up.

`Loops` holds every loop's vertices one after another with what refinement needs per
vertex. `drop_folds` and `tidy` remove what a projection or a refinement can leave behind
near features thinner than a cell -- repeated vertices, spikes, short twists, flat loops;
`simplify` is Douglas-Peucker (Douglas & Peucker, "Algorithms for the reduction of the
number of points required to represent a digitized line", Cartographica 1973) on every
loop at once. All of it is vectorized over the vertices of all loops.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .distance import point_segment

__all__ = [
    "Loops",
    "crosses",
    "drop_covered",
    "drop_folds",
    "segments_cross",
    "simplify",
    "tidy",
    "unit",
]

COS30 = float(np.cos(np.radians(30)))
_UNTANGLE = 16  # chords ahead checked for a crossing by the final clean-up


@dataclass
class Loops:
    """Closed loops stored flat, loop after loop, with what refinement needs per vertex.

    Attributes
    ----------
    xy : (n, 2) float
    normal, normal_in : (n, 2) float
        Unit gradient of the distance at the vertex, as seen from the chord leaving it and
        from the chord arriving at it (they differ at a corner, where two features meet).
    seg, seg_in : (n,) int64
        The nearest input segment on either side, likewise.
    loop : (n,) int64
        Loop id of each vertex, nondecreasing.
    todo : (n,) bool
        The chord from this vertex to the next still needs a check.
    """

    xy: np.ndarray
    normal: np.ndarray
    seg: np.ndarray
    loop: np.ndarray
    todo: np.ndarray
    normal_in: np.ndarray | None = None
    seg_in: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.normal_in is None:
            self.normal_in = self.normal.copy()
        if self.seg_in is None:
            self.seg_in = self.seg.copy()

    @property
    def next(self) -> np.ndarray:
        n = self.loop.size
        nxt = np.arange(1, n + 1)
        last = np.flatnonzero(np.diff(self.loop, append=-1) != 0)
        nxt[last] = np.concatenate([[0], last[:-1] + 1])
        return nxt

    def offsets(self) -> np.ndarray:
        counts = np.bincount(self.loop)
        return np.concatenate([[0], np.cumsum(counts[counts > 0])])

    def insert(self, after: np.ndarray, new: Any, rows: np.ndarray) -> Loops:
        """New vertices ``new[rows]`` after the given ones; the chords on both sides of each
        are to do. ``new`` has arrays ``point``, ``normal``, ``seg``, ``normal_in`` and
        ``seg_in``."""
        n = self.loop.size
        order = np.argsort(np.concatenate([np.arange(n), after + 0.5]), kind="stable")
        todo = self.todo.copy()
        todo[after] = True

        def cat(old, extra):
            return np.concatenate([old, extra[rows]])[order]

        return Loops(
            cat(self.xy, new.point),
            cat(self.normal, new.normal),
            cat(self.seg, new.seg),
            np.concatenate([self.loop, self.loop[after]])[order],
            np.concatenate([todo, np.ones(after.size, dtype=bool)])[order],
            cat(self.normal_in, new.normal_in),
            cat(self.seg_in, new.seg_in),
        )

    def select(self, keep: np.ndarray) -> Loops:
        return Loops(
            self.xy[keep],
            self.normal[keep],
            self.seg[keep],
            self.loop[keep],
            self.todo[keep],
            self.normal_in[keep],
            self.seg_in[keep],
        )


def unit(v: np.ndarray) -> np.ndarray:
    length = np.hypot(v[:, 0], v[:, 1])
    return v / np.where(length > 0, length, 1.0)[:, None]


def segments_cross(a, b, c, d) -> np.ndarray:
    """Whether segments ``a -> b`` and ``c -> d`` properly cross, pairwise."""

    def orient(p, q, r):
        return (q[:, 0] - p[:, 0]) * (r[:, 1] - p[:, 1]) - (q[:, 1] - p[:, 1]) * (r[:, 0] - p[:, 0])

    return (orient(a, b, c) * orient(a, b, d) < 0) & (orient(c, d, a) * orient(c, d, b) < 0)


def crosses(xy: np.ndarray, i1: np.ndarray, j0: np.ndarray, j1: np.ndarray) -> np.ndarray:
    """Whether chord ``k -> i1[k]`` properly crosses chord ``j0[k] -> j1[k]``, for every k."""
    return segments_cross(xy, xy[i1], xy[j0], xy[j1])


def drop_folds(loops: Loops, before: np.ndarray, ok: np.ndarray) -> Loops:
    """Drop the vertices that failed to project, and pairs that projection put in reverse.

    Near a corner of the offset two neighbours can be moved past each other; both go, and
    the chord refinement recovers the corner from their neighbours. A loop that would keep
    fewer than three vertices is kept as it was.
    """
    keep = ok.copy()
    for _ in range(4):
        idx = np.flatnonzero(keep)
        sub = loops.select(keep)
        nxt = sub.next
        n2 = nxt[nxt]
        flip = np.einsum("ij,ij->i", sub.xy[nxt] - sub.xy, before[idx[nxt]] - before[idx]) <= 0
        # A chord crossing the chord two or three ahead: the vertices between are reversed.
        cross2 = crosses(sub.xy, nxt, n2, nxt[n2])
        cross3 = crosses(sub.xy, nxt, nxt[n2], nxt[nxt[n2]])
        # Going back along one smooth stretch (normals alike): a spike the projection
        # folded flat onto one side of a notch narrower than a cell.
        back = (
            (np.einsum("ij,ij->i", sub.xy[nxt] - sub.xy, sub.xy[n2] - sub.xy[nxt]) < 0)
            & (np.einsum("ij,ij->i", sub.normal, sub.normal[nxt]) > COS30)
            & (np.einsum("ij,ij->i", sub.normal[nxt], sub.normal[n2]) > COS30)
        )
        if not (flip.any() or cross2.any() or cross3.any() or back.any()):
            break
        keep[idx[flip]] = False
        keep[idx[nxt[back]]] = False
        keep[idx[nxt[flip | cross2 | cross3]]] = False
        keep[idx[n2[cross2 | cross3]]] = False
        keep[idx[nxt[n2[cross3]]]] = False
    count = np.bincount(loops.loop[keep], minlength=loops.loop.max() + 1)
    keep |= count[loops.loop] < 3
    return loops.select(keep)


def tidy(loops: Loops, gap: float) -> Loops:
    """Remove degenerate bits: repeated vertices, folds, detours, flat loops.

    A vertex within ``gap`` of the previous one goes; so does a vertex where the loop turns
    straight back along one smooth stretch (normals alike). A loop that passes the same
    point twice (a corner found from two chords) loses the shorter way between the two
    visits. Loops left with fewer than three vertices or no area go too.
    """
    for _ in range(6):
        nxt = loops.next
        n2 = nxt[nxt]
        xy, normal = loops.xy, loops.normal
        cut = np.zeros(xy.shape[0], dtype=bool)
        cut[nxt[np.hypot(*(xy[nxt] - xy).T) < gap]] = True
        back = (
            (np.einsum("ij,ij->i", xy[nxt] - xy, xy[n2] - xy[nxt]) < 0)
            & (np.einsum("ij,ij->i", normal, normal[nxt]) > COS30)
            & (np.einsum("ij,ij->i", normal[nxt], normal[n2]) > COS30)
        )
        cut[nxt[back]] = True
        cut |= _detours(loops, gap)
        # A chord crossing one a few chords ahead: the vertices between are twisted. All
        # offsets o = 2 .. _UNTANGLE at once: steps[o - 1] is the vertex o ahead, and the
        # vertex k + 1 ahead is between for every crossing at an offset o > k.
        steps = np.empty((_UNTANGLE + 1, nxt.size), dtype=nxt.dtype)
        steps[0] = nxt
        for o in range(1, _UNTANGLE + 1):
            steps[o] = nxt[steps[o - 1]]
        n = nxt.size
        # (Only chords whose bounding boxes overlap can cross: the few tested exactly.)
        x, y = xy[:, 0], xy[:, 1]
        x_lo, x_hi = np.minimum(x, x[nxt]), np.maximum(x, x[nxt])
        y_lo, y_hi = np.minimum(y, y[nxt]), np.maximum(y, y[nxt])
        ahead = steps[1:_UNTANGLE]  # (o - 2, i): the chord o ahead of chord i
        overlap = (x_lo[ahead] <= x_hi) & (x_lo <= x_hi[ahead])
        overlap &= (y_lo[ahead] <= y_hi) & (y_lo <= y_hi[ahead])
        pair = np.flatnonzero(overlap)
        i, j = pair % n, ahead.reshape(-1)[pair]
        crossing = np.zeros((_UNTANGLE - 1, n), dtype=bool)  # row o - 2
        crossing.reshape(-1)[pair] = segments_cross(xy[i], xy[nxt[i]], xy[j], xy[nxt[j]])
        beyond = np.logical_or.accumulate(crossing[::-1], axis=0)[::-1]  # any offset >= o
        between = beyond[np.maximum(np.arange(_UNTANGLE) - 1, 0)]  # (k, n): any o > k
        cut[steps[:_UNTANGLE][between]] = True
        if not cut.any():
            break
        loops = loops.select(~cut)
    if loops.loop.size == 0:
        return loops
    nxt = loops.next
    x, y = loops.xy[:, 0], loops.xy[:, 1]
    area = np.bincount(loops.loop, x * y[nxt] - x[nxt] * y, minlength=loops.loop.max() + 1)
    count = np.bincount(loops.loop, minlength=area.size)
    keep = (count >= 3) & (np.abs(area) > gap * gap)
    return loops.select(keep[loops.loop])


_COVER_PAIRS = 1 << 22  # (vertex, chord) pairs `drop_covered` tests at once, about


def drop_covered(loops: Loops, max_area: float) -> Loops:
    """Drop the small loops that lie inside what the other loops bound already.

    Where a part of the result narrows below a cell (the tip of a thin spike), marching
    squares can cut it off as a loop of its own; refinement then recovers the true corner of
    the main loop, whose tip comes to cover the piece cut off. Such a piece is an island
    inside an island (or a hole outside every island): the winding number of its inside
    with respect to the other loops is 1 or more for an island (0 or less for a hole),
    where a piece that belongs would have 0 (1). A loop of area at most ``max_area`` goes
    when any of its points halfway between its vertex mean and its vertices is so covered
    (points inside it: such a piece is a sliver of a few vertices, some of them on the
    other loop, found from both). Loops of a valid result never overlap, so a piece that
    overlaps in part goes too (what it held outside the other loop is smaller than it).
    """
    if loops.loop.size == 0:
        return loops
    nxt = loops.next
    x, y = loops.xy[:, 0], loops.xy[:, 1]
    n_loops = int(loops.loop[-1]) + 1
    area2 = np.bincount(loops.loop, x * y[nxt] - x[nxt] * y, minlength=n_loops)
    count = np.bincount(loops.loop, minlength=n_loops)
    if (count > 0).sum() < 2:
        return loops
    small = (count > 0) & (np.abs(area2) <= 2 * max_area)
    test = np.flatnonzero(small[loops.loop])
    if test.size == 0:
        return loops
    mean = (
        np.stack(
            [np.bincount(loops.loop, x, n_loops), np.bincount(loops.loop, y, n_loops)], axis=-1
        )
        / np.maximum(count, 1)[:, None]
    )
    inner = (loops.xy[test] + mean[loops.loop[test]]) / 2
    # Winding numbers by signed crossings of the ray toward +x (Haines's half-open rule).
    x0, y0, x1, y1 = x, y, x[nxt], y[nxt]
    dy = np.where(y1 != y0, y1 - y0, 1.0)
    winding = np.zeros(test.size, dtype=np.int64)
    step = max(1, _COVER_PAIRS // x.size)
    for start in range(0, test.size, step):  # (chunks of vertices: a few, for big inputs)
        t = test[start : start + step]
        px, py = inner[start : start + step, :1], inner[start : start + step, 1:]
        up = (y0 <= py) & (y1 > py)
        down = (y1 <= py) & (y0 > py)
        right = x0 + (py - y0) * (x1 - x0) / dy > px
        other = loops.loop[None, :] != loops.loop[t, None]
        winding[start : start + step] = ((up & right & other).sum(axis=1)) - (
            (down & right & other).sum(axis=1)
        )
    island = area2[loops.loop[test]] > 0
    covered = np.where(island, winding >= 1, winding <= 0)
    votes = np.bincount(loops.loop[test], covered, minlength=n_loops)
    drop = small & (votes > 0)
    if not drop.any():
        return loops
    return loops.select(~drop[loops.loop])


def _detours(loops: Loops, gap: float) -> np.ndarray:
    """Vertices on the shorter way between two visits of a loop to the same point."""
    n = loops.loop.size
    cut = np.zeros(n, dtype=bool)
    if n == 0:
        return cut
    first = np.flatnonzero(np.diff(loops.loop, prepend=-1) != 0)
    runs = np.diff(np.append(first, n))
    start, size = np.repeat(first, runs), np.repeat(runs, runs)
    for shift in (0.0, 0.5):  # two staggered bucketings catch pairs across bucket borders
        key = np.floor(loops.xy / (4 * gap) + shift).astype(np.int64)
        order = np.lexsort((key[:, 1], key[:, 0], loops.loop))
        a, b = order[:-1], order[1:]
        same = (
            (loops.loop[a] == loops.loop[b])
            & (key[a, 0] == key[b, 0])
            & (key[a, 1] == key[b, 1])
            & (np.hypot(*(loops.xy[a] - loops.xy[b]).T) < gap)
        )
        i, j = np.minimum(a[same], b[same]), np.maximum(a[same], b[same])
        for p, q in zip(i.tolist(), j.tolist(), strict=True):  # a handful at most
            if q - p <= size[p] - (q - p):
                cut[p + 1 : q + 1] = True
            else:
                cut[q + 1 : start[p] + size[p]] = True
                cut[start[p] : p + 1] = True
    return cut


def simplify(xy: np.ndarray, offsets: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Douglas-Peucker on closed loops, all loops at once.

    Each loop is split at its first vertex and the vertex farthest from it; every span
    whose farthest interior vertex (from the span's chord) is beyond ``tol`` is split there,
    round after round, and the other interior vertices are dropped. Loops left with fewer
    than three vertices (slivers thinner than ``2 tol``) are dropped.

    Parameters
    ----------
    xy : (n, 2) float
        Vertices, loop after loop (first vertex not repeated).
    offsets : (n_loops + 1,) int
    tol : float
        Largest distance from a dropped vertex to the simplified loop.

    Returns
    -------
    xy : (m, 2) float
    offsets : (k + 1,) int
    """
    n = xy.shape[0]
    sizes = np.diff(offsets)
    real = np.flatnonzero(sizes > 0)
    first, end = offsets[:-1][real], offsets[1:][real]
    loop = np.repeat(np.arange(real.size), sizes[real])
    d0 = np.hypot(*(xy - xy[first[loop]]).T)
    best = np.full(real.size, -1.0)
    np.maximum.at(best, loop, d0)
    far = np.full(real.size, n)
    np.minimum.at(far, loop, np.where(d0 == best[loop], np.arange(n), n))
    keep = np.zeros(n, dtype=bool)
    keep[first] = keep[far] = True
    # Spans (s, e) of loop lp in global indices; e == end[lp] stands for the loop's first
    # vertex again.
    s = np.concatenate([first, far])
    e = np.concatenate([far, end])
    lp = np.concatenate([np.arange(real.size), np.arange(real.size)])
    while True:
        inner = e - s - 1
        live = inner > 0
        s, e, lp, inner = s[live], e[live], lp[live], inner[live]
        if s.size == 0:
            break
        span = np.repeat(np.arange(s.size), inner)
        idx = np.arange(span.size) - np.repeat(np.cumsum(inner) - inner, inner) + s[span] + 1
        stop = np.where(e == end[lp], first[lp], e)
        dist, _ = point_segment(xy[idx], xy[s][span], xy[stop][span])
        top = np.full(s.size, -1.0)
        np.maximum.at(top, span, dist)
        pick = np.full(s.size, n)
        np.minimum.at(pick, span, np.where(dist == top[span], idx, n))
        split = top > tol
        keep[pick[split]] = True
        s, e, lp = (
            np.concatenate([s[split], pick[split]]),
            np.concatenate([pick[split], e[split]]),
            np.concatenate([lp[split], lp[split]]),
        )
    counts = np.bincount(loop[keep], minlength=real.size)
    ok = counts >= 3
    keep &= ok[loop]
    return xy[keep], np.concatenate([[0], np.cumsum(counts[ok])])
