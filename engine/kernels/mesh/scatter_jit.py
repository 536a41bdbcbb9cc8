"""The compiled loop of :func:`formgraph.kernels.mesh.scatter.poisson_disk` (numba, cached
on disk): dart throwing on a hashed grid.

Imported only when a Poisson-disk set is asked for, so ``import formgraph`` never pays for
numba. At module level so numba's on-disk cache finds it again in a new process.
"""

from __future__ import annotations

import numba as nb
import numpy as np

_MIX = np.uint64(0x9E3779B97F4A7C15)  # Fibonacci hashing (Knuth, TAOCP 6.4)


@nb.njit(cache=True, inline="always")
def _slot(i, j, k, shift):
    key = np.uint64((i * 73856093) ^ (j * 19349663) ^ (k * 83492791))
    return np.int64((key * _MIX) >> np.uint64(shift))


@nb.njit(cache=True, nogil=True)
def throw(points, spacing, origin, taken):
    """Take ``points`` (n, 3) in order, each unless it lies closer than ``spacing`` to one
    taken before it; set ``taken`` (n,) bool for the taken ones, return their count.

    The grid's cells are ``spacing`` wide, so the points within ``spacing`` of a point lie
    in the 3 x 3 x 3 cells round its own; each occupied cell heads a linked list of its
    taken points, found through an open-addressing hash table of cells."""
    n = len(points)
    bits = 4
    while (1 << bits) < 2 * n + 16:
        bits += 1
    size = 1 << bits
    mask = size - 1
    shift = 64 - bits
    cell = np.empty((size, 3), np.int64)
    head = np.full(size, -1, np.int64)  # a slot's first taken point, -1: an empty slot
    after = np.full(n, -1, np.int64)  # the next taken point of the same cell
    s2 = spacing * spacing
    h = spacing * (1.0 + 1e-12)  # every point nearer than the spacing is in the 27 cells
    count = 0
    for q in range(n):
        px, py, pz = points[q, 0], points[q, 1], points[q, 2]
        ci = np.int64(np.floor((px - origin[0]) / h))
        cj = np.int64(np.floor((py - origin[1]) / h))
        ck = np.int64(np.floor((pz - origin[2]) / h))
        free = True
        for d in range(27):
            i, j, k = ci + d // 9 - 1, cj + (d // 3) % 3 - 1, ck + d % 3 - 1
            s = _slot(i, j, k, shift)
            while head[s] >= 0:
                if cell[s, 0] == i and cell[s, 1] == j and cell[s, 2] == k:
                    o = head[s]
                    while o >= 0:
                        x, y, z = points[o, 0] - px, points[o, 1] - py, points[o, 2] - pz
                        if x * x + y * y + z * z < s2:
                            free = False
                            break
                        o = after[o]
                    break
                s = (s + 1) & mask
            if not free:
                break
        if not free:
            continue
        s = _slot(ci, cj, ck, shift)
        while head[s] >= 0 and not (cell[s, 0] == ci and cell[s, 1] == cj and cell[s, 2] == ck):
            s = (s + 1) & mask
        if head[s] < 0:
            cell[s, 0], cell[s, 1], cell[s, 2] = ci, cj, ck
        after[q] = head[s]
        head[s] = q
        taken[q] = True
        count += 1
    return count
