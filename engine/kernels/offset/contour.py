"""Marching squares on a sampled scalar field, with the crossings linked into closed loops.

The contour is built from the grid edges whose end samples lie on different sides of the
level (Lorensen & Cline, "Marching cubes", SIGGRAPH 1987, in its 2-D form): one vertex per
crossed edge, placed by linear interpolation. Each crossing knows the cell the contour
enters through it; a 16-case table (plus the cell-centre value for the two saddle cases, the
"asymptotic"-free centre rule of Wyvill, McPheeters & Wyvill 1986) gives the edge it leaves
by, so every crossing gets one successor. The successors form a permutation whose cycles are
the loops; they are extracted with pointer jumping (Wyllie's list ranking, "The complexity
of parallel computations", 1979), vectorized, in ``O(n log L)`` for ``n`` crossings and
loops of at most ``L`` vertices. Nothing loops over cells or vertices in Python.

Loops run with the inside region on their left: counter-clockwise around islands of the
inside, clockwise around holes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Crossings",
    "InconsistentField",
    "marching_squares",
    "split_loops",
    "trace_crossings",
    "unique_ids",
]


class InconsistentField(ValueError):
    """Sampled values that no contour can follow: a contour enters a cell it cannot leave,
    or leaves it through an edge whose samples are on one side of the level.

    Attributes
    ----------
    edges : (k,) int64
        Flat ids of the samples where it happened (the cell's or the edge's first sample).
    """

    def __init__(self, message: str, edges: np.ndarray) -> None:
        super().__init__(message)
        self.edges = np.asarray(edges, dtype=np.int64)


# Cell corners counter-clockwise: 0 = (i, j) bottom-left, 1 = (i, j+1) bottom-right,
# 2 = (i+1, j+1) top-right, 3 = (i+1, j) top-left. Side s joins corner s to corner s+1:
# 0 bottom, 1 right, 2 top, 3 left. Crossing side s from inside corner s to outside corner
# s+1 enters the cell (the inside stays on the left).


def _exit_table() -> np.ndarray:
    """``table[case, entry_side, centre_inside]`` -> exit side (-1 where impossible)."""
    table = np.full((16, 4, 2), -1, dtype=np.int8)
    for case in range(16):
        inside = [(case >> c) & 1 for c in range(4)]
        entries = [s for s in range(4) if inside[s] and not inside[(s + 1) % 4]]
        exits = [s for s in range(4) if not inside[s] and inside[(s + 1) % 4]]
        for centre in (0, 1):
            for s in entries:
                if len(exits) == 1:
                    table[case, s, centre] = exits[0]
                else:  # saddle: cut off the corners that differ from the centre
                    corner = (s + 1) % 4  # the corner between side s and side s+1
                    table[case, s, centre] = (
                        (s + 1) % 4 if inside[corner] != centre else (s - 1) % 4
                    )
    return table


_EXIT = _exit_table()
# Exit side -> (row offset, column offset, is vertical edge) of the edge in the cell.
_SIDE_DI = np.array([0, 0, 1, 0])
_SIDE_DJ = np.array([0, 1, 0, 0])
_SIDE_VERTICAL = np.array([False, True, False, True])


@dataclass(frozen=True)
class Crossings:
    """Linked contour crossings of one field, in grid index units.

    Attributes
    ----------
    col, row : (n,) float
        Position of each crossing: column (x) and row (y) in grid index units.
    edge : (n,) int64
        Flat id ``i * nx + j`` of the crossed edge's first sample.
    vertical : (n,) bool
        True for an edge from ``(i, j)`` to ``(i + 1, j)``, False for ``(i, j)`` to
        ``(i, j + 1)``.
    order : (n,) int64
        Crossing indices loop after loop, each loop in walking order.
    offsets : (n_loops + 1,) int64
        Loop ``k`` is ``order[offsets[k]:offsets[k + 1]]``.
    """

    col: np.ndarray
    row: np.ndarray
    edge: np.ndarray
    vertical: np.ndarray
    order: np.ndarray
    offsets: np.ndarray


def trace_crossings(
    h_edges: np.ndarray,
    v_edges: np.ndarray,
    nx: int,
    value: Callable[[np.ndarray], np.ndarray],
    level: float,
    below: bool,
    centre: Callable[[np.ndarray], np.ndarray] | None = None,
) -> Crossings:
    """Link the crossed edges of a field into closed loops.

    Works the same on a dense array and on a sparse set of samples: the field is only read
    through ``value``, at the ends of crossed edges and at the corners of crossed cells.

    Parameters
    ----------
    h_edges : (nh,) int64, sorted, unique
        Flat ids ``i * nx + j`` of the crossed edges from sample ``(i, j)`` to ``(i, j+1)``.
    v_edges : (nv,) int64, sorted, unique
        Flat ids of the crossed edges from ``(i, j)`` to ``(i + 1, j)``.
    nx : int
        Samples per row.
    value : callable
        ``value(flat_ids) -> (m,) float``, the field at those samples.
    level : float
        Contour level.
    below : bool
        The inside is ``field < level`` if True, ``field > level`` if False.
    centre : callable, optional
        ``centre(cell_ids) -> (m,) float``, the field at the centres of the given cells
        (flat ids of their lower-left samples); asked only for saddle cells. Default: the
        mean of the four corners (the bilinear interpolant's value there).

    Returns
    -------
    Crossings
        Positions and loops; loops keep the inside on their left.

    Notes
    -----
    Every cell the contour enters must have all four corner values available and every
    crossed edge of it listed; the caller guarantees the field is outside along its border.
    """
    edge = np.concatenate([h_edges, v_edges]).astype(np.int64)
    vertical = np.zeros(edge.size, dtype=bool)
    vertical[h_edges.size :] = True
    n = edge.size
    if n == 0:
        empty = np.zeros(0)
        return Crossings(empty, empty, edge, vertical, np.zeros(0, np.int64), np.zeros(1, np.int64))
    i, j = np.divmod(edge, nx)
    far = edge + np.where(vertical, nx, 1)
    f0 = value(edge)
    f1 = value(far)
    if not (np.isfinite(f0).all() and np.isfinite(f1).all()):
        raise ValueError("the field must be finite; got NaN or infinity next to the contour")
    t = (level - f0) / (f1 - f0)
    col = j + np.where(vertical, 0.0, t)
    row = i + np.where(vertical, t, 0.0)

    # Which way the contour crosses: with the inside on the left, a horizontal edge whose
    # first (left) sample is inside is crossed upward, a vertical edge whose first (lower)
    # sample is inside is crossed toward -x.
    first_in = (f0 < level) if below else (f0 > level)
    ci = np.where(vertical, i, np.where(first_in, i, i - 1))
    cj = np.where(vertical, np.where(first_in, j - 1, j), j)
    entry = np.where(vertical, np.where(first_in, 1, 3), np.where(first_in, 0, 2))

    corner = ci * nx + cj
    c = np.stack([corner, corner + 1, corner + nx + 1, corner + nx])
    vals = value(c.reshape(-1)).reshape(4, n)
    inside = (vals < level) if below else (vals > level)
    bits = inside.astype(np.int8)
    case = bits[0] | (bits[1] << 1) | (bits[2] << 2) | (bits[3] << 3)
    mid = vals.mean(axis=0)
    if centre is not None:
        saddle = np.flatnonzero((case == 5) | (case == 10))
        if saddle.size:
            # Each saddle cell is entered twice; ask once per cell.
            cells, inverse = unique_ids(corner[saddle], return_inverse=True)
            mid[saddle] = centre(cells)[inverse]
    centre_in = (mid < level) if below else (mid > level)
    exit_side = _EXIT[case, entry, centre_in.astype(np.int8)].astype(np.int64)
    if (exit_side < 0).any():  # cannot happen with consistent values; never index with -1
        raise InconsistentField(
            "inconsistent field samples: a contour enters a cell it cannot leave",
            corner[exit_side < 0],
        )

    exit_edge = (ci + _SIDE_DI[exit_side]) * nx + cj + _SIDE_DJ[exit_side]
    exit_vertical = _SIDE_VERTICAL[exit_side]
    succ = np.empty(n, dtype=np.int64)
    succ[~exit_vertical] = _lookup(h_edges, exit_edge[~exit_vertical])
    succ[exit_vertical] = h_edges.size + _lookup(v_edges, exit_edge[exit_vertical])
    order, offsets = _cycles(succ)
    return Crossings(col, row, edge, vertical, order, offsets)


def unique_ids(
    ids: np.ndarray, return_inverse: bool = False, return_counts: bool = False
) -> np.ndarray | tuple[np.ndarray, ...]:
    """Sorted distinct values of an integer array, by one sort: ``np.unique`` for ids.

    Gives what ``np.unique`` gives (the sorted values, and with the flags the inverse and
    the counts), but numpy 2 hashes integers in ``np.unique``, which on these arrays of
    grid ids is ten to twenty times slower than sorting them.

    Parameters
    ----------
    ids : (n,) int
    return_inverse, return_counts : bool

    Returns
    -------
    values : (k,) int
    inverse : (n,) int64, optional
        ``values[inverse] == ids``.
    counts : (k,) int64, optional
    """
    ids = np.asarray(ids).reshape(-1)
    if not (return_inverse or return_counts):
        s = np.sort(ids)
        first = np.ones(s.size, dtype=bool)
        np.not_equal(s[1:], s[:-1], out=first[1:])
        return s[first]
    order = np.argsort(ids, kind="stable")
    s = ids[order]
    first = np.ones(s.size, dtype=bool)
    np.not_equal(s[1:], s[:-1], out=first[1:])
    out = [s[first]]
    if return_inverse:
        inverse = np.empty(ids.size, dtype=np.int64)
        inverse[order] = np.cumsum(first) - 1
        out.append(inverse)
    if return_counts:
        out.append(np.diff(np.append(np.flatnonzero(first), ids.size)))
    return tuple(out)


def _lookup(sorted_ids: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """Positions of ``ids`` in ``sorted_ids``; every id must be present."""
    if ids.size == 0:
        return np.zeros(0, dtype=np.int64)
    perm = np.argsort(ids)  # sorted queries make searchsorted cache-friendly
    pos = np.empty(ids.size, dtype=np.int64)
    pos[perm] = np.searchsorted(sorted_ids, ids[perm])
    ok = pos < sorted_ids.size
    ok[ok] = sorted_ids[pos[ok]] == ids[ok]
    if not ok.all():
        raise InconsistentField(
            "inconsistent field samples: a contour leaves through an uncrossed edge", ids[~ok]
        )
    return pos


def _cycles(succ: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cycles of the permutation ``succ`` by pointer jumping.

    After round ``r`` each element knows the smallest index among its next ``2**r``
    successors and how many steps ahead it lies; a round that changes nothing proves every
    cycle is covered. Cycles come out ordered by their smallest element, each starting there.

    Returns
    -------
    order : (n,) int64
        Elements cycle after cycle, in successor order.
    offsets : (n_cycles + 1,) int64
    """
    n = succ.size
    label = np.arange(n)
    ahead = np.zeros(n, dtype=np.int64)
    nxt = succ.copy()
    width = 1
    while True:
        nl = label[nxt]
        better = nl < label
        if not better.any():
            break
        ahead = np.where(better, ahead[nxt] + width, ahead)
        label = np.where(better, nl, label)
        nxt = nxt[nxt]
        width *= 2
    sizes = np.bincount(label, minlength=n)
    heads = np.flatnonzero(sizes)
    start = np.zeros(n, dtype=np.int64)
    start[heads] = np.cumsum(sizes[heads]) - sizes[heads]
    length = sizes[label]
    position = (length - ahead % length) % length
    order = np.empty(n, dtype=np.int64)
    order[start[label] + position] = np.arange(n)
    offsets = np.concatenate([[0], np.cumsum(sizes[heads])])
    return order, offsets


def split_loops(points: np.ndarray, offsets: np.ndarray, min_vertices: int = 3) -> list[np.ndarray]:
    """Split concatenated loops, dropping repeated consecutive vertices and tiny loops.

    Parameters
    ----------
    points : (n, 2) float
        Vertices loop after loop.
    offsets : (n_loops + 1,) int
        Loop ``k`` is ``points[offsets[k]:offsets[k + 1]]``.
    min_vertices : int
        Loops with fewer distinct vertices are dropped (they enclose no area).

    Returns
    -------
    list of (m, 2) float
        Each loop once round, its first vertex not repeated at the end.
    """
    n = points.shape[0]
    if n == 0:
        return []
    loop = np.repeat(np.arange(offsets.size - 1), np.diff(offsets))
    prev = np.arange(n) - 1
    first = offsets[:-1][np.diff(offsets) > 0]
    prev[first] = offsets[1:][np.diff(offsets) > 0] - 1
    keep = (points != points[prev]).any(axis=1)
    counts = np.bincount(loop[keep], minlength=offsets.size - 1)
    kept = points[keep]
    bounds = np.concatenate([[0], np.cumsum(counts)])
    return [
        kept[bounds[k] : bounds[k + 1]] for k in range(counts.size) if counts[k] >= min_vertices
    ]


def marching_squares(
    field: np.ndarray,
    level: float,
    origin: tuple[float, float] | np.ndarray = (0.0, 0.0),
    cell: float = 1.0,
    *,
    below: bool = False,
) -> list[np.ndarray]:
    """Closed contour loops of a sampled 2-D field.

    Parameters
    ----------
    field : (ny, nx) float
        Samples; ``field[i, j]`` lies at ``(origin[0] + j * cell, origin[1] + i * cell)``.
    level : float
        Contour level.
    origin : (2,) float
        Position of ``field[0, 0]``.
    cell : float
        Sample spacing, > 0.
    below : bool
        If False (default) the inside is ``field > level``, else ``field < level``.

    Returns
    -------
    list of (m, 2) float
        Closed loops (first vertex not repeated), each with the inside on its left:
        counter-clockwise around islands, clockwise around holes. A region that reaches the
        border of the field is closed along the border (the field is taken as outside beyond
        it). Vertices are placed by linear interpolation on the grid edges; saddle cells are
        resolved by the value at the cell centre (the mean of the four corners).

    Raises
    ------
    ValueError
        If the field is not a finite 2-D array of at least 2 x 2 samples, or the level,
        origin or cell are not finite (cell > 0).

    Example
    -------
    >>> y, x = np.mgrid[-2:3, -2:3].astype(float)
    >>> loops = marching_squares(1.5 - np.hypot(x, y), 0.0, origin=(-2, -2))
    >>> len(loops), loops[0].shape
    (1, (8, 2))
    """
    field = np.asarray(field, dtype=float)
    if field.ndim != 2 or min(field.shape) < 2:
        raise ValueError(f"field must be a 2-D array of at least 2 x 2 samples, got {field.shape}")
    origin = np.asarray(origin, dtype=float)
    if origin.shape != (2,) or not np.isfinite(origin).all():
        raise ValueError(f"origin must be two finite numbers, got {origin.tolist()}")
    if not (np.isfinite(cell) and cell > 0):
        raise ValueError(f"cell must be a positive finite number, got {cell}")
    if not np.isfinite(level):
        raise ValueError(f"level must be a finite number, got {level}")
    if np.isnan(field.min()):
        raise ValueError("field contains NaN")

    inside = (field < level) if below else (field > level)
    pad = 0
    if inside[0].any() or inside[-1].any() or inside[:, 0].any() or inside[:, -1].any():
        # A ring of samples exactly at the level is outside and puts the closing vertices
        # one sample beyond the border; they are clamped back onto it below.
        field = np.pad(field, 1, constant_values=level)
        inside = np.pad(inside, 1, constant_values=False)
        pad = 1
    ny, nx = field.shape
    flat = inside.reshape(-1)
    h = np.flatnonzero(flat[1:] ^ flat[:-1])
    h = h[h % nx != nx - 1]
    v = np.flatnonzero(flat[nx:] ^ flat[:-nx])
    values = field.reshape(-1)
    cr = trace_crossings(h, v, nx, values.take, float(level), below)
    col, row = cr.col[cr.order] - pad, cr.row[cr.order] - pad
    if pad:
        col = np.clip(col, 0.0, nx - 3.0)
        row = np.clip(row, 0.0, ny - 3.0)
    pts = np.stack([origin[0] + col * cell, origin[1] + row * cell], axis=-1)
    return split_loops(pts, cr.offsets)
