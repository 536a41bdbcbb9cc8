"""The mesher's lattice: the blocks of finest cells the surface can reach, the slots of
the corners they use, and each corner's sign.

The finest grid has cells of size ``cell``; only the cells the surface can reach are ever
made. Starting from a coarse grid, each level keeps the cells whose centre value is
within the field's Lipschitz reach of zero (``|f(c)| <= L * half-diagonal``: a cell
farther than that from the surface cannot hold any of it, nor any sign change among the
grid corners in it) and splits them into eight. Down to blocks of 8^3 finest cells this
is a list of cells; inside the kept blocks it goes on as dense per-block arrays (levels
of 4 and 2 cells), so the work is in the surface's area: halving the cell makes about
four times the cells, not eight.

Every grid corner is owned by one block (a block owns its 8^3 lower corners; the corners
on its upper faces belong to its neighbours), so a corner is sampled once and its sign
decided once, in one place, whichever cells use it. A corner's sign is inferred without
sampling where a sampled point of the level of 2 cells is farther from zero than the
field can change between them (``|f(q)| > L |p - q|``); the rest are sampled, in chunks
that stay in the processor's cache.

A field whose values on a lattice cost a fraction of its points (``grid``: a TPMS, a box,
a sphere and their blends, on tables along the axes) is sampled instead at every corner
of the kept blocks, block lattice by block lattice, none inferred: on a lattice the
samples are cheaper than the bookkeeping that would avoid them.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np

from ..finite import all_finite

__all__ = [
    "B",
    "B3",
    "CHUNK",
    "CORNERS",
    "GROUP",
    "LOCAL",
    "checked",
    "BudgetExceeded",
    "Lattice",
    "plan_grid",
]

Fn = Callable[[np.ndarray], np.ndarray]
SQRT3_2 = np.sqrt(3.0) / 2.0
CHUNK = 1 << 16  # points per call of the field: its temporaries stay in the cache


class BudgetExceeded(Exception):
    """More cells or points would be made than the caller allows (``count`` of ``what``)."""

    def __init__(self, count: int, what: str):
        super().__init__(f"{count} {what}")
        self.count = count
        self.what = what


CORNERS = np.array(list(itertools.product((0, 1), repeat=3)), dtype=np.int64)  # (8, 3) xyz

# ---------------------------------------------------------------------------- the grid

GRID_SHIFT = np.array([0.1234567, 0.2345678, 0.3456789]) * 0.5
BLOCK_LEVEL = 3
B = 1 << BLOCK_LEVEL  # a block is B^3 finest cells and owns B^3 corners
B3 = B**3
GROUP = 128  # kept blocks worked on at a time (65,536 cells)
C2 = 4 * CORNERS + 2  # the centres of a block's cells of 4, in corners
LOCAL = np.stack(np.unravel_index(np.arange(B3), (B, B, B)), axis=-1).astype(np.float64)


def plan_grid(lo: np.ndarray, hi: np.ndarray, cell: float, coarse: int = 16):
    """The finest grid over ``[lo, hi]`` (padded by a cell) and its octree depth.

    Returns ``origin (3,)``, ``levels`` (at least the block level, 3) and ``blocks (3,)``:
    the coarse grid has ``blocks`` cells a side, each ``2^levels`` finest cells, and the
    finest grid covers the padded box.
    """
    lo = np.asarray(lo, dtype=np.float64) - cell
    hi = np.asarray(hi, dtype=np.float64) + cell
    n = np.maximum(np.ceil((hi - lo) / cell).astype(np.int64), 1)
    levels = max(BLOCK_LEVEL, int(np.ceil(np.log2(max(n.max() / coarse, 1.0)))))
    blocks = -(-n // (1 << levels))
    size = blocks * (1 << levels)
    # centre the grid on the box, shifted by a generic fraction of a cell: the planes of
    # boxes and cuts at round coordinates then never pass exactly through grid corners
    origin = (lo + hi) / 2.0 - size * cell / 2.0 + cell * GRID_SHIFT
    return origin, levels, blocks


def checked(values: np.ndarray) -> np.ndarray:
    """A field's values as flat float64, refused (ValueError) where not finite."""
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if not all_finite(v):
        raise ValueError("the field is not finite at some points (NaN or infinity)")
    return v


def _eval(f: Fn, p: np.ndarray) -> np.ndarray:
    """``f`` at points ``(n, 3)``, checked, in chunks of :data:`CHUNK` points."""
    if len(p) <= CHUNK:
        return checked(f(p))
    return np.concatenate([checked(f(p[i : i + CHUNK])) for i in range(0, len(p), CHUNK)])


def _eval_ijk(f: Fn, origin, cell: float, ijk: np.ndarray, size: float = 1.0) -> np.ndarray:
    """``f`` at grid points ``origin + ijk * cell * size``, the coordinates made per chunk."""
    out = np.empty(len(ijk))
    step = cell * size
    for i in range(0, len(ijk), CHUNK):
        out[i : i + CHUNK] = checked(f(origin + ijk[i : i + CHUNK] * step))
    return out


def _reach(lipschitz: float, size: float) -> float:
    """How far from zero a value at the centre of a cell of ``size`` may be while the
    surface still reaches a point of the closed cell."""
    return lipschitz * SQRT3_2 * size * (1.0 + 1e-9) + 1e-12 * size


def _kept_blocks(f: Fn, origin, levels: int, blocks, cell: float, lipschitz: float, max_cells):
    """Integer (i, j, k) of the blocks (level 3) the surface may reach, and the values
    at their centres."""
    g = np.stack(np.meshgrid(*(np.arange(b) for b in blocks), indexing="ij"), axis=-1)
    g = g.reshape(-1, 3)
    if len(g) > max_cells:
        raise BudgetExceeded(len(g), "coarse cells")
    for level in range(levels, BLOCK_LEVEL - 1, -1):
        size = float(1 << level)
        val = _eval_ijk(f, origin, cell, g + 0.5, size)
        keep = np.abs(val) <= _reach(lipschitz, size * cell)
        g, val = g[keep], val[keep]
        if level == BLOCK_LEVEL or not len(g):
            break
        if 8 * len(g) > max_cells:
            raise BudgetExceeded(8 * len(g), "cells")
        g = (2 * g[:, None, :] + CORNERS[None, :, :]).reshape(-1, 3)
    return g, val


# ------------------------------------------------------- blocks, their slots, their signs


def _key(c: np.ndarray, dims: np.ndarray) -> np.ndarray:
    return (c[..., 0] * dims[1] + c[..., 1]) * dims[2] + c[..., 2]


def _region(w: int):
    """For the neighbour ``w`` (a CORNERS code) of a block: where its owned corners sit in
    the block's (9, 9, 9) corner grid, and where they sit in the neighbour's own slot."""
    up = CORNERS[w]
    here = tuple(B if u else slice(0, B) for u in up)
    there = tuple(0 if u else slice(0, B) for u in up)
    return (slice(None), *here), there


REGIONS = [_region(w) for w in range(8)]


class Lattice:
    """The kept blocks, the slots of the corners they use, and every needed corner's sign.

    ``nbr (nk, 8)``: the slots of each kept block and its seven upper neighbours (its own
    slot first); ``inside (ns, 8, 8, 8)``: the decided signs; ``values``: the sampled values
    (NaN where a sign was inferred or not needed); ``kept1 (nk, 4, 4, 4)``: the kept cells
    of 2. Blocks are worked on :data:`GROUP` at a time, so the arrays stay in the cache.
    """

    def __init__(self, f: Fn, lo, hi, cell: float, lipschitz: float, max_cells: int, grid=None):
        self.f, self.cell = f, cell
        self.origin, levels, blocks = plan_grid(lo, hi, cell)
        g, vc = _kept_blocks(f, self.origin, levels, blocks, cell, lipschitz, max_cells)
        self.blocks = g
        nk = len(g)
        if not nk:
            return
        if nk * B3 > max_cells:
            raise BudgetExceeded(nk * B3, "cells")
        # slots: every kept block and its upper neighbours own their lower 8^3 corners
        dims = (blocks << (levels - BLOCK_LEVEL)) + 1
        order = np.argsort(_key(g, dims))  # neighbouring blocks, neighbouring slots
        g, vc = g[order], vc[order]
        self.blocks = g
        keys = _key(g[:, None, :] + CORNERS[None, :, :], dims)
        touched = np.unique(keys)
        ns = len(touched)
        if ns * B3 > 4 * max_cells:
            raise BudgetExceeded(ns * B3, "corner slots")
        # the kept blocks take slots 0..nk-1 in their order (a group's own slots are a
        # slice), the other touched blocks the rest
        at = np.searchsorted(touched, keys)
        remap = np.empty(ns, dtype=np.int64)
        remap[at[:, 0]] = np.arange(nk)
        rest = np.ones(ns, dtype=bool)
        rest[at[:, 0]] = False
        remap[rest] = np.arange(nk, ns)
        d1, d2 = int(dims[1]), int(dims[2])
        self.base = np.empty((ns, 3), dtype=np.int64)
        self.base[remap] = (
            np.stack([touched // (d1 * d2), touched // d2 % d1, touched % d2], -1) * B
        )
        self.touched, self.dims, self._remap = touched, dims, remap
        self.nbr = nbr = remap[at]
        if grid is not None:
            self._dense(grid, ns)
            return
        values = np.full((ns, B, B, B), np.nan)
        need = np.zeros((ns, B, B, B), dtype=bool)
        known = np.zeros((ns, B, B, B), dtype=bool)
        inside = np.zeros((ns, B, B, B), dtype=bool)
        self.kept1 = np.zeros((nk, 4, 4, 4), dtype=bool)
        values[nbr[:, 0], 4, 4, 4] = vc
        for s in range(0, nk, GROUP):
            e = min(s + GROUP, nk)
            val1 = self._levels(g[s:e], np.arange(s, e), values, lipschitz)
            with np.errstate(invalid="ignore"):
                kept1 = np.abs(val1) <= _reach(lipschitz, 2 * cell)
            self.kept1[s:e] = kept1
            # the corners of the kept cells of 2 (3^3 each), marked in their owners' slots
            need9 = np.zeros((e - s, B + 1, B + 1, B + 1), dtype=bool)
            for i, j, k in itertools.product(range(3), repeat=3):
                need9[:, i : i + B : 2, j : j + B : 2, k : k + B : 2] |= kept1
            for w, (here, there) in enumerate(REGIONS):
                need[(slice(s, e) if w == 0 else nbr[s:e, w], *there)] |= need9[here]
            # signs inferred from the centres of the cells of 2: |f(q)| > L |p - q|
            inferred, negative = _infer(val1, lipschitz * cell)
            own = values[s:e]
            sampled = ~np.isnan(own)
            known[s:e] = inferred | sampled
            inside[s:e] = np.where(sampled, own < 0, negative)
        values, need, known, inside = (a.reshape(-1) for a in (values, need, known, inside))
        todo = np.flatnonzero(need & ~known)
        values[todo] = self.sample(todo)
        inside[todo] = values[todo] < 0
        self.values, self.inside = values, inside.reshape(ns, B, B, B)

    def _dense(self, grid, ns: int) -> None:
        """Every corner the kept blocks use, sampled on lattices by ``grid`` (a field whose
        lattices cost a fraction of its points: no culling inside the blocks): all of a
        kept block's own, and of the other touched slots the three lower faces (the only
        corners of theirs a kept block's cells reach; the rest stay NaN)."""
        self.kept1 = None
        nk, cell = len(self.blocks), self.cell
        at = self.origin + self.base * cell
        values = np.empty((ns, B, B, B))  # each block written once (one pass of memory)
        values[nk:] = np.nan
        for s in range(0, nk, GROUP):
            e = min(s + GROUP, nk)
            values[s:e] = checked(grid(at[s:e], cell, (B, B, B))).reshape(e - s, B, B, B)
        for s in range(nk, ns, GROUP):
            e = min(s + GROUP, ns)
            for k in range(3):
                face = (slice(s, e), *(0 if j == k else slice(None) for j in range(3)))
                shape = tuple(1 if j == k else B for j in range(3))
                values[face] = checked(grid(at[s:e], cell, shape)).reshape(values[face].shape)
        self.values = values.reshape(-1)
        with np.errstate(invalid="ignore"):
            self.inside = values < 0

    def _levels(self, g, own, values, lipschitz: float) -> np.ndarray:
        """The levels of 4 and 2 cells inside blocks ``g`` (dense per-block arrays, their
        own slots ``own``): their centres sampled into ``values``; returns the values at
        the centres of the cells of 2 ``(n, 4, 4, 4)`` (NaN where the cell of 4 was
        culled)."""
        n, cell = len(g), self.cell
        v2 = _eval_ijk(self.f, self.origin, cell, (B * g[:, None, :] + C2).reshape(-1, 3))
        b2, q2 = np.nonzero(np.abs(v2.reshape(n, 8)) <= _reach(lipschitz, 4 * cell))
        r1 = (2 * CORNERS[q2][:, None, :] + CORNERS[None, :, :]).reshape(-1, 3)
        b1 = np.repeat(b2, 8)
        v1 = _eval_ijk(self.f, self.origin, cell, B * g[b1] + 2 * r1 + 1)
        val1 = np.full((n, 4, 4, 4), np.nan)
        val1[b1, r1[:, 0], r1[:, 1], r1[:, 2]] = v1
        values[(np.repeat(own, 8), *np.tile(C2, (n, 1)).T)] = v2
        values[(own[b1], *(2 * r1 + 1).T)] = v1
        return val1

    def sample(self, corners: np.ndarray) -> np.ndarray:
        """The field at corner numbers (slot * 512 + local corner), chunk by chunk."""
        out = np.empty(len(corners))
        for i in range(0, len(corners), CHUNK):
            out[i : i + CHUNK] = checked(self.f(self.point(corners[i : i + CHUNK])))
        return out

    def point(self, corner: np.ndarray) -> np.ndarray:
        """The coordinates of corner numbers."""
        if not hasattr(self, "_at"):
            self._at = self.origin + self.base * self.cell  # each slot's corner 0
            self._local = LOCAL * self.cell
        # np.take gathers rows faster than fancy indexing does
        return np.take(self._at, corner >> 9, axis=0) + np.take(
            self._local, corner & (B3 - 1), axis=0
        )

    def neighbours(self) -> np.ndarray:
        """``(ns, 2, 3)``: each slot's face neighbours below and above along each axis
        (their slots; -1 where that block has none)."""
        if not hasattr(self, "_next"):
            unit = np.array([-1, 1])[None, :, None, None] * np.eye(3, dtype=np.int64)
            key = _key(self.base[:, None, None, :] // B + unit, self.dims)
            at = np.minimum(np.searchsorted(self.touched, key), len(self.touched) - 1)
            self._next = np.where(self.touched[at] == key, self._remap[at], -1)
        return self._next

    def step(self, corner: np.ndarray, axis: np.ndarray, by: int) -> np.ndarray:
        """The corners one step (``by`` = 1 or -1) along ``axis`` from ``corner``; -1 where
        that corner has no slot."""
        slot, loc = corner >> 9, corner & (B3 - 1)
        bit = 6 - 3 * axis
        coord = ((loc >> bit) & 7) + by
        wrap = (coord < 0) | (coord >= B)
        out = np.where(wrap, 0, corner + np.left_shift(by, bit))
        if wrap.any():
            nxt = self.neighbours()[slot[wrap], (by + 1) // 2, axis[wrap]]
            moved = nxt * B3 + (loc[wrap] & ~(7 << bit[wrap])) + ((coord[wrap] & 7) << bit[wrap])
            out[wrap] = np.where(nxt >= 0, moved, -1)
        return out

    def mixed_cells(self, s: int, e: int):
        """The cells with a sign change in kept blocks ``s:e``: flat indices (block * 512 +
        local cell) and their cases."""
        n, nbr = e - s, self.nbr[s:e]
        ins9 = np.empty((n, B + 1, B + 1, B + 1), dtype=bool)
        for w, (here, there) in enumerate(REGIONS):
            ins9[here] = self.inside[(slice(s, e) if w == 0 else nbr[:, w], *there)]
        ins9 = ins9.view(np.uint8)
        # corner (x, y, z) is bit 4x + 2y + z: pairs along z, then y, then x
        pz = ins9[..., :B] | (ins9[..., 1:] << 1)
        py = pz[:, :, :B] | (pz[:, :, 1:] << 2)
        case = py[:, :B] | (py[:, 1:] << 4)
        mixed = (case + np.uint8(1)) > 1  # neither 0 nor 255 (which wraps to 0)
        if self.kept1 is not None:
            up = self.kept1[s:e, :, None, :, None, :, None]
            mixed &= np.broadcast_to(up, (n, 4, 2, 4, 2, 4, 2)).reshape(n, B, B, B)
        cells = np.flatnonzero(mixed)
        return cells + s * B3, case.reshape(-1)[cells]


def _with_previous(a: np.ndarray, axis: int, pick) -> np.ndarray:
    """``pick`` (np.fmax or np.fmin) of each entry and the one before it along ``axis``
    (of the last three: 1, 2, 3), the first against nothing."""
    out = a.copy()
    here = [slice(None)] * 4
    before = [slice(None)] * 4
    here[axis], before[axis] = slice(1, None), slice(None, -1)
    out[tuple(here)] = pick(a[tuple(here)], a[tuple(before)])
    return out


def _infer(val1: np.ndarray, step: float):
    """Which of a block's 8^3 corners have a sign known from the sampled centres of the
    cells of 2 (``val1 (nk, 4, 4, 4)``, NaN where not sampled), and whether it is negative.

    A corner with ``e`` even coordinates is ``step * sqrt(e)`` from each of its ``2^e``
    nearest centres (``step`` is the Lipschitz bound times the cell); the largest and
    smallest of them are running maxima along the even axes, one axis at a time.
    """
    nk = len(val1)
    inferred = np.zeros((nk, B, B, B), dtype=bool)
    negative = np.zeros((nk, B, B, B), dtype=bool)
    hi: dict[tuple, np.ndarray] = {(): val1}
    lo: dict[tuple, np.ndarray] = {(): val1}
    with np.errstate(invalid="ignore"):
        for parity in CORNERS:
            # an odd coordinate 2a + 1 is centre a's; an even one 2a lies between a - 1 and a
            even = tuple(k for k in range(3) if not parity[k])
            for n in range(1, len(even) + 1):
                sub, parent = even[:n], even[: n - 1]
                if sub not in hi:
                    hi[sub] = _with_previous(hi[parent], 1 + sub[-1], np.fmax)
                    lo[sub] = _with_previous(lo[parent], 1 + sub[-1], np.fmin)
            reach = step * np.sqrt(len(even)) * (1 + 1e-9)
            pos, neg = hi[even] > reach, lo[even] < -reach
            at = (slice(None), *(slice(int(p), B, 2) for p in parity))
            inferred[at] = pos | neg
            negative[at] = neg & ~pos
    return inferred, negative
