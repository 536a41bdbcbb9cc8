"""Adaptive meshing of the zero set of a distance field: octree culling, marching cubes.

The culling, the blocks of cells it keeps and the signs at their corners are
:mod:`.lattice`'s: the work is in the surface's area, halving the cell makes about four
times the cells, not eight.

The cells with a sign change are polygonized by marching cubes with a table built from
one rule on each face (:mod:`.mctable`: inside corners are separated), so neighbouring
cubes draw the same segments on a shared face and the surface, a function of the signs
at shared corners only, is watertight by construction; triangles point to the positive
(outside) side. A vertex is identified by its edge (owner block, axis, corner): a perfect
hash, marked where used; a slot's edges are used only by its own block and its lower
neighbours, which come first, so each group of blocks numbers its own slots' marks as
soon as it is through, in order, no sort. Each vertex is put on its edge by root-finding
on the field itself (:mod:`.roots`: a cubic first guess from the samples along the edge's
grid line, then one sample, which decides nine vertices in ten on a smooth field), not
only by linear interpolation; a field sampled on lattices takes those samples on its
edges' lines (``lines``), where only the coordinate along the edge is new.

Lorensen & Cline 1987; Nielson & Hamann 1991 (the ambiguous face).
"""

from __future__ import annotations

import numpy as np

from ..buffers import fill_frozen
from .lattice import (
    B3,
    CHUNK,
    CORNERS,
    GROUP,
    LOCAL,
    B,
    BudgetExceeded,
    Fn,
    Lattice,
    checked,
    plan_grid,
)
from .mctable import EDGE_AXIS, EDGE_START, TRI_COUNT, TRI_EDGES
from .roots import END_GAP, Brackets, guess, roots

__all__ = ["CHUNK", "BudgetExceeded", "crossing_cells", "mesh_field", "plan_grid"]


def _edge_tables():
    """Per (local cell, cube edge): the neighbour code (CORNERS index) of the block owning
    the edge's start, and ``axis * 512 + local corner`` there."""
    loc = np.arange(B3)
    cellxyz = np.stack([loc >> 6, (loc >> 3) & 7, loc & 7], axis=-1)
    start = cellxyz[:, None, :] + CORNERS[EDGE_START][None, :, :]  # (512, 12, 3)
    w = (start[..., 0] >> 3) << 2 | (start[..., 1] >> 3) << 1 | (start[..., 2] >> 3)
    s = start & (B - 1)
    lin = (s[..., 0] << 6) | (s[..., 1] << 3) | s[..., 2]
    place = EDGE_AXIS[None, :] * B3 + lin
    return w.reshape(-1).astype(np.int32), place.reshape(-1).astype(np.int32)


EDGE_OWNER, EDGE_PLACE = _edge_tables()  # indexed by local cell * 12 + edge
EDGE_PACK = EDGE_OWNER << 11 | EDGE_PLACE  # both in one gather (a place is below 1536)
TRI_ROWS = TRI_EDGES.reshape(-1, 3).astype(np.int32)  # case * 5 + triangle -> its edges


# per bit of a 16-bit word: the mask of the bits below it, and of the count above them
BELOW = (np.left_shift(1, np.arange(16), dtype=np.int64) - 1) | ~np.int64(0xFFFF)


def _ranks(used: np.ndarray, hashes: list[np.ndarray], out: np.ndarray) -> int:
    """Each hash's rank among the ``used`` ones (its vertex number) written to ``out``
    (flat, one per hash, in order); returns their count.

    The rank is the count of used entries before it: a prefix sum over 16-bit words of
    the packed marks plus the bits below it in its own word, so no array of the hash
    space's size is ever written (its pages alone cost more than the counting).
    """
    words = np.packbits(used, bitorder="little").view("<u2")
    pop = np.bitwise_count(words).astype(np.int64)
    # the count before each word and the word itself in one int64: one gather a hash
    packed = np.cumsum(pop)
    count = int(packed[-1]) if len(packed) else 0
    packed -= pop
    packed <<= 16
    packed |= words
    at = 0
    for h in hashes:
        h = h.reshape(-1)
        word = np.take(packed, h >> 4)
        word &= np.take(BELOW, h & 15)  # the count before the word, the bits below h's
        rank = out[at : at + h.size]
        np.right_shift(word, 16, out=rank)
        word &= 0xFFFF
        rank += np.bitwise_count(word)
        at += h.size
    return count


def crossing_cells(f: Fn, lo, hi, cell: float, lipschitz: float = 1.0, max_cells=50_000_000):
    """Global (i, j, k) of the finest cells :func:`mesh_field` polygonizes (those with a
    sign change among their corners), on the grid of :func:`plan_grid`."""
    lat = Lattice(f, lo, hi, cell, lipschitz, max_cells)
    out = [np.zeros((0, 3), np.int64)]
    for s in range(0, len(lat.blocks), GROUP):
        cells, _ = lat.mixed_cells(s, min(s + GROUP, len(lat.blocks)))
        loc = cells & (B3 - 1)
        local = np.stack([loc >> 6, (loc >> 3) & 7, loc & 7], axis=-1)
        out.append(lat.blocks[cells >> 9] * B + local)
    return np.concatenate(out)


def _edge_hashes(cells: np.ndarray, case: np.ndarray, nbr: np.ndarray) -> np.ndarray:
    """The triangles of mixed ``cells`` (flat block * 512 + local indices) as ``(t, 3)``
    edge hashes: owner slot * 1536 + axis * 512 + owner's local corner (``nbr``
    flattened, eight slots a block)."""
    count = TRI_COUNT[case]
    dt = cells.dtype
    # each triangle's row of the table (case * 5 + its rank in the cell) and its cell
    row = np.repeat(case.astype(dt) * 5 - (np.cumsum(count, dtype=dt) - count), count)
    row += np.arange(len(row), dtype=dt)
    cw = np.repeat(cells, count)
    key = np.take(TRI_ROWS, row, axis=0)  # (t, 3): the cube edges, then (local cell, edge)
    key += ((cw & (B3 - 1)) * 12)[:, None]
    packed = np.take(EDGE_PACK, key)
    owner = np.take(nbr, ((cw >> 9) * 8)[:, None] + (packed >> 11))
    owner *= 3 * B3
    owner += packed & 2047
    return owner


HALO = B + 3  # a block's corners -1..9 along each axis: its edges' samples at -1, 0, 1, 2
LOCAL_T = np.ascontiguousarray(LOCAL.T.astype(np.int32))  # (3, 512): a corner's x, y, z
HALO_AT = (LOCAL.astype(np.int64) + 1) @ np.array(
    [HALO * HALO, HALO, 1]
)  # local corner -> halo position
HALO_STEP = np.array([HALO * HALO, HALO, 1])  # one corner along each axis in the halo


class _Vertices:
    """The mesher's ``count`` vertices, placed on their edges in number order (the used
    edges of the kept slots group by group, then the touched slots' that are not kept).

    The samples at -1, 0, 1 and 2 along an edge come from the group's corner values with
    a halo of its six face neighbours' (one gather each, no per-vertex search); the first
    guess is their cubic's root (:func:`.roots.guess`), the first sample on the edge's
    line follows group by group, and the few vertices that need more are stepped all
    together at the end (:func:`.roots.roots`).
    """

    def __init__(self, lat: Lattice, f: Fn, out: np.ndarray, steps: int, lipschitz, lines, dense):
        self.lat, self.f, self.steps, self.lipschitz = lat, f, steps, lipschitz
        self.lines, self.dense = lines, dense
        self.verts = out  # (count, 3), every row written
        self.placed = 0
        self.brackets = Brackets()
        self.pending: list[tuple[np.ndarray, ...]] = []
        self.waiting = 0  # edges pending
        self.halo = np.full((min(GROUP, len(lat.blocks)), HALO, HALO, HALO), np.nan)
        self.corners = lat.values.reshape(-1, B, B, B)
        self.base_t = np.ascontiguousarray(lat.base.T.astype(np.int32))  # slots' corner 0

    def own(self, s: int, e: int, used: np.ndarray) -> None:
        """The used edges of kept slots ``s:e``, as positions in their edge range (slot,
        axis, corner: ``(slot - s) * 1536 + axis * 512 + corner``), in order."""
        q = used >> 9
        b = q // 3
        axis, loc = q - 3 * b, used & (B3 - 1)
        halo = self._halo(s, e).reshape(-1)
        at = b * HALO**3 + np.take(HALO_AT, loc)
        step = np.take(HALO_STEP, axis)
        fa, fb = np.take(halo, at), np.take(halo, at + step)
        fm, fq = np.take(halo, at - step), np.take(halo, at + 2 * step)
        if not self.dense:  # an end whose sign was inferred: sample it now
            start = (b + s) * B3 + loc
            for v, m in ((fa, np.isnan(fa)), (fb, np.isnan(fb))):
                if m.any():
                    corner = start[m] if v is fa else self.lat.step(start[m], axis[m], 1)
                    v[m] = self._corners(corner)
        ijk_t = np.take(self.base_t, b + s, axis=1)
        ijk_t += np.take(LOCAL_T, loc, axis=1)
        self._queue(ijk_t, axis, fm, fa, fb, fq)

    def others(self, edges: np.ndarray) -> None:
        """Used edges of the touched slots that are not kept (``slot * 1536 + axis * 512
        + corner``): the kept blocks' upper faces, found by searching for the neighbours."""
        lat = self.lat
        slot, rem = np.divmod(edges, 3 * B3)
        axis, loc = rem >> 9, rem & (B3 - 1)
        start = slot * B3 + loc
        end = lat.step(start, axis, 1)  # an edge's end is always in a slot
        before, after = lat.step(start, axis, -1), lat.step(end, axis, 1)
        fa, fb = self._corners(start), self._corners(end)
        fm = np.where(before >= 0, lat.values[before], np.nan)
        fq = np.where(after >= 0, lat.values[after], np.nan)
        self._queue(self.base_t[:, slot] + LOCAL_T[:, loc], axis, fm, fa, fb, fq)
        self._flush()

    def _corners(self, corner: np.ndarray) -> np.ndarray:
        """The values at corners, those not sampled yet sampled now (once each)."""
        values = self.lat.values
        v = values[corner]
        if not self.dense:
            missing = np.unique(corner[np.isnan(v)])
            if len(missing):
                values[missing] = self.lat.sample(missing)
                v = values[corner]
        return v

    def _halo(self, s: int, e: int) -> np.ndarray:
        """Blocks ``s:e``'s corner values with one layer of the lower and two of the upper
        face neighbours' along each axis, ``(n, 11, 11, 11)`` (the halo's edges unused)."""
        n, lat, corners = e - s, self.lat, self.corners
        halo = self.halo[:n]
        inner = slice(1, B + 1)
        halo[:, inner, inner, inner] = corners[s:e]
        below = lat.neighbours()[s:e, 0]
        for axis, code in ((0, 4), (1, 2), (2, 1)):
            up = [slice(None), inner, inner, inner]
            down = list(up)
            up[1 + axis], down[1 + axis] = slice(B + 1, B + 3), slice(0, 1)
            src_up = [slice(None)] * 3
            src_down = list(src_up)
            src_up[axis], src_down[axis] = slice(0, 2), slice(B - 1, B)
            halo[tuple(up)] = corners[(lat.nbr[s:e, code], *src_up)]
            low = below[:, axis]
            halo[tuple(down)] = corners[(low, *src_down)]
            if (low < 0).any():
                down[0] = low < 0
                halo[tuple(down)] = np.nan
        return halo

    def _along(self, ijk: np.ndarray, axis: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The field at parameters ``t`` on edges ``(ijk, axis)``, chunk by chunk."""
        lat, out = self.lat, np.empty(len(t))
        # the lines of a batch of placed edges in one call; points as the field is promised
        n = CHUNK if self.lines is None else 2 * CHUNK
        for i in range(0, len(t), n):
            j, a, u = (v[i : i + n] for v in (ijk, axis, t))
            if self.lines is not None:  # on the lattice's lines: only the moving coordinate
                out[i : i + n] = checked(self.lines(lat.origin, lat.cell, j, a, u))
            else:
                out[i : i + n] = checked(self.f(self._points(j, a, u)))
        return out

    def _points(self, ijk: np.ndarray, axis: np.ndarray, t: np.ndarray, out=None) -> np.ndarray:
        """The points at parameters ``t`` on edges ``(ijk, axis)`` (into ``out``)."""
        p = np.empty((len(t), 3)) if out is None else out
        cell = self.lat.cell
        np.multiply(ijk, cell, out=p)
        p += self.lat.origin
        p.reshape(-1)[np.arange(0, 3 * len(t), 3) + axis] += t * cell
        return p

    def _queue(self, *edges: np.ndarray) -> None:
        """Edges to place, ``(ijk (3, n), axis, fm, fa, fb, fq)`` (the lattice indices by
        columns: the lines' tables take them so without a copy): placed :data:`CHUNK` or more
        at a time (a group's are too few to be worth the calls)."""
        self.pending.append(edges)
        self.waiting += edges[0].shape[1]
        if self.waiting >= CHUNK:
            self._flush()

    def _flush(self) -> None:
        if self.pending:
            ijk_t, *edges = zip(*self.pending, strict=True)
            edges = [np.concatenate(a) for a in edges]
            self.pending, self.waiting = [], 0
            self._place(np.concatenate(ijk_t, axis=1).T, *edges)

    def _place(self, ijk, axis, fm, fa, fb, fq) -> None:
        n = len(fa)
        if self.steps:
            t = guess(fm, fa, fb, fq)
            fc = self._along(ijk, axis, t)
            num = np.arange(self.placed, self.placed + n)
            args = (self.lat.cell, self.lipschitz, ijk, axis)
            t = self.brackets.first(num, t, fc, fa, fb, *args)
        else:  # linear interpolation
            den = fa - fb
            t = np.divide(fa, den, out=np.full(n, 0.5), where=den != 0)
            t = np.clip(t, END_GAP, 1 - END_GAP, out=t)
        self._points(ijk, axis, t, out=self.verts[self.placed : self.placed + n])
        self.placed += n

    def finish(self) -> np.ndarray:
        """Every vertex, in number order."""
        self._flush()
        verts = self.verts
        arrays = self.brackets.arrays()
        if len(arrays[0]):
            ijk, axis = arrays[6:]

            def along(i, t):
                return self._along(ijk[i], axis[i], t)

            idx, t = roots(along, self.brackets, self.steps, self.lat.cell, self.lipschitz)
            verts[idx] = self._points(ijk, axis, t)
        return verts


MAX_SIDE = 1 << 20  # cells a side at most: (blocks a side)^3 well inside int64


def mesh_field(
    f: Fn,
    lo,
    hi,
    cell: float,
    lipschitz: float = 1.0,
    max_cells: int = 50_000_000,
    root_steps: int = 8,
    grid=None,
    lines=None,
):
    """Triangles of the zero set of ``f`` inside ``[lo, hi]``, watertight and outward.

    Parameters
    ----------
    f : callable (n, 3) -> (n,)
        The field, negative inside; ``lipschitz`` bounds its gradient (1 for a distance).
        For a closed surface the field must be positive on the box's boundary (intersect
        an unbounded field with a box first). It is called on at most 65,536 points at a
        time.
    lo, hi : (3,) float
        The box to mesh.
    cell : float
        The finest cell's size; vertices end within a small fraction of it of the surface.
    max_cells : int
        Refuse (:class:`BudgetExceeded`) before making more cells or corners than this.
    root_steps : int
        Samples of the field per vertex at most before bisection takes over (most take
        one, see :mod:`.roots`); 0 is linear interpolation.
    grid : callable (origins (n, 3), step, shape) -> (n, *shape), optional
        The same field on lattices of points (``Field.evaluate_grid``), for a field whose
        lattices are cheaper than its points: then every corner of the blocks kept by the
        coarse levels is sampled that way, none inferred.
    lines : callable (origin, step, ijk (n, 3), axis (n,), t (n,)) -> (n,), optional
        The same field at ``origin + (ijk + t e_axis) * step`` (``Field.evaluate_lines``):
        every sample of a vertex on its edge is taken that way.

    Returns
    -------
    vertices : (n, 3) float64
        Read-only, backed by immutable bytes (frozen: a Mesh shares it as it is).
    triangles : (m, 3) int64
        Oriented so that normals point toward positive values; frozen too.
    """
    if not (cell > 0 and np.isfinite(cell)):
        raise ValueError(f"cell must be > 0, got {cell:g}")
    side = float(np.max(np.asarray(hi, float) - np.asarray(lo, float))) / cell
    if not side <= MAX_SIDE:  # block keys and lattice indices stay exact in int64
        raise ValueError(
            f"the box is {side:.3g} cells across, over the {MAX_SIDE:,} a side the mesher "
            "can number: use a larger cell or a smaller box"
        )
    empty = np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    lat = Lattice(f, lo, hi, cell, lipschitz, max_cells, grid)
    nk = len(lat.blocks)
    if not nk:
        return empty
    ns, edges = len(lat.touched), 3 * B3
    idx = np.int32 if ns * edges < 2**31 else np.int64
    nbr = lat.nbr.astype(idx).reshape(-1)
    # the used edges, marked; their numbers are their ranks among the marks (hash order:
    # slot by slot, the kept ones first). A slot's edges are used only by its own block's
    # cells and its lower neighbours' (earlier in the order), so the vertices are placed
    # group by group in number order
    used = np.zeros(ns * edges, dtype=bool)
    hashes = []
    for s in range(0, nk, GROUP):
        e = min(s + GROUP, nk)
        cells, case = lat.mixed_cells(s, e)
        edge = _edge_hashes(cells.astype(idx), case, nbr)  # a perfect hash of the edge
        used[edge] = True
        hashes.append(edge)
    # both outputs are written straight into immutable buffers (frozen arrays): a Mesh
    # made of them shares them, where copying them there would cost a tenth of the meshing
    count = 0

    def number(out: np.ndarray) -> None:
        nonlocal count
        count = _ranks(used, hashes, out)

    tri = fill_frozen(sum(h.size for h in hashes), np.int64, number).reshape(-1, 3)
    hashes.clear()  # their ranks are written: let them go
    if not count:
        return empty

    def place(out: np.ndarray) -> None:
        vertices = _Vertices(lat, f, out, root_steps, lipschitz, lines, grid is not None)
        for s in range(0, nk, GROUP):
            e = min(s + GROUP, nk)
            own = np.flatnonzero(used[s * edges : e * edges])
            if len(own):
                vertices.own(s, e, own)
        rest = np.flatnonzero(used[nk * edges :])
        if len(rest):
            vertices.others(rest + nk * edges)
        vertices.finish()

    return fill_frozen((count, 3), np.float64, place), tri
