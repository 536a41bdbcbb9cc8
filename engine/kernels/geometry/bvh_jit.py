"""The compiled loops of :mod:`formgraph.kernels.geometry.bvh` (numba, cached on disk).

Imported only when a tree is built, so ``import formgraph`` never pays for numba. The
functions live at module level so numba's on-disk cache finds them again in a new process.
"""

from __future__ import annotations

import numba as nb
import numpy as np

_STACK = 256  # a median split halves the count: depth <= 64 for any array numpy can hold

jit = nb.njit(cache=True, nogil=True)
inline = nb.njit(cache=True, inline="always")


@jit
def split(corners, leaf_size):
    m, k = corners.shape[0], corners.shape[1]
    centre = np.empty((m, 3))
    for i in range(m):
        for a in range(3):
            s = 0.0
            for j in range(k):
                s += corners[i, j, a]
            centre[i, a] = s / k
    order = np.arange(m)
    cap = max(2 * m - 1, 1)
    box = np.empty((cap, 6))
    child = np.full(cap, -1, np.int64)
    start = np.zeros(cap, np.int64)
    count = np.zeros(cap, np.int64)
    st_node = np.empty(_STACK, np.int64)
    st_s = np.empty(_STACK, np.int64)
    st_e = np.empty(_STACK, np.int64)
    st_node[0], st_s[0], st_e[0] = 0, 0, m
    top, n_nodes = 1, 1
    while top > 0:
        top -= 1
        node, s, e = st_node[top], st_s[top], st_e[top]
        lo = np.full(3, np.inf)
        hi = np.full(3, -np.inf)
        clo = np.full(3, np.inf)
        chi = np.full(3, -np.inf)
        for q in range(s, e):
            i = order[q]
            for a in range(3):
                for j in range(k):
                    x = corners[i, j, a]
                    lo[a] = min(lo[a], x)
                    hi[a] = max(hi[a], x)
                clo[a] = min(clo[a], centre[i, a])
                chi[a] = max(chi[a], centre[i, a])
        for a in range(3):
            box[node, a] = lo[a]
            box[node, 3 + a] = hi[a]
        start[node], count[node] = s, e - s
        if e - s <= leaf_size:
            continue
        axis = int(np.argmax(chi - clo))
        seg = order[s:e].copy()
        keys = np.empty(e - s)
        for q in range(e - s):
            keys[q] = centre[seg[q], axis]
        idx = np.argsort(keys, kind="mergesort")  # stable: the same tree every run
        for q in range(e - s):
            order[s + q] = seg[idx[q]]
        mid = (s + e) // 2
        child[node] = n_nodes
        st_node[top], st_s[top], st_e[top] = n_nodes, s, mid
        st_node[top + 1], st_s[top + 1], st_e[top + 1] = n_nodes + 1, mid, e
        top += 2
        n_nodes += 2
    return (
        order,
        box[:n_nodes].copy(),
        child[:n_nodes].copy(),
        start[:n_nodes].copy(),
        (count[:n_nodes].copy()),
    )


@jit
def slabs(c, box, start, count):
    """Per node: middle (3), unit axis (3), half-thickness, reach (the tree's order)."""
    n, k = len(box), c.shape[1]
    out = np.zeros((n, 8))
    for node in range(n):
        s, e = start[node], start[node] + count[node]
        ax = np.zeros(3)
        if k == 3:
            for i in range(s, e):
                a0, a1, a2 = (
                    c[i, 1, 0] - c[i, 0, 0],
                    c[i, 1, 1] - c[i, 0, 1],
                    c[i, 1, 2] - c[i, 0, 2],
                )
                b0, b1, b2 = (
                    c[i, 2, 0] - c[i, 0, 0],
                    c[i, 2, 1] - c[i, 0, 1],
                    c[i, 2, 2] - c[i, 0, 2],
                )
                ax[0] += a1 * b2 - a2 * b1
                ax[1] += a2 * b0 - a0 * b2
                ax[2] += a0 * b1 - a1 * b0
        la = np.sqrt(ax[0] ** 2 + ax[1] ** 2 + ax[2] ** 2)
        if la > 0:
            ax /= la  # else 0: the slab is the whole ball
        mid = (box[node, :3] + box[node, 3:]) / 2
        reach, thick = 0.0, 0.0
        for i in range(s, e):
            for j in range(k):
                q0, q1, q2 = c[i, j, 0] - mid[0], c[i, j, 1] - mid[1], c[i, j, 2] - mid[2]
                reach = max(reach, q0 * q0 + q1 * q1 + q2 * q2)
                thick = max(thick, abs(q0 * ax[0] + q1 * ax[1] + q2 * ax[2]))
        out[node, :3] = mid
        out[node, 3:6] = ax
        out[node, 6] = thick
        out[node, 7] = np.sqrt(reach)
    return out


@inline
def segment(p0, p1, p2, a0, a1, a2, e0, e1, e2, aa):
    """Squared distance to the segment a + t e and t."""
    t = 0.0
    if aa > 0.0:
        t = ((p0 - a0) * e0 + (p1 - a1) * e1 + (p2 - a2) * e2) / aa
        t = min(max(t, 0.0), 1.0)
    x, y, z = p0 - a0 - t * e0, p1 - a1 - t * e1, p2 - a2 - t * e2
    return x * x + y * y + z * z, t


@inline
def edges(p0, p1, p2, r):
    """A triangle without area: the nearest of its three edges, as (d2, v, w)."""
    a0, a1, a2 = r[0], r[1], r[2]
    d, t = segment(p0, p1, p2, a0, a1, a2, r[3], r[4], r[5], r[9])
    bv, bw = t, 0.0
    d2, t = segment(p0, p1, p2, a0, a1, a2, r[6], r[7], r[8], r[11])
    if d2 < d:
        d, bv, bw = d2, 0.0, t
    f0, f1, f2 = r[6] - r[3], r[7] - r[4], r[8] - r[5]
    d2, t = segment(
        p0, p1, p2, a0 + r[3], a1 + r[4], a2 + r[5], f0, f1, f2, f0 * f0 + f1 * f1 + f2 * f2
    )
    if d2 < d:
        d, bv, bw = d2, 1.0 - t, t
    return d, bv, bw


@inline
def triangle(p0, p1, p2, r):
    """Squared distance to the triangle of row ``r`` and the closest point's (v, w)
    (Ericson 5.1.5: the first Voronoi region that holds the point wins)."""
    ap0, ap1, ap2 = p0 - r[0], p1 - r[1], p2 - r[2]
    aa, ab, bb = r[9], r[10], r[11]
    d1 = r[3] * ap0 + r[4] * ap1 + r[5] * ap2
    d2 = r[6] * ap0 + r[7] * ap1 + r[8] * ap2
    d3, d4 = d1 - aa, d2 - ab
    d5, d6 = d1 - ab, d2 - bb
    vc = d1 * d4 - d3 * d2
    vb = d5 * d2 - d1 * d6
    va = d3 * d6 - d5 * d4
    if d1 <= 0.0 and d2 <= 0.0:
        v, w = 0.0, 0.0
    elif d3 >= 0.0 and d4 <= d3:
        v, w = 1.0, 0.0
    elif vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v, w = (d1 / (d1 - d3) if d1 > d3 else 0.0), 0.0
    elif d6 >= 0.0 and d5 <= d6:
        v, w = 0.0, 1.0
    elif vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        v, w = 0.0, (d2 / (d2 - d6) if d2 > d6 else 0.0)
    elif va <= 0.0 and d4 >= d3 and d5 >= d6:
        den = (d4 - d3) + (d5 - d6)
        t = (d4 - d3) / den if den > 0.0 else 0.0
        v, w = 1.0 - t, t
    else:
        den = va + vb + vc
        if not den > 0.0:  # no area (collinear corners): the nearest edge
            return edges(p0, p1, p2, r)
        v, w = vb / den, vc / den
    x = ap0 - v * r[3] - w * r[6]
    y = ap1 - v * r[4] - w * r[7]
    z = ap2 - v * r[5] - w * r[8]
    return x * x + y * y + z * z, v, w


@inline
def prim(p0, p1, p2, r, k):
    if k == 3:
        return triangle(p0, p1, p2, r)
    d, t = segment(p0, p1, p2, r[0], r[1], r[2], r[3], r[4], r[5], r[9])
    return d, t, 0.0


@inline
def bound(p0, p1, p2, b, s):
    """Squared lower bound of the distance to what a node holds: the larger of its
    box's and its slab-in-a-ball's."""
    x = max(b[0] - p0, p0 - b[3], 0.0)
    y = max(b[1] - p1, p1 - b[4], 0.0)
    z = max(b[2] - p2, p2 - b[5], 0.0)
    d = x * x + y * y + z * z
    q0, q1, q2 = p0 - s[0], p1 - s[1], p2 - s[2]
    h = abs(q0 * s[3] + q1 * s[4] + q2 * s[5])
    r2 = q0 * q0 + q1 * q1 + q2 * q2 - h * h
    rho = np.sqrt(r2) if r2 > 0.0 else 0.0
    u, v = h - s[6], rho - s[7]
    c = (u * u if u > 0.0 else 0.0) + (v * v if v > 0.0 else 0.0)
    return c if c > d else d


@jit
def walk(points, rows, k, box, slab, child, start, count):
    n = len(points)
    dist = np.empty(n)
    best_prim = np.empty(n, np.int64)
    vv = np.empty(n)
    ww = np.empty(n)
    stack = np.empty(_STACK, np.int64)
    low = np.empty(_STACK)
    for i in range(n):
        p0, p1, p2 = points[i, 0], points[i, 1], points[i, 2]
        best, bp, bv, bw = np.inf, -1, 0.0, 0.0
        if i > 0:  # the previous point's nearest: near, in Morton order
            bp = best_prim[i - 1]
            best, bv, bw = prim(p0, p1, p2, rows[bp], k)
        stack[0], low[0], top = 0, 0.0, 1
        while top > 0:
            top -= 1
            node = stack[top]
            if low[top] >= best:
                continue
            left = child[node]
            if left < 0:
                for j in range(start[node], start[node] + count[node]):
                    d, v, w = prim(p0, p1, p2, rows[j], k)
                    if d < best:
                        best, bp, bv, bw = d, j, v, w
                continue
            right = left + 1
            dl = bound(p0, p1, p2, box[left], slab[left])
            dr = bound(p0, p1, p2, box[right], slab[right])
            if dl > dr:  # the nearer child on top of the stack
                left, right, dl, dr = right, left, dr, dl
            if dr < best:
                stack[top], low[top] = right, dr
                top += 1
            if dl < best:
                stack[top], low[top] = left, dl
                top += 1
        dist[i], best_prim[i], vv[i], ww[i] = np.sqrt(best), bp, bv, bw
    return dist, best_prim, vv, ww
