"""Pairs of points closer than a tolerance, by sorting them into cells (for the weld).

Two points within ``tol`` of each other lie in the same or in neighbouring cells of a grid a
little coarser than ``tol``, so the pairs come from one sort of the cells' keys and a search
of each cell's neighbours (13 of them: each unordered pair of cells once). Only occupied
cells cost anything: a cell's three numbers are packed into one int64 key where they fit 21
bits an axis, hashed otherwise (a tolerance tiny against the coordinates).

Where they fit, the cells are first made 8 times coarser: a point then has a neighbour in
another cell only if it lies near the face between them, so each point searches only the
cells across the faces it is near (about one search a point instead of 13), unless the
coarse cells are crowded (a tolerance near the points' spacing), when the fine ones serve.
"""

from __future__ import annotations

import numpy as np

from .keys import mix64

__all__ = ["MAX_PAIRS", "close_pairs"]

#: most candidate vertex pairs a weld compares (a tolerance near the mesh's size would
#: compare every vertex with every other)
MAX_PAIRS = 20_000_000


def _cell_hash(q: np.ndarray, salt: int) -> np.ndarray:
    """A 64-bit hash of int64 cell coordinates ``q`` (k, 3), salted."""
    b = q.view(np.uint64)
    return mix64(mix64(mix64(b[:, 0] ^ np.uint64(salt)) ^ b[:, 1]) ^ b[:, 2])


def close_pairs(v: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """All pairs ``i < j`` with ``|v[i] - v[j]| <= tol`` (cells of side about ``tol``).

    The cells are sparse: each point's three int64 cell numbers, relative to the bounding
    box's minimum, are hashed and sorted, so only occupied cells cost anything and a tolerance
    that is tiny against the coordinates works (a radius-1e10 sphere welded at 1e-3).
    """
    lo = v.min(axis=0)
    # a cell a little wider than tol absorbs the rounding of (v - lo) / side: two points
    # within tol then never land two cells apart (the error is below 8 eps max|v|)
    side = tol + 8 * np.finfo(np.float64).eps * float(np.abs(v).max())
    with np.errstate(over="ignore"):
        qf = np.floor((v - lo) / side)
    # only the cell numbers themselves must fit an int64 (with room for the +-1 neighbours)
    if not np.isfinite(qf).all() or qf.max() >= 2.0**62:
        raise ValueError(
            f"weld tolerance {tol:g} is too small for a mesh this large (a cell number "
            "along an axis would pass 2^62); 0 merges exact duplicates only"
        )
    q = np.ascontiguousarray(qf.astype(np.int64))
    if qf.max(initial=0.0) < _PACKED - 2:
        pairs = _close_pairs_coarse(v, lo, side, tol)
        return _close_pairs_packed(v, q, tol) if pairs is None else pairs
    for salt in (0, 0x9E3779B97F4A7C15, 0x2545F4914F6CDD1D):
        h = _cell_hash(q, salt)
        order = np.argsort(h, kind="stable")
        hs = h[order]
        new_cell = np.r_[True, hs[1:] != hs[:-1]]
        starts = np.flatnonzero(new_cell)
        cells, rep = hs[starts], q[order[starts]]
        # a hash collision would put two cells in one bucket: check, and re-salt
        if np.array_equal(q[order], rep[np.cumsum(new_cell) - 1]):
            break
    else:  # pragma: no cover - three 64-bit collisions in a row
        raise ValueError("weld could not hash its cells without collisions")
    counts = np.diff(np.r_[starts, len(v)])
    start = np.r_[starts, len(v)]
    # the cell itself and the 13 neighbours "after" it: each unordered cell pair once
    offsets = [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)]
    found = []
    for dx, dy, dz in offsets[13:]:
        target = rep + np.array([dx, dy, dz], dtype=np.int64)
        pos = np.minimum(np.searchsorted(cells, _cell_hash(target, salt)), cells.size - 1)
        hit = np.flatnonzero((rep[pos] == target).all(axis=1))
        found.append((dx, dy, dz, hit, pos[hit]))
    # pairs to compare: na * nb between two cells, na (na - 1) / 2 within one
    total = 0
    for dx, dy, dz, ca, cb in found:
        na, nb = counts[ca], counts[cb]
        same = (dx, dy, dz) == (0, 0, 0)
        total += int(np.sum(na * (nb - 1) // 2 if same else na * nb))
    why = (
        "use a smaller tolerance"
        if side < 2 * tol
        else f"the coordinates' float spacing ({side - tol:.3g}) is coarser than the "
        "tolerance, so the cells cannot be smaller"
    )
    _check_pairs(total, tol, why)
    ii, jj = [], []
    for dx, dy, dz, ca, cb in found:
        if ca.size == 0:
            continue
        na, nb = counts[ca], counts[cb]
        pairs = na * nb
        owner = np.repeat(np.arange(ca.size), pairs)
        k = np.arange(owner.size) - np.repeat(np.cumsum(pairs) - pairs, pairs)
        i = order[start[ca][owner] + k // nb[owner]]
        j = order[start[cb][owner] + k % nb[owner]]
        keep = i < j if (dx, dy, dz) == (0, 0, 0) else i != j
        ii.append(i[keep])
        jj.append(j[keep])
    i = np.concatenate(ii) if ii else np.zeros(0, np.int64)
    j = np.concatenate(jj) if jj else np.zeros(0, np.int64)
    # compared in units of tol: tol * tol underflows for a tiny tolerance
    with np.errstate(over="ignore"):
        d = (v[i] - v[j]) / tol
        close = np.einsum("ij,ij->i", d, d) <= 1.0
    return i[close], j[close]


_PACKED = 1 << 21  # cell numbers below this per axis pack into one int64 key (3 x 21 bits)
_NEIGHBOURS = [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)][13:]


def _packed_cells(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points grouped by their cell numbers ``q`` (n, 3), each cell one int64 key
    ``(x + 1) << 42 | (y + 1) << 21 | z + 1``: the points' order sorted by key, the keys in
    that order, and each occupied cell's first place in it and point count."""
    key = ((q[:, 0] + 1) << 42) | ((q[:, 1] + 1) << 21) | (q[:, 2] + 1)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    new_cell = np.empty(ks.size, dtype=bool)
    new_cell[0] = True
    np.not_equal(ks[1:], ks[:-1], out=new_cell[1:])
    starts = np.flatnonzero(new_cell)
    return order, ks, starts, np.diff(np.r_[starts, len(q)])


def _close_pairs_packed(v: np.ndarray, q: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """`close_pairs` where the cell numbers fit 21 bits an axis (a tolerance above about
    1e-6 of the extent): each cell is one int64 key ``(x + 1) << 42 | (y + 1) << 21 | z + 1``,
    so a neighbour's key is the cell's plus a constant. The cells sorted once, every
    neighbour look-up is then a search of sorted keys in sorted keys (no hashing, no
    collision check, and cache-friendly: the searches walk both arrays in order)."""
    order, ks, starts, counts = _packed_cells(q)
    cells = ks[starts]
    found = []
    for dx, dy, dz in _NEIGHBOURS:
        shift = (dx << 42) + (dy << 21) + dz
        if shift == 0:
            hit = np.flatnonzero(counts > 1)
            found.append((True, hit, hit))
            continue
        target = cells + shift  # sorted, as cells are
        pos = np.minimum(np.searchsorted(cells, target), cells.size - 1)
        hit = np.flatnonzero(cells[pos] == target)
        found.append((False, hit, pos[hit]))
    groups = [(same, starts[a], counts[a], starts[b], counts[b]) for same, a, b in found]
    return _pairs_within(v, tol, order, groups)


def _pairs_within(v, tol, order, found):
    """The point pairs of the groups ``found`` closer than ``tol``, after the count of pairs
    to compare is checked against ``MAX_PAIRS``.

    Each entry is ``(same, start_a, count_a, start_b, count_b)``: runs of the sorted points
    (``order``) to pair, a run with itself where ``same`` (each pair once)."""
    total = 0
    for same, _, na, _, nb in found:
        total += int(np.sum(na * (nb - 1) // 2 if same else na * nb))
    _check_pairs(total, tol, "use a smaller tolerance")
    ii, jj = [], []
    for same, sa, na, sb, nb in found:
        if sa.size == 0:
            continue
        pairs = na * nb
        owner = np.repeat(np.arange(sa.size), pairs)
        k = np.arange(owner.size) - np.repeat(np.cumsum(pairs) - pairs, pairs)
        i = order[sa[owner] + k // nb[owner]]
        j = order[sb[owner] + k % nb[owner]]
        keep = i < j if same else i != j
        ii.append(i[keep])
        jj.append(j[keep])
    i = np.concatenate(ii) if ii else np.zeros(0, np.int64)
    j = np.concatenate(jj) if jj else np.zeros(0, np.int64)
    with np.errstate(over="ignore"):  # compared in units of tol: tol * tol may underflow
        d = (v[i] - v[j]) / tol
        close = np.einsum("ij,ij->i", d, d) <= 1.0
    return i[close], j[close]


#: coarse cells are this many fine ones wide: a point then needs its neighbours' cells only
#: across the faces it lies near (within two fine cells), on average about one search of
#: the 13 instead of all of them
_COARSE = 8


def _close_pairs_coarse(v: np.ndarray, lo: np.ndarray, side: float, tol: float):
    """`close_pairs` in cells ``_COARSE`` times wider, each point probing only the
    neighbouring cells across the faces it is near; None where the wider cells are crowded
    (more pairs within them than twice the points), for the fine cells to do."""
    with np.errstate(over="ignore"):
        f = (v - lo) / (_COARSE * side)
    qf = np.floor(f)
    if qf.max(initial=0.0) >= _PACKED - 2:
        return None
    q = qf.astype(np.int64)
    order, ks, starts, counts = _packed_cells(q)
    cells = ks[starts]
    if int(np.sum(counts * (counts - 1) // 2)) > 2 * len(v):
        return None
    # near a face: within two fine cells of it (a pair within tol is within one, and the
    # rounding of f is far below a fine cell's slack)
    r = np.take(f - qf, order, axis=0)
    band = 2.0 / _COARSE
    near = {-1: r < band, 1: r > 1.0 - band}
    crowd = np.flatnonzero(counts > 1)
    found = [(True, starts[crowd], counts[crowd], starts[crowd], counts[crowd])]
    for d in _NEIGHBOURS[1:]:  # (the first is the cell itself)
        probe = np.ones(len(v), dtype=bool)
        for axis, step in enumerate(d):
            if step:
                probe &= near[step][:, axis]
        pos = np.flatnonzero(probe)
        target = ks[pos] + ((d[0] << 42) + (d[1] << 21) + d[2])  # sorted, as ks is
        c = np.minimum(np.searchsorted(cells, target), cells.size - 1)
        hit = cells[c] == target
        c = c[hit]
        found.append((False, pos[hit], np.ones(c.size, np.int64), starts[c], counts[c]))
    return _pairs_within(v, tol, order, found)


def _check_pairs(total: int, tol: float, why: str) -> None:
    """Refuse a search that would compare more than ``MAX_PAIRS`` vertex pairs."""
    if total > MAX_PAIRS:
        raise ValueError(
            f"weld tolerance {tol:g} is too coarse for this mesh: {total:,} vertex pairs fall "
            f"within a cell of each other (limit {MAX_PAIRS:,}); {why}"
        )
