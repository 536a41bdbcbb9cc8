"""Flat faces a smooth blend pushed outward: how far a blended surface passes the planes of
its inputs' flat faces where the sharp shape does not.

A smooth union (``min(a, b) - h^2 k / 4``, :func:`formgraph.kernels.field.sdf.smooth_min`)
adds material wherever two operands are within ``k`` of each other, also where both lie
on one side of a shared plane: four blocks standing on z = 0 and touching get a ridge
under each seam that passes the bed by up to ``k / 4`` (more where several meet), which
only a slicer notices. A fillet in a concave corner passes the plane of a face as well (a
post on a plate is filleted above the plate's top), but there the sharp shape itself goes
on beyond that plane. So the test, per plane of an input's flat face (outward normal
``n``, offset ``c``):

1. the vertices of the blended mesh beyond the plane by more than ``tol``;
2. if one of them is untouched by the blend (the sharp field equals the blended one
   there, so the vertex is on the sharp surface) the sharp shape crosses the plane: the
   face does not bound it, nothing is reported;
3. otherwise each is projected onto the sharp surface (Newton steps ``p - f grad f /
   |grad f|^2``, exact in one step for a distance field); if a foot is beyond the plane the
   sharp shape crosses it there (a bump the blend swallowed): nothing is reported;
4. else the plane bounded the sharp shape and the blend moved its face: the largest
   excess, where, and how many vertices pass.

Untouched vertices are found exactly (the blend is ``min`` bit for bit where the operands
differ by ``k`` or more), so the test costs two field evaluations a vertex plus the
projection of the few vertices of a bulge.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["Overshoot", "coplanar_faces", "overshoots", "project"]


@dataclass(frozen=True)
class Overshoot:
    """A flat face pushed past its plane: ``normal`` (3,) outward, ``offset`` (the plane
    ``normal . p = offset``), ``excess`` (the farthest vertex's distance beyond it),
    ``where`` (3,) that vertex, ``count`` (vertices beyond by more than the tolerance)."""

    normal: np.ndarray
    offset: float
    excess: float
    where: np.ndarray
    count: int


def project(
    value: Callable[[np.ndarray], np.ndarray], points: np.ndarray, step: float, iterations: int = 2
) -> np.ndarray:
    """Points (n, 3) moved onto the zero set of ``value`` by Newton steps along its gradient
    (forward differences of ``step``): ``p - f(p) g / |g|^2``. One step is exact for a
    Euclidean distance whose gradient is defined at ``p``; a second settles a bound (an
    intersection's value, less than the distance, stops short: the foot stays outside)."""
    p = np.array(points, dtype=np.float64)
    for _ in range(iterations):
        around = value((p[:, None, :] + np.vstack([np.zeros(3), np.eye(3) * step])).reshape(-1, 3))
        around = around.reshape(len(p), 4)
        f, g = around[:, 0], (around[:, 1:] - around[:, :1]) / step
        g2 = np.einsum("ij,ij->i", g, g)
        ok = g2 > 1e-24
        p[ok] -= (f[ok] / g2[ok])[:, None] * g[ok]
    return p


def _outermost(normals: np.ndarray, offsets: np.ndarray, tol: float) -> np.ndarray:
    """Indices of the planes kept when parallel planes within ``tol`` of each other are one
    (the outermost of them: the others do not bound the shape by more than ``tol``)."""
    key = np.round(normals, 9)
    order = np.lexsort((-offsets, *key.T[::-1]))
    same = (key[order][1:] == key[order][:-1]).all(axis=1)
    close = offsets[order][:-1] - offsets[order][1:] <= tol
    return order[np.concatenate([[True], ~(same & close)])]


def _rows(planes: int) -> int:
    """Points a block, so a (points x planes) table stays near 4M numbers."""
    return max(1, 4_000_000 // max(planes, 1))


def _along(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """``points @ normals.T`` (points, planes) without BLAS, whose threads cost more than
    the product for an inner size of 3."""
    return np.einsum("ij,kj->ik", points, normals)


def _max_along(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Per plane, the largest ``n . p`` over ``points`` (-inf when there are none)."""
    best, rows = np.full(len(normals), -np.inf), _rows(len(normals))
    for i in range(0, len(points), rows):
        best = np.maximum(best, _along(points[i : i + rows], normals).max(axis=0))
    return best


def _past_any(points: np.ndarray, normals: np.ndarray, offsets: np.ndarray, tol: float):
    """Which points are past at least one plane by more than ``tol``."""
    rows = _rows(len(normals))
    return np.concatenate(
        [np.zeros(0, dtype=bool)]
        + [
            (_along(points[i : i + rows], normals) - offsets > tol).any(axis=1)
            for i in range(0, len(points), rows)
        ]
    )


def overshoots(
    vertices: np.ndarray,
    sharp: Callable[[np.ndarray], np.ndarray],
    normals: np.ndarray,
    offsets: np.ndarray,
    tol: float,
) -> list[Overshoot]:
    """The planes whose face bounded the sharp shape and which the blended surface passes.

    Parameters
    ----------
    vertices : (n, 3) float
        The blended field's mesh (its vertices on the blended zero set, to ``tol / 100``).
    sharp : callable
        The same recipe with its smooth unions sharp: points (m, 3) -> (m,) values.
    normals, offsets : (p, 3) float, (p,) float
        Candidate planes ``n . x = c``, ``n`` unit and outward (the inputs' flat faces);
        parallel ones within ``tol`` count once.
    tol : float
        How far past a plane counts (> 0).

    Returns
    -------
    list[Overshoot]
        Largest excess first.

    Notes
    -----
    Only the vertices past some plane are looked at. One whose sharp value is within
    ``tol / 20`` of zero is on the sharp surface too (the blend moved it less than that):
    the sharp shape crosses each plane it is past. The others are projected onto the sharp
    surface, and a foot that lands on it (its value within ``tol / 2`` of zero; near an
    edge a difference step can overshoot into the empty side) past a plane shows the sharp
    shape crossing that plane as well.
    """
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    c = np.asarray(offsets, dtype=np.float64).reshape(-1)
    if not len(v) or not len(n):
        return []
    keep = _outermost(n, c, tol)
    n, c = n[keep], c[keep]
    p = v
    # a plane inside the shape (a face the union covers) is crossed over a wide area: a
    # sample of the vertices past the planes dismisses most, then all are looked at
    for stride in (max(1, len(v) // 4096), 1):
        p = p[_past_any(p, n, c, tol)]
        if not len(p):
            return []
        look = np.zeros(len(p), dtype=bool)
        look[::stride] = True
        on_sharp = np.zeros(len(p), dtype=bool)
        on_sharp[look] = np.abs(sharp(p[look])) <= tol / 20
        crossed = _max_along(p[on_sharp], n) - c > tol
        n, c = n[~crossed], c[~crossed]
        p = p[~on_sharp]
        if not len(n):
            return []
    p = p[_past_any(p, n, c, tol)]
    if not len(p):
        return []
    feet = project(sharp, p, step=tol / 4)
    landed = np.abs(sharp(feet)) <= tol / 2
    foot_past = np.zeros(len(n), dtype=bool)
    excess, worst = np.full(len(n), -np.inf), np.zeros(len(n), dtype=np.int64)
    count = np.zeros(len(n), dtype=np.int64)
    rows = _rows(len(n))
    for i in range(0, len(p), rows):
        j = slice(i, i + rows)
        d = _along(p[j], n) - c
        beyond = d > tol
        foot_past |= (beyond & landed[j, None] & (_along(feet[j], n) - c > tol)).any(axis=0)
        count += beyond.sum(axis=0)
        k = d.argmax(axis=0)
        m = d[k, np.arange(len(n))]
        better = m > excess
        excess[better], worst[better] = m[better], k[better] + i
    found = [
        Overshoot(n[k], float(c[k]), float(excess[k]), p[worst[k]], int(count[k]))
        for k in np.flatnonzero(~foot_past & (count > 0))
    ]
    return sorted(found, key=lambda o: -o.excess)


def coplanar_faces(
    corners: np.ndarray, min_share: float = 0.01, angle: float = 1e-4
) -> tuple[np.ndarray, np.ndarray]:
    """The planes of a triangle mesh's flat faces: coplanar triangles grouped, kept when
    together they hold at least ``min_share`` of the area.

    Parameters
    ----------
    corners : (t, 3, 3) float
        Triangles.
    min_share : float
        The smallest share of the total area a flat face has.
    angle : float
        Normals and offsets (relative to the mesh's size) are grouped at this resolution.

    Returns
    -------
    normals : (p, 3) float
        Unit outward normals (counter-clockwise triangles).
    offsets : (p,) float
        ``normal . x`` on each plane.
    """
    t = np.asarray(corners, dtype=np.float64).reshape(-1, 3, 3)
    cross = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    keep = double_area > 0
    if not keep.any():
        return np.zeros((0, 3)), np.zeros(0)
    normal = cross[keep] / double_area[keep, None]
    offset = np.einsum("ij,ij->i", normal, t[keep, 0])
    size = float(np.ptp(t.reshape(-1, 3), axis=0).max()) or 1.0
    key = np.column_stack([np.round(normal / angle), np.round(offset / (angle * size))])
    _, group, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    area = np.bincount(inverse.reshape(-1), weights=double_area[keep])
    big = area >= min_share * double_area.sum()
    return normal[group[big]], offset[group[big]]
