"""Repair of meshes into solids: ``mesh.weld`` -> ``mesh.orient`` -> ``mesh.cap`` turns a
triangle soup or an open tube into a printable solid; ``mesh.flip`` turns it inside out
(:mod:`formgraph.kernels.mesh.repair`).
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Mesh
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import meshops
from formgraph.kernels.mesh import repair as kr
from formgraph.nodes.mesh._common import (
    clipping,
    mesh_arrays,
    topology,
)


@node("mesh.weld", version=1)
def weld(
    mesh: Mesh, tolerance: Annotated[float | None, Range(min=0)] = None, *, ctx: Context
) -> Mesh:
    """Merge vertices closer than the tolerance; drop the faces that collapse.

    Closeness is transitive (a chain of close vertices becomes one); each group keeps the
    position of its first vertex; unused vertices are removed. Sparse cells one tolerance wide
    make it O(n log n).

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh, e.g. an STL-like triangle soup.
    tolerance : float | None
        Merge distance. None: 1e-6 of the bounding-box diagonal (joins seams and
        duplicated vertices, never features); 0: exact duplicates only.
    """
    try:
        v, fi, fo = kr.weld(*mesh_arrays(mesh), tolerance)
    except ValueError as exc:
        raise InputError("tolerance", str(exc)) from None
    dropped = mesh.n_faces - (fo.size - 1)

    # each group keeps its first vertex's position, and so its attributes (found only
    # when there are attributes to carry: a sort of every vertex)
    def points() -> carry.Carry:
        return carry.copy(carry.by_position(mesh.vertices, v))

    faces = carry.SAME
    if dropped:
        ctx.warn(f"{dropped} faces collapsed and were dropped")
        if mesh.face_data:
            faces = carry.DROP
            ctx.warn("with faces dropped, the face attributes were dropped too")
    # merged vertices, the surviving faces renumbered: valid by construction
    return Mesh.trusted(v, fi, fo, **carry.carried(mesh, points, faces))


@node("mesh.orient", version=1)
def orient(mesh: Mesh, *, ctx: Context) -> Mesh:
    """Consistent face orientation; every closed part outward (positive volume).

    Faces that share an edge are made to run it in opposite directions (a parity
    union-find over the edges, all at once); then each closed part is turned so its signed
    volume is positive, except a cavity (a part inside an odd number of the others, by the
    generalized winding number), which faces inward so a hollow stays hollow. An open part
    is turned so its faces look away from its centroid, or, if it is flat, so most of its
    area keeps the side it had.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh; edges on more than two faces do not link their faces.
    """
    fi, conflicts = kr.orient(*mesh_arrays(mesh))
    if conflicts:
        ctx.warn(
            f"part of the mesh cannot be oriented (it is one-sided, like a Moebius strip): "
            f"faces still disagree across {conflicts} of its edges"
        )
    # the same faces, some reversed: valid by construction (and shared when none turned)
    return Mesh.trusted(mesh.vertices, fi, mesh.face_offsets, mesh.point_data, mesh.face_data)


@node("mesh.flip", version=1)
def flip(mesh: Mesh) -> Mesh:
    """Reverse every face (inside out), keeping each face's first vertex.

    Parameters
    ----------
    mesh : Mesh
        The mesh to turn.
    """
    return Mesh(
        mesh.vertices,
        meshops.reverse_faces(mesh.face_indices, mesh.face_offsets),
        mesh.face_offsets,
        mesh.point_data,
        mesh.face_data,
    )


@node("mesh.cap", version=1)
def cap(mesh: Mesh, *, ctx: Context) -> Mesh:
    """Fill every boundary loop, so an open tube comes out watertight.

    A planar loop becomes its polygon, triangulated by ear clipping in its plane (concave
    outlines stay inside); any other loop a fan of triangles to its centroid. The new
    faces run each loop opposite to its neighbours, so orientation stays consistent.

    A flat open sheet (a part lying in one plane, e.g. ``mesh.plane`` or two triangles of a
    square) has nothing to enclose: its outline's cap lies on the sheet itself, giving a
    two-sided shell of zero volume (doubled faces, often non-manifold edges) that no slicer
    prints. It is still capped as asked, with a warning; ``mesh.solidify`` is the way to make
    a flat sheet printable (it gives it a thickness).

    Parameters
    ----------
    mesh : Mesh
        An oriented manifold mesh (mesh.weld and mesh.orient make one).
    """
    v, fi, fo = topology("mesh", clipping, ctx, kr.cap, *mesh_arrays(mesh))
    # the old faces and triangles of their own loops' vertices: valid by construction
    out = Mesh.trusted(v, fi, fo, **carry.carried(mesh, *_cap_rules(mesh, v, fi, fo)))
    if out.n_faces > mesh.n_faces:
        flat = kr.flat_open_parts(*mesh_arrays(mesh))
        if flat:
            ctx.warn(
                f"{flat} part{'s' if flat != 1 else ''} of the mesh "
                f"{'are flat open sheets' if flat != 1 else 'is a flat open sheet'}: capping "
                "its outline lays the cap on the sheet, a two-sided shell of zero volume "
                "(not printable); use mesh.solidify to give a flat sheet a thickness"
            )
    return out


def _cap_rules(mesh: Mesh, v: np.ndarray, fi: np.ndarray, fo: np.ndarray) -> tuple:
    """The old vertices and faces keep theirs; a fan's centre vertex gets the mean of its
    loop's vertices (the centre is their mean too), a cap face 0."""
    n, f = mesh.n_vertices, mesh.n_faces
    caps = fi[mesh.face_offsets[-1] :].reshape(-1, 3)
    fan = caps[caps[:, 0] >= n]
    count = np.bincount(fan[:, 0] - n, minlength=len(v) - n)
    rows = np.concatenate([np.arange(n), fan[:, 0]])
    index = np.concatenate([np.arange(n), fan[:, 1]])
    weight = np.concatenate([np.ones(n), 1.0 / count[fan[:, 0] - n]])
    faces = np.concatenate([np.arange(f), np.full(fo.size - 1 - f, -1)])
    return carry.mix(rows, index, weight, len(v)), carry.copy(faces)
