"""``mesh.slice`` and ``mesh.project``: the section of a mesh by a plane and the outline of
its shadow, as region loops (:mod:`formgraph.kernels.mesh.section`).
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.geometry import Curve, Mesh, NurbsCurve, frozen_array
from formgraph.kernels.io.meshdata import fan_triangles
from formgraph.kernels.mesh import repair
from formgraph.kernels.mesh import section as ksection
from formgraph.nodes import _outlines as _o


class Axis(str, Enum):
    """The axis a cutting plane is perpendicular to."""

    x = "x"
    y = "y"
    z = "z"


#: the columns (u, w, along) of each axis's frame: (u, w) right-handed seen from +axis
_FRAME = {"x": (1, 2, 0), "y": (2, 0, 1), "z": (0, 1, 2)}


def _curves(rings: tuple[np.ndarray, np.ndarray, np.ndarray, bool], place) -> list[Curve]:
    """Rings (:func:`~formgraph.kernels.mesh.section.section_rings`) as closed polylines,
    each point placed in 3-D by ``place((m, 2)) -> (m, 3)``; t is arc length."""
    coords, offsets, step, _ = rings
    if len(offsets) < 2:
        return []
    xyz = frozen_array(place(coords))
    knots = frozen_array(_o.chord_knots(step, offsets))
    out: list[Curve] = []
    for i in range(len(offsets) - 1):  # one step per loop: its points are a view
        a, b = int(offsets[i]), int(offsets[i + 1])
        out.append(NurbsCurve._of_valid(xyz[a:b], 1, knots[a + 2 * i : b + 2 * i + 2]))
    return out


def _triangles(mesh: Mesh) -> np.ndarray:
    """The mesh's faces as the triangles it exports (each face fanned from its first
    corner)."""
    return mesh.derived(
        "fan triangles", lambda: fan_triangles(mesh.face_indices, mesh.face_offsets)
    )


def _frame(mesh: Mesh, u: int, w: int, along: int) -> tuple[np.ndarray, float, float, list[int]]:
    """The vertices in the plane's frame (u, w, along), the range along the axis, and a
    count of the sections taken of this mesh."""
    v = mesh.vertices
    frame = np.column_stack([v[:, u], v[:, w], v[:, along]])
    return frame, float(frame[:, 2].min()), float(frame[:, 2].max()), [0]


@node("mesh.slice", version=1)
def mesh_slice(
    mesh: Mesh, height: float = 0.0, axis: Axis = Axis.z, *, ctx: Context
) -> list[Curve]:
    """The section of a closed mesh by the plane ``axis = height``, as closed region loops.

    OpenSCAD's ``projection(cut = true)`` of a solid moved to the plane, Grasshopper's
    Mesh | Plane. Every triangle with corners on both sides of the plane is cut (a corner
    counts as above when its coordinate is greater than ``height``: the bottom face of a
    box is its section at the bottom, the plane through its top gives nothing, as
    manifold3d's ``slice``), the cuts are chained across shared edges, and the loops are
    closed polylines in the plane: outer loops counter-clockwise and holes clockwise seen
    from +axis (for x the plane's (y, z), for y its (z, x)). The points are where the
    mesh's edges cross the plane, computed once per edge. Loops of parts that overlap or
    cross are united by their winding numbers (the section of the union). ``repeat:`` over
    heights makes a stack of layers.

    Parameters
    ----------
    mesh : Mesh
        A closed, outward mesh (an open one gives the loops that close, with a warning).
    height : float
        Where the plane cuts the axis.
    axis : Axis
        x, y or z: the axis the plane is perpendicular to.

    Example
    -------
    ``layers: {type: mesh.slice, repeat: {i: 10}, mesh: "@part", height: "=3 * i + 1.5"}``
    """
    if not math.isfinite(height):
        raise InputError("height", f"height must be a finite number, got {height}")
    if mesh.n_faces == 0:
        ctx.warn("mesh has no faces: no section")
        return []
    u, w, along = _FRAME[Axis(axis).value]
    tri = _triangles(mesh)
    frame, lo, hi, seen = mesh.derived(f"slice frame {along}", lambda: _frame(mesh, u, w, along))
    if not lo <= height < hi:
        ctx.warn(
            f"the plane {axis.value} = {height:g} misses the mesh (it spans {axis.value} "
            f"from {lo:g} to {hi:g}; a plane at its top cuts nothing): no section"
        )
        return []
    # a mesh sliced more than once (a stack, a slider) gets an index of its triangles by z
    seen[0] += 1
    cut = None
    if seen[0] > 1 and len(tri) > 4096:
        z = frame[:, 2]
        index = mesh.derived(f"slice index {along}", lambda: ksection.SliceIndex(z, tri))
        cut = index.cut(float(height))
    xy, offsets, open_chains = ksection.slice_loops(frame, tri, float(height), cut)
    if open_chains:
        ctx.warn(
            f"{open_chains} section segment(s) found no neighbour across an edge: the mesh "
            "is open or not manifold there, and the chains that do not close were left out "
            "(mesh.weld and mesh.cap make it a closed solid)"
        )
    rings = ksection.section_rings(xy, offsets)
    if rings[3]:
        ctx.warn(
            "the section's loops overlap or cross (parts of the mesh overlap or its faces "
            "intersect): they were united by their winding numbers"
        )
    h = float(height)

    def place(p: np.ndarray) -> np.ndarray:
        out = np.empty((len(p), 3))
        out[:, u], out[:, w], out[:, along] = p[:, 0], p[:, 1], h
        return out

    curves = _curves(rings, place)
    if not curves:
        ctx.warn(f"the plane {axis.value} = {height:g} leaves no area in its section")
    return curves


@node("mesh.project", version=1)
def project(mesh: Mesh, *, ctx: Context) -> list[Curve]:
    """The outline of a mesh's shadow on the XY plane, as closed region loops at z = 0.

    OpenSCAD's ``projection()``, Grasshopper's Mesh Shadow. The shadow is the union of all
    faces projected straight down. It is found without a boolean per face: the faces are
    counted +1 where they face up and -1 where they face down (read backwards), so the
    edges between faces of one kind cancel and what remains (the silhouette and the
    boundary, coincident vertices merged first) is a set of loops whose winding number
    counts the faces over each point; their nonzero fill (Clipper2's sweep, in
    manifold3d, scaled by a power of two so its 1e-8 grid is below double rounding) is the
    shadow. Outer loops counter-clockwise, holes clockwise seen from +z.

    Parameters
    ----------
    mesh : Mesh
        Any mesh, open or closed.

    Example
    -------
    ``footprint: {type: mesh.project, mesh: "@part"}``
    """
    if mesh.n_faces == 0:
        ctx.warn("mesh has no faces: no shadow")
        return []
    first, merged = repair.exact_duplicates(mesh.vertices)
    tri = fan_triangles(merged[mesh.face_indices], mesh.face_offsets)
    xy, offsets = ksection.shadow_loops(mesh.vertices[first], tri)
    if len(offsets) < 2:
        ctx.warn("every face is seen edge-on from above: the shadow has no area")
        return []
    rings = ksection.section_rings(xy, offsets, fill=True)

    def place(p: np.ndarray) -> np.ndarray:
        return np.column_stack([p, np.zeros(len(p))])

    curves = _curves(rings, place)
    if not curves:
        ctx.warn("the shadow has no area")
    return curves
