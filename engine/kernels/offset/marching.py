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

import math
from collections.abc import Sequence

import numpy as np

from .band import Field, band_cells, store_lookup, thin_parts
from .contour import InconsistentField, split_loops, trace_crossings
from .distance import RowParity, SegmentTree, WorkLimit
from .loops import simplify as simplify_loops
from .refine import exact_loops
from .refine import smooth as smooth_loops

__all__ = [
    "DEFAULT_MAX_CELLS",
    "OffsetTraceError",
    "WorkLimit",
    "check_options",
    "default_cell",
    "grid_cells",
    "offset_polylines",
    "polyline_segments",
]


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


def polyline_segments(
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


def check_options(distance: float, smooth: int, simplify: float) -> float:
    """``distance`` as a float, after checking it and the smoothing and simplification."""
    distance = float(distance)
    if not np.isfinite(distance) or distance == 0:
        raise ValueError(f"distance must be a nonzero finite number, got {distance}")
    if isinstance(smooth, bool) or int(smooth) != smooth or smooth < 0:
        raise ValueError(f"smooth must be a whole number of passes >= 0, got {smooth}")
    if not (np.isfinite(simplify) and simplify >= 0):
        raise ValueError(f"simplify must be a tolerance >= 0, got {simplify}")
    return distance


def grid_cells(lo: np.ndarray, hi: np.ndarray, distance: float, cell: float) -> int:
    """How many cells the offset grid has, for input bounds ``lo, hi`` (each (2,)).

    The grid covers the input grown by ``|distance|`` plus two cells, rounded up to whole
    coarse cells. (Only a band of it is ever sampled; this is the size checked against
    ``max_cells``.)
    """
    # (In Python floats: numpy's calls on two numbers cost more than the arithmetic.)
    margin = abs(float(distance)) + 2 * float(cell)
    (x0, y0), (x1, y1) = np.asarray(lo, float).tolist(), np.asarray(hi, float).tolist()
    sx, sy = (x1 - x0 + 2 * margin) / cell, (y1 - y0 + 2 * margin) / cell
    big = max(sx, sy)
    if not (math.isfinite(sx) and math.isfinite(sy)) or big > 2.0**31:
        return 2**62  # more than any budget (a cell tiny next to the input)
    step = 2 ** max(0, math.ceil(math.log2(max(big / _COARSE_CELLS, 1.0))))
    return math.ceil(sx / step) * step * math.ceil(sy / step) * step


def _trace(field: Field, ids, values, cells, ncx: int):
    """Marching squares on the band's samples (`contour.trace_crossings`)."""
    nx = ncx + 1
    distance = field.level
    radius = abs(distance)
    value = store_lookup(ids, values, checked=True)
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


def _upper_bounds(xy: np.ndarray, cr, ids, feet, ncx: int) -> np.ndarray:
    """Upper bounds of the traced vertices' distances: to the nearest input points of the
    two samples of each vertex's grid edge (inf where a sample's is unknown)."""
    foot = store_lookup(ids, feet)
    edge, vertical = cr.edge[cr.order], cr.vertical[cr.order]
    f0, f1 = foot(edge), foot(edge + np.where(vertical, ncx + 1, 1))
    upper = np.fmin(np.hypot(*(xy - f0).T), np.hypot(*(xy - f1).T))
    upper[np.isnan(upper)] = np.inf
    return upper


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
    a, b, seg_closed = polyline_segments(polylines, closed)
    distance = check_options(distance, smooth, simplify)
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
    # (The fine samples, the projections and the checks look no farther than this.)
    tree.index_reach(2 * abs(distance) + 2 * cell)
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
            field = Field(tree, parity, origin, cell, distance)
            ids, values, feet, cells = band_cells(field, ncx, ncy, levels)
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
        if not tiny and not thin_parts(field, ids, values, feet, cells, ncx):
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
        upper = _upper_bounds(xy, cr, ids, feet, ncx)
        loops = exact_loops(tree, xy, cr.offsets, radius, 1.5 * cell, tol / 2, distance < 0, upper)
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
