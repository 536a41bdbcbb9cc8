"""Robust offset of polylines: signed distance field on a grid, then marching squares.

The offset at distance ``d`` is the level set ``f = d`` of the signed distance ``f`` to the
input segments (negative inside the closed polylines by the even-odd rule). ``f`` is never
sampled on the whole grid: a coarse grid is evaluated first and only the cells that the
1-Lipschitz bound ``|f(x) - f(corner)| <= |x - corner|`` cannot rule out are split, level
after level, down to the final cell size -- a quadtree restricted to a band around the
contour, so the work grows with the length of the result, not with the grid area. Each
sample is the exact point-segment distance (`distance.SegmentTree`), signed by the
crossing-number test on its grid row (`distance.RowParity`). Saddle cells are decided by
the exact value at their centre.

Where a part of the result is thinner than a cell (a strip between samples, an island no
sample sees, a loop of a few vertices) the grid is halved, up to four times.

The contour is traced by `contour.trace_crossings` on the sparse samples, then made exact
(`refine`): every vertex is moved onto the level set along the gradient of its nearest
feature (for a distance field that Newton step is exact), and chords that stray from the
level set by more than half the tolerance get exact points inserted -- the corner where
two features' offsets meet (Kobbelt, Botsch, Schwanecke & Seidel, "Feature sensitive
surface extraction from volume data", SIGGRAPH 2001), or a projected chord point. The
result's error is then set by that tolerance, not by the cell: measured at 0.01-0.05 %
of the extent for the default tolerance of 0.1 %.

Known limits: islands or strips of the result thinner than the finest cell tried (1/16 of
the default) can still be missed or cut; near-degenerate cusps converge slowly.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .contour import InconsistentField, split_loops, trace_crossings, unique_ids
from .distance import RowParity, SegmentTree, WorkLimit
from .loops import simplify as simplify_loops
from .refine import exact_loops
from .refine import smooth as smooth_loops

__all__ = ["OffsetTraceError", "WorkLimit", "default_cell", "grid_cells", "offset_polylines"]


class OffsetTraceError(ValueError):
    """The sampled distance field could not be traced into closed loops (a defect of the
    kernel on this input, not a bad argument): raised only after shifted grids failed too."""


DEFAULT_MAX_CELLS = 2**27
_COARSE_CELLS = 32  # cells per side of the first, full level of the quadtree
_TOLERANCE = 1e-3  # default error, as a fraction of the input's extent
_MAX_HALVINGS = 4  # finer grids tried when a part of the result is thinner than a cell
_MIN_LOOP = 8  # a traced loop with fewer vertices asks for a finer grid
# Grid shifts (fractions of a cell) tried when tracing meets inconsistent samples: a sample
# a rounding error from the level on one grid is well clear of it on the next.
_SHIFTS = (0.0, 0.381966, 0.618034 + 0.13)


def default_cell(extent: float, distance: float, tolerance: float = 1e-3) -> float:
    """The default grid cell for an offset of ``distance`` of an input of size ``extent``.

    Plain marching squares with linear interpolation errs by the chord sag between
    neighbouring vertices, second order in the cell: for arcs of radius ``R >= |d|`` and
    chords of at most ``sqrt(2) h``, ``h**2 / (4 R)`` (measured: ``bench/offset_accuracy.py``).
    Here vertices are made exact and chords refined to the tolerance, so the cell only has
    to resolve the shape: ``h = 2 sqrt(|d| tol)`` already puts the raw sag near the
    tolerance (little left to refine), and ``h <= |d| / 2`` keeps every part of the region
    on the input's side (at least ``2 |d|`` thick) four cells wide.

    Parameters
    ----------
    extent : float
        Largest side of the input's bounding box (if 0, ``2 |distance|`` is used).
    distance : float
        Offset distance, nonzero.
    tolerance : float
        Error target as a fraction of ``extent``.

    Returns
    -------
    float
    """
    d = abs(distance)
    scale = extent if extent > 0 else 2 * d
    return float(min(d / 2, 2 * np.sqrt(d * tolerance * scale)))


def _segments(
    polylines: Sequence[np.ndarray], closed: Sequence[bool]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Concatenated segments ``a -> b`` and whether each belongs to a closed polyline."""
    if len(polylines) == 0:
        raise ValueError("offset needs at least one polyline, got none")
    if len(closed) != len(polylines):
        raise ValueError(
            f"closed must give one flag per polyline: {len(polylines)} polylines, "
            f"{len(closed)} flags"
        )
    a, b, c = [], [], []
    for k, (pts, is_closed) in enumerate(zip(polylines, closed, strict=True)):
        p = np.asarray(pts, dtype=float)
        if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] == 0:
            raise ValueError(f"polyline {k} must be an (n, 2) array with n >= 1, got {p.shape}")
        if not np.isfinite(p).all():
            raise ValueError(f"polyline {k} has NaN or infinite coordinates")
        if p.shape[0] == 1:
            p = np.concatenate([p, p])
        if is_closed:
            p = np.concatenate([p, p[:1]])
        a.append(p[:-1])
        b.append(p[1:])
        c.append(np.full(p.shape[0] - 1, bool(is_closed)))
    return np.concatenate(a), np.concatenate(b), np.concatenate(c)


class _Field:
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


def _store_lookup(ids: np.ndarray, values: np.ndarray, checked: bool = False):
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


def _band_cells(field: _Field, ncx: int, ncy: int, levels: int):
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
        value = _store_lookup(pid, values)
        foot = _store_lookup(pid, feet)
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


def grid_cells(lo: np.ndarray, hi: np.ndarray, distance: float, cell: float) -> int:
    """How many cells the offset grid has, for input bounds ``lo, hi`` (each (2,)).

    The grid covers the input grown by ``|distance|`` plus two cells, rounded up to whole
    coarse cells. (Only a band of it is ever sampled; this is the size checked against
    ``max_cells``.)
    """
    margin = abs(distance) + 2 * cell
    size = (np.asarray(hi, float) - np.asarray(lo, float) + 2 * margin) / cell
    if not np.all(np.isfinite(size)) or size.max() > 2.0**31:
        return 2**62  # more than any budget (a cell tiny next to the input)
    levels = max(0, int(np.ceil(np.log2(max(size.max() / _COARSE_CELLS, 1.0)))))
    step = 2**levels
    ncx, ncy = (np.ceil(size / step) * step).tolist()
    return int(ncx * ncy)


def _trace(field: _Field, ids, values, cells, ncx: int):
    """Marching squares on the band's samples (`contour.trace_crossings`)."""
    nx = ncx + 1
    distance = field.level
    radius = abs(distance)
    value = _store_lookup(ids, values, checked=True)
    c00, c01, c10 = value(cells), value(cells + 1), value(cells + nx)
    in00, in01, in10 = c00 < distance, c01 < distance, c10 < distance
    h_edges = np.sort(cells[in00 != in01])
    v_edges = np.sort(cells[in00 != in10])
    exact_centre = None
    if field.cell < 0.5 * radius:
        # A saddle cell's centre is within 1.5 cells of the level: on the level's side of
        # the input, so its exact (signed) value is the unsigned distance, signed like d.
        def exact_centre(c: np.ndarray) -> np.ndarray:
            i, j = np.divmod(c, nx)
            pts = field.origin + (np.stack([j, i], axis=-1) + 0.5) * field.cell
            near = field.tree.query(pts, radius - 2 * field.cell, radius + 2 * field.cell)
            return np.sign(distance) * near.dist

    return trace_crossings(h_edges, v_edges, nx, value, distance, True, exact_centre)


def _grid(lo: np.ndarray, hi: np.ndarray, distance: float, cell: float, max_cells: int, shift=0.0):
    """Origin, cells per side and quadtree depth of the grid covering the offset (its
    samples moved by ``shift`` cells along both axes; the margin covers that)."""
    margin = abs(distance) + 2 * cell
    size = (hi - lo + 2 * margin) / cell
    levels = max(0, int(np.ceil(np.log2(max(size.max() / _COARSE_CELLS, 1.0)))))
    step = 2**levels
    ncx, ncy = (np.ceil(size / step).astype(np.int64) * step).tolist()
    if ncx * ncy > max_cells:
        raise ValueError(
            f"the offset grid would need {ncx} x {ncy} = {ncx * ncy} cells, more than the "
            f"limit of {max_cells}; use a larger cell than {cell:.6g}"
        )
    origin = (lo + hi) / 2 - (np.array([ncx, ncy]) / 2 - shift) * cell
    return origin, ncx, ncy, levels


def _thin_parts(field: _Field, ids, values, feet, cells, ncx: int) -> bool:
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
    value = _store_lookup(ids, values)
    foot = _store_lookup(ids, feet)
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


def _hidden_island(field: _Field, cells, value, foot, near, nx: int) -> bool:
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


def _laplacian(xy: np.ndarray, offsets: np.ndarray, passes: int) -> np.ndarray:
    """Plain Laplacian smoothing of closed loops (used when the cell is too coarse to keep
    the vertices on the offset exactly)."""
    n = xy.shape[0]
    nxt = np.arange(1, n + 1)
    prev = np.arange(-1, n - 1)
    nonempty = np.diff(offsets) > 0
    nxt[offsets[1:][nonempty] - 1] = offsets[:-1][nonempty]
    prev[offsets[:-1][nonempty]] = offsets[1:][nonempty] - 1
    for _ in range(passes):
        xy = xy + 0.5 * ((xy[prev] + xy[nxt]) / 2 - xy)
    return xy


def offset_polylines(
    polylines: Sequence[np.ndarray],
    closed: Sequence[bool],
    distance: float,
    cell: float | None = None,
    smooth: int = 0,
    simplify: float = 0.0,
    max_cells: int = DEFAULT_MAX_CELLS,
) -> list[np.ndarray]:
    """Offset polylines by a signed distance: closed loops bounding ``{f < distance}``.

    Parameters
    ----------
    polylines : sequence of (n, 2) float
        Input polylines in the plane. A closed polyline's last vertex joins its first.
    closed : sequence of bool
        One flag per polyline. Closed polylines bound a region by the even-odd rule
        (nested ones make holes, self-intersections are fine); open ones bound nothing.
    distance : float
        Nonzero. Positive grows the region (and turns open polylines into bands of
        half-width ``distance``); negative shrinks the region.
    cell : float, optional
        Grid cell size. Default: `default_cell`. The cell sets which details of the
        result are found (parts thinner than about a cell trigger up to four halvings);
        the accuracy of what is found is 0.1 % of the input's extent whatever the cell
        (vertices are exact, chords refined), as long as the cell is below 0.9 |distance|.
    smooth : int
        Smoothing passes (Laplacian, each followed by a projection back onto the offset).
    simplify : float
        Douglas-Peucker tolerance (0: none).
    max_cells : int
        Largest grid (in cells) accepted; also the most (point, segment) pairs the
        distance queries may test together (their work: a messy input, many long segments
        criss-crossing, makes each sample near the result test many).

    Returns
    -------
    list of (m, 2) float
        Closed loops (first vertex not repeated): counter-clockwise around each island of
        the result, clockwise around its holes.

    Raises
    ------
    ValueError
        If there are no polylines, a polyline is not a finite (n, 2) array, distance is 0 or
        not finite, cell is not positive, or the grid would exceed ``max_cells``.
        `WorkLimit` (a ValueError) if the distance queries pass ``max_cells`` pairs;
        `OffsetTraceError` (a ValueError) if the outline cannot be traced.

    Example
    -------
    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    >>> (loop,) = offset_polylines([square], [True], 0.25)
    >>> bool(np.isclose(np.abs(loop).max(), 1.25, atol=1e-3))
    True
    """
    a, b, seg_closed = _segments(polylines, closed)
    distance = float(distance)
    if not np.isfinite(distance) or distance == 0:
        raise ValueError(f"distance must be a nonzero finite number, got {distance}")
    if isinstance(smooth, bool) or int(smooth) != smooth or smooth < 0:
        raise ValueError(f"smooth must be a whole number of passes >= 0, got {smooth}")
    if not (np.isfinite(simplify) and simplify >= 0):
        raise ValueError(f"simplify must be a tolerance >= 0, got {simplify}")
    # (Per coordinate: numpy reduces an (n, 2) array along its long axis slowly.)
    lo = np.array([min(a[:, k].min(), b[:, k].min()) for k in range(2)])
    hi = np.array([max(a[:, k].max(), b[:, k].max()) for k in range(2)])
    extent = float((hi - lo).max())
    if cell is None:
        cell = default_cell(extent, distance)
    cell = float(cell)
    if not (np.isfinite(cell) and cell > 0):
        raise ValueError(f"cell must be a positive finite number, got {cell}")

    # Every (point, segment) pair the distance queries test counts against the budget too.
    tree = SegmentTree(a, b, max_pairs=max_cells)
    if seg_closed.all():  # (a boolean row selection of every row costs a copy's time)
        closed_a, closed_b = a, b
    else:
        closed_a, closed_b = a[seg_closed], b[seg_closed]
    radius = abs(distance)
    for halvings in range(_MAX_HALVINGS + 1):
        for shift in _SHIFTS:
            origin, ncx, ncy, levels = _grid(lo, hi, distance, cell, max_cells, shift)
            parity = (
                RowParity(closed_a, closed_b, origin, cell, ncy + 1, ncx + 1)
                if closed_a.shape[0]
                else None
            )
            field = _Field(tree, parity, origin, cell, distance)
            ids, values, feet, cells = _band_cells(field, ncx, ncy, levels)
            try:
                cr = _trace(field, ids, values, cells, ncx)
                break
            except InconsistentField as exc:
                failure = exc
        else:
            i, j = np.divmod(failure.edges[0], ncx + 1)
            x, y = (origin + np.array([j, i]) * cell).tolist()
            raise OffsetTraceError(
                f"the offset could not trace its outline near ({x:.6g}, {y:.6g}): {failure} "
                f"on {len(_SHIFTS)} shifted grids of cell {cell:.6g}. This is a defect of the "
                "offset on this input (please report it with the curves); a slightly "
                "different cell usually avoids it"
            ) from None
        # A part of the result thinner than a cell can pass between samples and be cut or
        # missed, and a loop of a few vertices is too coarse to refine: then sample twice
        # as finely (as far as the budget allows).
        if halvings == _MAX_HALVINGS:
            break
        tiny = (np.diff(cr.offsets) < _MIN_LOOP).any()
        if not tiny and not _thin_parts(field, ids, values, feet, cells, ncx):
            break
        try:
            _grid(lo, hi, distance, cell / 2, max_cells)
        except ValueError:
            break
        cell /= 2
    xy = origin + np.stack([cr.col, cr.row], axis=-1)[cr.order] * cell
    if smooth * xy.shape[0] > max_cells:  # each pass moves every vertex: budget the passes
        raise ValueError(
            f"smoothing: {smooth} passes over {xy.shape[0]:,} vertices would make "
            f"{smooth * xy.shape[0]:,} vertex moves, over the limit of {max_cells:,}"
        )
    if cell < 0.9 * radius and xy.shape[0]:
        # Every point within 0.9 |d| of the level lies on the level's side of the input, so
        # the unsigned distance alone can make the loops exact.
        tol = _TOLERANCE * (extent if extent > 0 else 2 * radius)
        loops = exact_loops(tree, xy, cr.offsets, radius, 1.5 * cell, tol / 2, distance < 0)
        if smooth:
            loops = smooth_loops(tree, loops, radius, smooth)
        xy, offsets = loops.xy, loops.offsets()
    else:
        offsets = cr.offsets
        if smooth:
            xy = _laplacian(xy, offsets, smooth)
    if simplify > 0:
        xy, offsets = simplify_loops(xy, offsets, simplify)
    return split_loops(xy, offsets)
