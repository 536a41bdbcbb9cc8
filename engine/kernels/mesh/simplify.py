"""Fewer triangles: quadric decimation, through fast-simplification.

* :func:`decimate`: Garland & Heckbert's quadric error metric edge collapse ("Surface
  simplification using quadric error metrics", SIGGRAPH 1997) as fast-simplification
  implements it (Fast-Quadric-Mesh-Simplification, C++; the collapse order by threshold
  sweeps, not a global heap).

It takes and gives triangles (callers triangulate polygons first) and reports, never
hides, a closed input that came out open (:class:`OpenedError`); :func:`is_closed` is
shared with the remesher (:mod:`.remesh`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["OpenedError", "decimate", "is_closed"]


class OpenedError(ValueError):
    """A closed mesh came out with open or non-manifold edges."""


def is_closed(triangles: np.ndarray) -> bool:
    """Every undirected edge is used by exactly two triangles."""
    t = np.asarray(triangles, dtype=np.int64)
    if not len(t):
        return False
    a, b = t.reshape(-1), t[:, [1, 2, 0]].reshape(-1)
    n = int(t.max()) + 1
    k = np.sort(np.minimum(a, b) * n + np.maximum(a, b))
    # every key exactly twice: equal in pairs, and each pair unlike the next
    if k.size % 2 or not (k[0::2] == k[1::2]).all():
        return False
    return bool((k[2::2] != k[1:-1:2]).all())


def _compact(v: np.ndarray, t: np.ndarray):
    """Drop degenerate triangles (a repeated corner) and unused vertices."""
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    used = np.zeros(len(v), dtype=bool)
    used[t] = True
    new = np.cumsum(used) - 1
    return v[used], new[t]


def _collapse_zero_edges(v: np.ndarray, t: np.ndarray):
    """Finish the collapses the library left undone: an edge whose two ends are at one
    point (as float32) is merged into its lower end, its two triangles dropped."""
    key = v.astype(np.float32)
    for _ in range(8):  # chains of such edges shorten by one link a pass
        e = np.stack([t, np.roll(t, -1, axis=1)], axis=2).reshape(-1, 2)
        zero = (key[e[:, 0]] == key[e[:, 1]]).all(axis=1) & (e[:, 0] != e[:, 1])
        if not zero.any():
            break
        lo, hi = e[zero].min(axis=1), e[zero].max(axis=1)
        target = np.arange(len(v))
        np.minimum.at(target, hi, lo)
        t = target[t]
        t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    return _compact(v, t)


def decimate(
    vertices: np.ndarray, triangles: np.ndarray, target_faces: int, aggression: float = 7.0
):
    """Quadric-error decimation to about ``target_faces`` triangles.

    Returns ``vertices (k, 3)``, ``triangles (m, 3)``; raises :class:`OpenedError` when a
    closed input comes out open (a collapse made a non-manifold edge).
    """
    import fast_simplification

    # the extension refuses read-only (frozen) arrays: copies of those only (it leaves its
    # inputs as they were)
    v = np.require(vertices, dtype=np.float64, requirements=["C", "W"])
    t = np.require(triangles, dtype=np.int64, requirements=["C", "W"])
    if target_faces >= len(t):
        return v.copy(), t.copy()
    reduction = 1.0 - target_faces / len(t)
    out_v, out_t = fast_simplification.simplify(v, t, target_reduction=reduction, agg=aggression)
    out_v, out_t = _collapse_zero_edges(np.asarray(out_v, np.float64), np.asarray(out_t, np.int64))
    # the checks look at the (small) result first, and at the input only when the result
    # fails one: whether that is a defect depends on whether the input was closed
    if not is_closed(out_t):
        if is_closed(t):
            raise OpenedError(
                f"decimating to {len(out_t)} triangles opened the closed mesh; ask for more faces"
            )
        return out_v, out_t
    pinched = len(out_v) - len(np.unique(out_v.astype(np.float32), axis=0))
    if pinched and is_closed(t):
        # two vertices at one point (as float32, an STL's precision): closed by its
        # indices, but a file of coordinates welds them into a non-manifold vertex
        raise OpenedError(
            f"decimating to {len(out_t)} triangles pinched the surface at {pinched} "
            f"point{'s' if pinched > 1 else ''} (two vertices at one position); ask for more "
            "faces"
        )
    return out_v, out_t
