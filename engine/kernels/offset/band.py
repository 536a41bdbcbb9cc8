"""The signed distance field on a band of grid samples, and the checks for parts of the
result thinner than a cell.

`band_cells` is the quadtree descent of `marching`: a coarse grid is evaluated, and only
the cells that the 1-Lipschitz bound ``|f(x) - f(corner)| <= |x - corner|`` cannot rule out
are split, level after level, down to the final cell -- so the work grows with the length
of the result, not with the grid area. `thin_parts` tells, from the samples' nearest input
points, whether some part of the result runs between samples (and the grid must be finer).
"""

from __future__ import annotations

import numpy as np

from .contour import InconsistentField, unique_ids

__all__ = ["Field", "band_cells", "store_lookup", "thin_parts"]


class Field:
    """The signed distance ``f`` at grid samples, exact where ``|f - level| <= band``."""

    def __init__(self, tree, parity, origin, cell, level):
        self.tree = tree
        self.parity = parity
        self.origin = origin
        self.cell = cell
        self.level = level

    def at(
        self, i: np.ndarray, j: np.ndarray, band: float, near: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Values at samples ``(i, j)``, and their nearest input points (NaN where the value
        is only certified, more than ``band`` from the level). ``near`` (m, 2), optional:
        known input points (NaN: none), whose distances seed the search's upper bound."""
        d = self.level
        if self.parity is None:
            inside = np.zeros(i.size, dtype=bool)
        else:
            inside = self.parity.inside(i, j)
        sign = np.where(inside, -1.0, 1.0)
        same = (sign > 0) == (d > 0)
        # Same side as the level: exact within |d| +- band. Other side: |f - d| = dist + |d|,
        # so only a distance below band - |d| can matter.
        lo = np.where(same, abs(d) - band, 0.0)
        hi = np.where(same, abs(d) + band, band - abs(d))
        f = np.zeros(i.size)
        feet = np.full((i.size, 2), np.nan)
        ask = np.flatnonzero(hi >= 0)
        if ask.size:
            pts = self.origin + np.stack([j[ask], i[ask]], axis=-1) * self.cell
            upper = None
            if near is not None:
                upper = np.hypot(*(pts - near[ask]).T)
                upper[np.isnan(upper)] = np.inf
            near = self.tree.query(pts, lo[ask], hi[ask], upper=upper)
            f[ask] = near.dist
            exact = ask[near.exact]
            seg = near.segment[near.exact]
            t = near.t[near.exact, None]
            feet[exact] = self.tree.a[seg] + t * (self.tree.b[seg] - self.tree.a[seg])
        return sign * f, feet


# Sample values are found through a dense table of positions while the grid has at most
# _DENSE samples per stored one, or at most _DENSE_MIN samples.
_DENSE = 32
_DENSE_MIN = 1 << 16


def store_lookup(ids: np.ndarray, values: np.ndarray, checked: bool = False):
    """``value(q)``: the ``values`` of sample ids ``q``, each one of the sorted ``ids``. A dense
    table of positions while the ids span a small grid or one the stored band fills well
    (two gathers a call), else a binary search (only a band of a big grid is stored).

    ``checked``: an id that is not stored raises `InconsistentField` (the tracer asks for
    the corners of every cell the contour enters; one the band left out means the samples
    disagree). Unchecked, only stored ids may be asked."""
    size = int(ids[-1]) + 1 if ids.size else 1
    if size <= max(_DENSE_MIN, _DENSE * ids.size):
        table = np.full(size, -1, dtype=np.int32) if checked else np.empty(size, dtype=np.int32)
        table[ids] = np.arange(ids.size, dtype=np.int32)

        def dense(q: np.ndarray) -> np.ndarray:
            if checked:
                inside = q < size
                pos = table[np.where(inside, q, 0)]
                missing = ~inside | (pos < 0)
                if missing.any():
                    raise InconsistentField(
                        "inconsistent field samples: a contour enters a cell outside the band",
                        q[missing],
                    )
                return values[pos]
            return values[table[q]]

        return dense

    def value(q: np.ndarray) -> np.ndarray:
        perm = np.argsort(q)
        pos = np.empty(q.size, dtype=np.int64)
        pos[perm] = np.searchsorted(ids, q[perm])
        pos = np.minimum(pos, ids.size - 1)
        if checked:
            missing = ids[pos] != q
            if missing.any():
                raise InconsistentField(
                    "inconsistent field samples: a contour enters a cell outside the band",
                    q[missing],
                )
        return values[pos]

    return value


def band_cells(field: Field, ncx: int, ncy: int, levels: int):
    """Quadtree descent: the finest cells that may hold the level set, with their samples.

    Returns
    -------
    ids : (m,) int64, sorted
        Flat ids ``i * (ncx + 1) + j`` of the evaluated fine samples.
    values : (m,) float
    feet : (m, 2) float
        Nearest input point of each sample (NaN where the value is only certified).
    cells : (k,) int64
        Flat ids of the lower-left samples of the fine cells that may hold the level set.
    """
    d = field.level
    step = 2**levels
    # Level `levels`: the whole coarse grid.
    ci, cj = np.mgrid[0 : ncy // step, 0 : ncx // step]
    ci, cj = ci.ravel(), cj.ravel()
    value = foot = gaps = None
    for lev in range(levels, -1, -1):
        step = 2**lev
        w = ncx // step + 1
        if lev == levels:
            pi, pj = np.mgrid[0 : ncy // step + 1, 0 : ncx // step + 1]
            pid = (pi * w + pj).ravel()
        else:
            # Children of the surviving parents, and their samples; a child goes unsampled
            # where the parent's corners already rule it out (`_children`).
            ci, cj = _children(ci, cj, gaps, step * field.cell)
            pid = unique_ids(
                (ci[:, None] + np.array([0, 0, 1, 1])) * w + cj[:, None] + np.array([0, 1, 0, 1])
            )
        pi, pj = np.divmod(pid, w)
        band = 1.5 * step * field.cell
        if lev == levels:
            values, feet = field.at(pi * step, pj * step, band)
        else:
            # Samples of the previous level were exact in a band twice as wide: reuse them.
            old = (pi % 2 == 0) & (pj % 2 == 0)
            values = np.empty(pid.size)
            feet = np.empty((pid.size, 2))
            before = (pi[old] // 2) * (w // 2 + 1) + pj[old] // 2
            values[old], feet[old] = value(before), foot(before)
            new = ~old
            # The nearest input point of the parent corner below-left of a new sample (a
            # corner of the parent cell it lies in, so sampled) bounds its distance.
            below = (pi[new] // 2) * (w // 2 + 1) + pj[new] // 2
            values[new], feet[new] = field.at(pi[new] * step, pj[new] * step, band, foot(below))
        value = store_lookup(pid, values)
        foot = store_lookup(pid, feet)
        corner = ci * w + cj
        corners = np.abs(
            np.stack([value(corner), value(corner + 1), value(corner + w), value(corner + w + 1)])
            - d
        )
        gap = corners.min(axis=0)
        # A cell can hold a point at the level only if a corner is within half a diagonal.
        keep = gap <= step * field.cell * _HALF_DIAGONAL
        # (Values outside the band are only certified beyond it: clamped there, the gaps
        # stay lower bounds for `_children`.)
        ci, cj, gaps = ci[keep], cj[keep], np.minimum(corners[:, keep], band)
    return pid, values, feet, ci * (ncx + 1) + cj


_HALF_DIAGONAL = np.sqrt(0.5) * (1 + 1e-9)  # a hair of slack against rounding
# For the 3 x 3 samples of a split cell (row-major, parent corners at 0, 2, 6, 8): which
# parent corner each child's corners are (in order 00, 01, 10, 11), and how far each of the
# 9 samples is from each parent corner, in child cells.
_CHILD_SAMPLES = np.array([[0, 1, 3, 4], [1, 2, 4, 5], [3, 4, 6, 7], [4, 5, 7, 8]])
_SAMPLE_TO_CORNER = np.linalg.norm(
    np.array(np.divmod(np.arange(9), 3)).T[:, None] - np.array([[0, 0], [0, 2], [2, 0], [2, 2]]),
    axis=2,
)  # (9 samples, 4 parent corners)


def _children(ci: np.ndarray, cj: np.ndarray, gaps: np.ndarray, h: float):
    """The four children of each cell ``(ci, cj)``, less those its corners rule out.

    ``gaps`` (4, m) holds lower bounds of ``|f - level|`` at each parent's corners 00, 01,
    10, 11. ``f`` being 1-Lipschitz, ``|f(y) - level| >= gap(c) - |y - c|`` at every sample
    ``y`` of the parent; a child whose four corners are all bounded above half its diagonal
    ``h`` would be dropped once sampled, so it is dropped now (the cells kept are the same,
    with fewer samples to evaluate).
    """
    # (Reductions over the short axes written out: (9, m) and (4, m) arrays, long rows.)
    corner_bound = gaps[:, None, :] - h * _SAMPLE_TO_CORNER.T[:, :, None]  # (4, 9, m)
    bound = np.maximum(
        np.maximum(corner_bound[0], corner_bound[1]), np.maximum(corner_bound[2], corner_bound[3])
    )  # (9, m)
    s = _CHILD_SAMPLES.T
    child_bound = np.minimum(
        np.minimum(bound[s[0]], bound[s[1]]), np.minimum(bound[s[2]], bound[s[3]])
    )
    keep = (child_bound <= h * _HALF_DIAGONAL).T  # (m, 4)
    ci = (2 * ci[:, None] + np.array([0, 0, 1, 1]))[keep]
    cj = (2 * cj[:, None] + np.array([0, 1, 0, 1]))[keep]
    return ci, cj


def thin_parts(field: Field, ids, values, feet, cells, ncx: int) -> bool:
    """Whether some part of the result is thinner than a cell and runs between samples.

    An edge whose two samples lie on the near side of the level (distance below ``|d|``)
    can still reach beyond it in between: the distance there is at most the distance to
    the nearer of the two samples' nearest input points, which is largest where the
    bisector of those points meets the edge. Where that bound passes ``|d|`` an exact query
    decides. A cell with two such edges has a strip of the far side running through it,
    which marching squares would cut; so does such an edge between two cells the contour
    crosses; such an edge between two cells the contour does not cross belongs to an island
    no sample sees. (One such edge between a crossed cell and an uncrossed one is the tip of
    a sharp corner, which refinement recovers.)
    """
    nx = ncx + 1
    radius = abs(field.level)
    value = store_lookup(ids, values)
    foot = store_lookup(ids, feet)
    near = (lambda f: f < field.level) if field.level > 0 else (lambda f: f > field.level)
    asked = []
    for step in (1, nx):  # bottom edges, then left edges, of every candidate cell
        f0, f1 = value(cells), value(cells + step)
        p0, p1 = foot(cells), foot(cells + step)
        ok = near(f0) & near(f1) & np.isfinite(p0).all(axis=1) & np.isfinite(p1).all(axis=1)
        # Far from the input on both ends (the edge does not cross it).
        ok &= (np.abs(f0) > 1.5 * field.cell) & (np.abs(f1) > 1.5 * field.cell)
        e, p0, p1 = cells[ok], p0[ok], p1[ok]
        i, j = np.divmod(e, nx)
        x0 = field.origin + np.stack([j, i], axis=-1) * field.cell
        along = np.array([1.0, 0.0]) if step == 1 else np.array([0.0, 1.0])
        # x0 + t along is as far from p0 as from p1.
        dp = p1 - p0
        den = (dp @ along) * field.cell
        num = (np.einsum("ij,ij->i", p1, p1) - np.einsum("ij,ij->i", p0, p0)) / 2
        num -= np.einsum("ij,ij->i", x0, dp)
        t = np.divide(num, den, out=np.full_like(num, -1.0), where=np.abs(den) > 0)
        x = x0 + t[:, None] * field.cell * along
        bound = np.hypot(*(x - p0).T)
        ask = np.flatnonzero((t > 0) & (t < 1) & (bound > radius))
        # A bottom edge also belongs to the cell below, a left edge to the cell left.
        asked.append((x[ask], e[ask], e[ask] - (nx if step == 1 else 1)))
    if _hidden_island(field, cells, value, foot, near, nx):
        return True
    x, own, other = (np.concatenate(v) for v in zip(*asked, strict=True))
    if x.shape[0] == 0:
        return False
    far = field.tree.query(x, radius, radius + field.cell).dist > radius  # (one query for both)
    if not far.any():
        return False
    owners = np.stack([own[far], other[far]])
    _, count = unique_ids(owners, return_counts=True)
    if (count >= 2).any():
        return True
    # An island thinner than a cell that no sample sees: its edge borders no crossed cell.
    corners = np.stack([value(cells), value(cells + 1), value(cells + nx), value(cells + nx + 1)])
    side = near(corners)
    crossed = np.sort(cells[side.any(axis=0) & ~side.all(axis=0)])
    if crossed.size == 0:
        seen = np.zeros(owners.shape, dtype=bool)
    else:  # (np.isin, by a search: far cheaper for these few ids)
        seen = crossed[np.minimum(np.searchsorted(crossed, owners), crossed.size - 1)] == owners
    # A far-side piece joining two crossed cells through an edge that marching squares
    # sees as uncrossed: a connection cut.
    return bool((~seen.any(axis=0)).any() or seen.all(axis=0).any())


def _hidden_island(field: Field, cells, value, foot, near, nx: int) -> bool:
    """Whether a cell whose four samples are all on the near side holds a far-side island.

    Inside such a cell the distance is at most the distance to the nearest of the four
    samples' nearest input points; the largest of that bound sits at the centre of a circle
    through three of them (a vertex of their Voronoi diagram). Where it passes ``|d|``, an
    exact query there decides.
    """
    radius = abs(field.level)
    corner = np.stack([cells, cells + 1, cells + nx + 1, cells + nx])
    f = value(corner.reshape(-1)).reshape(4, -1)
    p = foot(corner.reshape(-1)).reshape(4, -1, 2)
    ok = near(f).all(axis=0) & np.isfinite(p).all(axis=(0, 2))
    ok &= (np.abs(f) > 1.5 * field.cell).all(axis=0)
    cells, p = cells[ok], p[:, ok]
    if cells.size == 0:
        return False
    i, j = np.divmod(cells, nx)
    lo = field.origin + np.stack([j, i], axis=-1) * field.cell
    candidates = [lo + field.cell / 2]
    for a, b, c in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
        # Circumcentre of feet a, b, c.
        pa, pb, pc = p[a], p[b], p[c]
        bx, by = (pb - pa).T
        cx, cy = (pc - pa).T
        den = 2 * (bx * cy - by * cx)
        safe = np.abs(den) > 1e-300
        den = np.where(safe, den, 1.0)
        b2, c2 = bx * bx + by * by, cx * cx + cy * cy
        centre = pa + np.stack([cy * b2 - by * c2, bx * c2 - cx * b2], axis=-1) / den[:, None]
        candidates.append(np.where(safe[:, None], centre, lo + field.cell / 2))
    x = np.stack(candidates)  # (5, m, 2)
    inside = ((x >= lo) & (x <= lo + field.cell)).all(axis=2)
    bound = np.hypot(*(x[:, None] - p[None]).transpose(3, 0, 1, 2)).min(axis=1)
    ask = x[inside & (bound > radius)]
    if ask.size == 0:
        return False
    return bool((field.tree.query(ask, radius, radius + field.cell).dist > radius).any())
