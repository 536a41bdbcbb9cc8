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
(the exact nearest-triangle query of :mod:`formgraph.kernels.geometry.meshdist`, the one
``attr.transfer`` uses) and interpolates there by barycentric weights, and gives each new
face the old face nearest its centroid.

A ``normal`` attribute (three components) is a direction, not a position: :func:`turn`
maps it by the inverse transpose of the linear part and renormalizes it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
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


def _apply_all(data: Mapping[str, np.ndarray], rule: Carry) -> dict[str, np.ndarray]:
    out = {}
    for name, a in data.items():
        b = rule.apply(a)
        if b is not None:
            out[name] = b
    return out


def carried(source: Any, point: Carry = SAME, face: Carry = DROP) -> dict[str, Any]:
    """Keyword arguments ``point_data`` (and ``face_data`` for a mesh) for the output of an
    operation on ``source`` (a Points or a Mesh), by the two rules."""
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
    from ..geometry.meshdist import Nearest

    face_of = np.repeat(np.arange(source.n_faces), np.diff(source.face_offsets) - 2)
    closest = Nearest(sv[triangles])
    p = np.asarray(vertices, np.float64).reshape(-1, 3)
    if pd and len(p):
        _, tri, v, w = closest.locate(p)
        point = barycentric(triangles[tri], np.column_stack([v, w]))
    fi, fo = (np.asarray(x, np.int64) for x in faces)
    if fd and fo.size > 1:
        centre = np.add.reduceat(p[fi], fo[:-1]) / np.diff(fo)[:, None]
        face = copy(face_of[closest.nearest(centre)[1]])
    return carried(source, point, face)
