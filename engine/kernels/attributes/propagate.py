"""How attributes follow an operation: one rule per domain, applied by one function.

Every operation that makes new elements from old ones says, for points and for faces, how
each new element comes from the old: the same elements (``SAME``), a copy of one source
element each (:func:`copy`), a weighted mix of several (:func:`mix`, the operation's own
interpolation weights), or nothing (``DROP``). :func:`carried` applies the rules to every
attribute of a value at once, so a node declares its rules and gets every attribute right
without a line of bookkeeping (as Blender's nodes declare attribute propagation).

Subdivision is the one case where the weights are the operation itself: its kernels take
extra columns beside the coordinates (:func:`columns` / :func:`split_columns`), so point
attributes follow exactly the same stencils as the points.

A surface made anew from another (decimated, remeshed, offset) has no operation weights
to follow: :func:`onto` finds for each new point the closest point of the old surface
(an exact nearest-triangle query) and interpolates there by barycentric weights, and gives
each new face the old face nearest its centroid.

A ``normal`` attribute (three components) is a direction, not a position: :func:`turn`
maps it by the inverse transpose of the linear part and renormalizes it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "DROP",
    "SAME",
    "Carry",
    "barycentric",
    "by_position",
    "carried",
    "columns",
    "concat",
    "copy",
    "mix",
    "onto",
    "split_columns",
    "turn",
]

NORMAL = "normal"


@dataclass(frozen=True)
class Carry:
    """Where each output element of one domain comes from.

    Attributes
    ----------
    kind : str
        ``same``, ``copy``, ``mix``, ``barycentric`` or ``drop``.
    index : (m,) int or (k,) int or (m, 3) int, optional
        ``copy``: the source of each output element, -1 for none (it gets 0). ``mix``: the
        source of each term. ``barycentric``: each output element's three corners a, b, c.
    row, weight : (k,) int, (k,) float or (m, 2) float, optional
        ``mix``: the output element and the weight of each term. ``barycentric``: (v, w),
        the output being ``a + v (b - a) + w (c - a)``.
    size : int
        ``mix``: the number of output elements.
    """

    kind: str
    index: np.ndarray | None = None
    row: np.ndarray | None = None
    weight: np.ndarray | None = None
    size: int = 0

    def apply(self, a: np.ndarray) -> np.ndarray | None:
        """The output elements' values of one attribute ``a`` (n,) or (n, k)."""
        if self.kind == "same":
            return a
        if self.kind == "drop":
            return None
        if self.kind == "copy":
            idx = self.index
            if idx.size and idx.min() < 0:
                out = np.zeros((idx.size,) + a.shape[1:])
                ok = idx >= 0
                out[ok] = a[idx[ok]]
                return out
            return a[idx]
        if self.kind == "barycentric":  # a constant stays exact: b - a = c - a = 0
            i, (v, w) = self.index, self.weight.T
            shape = (len(i),) + (1,) * (a.ndim - 1)
            base = a[i[:, 0]]
            return (
                base
                + v.reshape(shape) * (a[i[:, 1]] - base)
                + w.reshape(shape) * (a[i[:, 2]] - base)
            )
        flat = a.reshape(len(a), -1)
        out = np.empty((self.size, flat.shape[1]))
        for c in range(flat.shape[1]):
            out[:, c] = np.bincount(self.row, self.weight * flat[self.index, c], self.size)
        return out.reshape((self.size,) + a.shape[1:])


SAME = Carry("same")
DROP = Carry("drop")


def copy(index: Any) -> Carry:
    """Each output element a copy of source element ``index[j]`` (-1: none, it gets 0)."""
    return Carry("copy", index=np.asarray(index, dtype=np.int64))


def mix(row: Any, index: Any, weight: Any, size: int) -> Carry:
    """Output element ``row[t]`` gets ``weight[t] * source[index[t]]`` for every term t."""
    return Carry(
        "mix",
        index=np.asarray(index, dtype=np.int64),
        row=np.asarray(row, dtype=np.int64),
        weight=np.asarray(weight, dtype=np.float64),
        size=int(size),
    )


def barycentric(corners: Any, vw: Any) -> Carry:
    """Each output element ``a + v (b - a) + w (c - a)`` of source elements ``corners[j]``
    = (a, b, c) with ``vw[j]`` = (v, w): exact for a constant, and for an attribute linear
    over the triangle up to rounding."""
    return Carry(
        "barycentric",
        index=np.asarray(corners, dtype=np.int64).reshape(-1, 3),
        weight=np.asarray(vw, dtype=np.float64).reshape(-1, 2),
    )


def _apply_all(
    data: Mapping[str, np.ndarray], rule: Carry | Callable[[], Carry]
) -> dict[str, np.ndarray]:
    if not data:
        return {}  # nothing to carry: the rule is not even made
    if not isinstance(rule, Carry):
        rule = rule()
    out = {}
    for name, a in data.items():
        b = rule.apply(a)
        if b is not None:
            out[name] = b
    return out


def carried(
    source: Any,
    point: Carry | Callable[[], Carry] = SAME,
    face: Carry | Callable[[], Carry] = DROP,
) -> dict[str, Any]:
    """Keyword arguments ``point_data`` (and ``face_data`` for a mesh) for the output of an
    operation on ``source`` (a Points or a Mesh), by the two rules.

    A rule that costs work to find (weld's provenance by position: a sort of every vertex)
    may be given as a function making it: it is called only when ``source`` has attributes
    of that kind to carry.
    """
    out = {"point_data": _apply_all(source.point_data, point)}
    if hasattr(source, "face_data"):
        out["face_data"] = _apply_all(source.face_data, face)
    return out


def concat(
    maps: Sequence[Mapping[str, np.ndarray]], sizes: Sequence[int]
) -> tuple[dict[str, np.ndarray], list[str]]:
    """The attributes of several inputs laid end to end (``merge``, ``union``, copies).

    An attribute that some inputs lack is 0 on their elements; one whose shape differs
    between inputs cannot be joined and is left out.

    Returns
    -------
    data : dict
    dropped : list of str
        The names left out because their shapes disagree.
    """
    shapes: dict[str, tuple[int, ...]] = {}
    dropped: set[str] = set()
    for m in maps:
        for name, a in m.items():
            if shapes.setdefault(name, a.shape[1:]) != a.shape[1:]:
                dropped.add(name)
    out = {}
    for name, tail in shapes.items():
        if name in dropped:
            continue
        parts = [
            m[name] if name in m else np.zeros((n,) + tail)
            for m, n in zip(maps, sizes, strict=True)
        ]
        out[name] = np.concatenate(parts) if parts else np.zeros((0,) + tail)
    return out, sorted(dropped)


def turn(data: Mapping[str, np.ndarray], linear: np.ndarray, which: Any = None) -> dict:
    """``data`` with its ``normal`` attribute turned by the linear map(s) ``linear``.

    Parameters
    ----------
    linear : (3, 3) or (c, 3, 3) float
        One map, or one per copy.
    which : (n,) int, optional
        With one map per copy: the copy each element belongs to.
    """
    n = data.get(NORMAL)
    if n is None or n.ndim != 2 or n.shape[1] != 3:
        return dict(data)
    lin = np.asarray(linear, dtype=np.float64)
    if lin.ndim == 2:
        inv_t = np.linalg.inv(lin).T
        out = n @ inv_t.T
    else:
        inv_t = np.transpose(np.linalg.inv(lin), (0, 2, 1))
        out = np.einsum("nij,nj->ni", inv_t[which], n)
    length = np.linalg.norm(out, axis=1, keepdims=True)
    out = np.divide(out, length, out=np.zeros_like(out), where=length > 0)
    return {**data, NORMAL: out}


def columns(vertices: np.ndarray, data: Mapping[str, np.ndarray]) -> np.ndarray:
    """The vertices with every point attribute's components as extra columns (n, 3 + k)."""
    if not data:
        return np.asarray(vertices, dtype=np.float64)
    n = len(vertices)
    return np.column_stack([vertices] + [a.reshape(n, -1) for a in data.values()])


def split_columns(
    stacked: np.ndarray, data: Mapping[str, np.ndarray]
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Undo :func:`columns` on a kernel's output: (vertices (m, 3), attributes), each
    copied once into a read-only array on an immutable buffer, which the Mesh keeps as it
    is (no second copy)."""
    stacked = np.ascontiguousarray(stacked, dtype=np.float64)
    out, at = {}, 3
    m = len(stacked)
    for name, a in data.items():
        k = int(np.prod(a.shape[1:], dtype=np.int64))
        out[name] = _block(stacked, at, k).reshape((m,) + a.shape[1:])
        at += k
    return _block(stacked, 0, 3), out


def _block(stacked: np.ndarray, at: int, k: int) -> np.ndarray:
    """Columns ``at:at + k`` of a C-ordered float64 array as a frozen (m, k) array: each
    row's k values are one item of a strided view, written straight into ``bytes`` (a
    strided block's own copy goes value by value, several times slower)."""
    m, d = stacked.shape
    if k == d:
        raw = stacked.tobytes()
    else:
        rows = np.ndarray(
            (m,), np.dtype((np.void, 8 * k)), buffer=stacked, offset=8 * at, strides=(8 * d,)
        )
        raw = rows.tobytes()
    return np.frombuffer(raw, dtype=np.float64).reshape(m, k)


def by_position(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """For each target point, the first source point at exactly the same coordinates, or
    -1: the provenance of operations that keep or repeat vertices (weld, compaction)."""
    src = np.ascontiguousarray(np.asarray(source, np.float64) + 0.0)
    tgt = np.ascontiguousarray(np.asarray(target, np.float64) + 0.0)
    if len(src) == 0 or len(tgt) == 0:
        return np.full(len(tgt), -1, dtype=np.int64)
    row = np.dtype((np.void, 24))
    s = src.view(row).reshape(-1)
    t = tgt.view(row).reshape(-1)
    order = np.argsort(s, kind="stable")  # the first of equal rows stays first
    ss = s[order]
    pos = np.minimum(np.searchsorted(ss, t), len(ss) - 1)
    found = ss[pos] == t
    return np.where(found, order[pos], -1)


def _dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", x, y)


class _Closest:
    """The closest point of a set of triangles ``corners`` (t, 3, 3) to many points: the
    nearest triangle and the point's barycentric (v, w) there, exactly.

    Each point looks at the triangles of its k nearest centres (scipy's cKDTree): the
    ``FIRST`` nearest exactly, then only those whose centre distance less their own reach
    (centre to farthest corner) could still beat the best so far. The best is certain when
    the last candidate's centre is farther than the best distance plus the largest reach
    of all (no other triangle can come nearer); a point left uncertain tries a larger k
    (``CANDIDATES``), and the few left after that go through ``field.meshdist.Nearest``'s
    exact tree.
    """

    CANDIDATES = (32, 128)  # per round
    FIRST = 4
    CHUNK = 1 << 14  # points per round: bounds the (point, candidate) pairs held at once

    def __init__(self, corners: np.ndarray):
        from scipy.spatial import cKDTree

        self.corners = corners
        self.a = corners[:, 0]
        self.e1, self.e2 = corners[:, 1] - self.a, corners[:, 2] - self.a
        self.aa, self.ab = _dot(self.e1, self.e1), _dot(self.e1, self.e2)
        self.bb = _dot(self.e2, self.e2)
        centre = corners.mean(axis=1)
        self.reach = np.linalg.norm(corners - centre[:, None], axis=2).max(axis=1)
        self.max_reach = float(self.reach.max())
        self.centres = cKDTree(centre)
        self.exact: Any = None  # the tree, built if a point needs it

    def pairs(self, p: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, ...]:
        """Distances and (v, w) from points ``p`` to triangles ``tri``, pair by pair."""
        from ..field.meshdist import _triangle_coefficients

        ap, e1, e2 = p - self.a[tri], self.e1[tri], self.e2[tri]
        v, w = _triangle_coefficients(
            _dot(e1, ap), _dot(e2, ap), self.aa[tri], self.ab[tri], self.bb[tri]
        )
        bad = ~(np.isfinite(v) & np.isfinite(w))
        if bad.any():  # no area and no edge to follow: the nearest corner alone
            far = np.linalg.norm(p[bad, None, :] - self.corners[tri[bad]], axis=2)
            best = np.argmin(far, axis=1)
            v[bad], w[bad] = best == 1, best == 2
        dist = np.linalg.norm(ap - v[:, None] * e1 - w[:, None] * e2, axis=1)
        return dist, v, w

    def query(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tri, v, w) of each point's closest point."""
        n = len(points)
        tri, v, w = np.empty(n, np.int64), np.empty(n), np.empty(n)
        for s in range(0, n, self.CHUNK):
            at = np.arange(s, min(s + self.CHUNK, n))
            for k in self.CANDIDATES:  # more candidates for the points still uncertain
                at = self._round(points, at, min(k, len(self.corners)), tri, v, w)
                if not at.size:
                    break
            if at.size:
                if self.exact is None:
                    from ..field.meshdist import Nearest

                    self.exact = Nearest(self.corners)
                t = self.exact.nearest(points[at])[1]
                tri[at] = t
                _, v[at], w[at] = self.pairs(points[at], t)
        return tri, v, w

    def _round(self, points, at, k, tri, v, w) -> np.ndarray:
        """The best of ``k`` candidates for the points ``at``; returns those uncertain."""
        p = points[at]
        first = min(self.FIRST, k)
        dc, cand = self.centres.query(p, k)
        dc, cand = dc.reshape(len(p), k), cand.reshape(len(p), k)
        dist = np.full((len(p), k), np.inf)
        cv, cw = np.zeros((len(p), k)), np.zeros((len(p), k))
        head = (slice(None), slice(0, first))
        pp = np.repeat(p, first, axis=0)
        dist[head], cv[head], cw[head] = (
            x.reshape(len(p), first) for x in self.pairs(pp, cand[head].ravel())
        )
        bound = dist[head].min(axis=1)
        i, j = np.nonzero(dc[:, first:] - self.reach[cand[:, first:]] < bound[:, None])
        j += first
        dist[i, j], cv[i, j], cw[i, j] = self.pairs(p[i], cand[i, j])
        best = np.argmin(dist, axis=1)
        row = np.arange(len(p))
        tri[at], v[at], w[at] = cand[row, best], cv[row, best], cw[row, best]
        if k == len(self.corners):
            return at[:0]
        return at[dc[:, -1] < dist[row, best] + self.max_reach]


def onto(
    source: Any,
    vertices: np.ndarray,
    faces: tuple[np.ndarray, np.ndarray],
    triangles: np.ndarray | None = None,
    max_tests: int | None = None,
) -> dict[str, Any]:
    """``point_data`` and ``face_data`` for a surface made anew from mesh ``source``.

    Each new vertex takes the point attributes at its closest point of ``source`` (the
    corners of the nearest triangle, by the barycentric weights of that point: a constant
    stays exact, an attribute linear over the triangle stays linear); each new face the
    face attributes of the source face nearest its centroid. Nothing is queried when the
    source has no attributes.

    Parameters
    ----------
    source : Mesh
        The input, with its attributes.
    vertices : (n, 3) float
        The new surface's vertices.
    faces : (face_indices, face_offsets)
        The new surface's faces.
    triangles : (t, 3) int, optional
        ``source``'s faces triangulated (``meshops.triangulate``'s, face by face), when
        the caller has them; else they are made here (``max_tests`` bounds the work).
    """
    pd, fd = source.point_data, source.face_data
    point, face = DROP, DROP
    if not (pd or fd) or source.n_faces == 0:
        return carried(source, point, face)
    from ..mesh.meshops import triangulate

    sv = np.asarray(source.vertices, np.float64)
    if triangles is None:
        _, tfi, _ = triangulate(sv, source.face_indices, source.face_offsets, max_tests)
        triangles = tfi.reshape(-1, 3)
    face_of = np.repeat(np.arange(source.n_faces), np.diff(source.face_offsets) - 2)
    closest = _Closest(sv[triangles])
    p = np.asarray(vertices, np.float64).reshape(-1, 3)
    if pd and len(p):
        tri, v, w = closest.query(p)
        point = barycentric(triangles[tri], np.column_stack([v, w]))
    fi, fo = (np.asarray(x, np.int64) for x in faces)
    if fd and fo.size > 1:
        centre = np.add.reduceat(p[fi], fo[:-1]) / np.diff(fo)[:, None]
        face = copy(face_of[closest.query(centre)[0]])
    return carried(source, point, face)
