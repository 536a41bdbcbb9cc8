"""``mesh.measure``: volume, area, bounds and the checks a slicer makes
(:mod:`formgraph.kernels.mesh.measure`, parts and cavities :mod:`formgraph.kernels.mesh.parts`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from formgraph.core.registry import Context, node
from formgraph.core.types import Vec3
from formgraph.geometry import Mesh
from formgraph.kernels.mesh import parts as kparts


class MeshMeasures(NamedTuple):
    area: float
    volume: float
    watertight: bool
    size: Vec3
    center: Vec3
    faces: int
    parts: int
    cavities: int


@node("mesh.measure", version=2)
def measure(mesh: Mesh, *, ctx: Context) -> MeshMeasures:
    """Area, volume, watertightness, bounding box, face count, parts and cavities of a mesh.

    Outputs: ``area`` (sum of face areas), ``volume`` (enclosed volume by the divergence
    theorem; 0, with a warning, for a mesh that is not watertight), ``watertight`` (every
    edge on exactly two faces), ``size`` and ``center`` of the bounding box, ``faces``,
    ``parts`` (connected parts: faces joined through shared edges once coincident vertices
    are merged, as ``mesh.split`` finds them) and ``cavities`` (closed parts inside an odd
    number of other closed parts: sealed voids, which a slicer prints as inner shells;
    found by the parity of a ray's crossings of the other parts).

    The volume is signed: a closed mesh whose faces point inward measures negative, with a
    warning (``mesh.orient`` turns it outward); a closed mesh whose faces disagree across
    some edges warns that its volume means nothing until it is oriented.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh.
    """
    watertight = mesh.is_watertight
    volume = mesh.volume if watertight else 0.0
    if mesh.n_faces == 0:
        ctx.warn("mesh has no faces: area and volume 0")
    elif not watertight:
        open_edges = int(np.count_nonzero(mesh.edge_table.counts != 2))
        ctx.warn(f"mesh is not watertight ({open_edges} open or non-manifold edges): volume 0")
    else:
        disagree = int(np.count_nonzero(mesh.edge_table.same_way))
        if disagree:
            ctx.warn(
                f"the faces disagree in orientation across {disagree} edges, so the volume "
                f"({volume:g}) means nothing; mesh.orient makes them agree"
            )
        elif volume < 0:
            ctx.warn(
                f"the mesh faces inward: its volume is negative ({volume:g}); mesh.orient "
                "turns it outward"
            )
    lo, hi = mesh.bounds
    parts = kparts.face_parts(*mesh.arrays)
    closed = np.flatnonzero(parts.closed)
    cavities = 0
    if len(closed) > 1:
        inside = kparts.inside_counts(*mesh.arrays, parts, closed)
        cavities = int(np.count_nonzero(inside % 2 == 1))
    return MeshMeasures(
        area=mesh.area,
        volume=float(volume),
        watertight=watertight,
        size=[float(x) for x in hi - lo],  # type: ignore[arg-type]
        center=[float(x) for x in (lo + hi) / 2],  # type: ignore[arg-type]
        faces=mesh.n_faces,
        parts=parts.count,
        cavities=cavities,
    )
