"""Points scattered on triangles: uniform by area, or a maximal Poisson-disk set.

* :func:`uniform`: each point on a triangle drawn with probability proportional to its
  area, at uniform barycentric coordinates (``sqrt`` of one uniform variable, Osada,
  Funkhouser, Chazelle & Dobkin, "Shape distributions", 2002, section 4.2).
* :func:`poisson_disk`: no two points closer (in space) than ``spacing``, and maximal:
  every point of the surface within about ``spacing`` of one. Dart throwing (Cook 1986;
  on a background grid as Bridson, "Fast Poisson disk sampling in arbitrary dimensions",
  2007): uniform candidates by area (``DENSITY`` per ``spacing^2`` a batch), each taken
  unless a point taken before it is nearer than the spacing, found in the 27 cells of a
  hashed grid of ``spacing`` cells round it (one compiled loop, :mod:`.scatter_jit`).
  ``DARTS`` candidates per ``spacing^2`` of area fill the gaps: every dart is within the
  spacing of a taken point (itself, or the one that kept it out), so a point of the
  surface farther than twice the spacing from every taken point needs a disc of radius
  ``spacing`` that no dart hit, a chance of ``exp(-5 pi)`` = 1.5e-7 per disc.

Deterministic for a given ``numpy.random.Generator`` state. Plain arrays in and out.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["DARTS", "most_points", "poisson_disk", "triangle_areas", "uniform"]

DARTS = 5.0  # candidates per spacing^2 of area


def triangle_areas(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(t,) the areas of triangles ``vertices[triangles]``."""
    p = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def most_points(area: float, spacing: float) -> int:
    """The most points ``spacing`` apart that an area can hold: the hexagonal packing's
    ``2 / (sqrt(3) spacing^2)`` per unit area, plus one (a bound to charge a budget with
    before anything is drawn; a curved or thin surface holds fewer)."""
    return int(np.ceil(2.0 * area / (np.sqrt(3.0) * spacing**2))) + 1


def uniform(
    vertices: np.ndarray, triangles: np.ndarray, count: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``count`` points uniform by area on triangles ``vertices[triangles]`` ((t, 3)).

    Returns
    -------
    points : (count, 3) float
    triangle : (count,) int
        The triangle each lies on.
    vw : (count, 2) float
        Its barycentric (v, w): ``a + v (b - a) + w (c - a)``.
    """
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    return _draw(v, t, np.cumsum(triangle_areas(v, t)), count, rng)


def _draw(v, t, cum, count, rng):
    if not len(t) or not cum[-1] > 0:
        raise ValueError("the surface has no area to scatter points on")
    tri = np.searchsorted(cum, rng.random(count) * cum[-1], side="right")
    tri = np.minimum(tri, len(t) - 1)
    return _place(v, t, tri, rng)


def _place(v, t, tri, rng):
    """Points at uniform barycentric coordinates on triangles ``tri`` of ``v[t]``."""
    count = len(tri)
    r1 = np.sqrt(rng.random(count))
    r2 = rng.random(count)
    vw = np.column_stack([r1 * (1.0 - r2), r1 * r2])
    corner = t[tri]
    a = v[corner[:, 0]]
    points = a + vw[:, :1] * (v[corner[:, 1]] - a) + vw[:, 1:] * (v[corner[:, 2]] - a)
    return points, tri, vw


def poisson_disk(
    vertices: np.ndarray,
    triangles: np.ndarray,
    spacing: float,
    rng: np.random.Generator,
    lift: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A maximal set of points on triangles no two closer than ``spacing``.

    ``lift(triangle, vw)``, if given, maps the candidates onto the surface the triangles
    approximate (an exact surface's points), and the spacing is kept between those.
    Returns the same three arrays as :func:`uniform` (``points``, ``triangle``, ``vw``).
    """
    from .scatter_jit import throw

    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    areas = triangle_areas(v, t)
    area = float(areas.sum())
    if not area > 0:
        raise ValueError("the surface has no area to scatter points on")
    count = max(16, int(np.ceil(DARTS * area / spacing**2)))
    # the darts' triangles by area (a multinomial draw, then in random order: the same
    # law as drawing each alone, without a search per dart)
    tri = np.repeat(np.arange(len(t)), rng.multinomial(count, areas / area))
    p, tri, vw = _place(v, t, tri[rng.permutation(count)], rng)
    if lift is not None:
        p = np.ascontiguousarray(lift(tri, vw), dtype=np.float64)
    taken = np.zeros(count, dtype=bool)
    throw(p, spacing, v.min(axis=0), taken)
    return p[taken], tri[taken], vw[taken]
