"""Adaptive meshing of the zero set of a distance field: octree culling, marching tetrahedra.

The finest grid has cells of size ``cell``; only the cells the surface can reach are ever
made. Starting from a coarse grid of blocks (``2^levels`` finest cells a side), each level
keeps the cells whose centre value is within the field's Lipschitz reach of zero
(``|f(c)| <= L * half-diagonal``: a cell farther than that from the surface cannot hold
any of it) and splits them into eight, down to the finest level. This is the offset's
quadtree in one more dimension, and it costs in the surface's area: halving the cell
makes about four times the cells, not eight.

The finest kept cells are polygonized by marching tetrahedra on the Freudenthal (Kuhn)
split of each cube into six tetrahedra round its main diagonal. The split is the same in
every cube, so neighbouring cubes cut their shared face along the same diagonal, and the
surface, a function of the values at shared corners only (each corner evaluated once,
found by its integer key), is watertight by construction; every cell with a sign change
among its corners is kept (a Lipschitz field with a zero in a cell has ``|f(c)|`` within
the reach), so no piece of the surface is missing either. Triangles are oriented so their
normals point to the positive (outside) side. Each vertex is put on its tetrahedron edge
by regula falsi (Illinois variant) on the field itself, not only by linear interpolation.

Treuhaft & Nielson, "Marching tetrahedra" (Doi & Koide 1991); Freudenthal 1942; Dowson &
Harrington's Illinois method (1971).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np

__all__ = ["BudgetExceeded", "mesh_field", "plan_grid"]

Fn = Callable[[np.ndarray], np.ndarray]
SQRT3_2 = np.sqrt(3.0) / 2.0


class BudgetExceeded(Exception):
    """More cells or points would be made than the caller allows (``count`` of ``what``)."""

    def __init__(self, count: int, what: str):
        super().__init__(f"{count} {what}")
        self.count = count
        self.what = what


# ---------------------------------------------------------------- the tetrahedra's tables

CORNERS = np.array(list(itertools.product((0, 1), repeat=3)), dtype=np.int64)  # (8, 3) xyz
# direction vectors of the edges used (all from a corner toward +): 7 nonzero 0/1 vectors
DIRS = CORNERS[1:]


def _corner_id(v) -> int:
    return int(v[0] * 4 + v[1] * 2 + v[2])


def _tables():
    """Per (tetrahedron, sign case): up to two triangles, each three (corner, direction)
    edges, oriented with the normal toward the outside (positive) vertices."""
    tets = []
    for perm in itertools.permutations(range(3)):
        path = [np.zeros(3, np.int64)]
        for axis in perm:
            step = path[-1].copy()
            step[axis] = 1
            path.append(step)
        tets.append(path)
    # edge of a tetrahedron between its path vertices i < j: from corner path[i], direction
    # path[j] - path[i] (the path is monotone, so that is a 0/1 vector)
    tri = np.full((6, 16, 2, 3, 2), -1, dtype=np.int64)  # (.., triangle, vertex, (corner, dir))
    for t, path in enumerate(tets):
        pos = np.array(path, dtype=np.float64)
        for case in range(16):
            inside = [(case >> i) & 1 == 1 for i in range(4)]
            ins = [i for i in range(4) if inside[i]]
            out = [i for i in range(4) if not inside[i]]
            if not ins or not out:
                continue
            cross = [(a, b) if a < b else (b, a) for a in ins for b in out]

            if len(ins) == 1 or len(out) == 1:
                polys = [cross]
            else:  # a quad: order its crossings round the loop (i0o0, i0o1, i1o1, i1o0)
                (i0, i1), (o0, o1) = ins, out
                loop = [(i0, o0), (i0, o1), (i1, o1), (i1, o0)]
                loop = [(a, b) if a < b else (b, a) for a, b in loop]
                polys = [[loop[0], loop[1], loop[2]], [loop[0], loop[2], loop[3]]]
            c_in = pos[ins].mean(axis=0)
            c_out = pos[out].mean(axis=0)
            for k, poly in enumerate(polys):
                a, b, c = ((pos[i] + pos[j]) / 2.0 for i, j in poly)
                if np.dot(np.cross(b - a, c - a), c_out - c_in) < 0:
                    poly = [poly[0], poly[2], poly[1]]
                for m, (i, j) in enumerate(poly):
                    tri[t, case, k, m] = (_corner_id(path[i]), _corner_id(path[j] - path[i]) - 1)
    tet_corners = np.array([[_corner_id(v) for v in path] for path in tets], dtype=np.int64)
    return tet_corners, tri


TET_CORNERS, TRI_TABLE = _tables()  # (6, 4) cube corners; (6, 16, 2, 3, 2)


# ---------------------------------------------------------------------------- the grid


GRID_SHIFT = np.array([0.1234567, 0.2345678, 0.3456789]) * 0.5
# a vertex stays this fraction of its edge off either end, so vertices never coincide, not
# even as the float32 coordinates of an STL (at 2,000 cells from the origin an ulp of
# float32 is 1e-4 of a cell)
END_GAP = 5e-4


def plan_grid(lo: np.ndarray, hi: np.ndarray, cell: float, coarse: int = 16):
    """The finest grid over ``[lo, hi]`` (padded by a cell) and its octree depth.

    Returns ``origin (3,)``, ``levels`` and ``blocks (3,)``: the coarse grid has ``blocks``
    cells a side, each ``2^levels`` finest cells, and the finest grid covers the padded box.
    """
    lo = np.asarray(lo, dtype=np.float64) - cell
    hi = np.asarray(hi, dtype=np.float64) + cell
    n = np.maximum(np.ceil((hi - lo) / cell).astype(np.int64), 1)
    levels = max(0, int(np.ceil(np.log2(max(n.max() / coarse, 1.0)))))
    blocks = -(-n // (1 << levels))
    size = blocks * (1 << levels)
    # centre the grid on the box, shifted by a generic fraction of a cell: the planes of
    # boxes and cuts at round coordinates then never pass exactly through grid corners
    origin = (lo + hi) / 2.0 - size * cell / 2.0 + cell * GRID_SHIFT
    return origin, levels, blocks


def _check(values: np.ndarray) -> np.ndarray:
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if not np.isfinite(v).all():
        raise ValueError("the field is not finite at some points (NaN or infinity)")
    return v


def active_cells(
    f: Fn, origin, levels: int, blocks, cell: float, lipschitz: float, max_cells: int
) -> np.ndarray:
    """Integer (i, j, k) of the finest cells the surface may cross: (m, 3) int64."""
    g = np.stack(np.meshgrid(*(np.arange(b) for b in blocks), indexing="ij"), axis=-1).reshape(
        -1, 3
    )
    if len(g) > max_cells:
        raise BudgetExceeded(len(g), "coarse cells")
    kids = CORNERS
    for level in range(levels, -1, -1):
        size = cell * (1 << level)
        centres = origin + (g + 0.5) * size
        val = _check(f(centres))
        g = g[np.abs(val) <= lipschitz * SQRT3_2 * size * (1.0 + 1e-9) + 1e-12 * size]
        if level == 0 or not len(g):
            break
        if 8 * len(g) > max_cells:
            raise BudgetExceeded(8 * len(g), "cells")
        g = (2 * g[:, None, :] + kids[None, :, :]).reshape(-1, 3)
    return g


def mesh_field(
    f: Fn,
    lo,
    hi,
    cell: float,
    lipschitz: float = 1.0,
    max_cells: int = 50_000_000,
    root_steps: int = 8,
):
    """Triangles of the zero set of ``f`` inside ``[lo, hi]``, watertight and outward.

    Parameters
    ----------
    f : callable (n, 3) -> (n,)
        The field, negative inside; ``lipschitz`` bounds its gradient (1 for a distance).
        For a closed surface the field must be positive on the box's boundary (intersect
        an unbounded field with a box first).
    lo, hi : (3,) float
        The box to mesh.
    cell : float
        The finest cell's size; vertices end within a small fraction of it of the surface.
    max_cells : int
        Refuse (:class:`BudgetExceeded`) before making more cells or corners than this.
    root_steps : int
        Regula falsi steps per vertex after the linear guess (skipped where converged).

    Returns
    -------
    vertices : (n, 3) float64
    triangles : (m, 3) int64
        Oriented so that normals point toward positive values.
    """
    if not (cell > 0 and np.isfinite(cell)):
        raise ValueError(f"cell must be > 0, got {cell:g}")
    origin, levels, blocks = plan_grid(lo, hi, cell)
    cells = active_cells(f, origin, levels, blocks, cell, lipschitz, max_cells)
    if not len(cells):
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    corner, pts = _number_corners(cells, blocks * (1 << levels), max_cells)
    val = _check(f(origin + pts * cell))
    inside = val < 0
    ins = inside[corner]  # (m, 8), corners in CORNERS order
    mixed = ins.any(axis=1) & ~ins.all(axis=1)
    corner = corner[mixed]
    ins = ins[mixed]
    # per tetrahedron: its sign case and up to two triangles of (corner, direction) edges
    bits = ins.astype(np.int8)
    case = sum(bits[:, TET_CORNERS[:, k]] << k for k in range(4))  # (m, 6)
    cell_of, tet = np.nonzero((case != 0) & (case != 15))  # the tetrahedra the surface cuts
    table = TRI_TABLE[tet, case[cell_of, tet]]  # (c, 2, 3, 2)
    second = table[:, 1, 0, 0] >= 0  # a quad: two triangles
    tri = np.concatenate([table[:, 0], table[second, 1]])  # (t, 3, 2): start corner, direction
    cell_of = np.concatenate([cell_of, cell_of[second]])
    start = corner[cell_of[:, None], tri[..., 0]]  # (t, 3) corner numbers
    end = corner[cell_of[:, None], tri[..., 0] + tri[..., 1] + 1]  # bit codes add: s & d = 0
    # one vertex per (start corner, direction): a perfect hash, no sort
    edge = start * 7 + tri[..., 1]
    used = np.zeros(len(pts) * 7, dtype=bool)
    used[edge] = True
    number = np.cumsum(used) - 1
    tri_v = number[edge]
    n_v = int(used.sum())
    ia = np.empty(n_v, dtype=np.int64)
    ib = np.empty(n_v, dtype=np.int64)
    ia[tri_v] = start
    ib[tri_v] = end
    pa = origin + pts[ia] * cell
    pb = origin + pts[ib] * cell
    verts = _roots(f, pa, pb, val[ia], val[ib], root_steps, cell)
    return verts, tri_v


def _roots(f: Fn, pa, pb, fa, fb, steps: int, cell: float) -> np.ndarray:
    """Points where ``f`` changes sign on segments ``pa -> pb`` (Illinois regula falsi).

    ``fa`` and ``fb`` have opposite signs (one is < 0, the other >= 0). Points are kept
    ``END_GAP`` off the ends, so edges meeting at a corner on the surface give distinct
    vertices (and no triangle collapses to a point in a file of float32 coordinates).
    """
    lo_t = np.zeros(len(pa))
    hi_t = np.ones(len(pa))
    flo, fhi = fa.copy(), fb.copy()
    t = np.clip(flo / (flo - fhi), END_GAP, 1 - END_GAP)
    tol = 1e-4 * cell
    idx = np.arange(len(pa))
    side = np.zeros(len(pa), dtype=np.int8)  # which end was kept last (Illinois)
    for _ in range(steps):
        p = pa[idx] + t[idx, None] * (pb[idx] - pa[idx])
        fp = _check(f(p))
        conv = np.abs(fp) <= tol
        same_lo = (fp < 0) == (flo[idx] < 0)
        # replace the end with the same sign; halve the other end's value if it was kept
        # twice in a row (the Illinois rule, superlinear and never stuck on one side)
        j = idx[same_lo]
        lo_t[j], flo[j] = t[j], fp[same_lo]
        fhi[j] = np.where(side[j] == 1, fhi[j] / 2.0, fhi[j])
        side[j] = 1
        k = idx[~same_lo]
        hi_t[k], fhi[k] = t[k], fp[~same_lo]
        flo[k] = np.where(side[k] == -1, flo[k] / 2.0, flo[k])
        side[k] = -1
        left = ~conv
        idx = idx[left]
        if not len(idx):
            break
        den = flo[idx] - fhi[idx]
        frac = np.divide(flo[idx], den, out=np.full(len(idx), 0.5), where=den != 0)
        t[idx] = np.clip(lo_t[idx] + frac * (hi_t[idx] - lo_t[idx]), END_GAP, 1 - END_GAP)
    # what regula falsi left (a kink of a sharp union on the edge converges only linearly):
    # bisection of the bracket, which halves it every step whatever the field's shape
    for _ in range(16 if steps else 0):
        if not len(idx):
            break
        t[idx] = np.clip((lo_t[idx] + hi_t[idx]) / 2.0, END_GAP, 1 - END_GAP)
        fp = _check(f(pa[idx] + t[idx, None] * (pb[idx] - pa[idx])))
        low = (fp < 0) == (flo[idx] < 0)
        lo_t[idx[low]], flo[idx[low]] = t[idx[low]], fp[low]
        hi_t[idx[~low]], fhi[idx[~low]] = t[idx[~low]], fp[~low]
        idx = idx[np.abs(fp) > tol]
    return pa + t[:, None] * (pb - pa)


BRICK = 8  # corners are hashed to (brick, position in the brick): 8 x 8 x 8 per brick


def _number_corners(cells: np.ndarray, n: np.ndarray, max_cells: int):
    """Number the distinct corners of ``cells`` without sorting.

    A corner (i, j, k) of the ``n``-cell grid lies in brick ``(i, j, k) // 8``; the bricks
    that hold any corner get a slot (a dense table over the bricks, 1/512 of the grid),
    and each slot 512 places, so ``slot * 512 + place`` is a perfect hash of the corner:
    marking the used places and counting them numbers the corners in O(cells).

    Returns ``corner (m, 8)``, each cell's corner numbers, and ``ijk (c, 3)`` of each corner.
    """
    nb = n // BRICK + 1
    cc = (cells[:, None, :] + CORNERS[None, :, :]).reshape(-1, 3)
    x, y, z = cc[:, 0], cc[:, 1], cc[:, 2]  # (integer matmul has no fast path in numpy)
    brick = ((x >> 3) * nb[1] + (y >> 3)) * nb[2] + (z >> 3)
    place = ((x & 7) << 6) | ((y & 7) << 3) | (z & 7)
    marked = np.zeros(int(np.prod(nb)), dtype=bool)
    marked[brick] = True
    n_slots = int(marked.sum())
    if n_slots * BRICK**3 > 4 * max_cells:
        raise BudgetExceeded(n_slots * BRICK**3, "corner slots")
    slot = np.cumsum(marked, dtype=np.int64) - 1
    hashed = slot[brick] * BRICK**3 + place
    used = np.zeros(n_slots * BRICK**3, dtype=bool)
    used[hashed] = True
    number = np.cumsum(used, dtype=np.int64) - 1
    corner = number[hashed]
    ijk = np.empty((int(number[-1]) + 1, 3), dtype=np.int64)
    ijk[corner] = cc
    return corner.reshape(-1, 8), ijk
