"""The convex hull of points in the plane, counter-clockwise.

qhull (Barber, Dobkin & Huhdanpaa 1996, "The Quickhull algorithm for convex hulls", through
scipy's ``ConvexHull``): for two dimensions it lists the hull's vertices in counter-
clockwise order, each an input point.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FlatHull", "hull_2d"]


class FlatHull(ValueError):
    """The points span no area (fewer than 3 distinct, or all on one line)."""


def hull_2d(xy: np.ndarray) -> np.ndarray:
    """Indices of the hull's vertices of (n, 2) points, counter-clockwise, no point twice.

    Raises
    ------
    FlatHull
        When the points span no area.
    """
    from scipy.spatial import ConvexHull, QhullError

    p = np.ascontiguousarray(xy, dtype=np.float64)
    distinct = len(np.unique(p, axis=0)) if len(p) < 3 else 3
    if distinct < 3:
        raise FlatHull(f"{distinct} distinct point(s) span no area: a hull needs 3 or more")
    try:
        h = ConvexHull(p)
    except QhullError:
        raise FlatHull(
            f"the {len(p)} points lie on one line (seen from +z): their hull has no area"
        ) from None
    return np.asarray(h.vertices, dtype=np.int64)
