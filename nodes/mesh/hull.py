"""``mesh.hull``: the convex hull of points, curves and meshes
(:mod:`formgraph.kernels.mesh.hull`)."""

from __future__ import annotations

from typing import Annotated

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Geometry, Mesh
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import hull as khull
from formgraph.nodes._pointsets import points_of


@node("mesh.hull", version=1)
def hull(
    geometry: Geometry | list[Geometry],
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Mesh:
    """The convex hull of points, curves or meshes (a list all together): a closed, outward
    triangle mesh.

    OpenSCAD's ``hull()`` of solids, Grasshopper's Convex Hull in space. The hull's vertices
    are input points, bit for bit (QuickHull through manifold3d), and keep their point
    attributes. Curves give their points: polylines their vertices, other curves points
    whose chords stay within ``tolerance`` of them.

    Parameters
    ----------
    geometry : Geometry | list[Geometry]
        Points, curves, meshes, or a list of them; at least 4 points not all in one plane.
    tolerance : float
        Largest distance between a curve and its chords. Default: 1e-5 of the size of
        everything given.

    Example
    -------
    ``shell: {type: mesh.hull, geometry: ["@base", "@top_ring"]}``
    """
    xyz, data = points_of(geometry, tolerance, ctx)
    try:
        v, fi, fo, source = khull.hull(xyz)
    except khull.FlatHull as exc:
        raise InputError(
            "geometry", f"{exc}; for the hull of a flat outline use curves.hull"
        ) from None
    rule = carry.copy(source)
    return Mesh(v, fi, fo, point_data={k: rule.apply(a) for k, a in data.items()})
