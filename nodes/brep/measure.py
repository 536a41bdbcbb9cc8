"""``brep.mesh`` and ``brep.measure``: a solid as a closed triangle mesh within a tolerance
(:mod:`formgraph.kernels.brep.tessellate`), and its exact measures
(:mod:`formgraph.kernels.brep.topology`)."""

from __future__ import annotations

from typing import Annotated, NamedTuple

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import Range
from formgraph.geometry import Mesh, Solid

from ._common import call, requires


@node("brep.mesh", version=1, requires=requires)
def mesh(
    solid: Solid,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    angle: Annotated[float, Range(min=0, max=90)] = 20.0,
    *,
    ctx: Context,
) -> Mesh:
    """The solid as a closed, outward triangle mesh no farther than ``tolerance`` from its
    surfaces (OCC's ``BRepMesh_IncrementalMesh``), the faces' nodes along shared edges
    merged: for the viewer, mesh exports, slicers and mesh booleans.

    Parameters
    ----------
    solid : Solid
        The solid to tessellate.
    tolerance : float | None
        The largest distance from a triangle to the surface; default 1/1000 of the
        solid's bounding-box diagonal.
    angle : float
        The largest angle, in degrees, between neighbouring triangles on a curved face.

    Example
    -------
    ``print: {type: brep.mesh, solid: "@bracket", tolerance: 0.01}``
    """
    if solid.is_empty:
        ctx.warn("the solid is empty: the mesh has no faces")
        return Mesh(np.zeros((0, 3)), np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64))
    tol = solid.default_tolerance() if tolerance is None else float(tolerance)
    if not tol > 0:
        raise InputError("tolerance", f"must be > 0, got {tol:g}")
    lo, hi = solid.bounds
    # the triangles a tolerance asks for grow as (size / tolerance): refuse a budget-breaking
    # request before OCC spends minutes on it
    span = float(np.linalg.norm(hi - lo))
    ctx.guard(min((span / tol) ** 2, 1e18), "triangles (from the tolerance)")
    if not 0 < angle <= 90:
        raise InputError("angle", f"must be in (0, 90] degrees, got {angle:g}")
    return call("solid", solid.mesh, tol, float(np.radians(angle)), ctx.guard)


class SolidMeasures(NamedTuple):
    volume: float
    area: float
    solids: int
    faces: int
    edges: int
    valid: bool


@node("brep.measure", version=1, requires=requires)
def measure(solid: Solid, *, ctx: Context) -> SolidMeasures:
    """The exact volume and area of a solid (Gauss integration over its faces), how many
    solids, faces and distinct edges it has, and whether OCC's checker
    (``BRepCheck_Analyzer``) finds it valid.

    Parameters
    ----------
    solid : Solid
        The solid to measure.

    Example
    -------
    ``m: {type: brep.measure, solid: "@bracket"}``
    """
    from formgraph.kernels.brep import topology

    m = topology.measure(solid.shape)
    if not m.valid:
        ctx.warn("OpenCASCADE's check finds the solid not valid: its measures may be wrong")
    return SolidMeasures(m.volume, m.area, m.solids, m.faces, m.edges, m.valid)
