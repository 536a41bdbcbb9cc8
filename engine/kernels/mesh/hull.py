"""The convex hull of points in space, as a closed outward triangle mesh.

manifold3d's ``Manifold.hull_points`` (QuickHull, Barber, Dobkin & Huhdanpaa 1996, in the
Manifold library's implementation) gives the hull on the input points themselves, so each
hull vertex is one of them, bit for bit: :func:`hull` says which (the first of equal ones),
for the attributes to follow.
"""

from __future__ import annotations

import numpy as np

from ..attributes.propagate import by_position

__all__ = ["FlatHull", "hull"]


class FlatHull(ValueError):
    """The points span no volume (fewer than 4, or all in one plane or on one line)."""


def hull(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The convex hull of (n, 3) points.

    Returns
    -------
    vertices : (k, 3) float
        Hull vertices, each one of the input points.
    face_indices, face_offsets
        Outward triangles.
    source : (k,) int64
        The input point of each hull vertex.

    Raises
    ------
    FlatHull
        When the points span no volume.
    """
    import manifold3d

    p = np.ascontiguousarray(points, dtype=np.float64)
    if len(p) < 4:
        raise FlatHull(f"{len(p)} point(s) span no volume: a hull in space needs 4 or more")
    m = manifold3d.Manifold.hull_points(p)
    if m.is_empty() or m.volume() <= 0:
        raise FlatHull(
            f"the {len(p)} points lie in one plane (or on one line): their hull has no volume"
        )
    mesh = m.to_mesh64()
    v = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    tri = np.ascontiguousarray(mesh.tri_verts).view(np.int64).reshape(-1)
    source = by_position(p, v)
    return v, tri, np.arange(0, tri.size + 1, 3, dtype=np.int64), source
