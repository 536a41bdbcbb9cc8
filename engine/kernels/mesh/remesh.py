"""Isotropic remeshing (Botsch & Kobbelt 2004), every operation batched over the mesh.

Botsch & Kobbelt, "A remeshing approach to multiresolution modeling" (SGP 2004): to reach
edges of length ``L``, repeat

1. split every edge longer than 4/3 L at its midpoint;
2. collapse every edge shorter than 4/5 L whose collapse makes no edge longer than 4/3 L;
3. flip edges where that brings the four vertices' valences nearer 6 (4 on a boundary);
4. move each vertex toward the centroid of its neighbours, in its tangent plane;
5. project the vertices back onto the input surface.

A loop over edges, one at a time, is what the paper describes; here each step works on all
edges at once. Splits need no care (a triangle with one, two or three split edges is cut
by its template, the same midpoint on both sides of an edge); collapses and flips are done
on an independent set a pass (each claims the vertices round it, and the edge with the
highest priority among those claiming a vertex wins it: Luby's rule), a few passes a
round. A collapse keeps the surface a manifold (the link condition: the ends share only
the edge's opposite vertices), flips no triangle over and makes no edge too long; a flip
makes no edge twice and no triangle fold over.

Feature edges (a dihedral angle over ``feature_angle``, and the boundary) are kept as a
set through every operation: they are split but never flipped, a vertex on one feature
line (two feature edges) moves only along it (collapsed into a neighbour on the line,
projected onto the input's feature edges), and a feature corner (any other count) stays
where it is. So creases stay sharp and boundaries stay where they were. The vertex
positions are projected with :class:`formgraph.kernels.geometry.meshdist.Nearest` (exact
closest points).
"""

from __future__ import annotations

import numpy as np

from .simplify import OpenedError, is_closed

__all__ = ["isotropic_remesh", "vertex_estimate"]

_SHIFT = np.int64(1) << np.int64(32)
# independent sets a round: each pass takes a share of what is left, so a few passes do
# most of it and the next round the rest
PASSES = 12


def _key(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.minimum(a, b) * _SHIFT + np.maximum(a, b)


class _Edges:
    """Undirected edges of triangles ``t`` (m, 3); half-edge ``3 f + k`` runs from corner
    ``k`` of face ``f`` to corner ``k + 1``."""

    def __init__(self, t: np.ndarray):
        a, b = t.reshape(-1), t[:, [1, 2, 0]].reshape(-1)
        key = _key(a, b)
        self.key, self.of_half, count = np.unique(key, return_inverse=True, return_counts=True)
        self.of_half = self.of_half.reshape(-1)
        if (count > 2).any():
            raise ValueError("the mesh has edges on more than two triangles (not a manifold)")
        self.count = count
        self.ends = np.stack([self.key // _SHIFT, self.key % _SHIFT], axis=1)
        order = np.argsort(self.of_half, kind="stable")
        first = np.cumsum(count) - count
        self.half = np.full((len(count), 2), -1, dtype=np.int64)
        self.half[:, 0] = order[first]
        two = count == 2
        self.half[two, 1] = order[first[two] + 1]


def _member(sorted_keys: np.ndarray, keys: np.ndarray) -> np.ndarray:
    """Which of ``keys`` are in ``sorted_keys`` (sorted, unique)."""
    i = np.minimum(np.searchsorted(sorted_keys, keys), max(len(sorted_keys) - 1, 0))
    return (sorted_keys[i] == keys) if len(sorted_keys) else np.zeros(len(keys), bool)


def _normals(v: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])


def _shape(p: np.ndarray, n: np.ndarray | None = None) -> np.ndarray:
    """Twice the area over the longest edge squared of triangles of corners ``p`` (m, 3, 3)
    (``n`` their normals): 0.87 equilateral, 0 a sliver."""
    if n is None:
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    e2 = ((p - p[:, [1, 2, 0]]) ** 2).sum(axis=2).max(axis=1)
    return np.linalg.norm(n, axis=1) / np.maximum(e2, 1e-300)


SLIVER = 0.05  # no operation makes a triangle thinner than this (about 3 degrees)


def _unit(x: np.ndarray) -> np.ndarray:
    return x / np.maximum(np.linalg.norm(x, axis=-1, keepdims=True), 1e-300)


def _vertex_faces(n: int, t: np.ndarray):
    """CSR of the faces round each vertex: ``start (n + 1,)``, ``face (3 m,)``."""
    corner = t.reshape(-1)
    order = np.argsort(corner, kind="stable")
    start = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(corner, minlength=n), out=start[1:])
    return start, order // 3


def _gather(start: np.ndarray, items: np.ndarray, of: np.ndarray):
    """For each entry ``i`` of ``of``, the CSR rows' items: (owner index, item)."""
    counts = start[of + 1] - start[of]
    owner = np.repeat(np.arange(len(of)), counts)
    skip = np.cumsum(counts) - counts
    pos = np.arange(int(counts.sum())) + np.repeat(start[of] - skip, counts)
    return owner, items[pos]


def _independent(n_vertices: int, owner: np.ndarray, vertex: np.ndarray, priority: np.ndarray):
    """Candidates (``priority`` each, distinct) that win every vertex they claim."""
    best = np.full(n_vertices, -np.inf)
    np.maximum.at(best, vertex, priority[owner])
    lost = np.zeros(len(priority), dtype=bool)
    lost[owner[best[vertex] != priority[owner]]] = True
    return ~lost


def _compact(v: np.ndarray, t: np.ndarray, feat: np.ndarray):
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    used = np.zeros(len(v), dtype=bool)
    used[t] = True
    new = np.cumsum(used) - 1
    fa, fb = feat // _SHIFT, feat % _SHIFT
    keep = used[fa] & used[fb]
    return v[used], new[t], np.unique(_key(new[fa[keep]], new[fb[keep]]))


def _features(v: np.ndarray, t: np.ndarray, angle: float) -> np.ndarray:
    """Keys of the boundary edges and of those whose dihedral angle exceeds ``angle``."""
    e = _Edges(t)
    n = _unit(_normals(v, t))
    two = e.count == 2
    cos = np.ones(len(e.key))
    cos[two] = np.einsum("ij,ij->i", n[e.half[two, 0] // 3], n[e.half[two, 1] // 3])
    return e.key[(~two) | (cos < np.cos(np.radians(angle)))]


def _split(v, t, feat, high: float):
    """Split every edge longer than ``high`` at its midpoint (one pass)."""
    e = _Edges(t)
    length = np.linalg.norm(v[e.ends[:, 0]] - v[e.ends[:, 1]], axis=1)
    long = length > high
    if not long.any():
        return v, t, feat, False
    mid = np.full(len(e.key), -1, dtype=np.int64)
    mid[long] = len(v) + np.arange(int(long.sum()))
    v = np.concatenate([v, (v[e.ends[long, 0]] + v[e.ends[long, 1]]) / 2.0])
    # the split feature edges' halves are feature edges
    fs = _member(e.key[long], feat)
    fe = e.ends[np.searchsorted(e.key, feat[fs])]
    fm = mid[np.searchsorted(e.key, feat[fs])]
    feat = np.unique(np.concatenate([feat[~fs], _key(fe[:, 0], fm), _key(fm, fe[:, 1])]))
    m = mid[e.of_half].reshape(-1, 3)  # per face, the midpoint of edge k (k -> k + 1), or -1
    s = m >= 0
    pattern = s.sum(axis=1)
    out = [t[pattern == 0]]
    # one split edge: rotate it to edge 0 (a -> b); then (a, m, c), (m, b, c)
    f = np.flatnonzero(pattern == 1)
    r = np.argmax(s[f], axis=1)
    tt, mm = _rotate(t[f], m[f], r)
    out += [
        np.stack([tt[:, 0], mm[:, 0], tt[:, 2]], 1),
        np.stack([mm[:, 0], tt[:, 1], tt[:, 2]], 1),
    ]
    # two: rotate the unsplit edge to edge 2 (c -> a); the quad (a, m0, m1, c) is cut
    # along its shorter diagonal
    f = np.flatnonzero(pattern == 2)
    r = (np.argmin(s[f], axis=1) + 1) % 3
    tt, mm = _rotate(t[f], m[f], r)
    a, b, c, m0, m1 = tt[:, 0], tt[:, 1], tt[:, 2], mm[:, 0], mm[:, 1]
    out.append(np.stack([m0, b, m1], 1))
    d_am1 = np.linalg.norm(v[a] - v[m1], axis=1)
    d_m0c = np.linalg.norm(v[m0] - v[c], axis=1)
    q = d_am1 <= d_m0c
    out += [
        np.stack([a[q], m0[q], m1[q]], 1),
        np.stack([a[q], m1[q], c[q]], 1),
        np.stack([a[~q], m0[~q], c[~q]], 1),
        np.stack([m0[~q], m1[~q], c[~q]], 1),
    ]
    # three: four triangles
    f = np.flatnonzero(pattern == 3)
    a, b, c = t[f].T
    m0, m1, m2 = m[f].T
    out += [
        np.stack([a, m0, m2], 1),
        np.stack([m0, b, m1], 1),
        np.stack([m2, m1, c], 1),
        np.stack([m0, m1, m2], 1),
    ]
    return v, np.concatenate(out), feat, True


def _rotate(t: np.ndarray, m: np.ndarray, r: np.ndarray):
    """Corners and edge midpoints of faces turned so corner ``r`` comes first."""
    k = (r[:, None] + np.arange(3)[None, :]) % 3
    rows = np.arange(len(t))[:, None]
    return t[rows, k], m[rows, k]


def _kinds(n: int, feat: np.ndarray) -> np.ndarray:
    """Per vertex: 0 free, 1 on one feature line (two feature edges), 2 a corner."""
    count = np.bincount(np.concatenate([feat // _SHIFT, feat % _SHIFT]), minlength=n)
    return np.where(count == 0, 0, np.where(count == 2, 1, 2))


def _collapse(v, t, feat, low: float, high: float, rng):
    """Collapse an independent set of the edges shorter than ``low`` (one pass)."""
    n = len(v)
    e = _Edges(t)
    a, b = e.ends[:, 0], e.ends[:, 1]
    length = np.linalg.norm(v[a] - v[b], axis=1)
    kind = _kinds(n, feat)
    is_feat = _member(feat, e.key)
    ka, kb = kind[a], kind[b]
    # which end goes (r) into which (k), and where k ends
    free2 = (ka == 0) & (kb == 0)
    a_goes = (ka == 0) | ((ka == 1) & is_feat & (kb >= 1))
    b_goes = ~a_goes & ((kb == 0) | ((kb == 1) & is_feat & (ka >= 1)))
    ok = (length < low) & (a_goes | b_goes)
    cand = np.flatnonzero(ok)
    if not len(cand):
        return v, t, feat, 0
    # first an independent set on the ends alone (shortest first, ties at random), so the
    # checks below see each vertex's ring at most once
    prio = rng.random(len(cand)) - length[cand] / low
    cand = cand[_independent(n, np.repeat(np.arange(len(cand)), 2), e.ends[cand].reshape(-1), prio)]
    r = np.where(a_goes[cand], a[cand], b[cand])
    k = np.where(a_goes[cand], b[cand], a[cand])
    target = np.where(free2[cand, None], (v[r] + v[k]) / 2.0, v[k])
    start, vf = _vertex_faces(n, t)
    # the faces round either end, each with the candidate it belongs to
    o1, f1 = _gather(start, vf, r)
    o2, f2 = _gather(start, vf, k)
    owner = np.concatenate([o1, o2])
    face = np.concatenate([f1, f2])

    # the link condition: the ends' common neighbours are exactly the edge's opposite
    # corners (as many as it has faces)
    def ring(o, f):
        own = np.repeat(o, 3)
        x = t[f].reshape(-1)
        out = (x != r[own]) & (x != k[own])
        return np.unique(own[out] * np.int64(n) + x[out])

    both = np.intersect1d(ring(o1, f1), ring(o2, f2), assume_unique=True) // n
    ok = np.bincount(both, minlength=len(cand)) == e.count[cand]
    # and no opposite corner is left on two triangles only (back to back: a tetrahedron
    # would collapse into a flat pillow), as OpenMesh's is_collapse_ok refuses
    valence = np.bincount(e.ends.reshape(-1), minlength=n)
    for side in range(2):
        h = e.half[cand, side]
        opp = t.reshape(-1)[np.where(h >= 0, h - h % 3 + (h % 3 + 2) % 3, 0)]
        ok &= (h < 0) | (valence[opp] > 3)
    # after the move: no face round the two ends flips over or grows an edge past high
    moved = np.where(t[face] == r[owner][:, None], k[owner][:, None], t[face])
    keep_face = ~((t[face] == r[owner][:, None]).any(1) & (t[face] == k[owner][:, None]).any(1))
    pos = v[moved]
    pos = np.where((moved == k[owner][:, None])[..., None], target[owner][:, None, :], pos)
    before = _normals(v, t[face])
    after = np.cross(pos[:, 1] - pos[:, 0], pos[:, 2] - pos[:, 0])
    good = np.einsum("ij,ij->i", before, after) > 0.1 * np.linalg.norm(
        before, axis=1
    ) * np.linalg.norm(after, axis=1)
    span = np.linalg.norm(pos - target[owner][:, None, :], axis=2).max(axis=1)
    thin = _shape(pos, after) < np.minimum(SLIVER, _shape(v[t[face]], before))
    bad = keep_face & (~good | (span > high) | thin)
    ok &= np.bincount(owner[bad], minlength=len(cand)) == 0
    # an independent set: each candidate claims every corner of its faces
    prio = rng.random(len(cand)) - length[cand] / low
    prio[~ok] = -np.inf
    win = _independent(n, np.repeat(owner, 3), t[face].reshape(-1), prio) & ok
    if not win.any():
        return v, t, feat, 0
    r, k, target = r[win], k[win], target[win]
    v = v.copy()
    v[k] = target
    remap = np.arange(n)
    remap[r] = k
    t = remap[t]
    fa, fb = remap[feat // _SHIFT], remap[feat % _SHIFT]
    feat = np.unique(_key(fa[fa != fb], fb[fa != fb]))
    v, t, feat = _compact(v, t, feat)
    return v, t, feat, int(win.sum())


def _flip(v, t, feat, boundary_vertex: np.ndarray, rng):
    """Flip an independent set of edges that bring valences nearer 6 (4 on a boundary)."""
    n = len(v)
    e = _Edges(t)
    cand = np.flatnonzero((e.count == 2) & ~_member(feat, e.key))
    h1, h2 = e.half[cand, 0], e.half[cand, 1]
    f1, k1 = h1 // 3, h1 % 3
    f2, k2 = h2 // 3, h2 % 3
    a, b, c = t[f1, k1], t[f1, (k1 + 1) % 3], t[f1, (k1 + 2) % 3]
    d = t[f2, (k2 + 2) % 3]
    val = np.bincount(e.ends.reshape(-1), minlength=n)
    want = np.where(boundary_vertex[:n], 4, 6)
    # the change of sum (valence - want)^2 over the four: -1 at a and b, +1 at c and d
    da, db, dc, dd = (val[x] - want[x] for x in (a, b, c, d))
    gain = 2 * (da + db - dc - dd) - 4
    # the geometry only for those that would help
    s = np.flatnonzero((gain > 0) & (c != d))
    s = s[~_member(e.key, _key(c[s], d[s]))]
    if not len(s):
        return t, 0
    a, b, c, d, f1, f2, gain = a[s], b[s], c[s], d[s], f1[s], f2[s], gain[s]
    # no fold: the new triangles face the way the old pair did, and are not slivers
    n_old = _normals(v, t[f1]) + _normals(v, t[f2])
    t1 = np.stack([a, d, c], 1)
    t2 = np.stack([d, b, c], 1)
    n1, n2 = _normals(v, t1), _normals(v, t2)
    ok = (np.einsum("ij,ij->i", n1, n_old) > 0) & (np.einsum("ij,ij->i", n2, n_old) > 0)
    ok &= np.einsum("ij,ij->i", _unit(n1), _unit(n2)) > 0.5  # no sharp new crease
    was = np.minimum(_shape(v[t[f1]]), _shape(v[t[f2]]))
    ok &= np.minimum(_shape(v[t1], n1), _shape(v[t2], n2)) >= np.minimum(SLIVER, was)
    if not ok.any():
        return t, 0
    prio = gain + rng.random(len(s))
    prio[~ok] = -np.inf
    owner = np.repeat(np.arange(len(s)), 4)
    win = _independent(n, owner, np.stack([a, b, c, d], 1).reshape(-1), prio) & ok
    t = t.copy()
    t[f1[win]] = t1[win]
    t[f2[win]] = t2[win]
    return t, int(win.sum())


def _relax(v, t, kind):
    """Move free vertices to their neighbours' centroid, within their tangent plane."""
    n = len(v)
    e = _Edges(t).ends
    i, j = np.concatenate([e[:, 0], e[:, 1]]), np.concatenate([e[:, 1], e[:, 0]])
    deg = np.bincount(i, minlength=n).astype(float)
    q = np.stack([np.bincount(i, v[j, k], n) for k in range(3)], 1) / np.maximum(deg, 1)[:, None]
    fn = _normals(v, t)
    vn = np.zeros_like(v)
    for k in range(3):
        np.add.at(vn, t[:, k], fn)
    vn = _unit(vn)
    step = q - v
    step -= vn * np.einsum("ij,ij->i", step, vn)[:, None]
    free = kind == 0
    out = v.copy()
    out[free] += step[free]
    return out


def vertex_estimate(vertices: np.ndarray, triangles: np.ndarray, edge_length: float) -> int:
    """The vertices of an equilateral triangulation of the surface with that edge length:
    its area over ``sqrt(3) / 2 * edge_length^2`` (the area per vertex)."""
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    area = 0.5 * np.linalg.norm(_normals(v, t), axis=1).sum()
    return int(round(area / (np.sqrt(3) / 2 * edge_length**2)))


def isotropic_remesh(
    vertices: np.ndarray,
    triangles: np.ndarray,
    edge_length: float,
    iterations: int = 10,
    feature_angle: float = 30.0,
    seed: int = 0,
):
    """Triangles of about ``edge_length`` over the input surface (Botsch & Kobbelt 2004).

    Parameters
    ----------
    vertices : (n, 3) float
    triangles : (m, 3) int
        An edge-manifold triangle mesh (each edge on one or two triangles).
    edge_length : float
        The target edge length, > 0.
    iterations : int
        Rounds of split, collapse, flip, relax and project.
    feature_angle : float
        Edges whose faces meet at more than this (degrees) are kept as creases.
    seed : int
        The tie-breaks of the independent sets (the result is deterministic for a seed).

    Returns
    -------
    vertices : (k, 3) float64
    triangles : (l, 3) int64
        Oriented as the input; closed when the input is.

    Raises
    ------
    ValueError
        On a mesh with an edge on more than two triangles, or not consistently oriented.
    OpenedError
        If a closed input came out open (a defect of this kernel, reported, not hidden).
    """
    from ..geometry.meshdist import Nearest

    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    if not len(t):
        raise ValueError("the mesh has no triangles")
    e = _Edges(t)
    two = e.count == 2
    h = e.half[two]
    if (t.reshape(-1)[h[:, 0]] == t.reshape(-1)[h[:, 1]]).any():
        raise ValueError("the faces are not consistently oriented (two run an edge one way)")
    closed = is_closed(t)
    surface = Nearest(v[t])
    feat = _features(v, t, feature_angle)
    lines = None
    if len(feat):
        lines = Nearest(v[np.stack([feat // _SHIFT, feat % _SHIFT], 1)])
    v, t, feat = _compact(v, t, feat)
    rng = np.random.default_rng(seed)
    high, low = 4.0 / 3.0 * edge_length, 4.0 / 5.0 * edge_length
    for _ in range(iterations):
        for _ in range(6):
            v, t, feat, more = _split(v, t, feat, high)
            if not more:
                break
        for _ in range(PASSES):
            v, t, feat, done = _collapse(v, t, feat, low, high, rng)
            if done <= len(t) // 2000:  # the few left wait for the next round
                break
        e = _Edges(t)
        boundary = np.zeros(len(v), dtype=bool)
        boundary[e.ends[e.count == 1].reshape(-1)] = True
        for _ in range(PASSES):
            t, done = _flip(v, t, feat, boundary, rng)
            if done <= len(t) // 2000:
                break
        kind = _kinds(len(v), feat)
        v = _relax(v, t, kind)
        free = kind == 0
        v[free] = surface.closest(v[free])[0]
        line = kind == 1
        if lines is not None and line.any():
            v[line] = lines.closest(v[line])[0]
    if closed and not is_closed(t):
        raise OpenedError("remeshing opened the closed mesh; try another edge_length")
    return v, t
