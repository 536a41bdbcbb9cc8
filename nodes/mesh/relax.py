"""``mesh.relax``: one step of form finding of a spring network (made to step with
``simulate:``). A thin adapter over :mod:`formgraph.kernels.mesh.relax`.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Vec3
from formgraph.geometry import Mesh
from formgraph.kernels.mesh import relax as kr

#: the point attribute that carries a relaxation's velocities from one step to the next
VELOCITY = "relax_velocity"


@node("mesh.relax", version=2)
def relax(
    mesh: Mesh,
    anchors: list[int] | None = None,
    rest_length: Annotated[float | None, Range(min=1e-12)] = None,
    stiffness: Annotated[float, Range(min=0)] = 1.0,
    load: Vec3 = (0.0, 0.0, 0.0),
    pressure: float = 0.0,
    reference: Mesh | None = None,
    rest_scale: Annotated[float, Range(min=1e-6)] = 1.0,
    anchor_boundary: bool = False,
    iterations: Annotated[int, Range(min=1, max=10_000)] = 10,
    momentum: bool = True,
    *,
    ctx: Context,
) -> Mesh:
    """One step of form finding: the mesh's edges as springs, moved toward equilibrium.

    Dynamic relaxation with kinetic damping (Barnes 1999): each vertex gets a fictitious
    mass from its springs' stiffness and a velocity that integrates the out-of-balance
    force; the velocities are zeroed at each peak of kinetic energy. A step runs
    ``iterations`` of these; with ``momentum`` the velocities ride along to the next step
    as the point attribute ``relax_velocity``, so the steps are one motion. Loads hang a
    net (turned upside down, a vault in pure compression); pressure inflates a closed mesh
    along its area-weighted vertex normals. Anchors do not move at all. Use with
    ``simulate:``; with the defaults a few hundred steps bring a small net to rest. The
    springs' rest lengths are those of the state the simulation started from (its
    ``from``), so they stay put while the net moves; alone, those of ``mesh``.

    Parameters
    ----------
    mesh : Mesh
        The network: every edge of its faces is a spring.
    anchors : list[int] | None
        Indices of vertices held fixed.
    rest_length : float | None
        One rest length for every spring; by default each spring's length in
        ``reference`` (under ``simulate:``, the first state) times ``rest_scale``.
    stiffness : float
        Force per unit strain of each spring (EA): tension = stiffness * (length - rest)
        / rest.
    load : Vec3
        The force on every vertex (gravity: [0, 0, -w]).
    pressure : float
        Force per unit area along the outward normals (closed, outward meshes inflate).
    reference : Mesh | None
        The mesh whose edge lengths are the rest lengths, with the mesh's faces. Default:
        under ``simulate:`` the simulation's first state (``from``), else ``mesh`` itself.
    rest_scale : float
        Rest lengths as a fraction of the reference's (below 1 pulls the net taut).
    anchor_boundary : bool
        Also hold every vertex of the mesh's boundary (a vault's springing line).
    iterations : int
        Relaxation iterations per step.
    momentum : bool
        Carry the velocities to the next step (the ``relax_velocity`` point attribute);
        off, every step starts at rest.
    """
    v = np.asarray(mesh.vertices)
    n = len(v)
    ref = reference
    if ref is None:  # a step of a simulation: the net it started as; alone: this one
        ref = ctx.start if isinstance(ctx.start, Mesh) else mesh
    same = ref is mesh or (
        ref.n_vertices == n
        and ref.face_offsets.shape == mesh.face_offsets.shape
        and (
            ref.face_indices is mesh.face_indices
            or np.array_equal(ref.face_indices, mesh.face_indices)
        )
        and np.array_equal(ref.face_offsets, mesh.face_offsets)
    )
    # the reference is the same object every step: its edge table is built once
    table = ref.edge_table if same else mesh.edge_table
    edges = table.vertices
    if rest_length is not None:
        rest = np.full(len(edges), float(rest_length))
    else:
        if not same:
            raise InputError("reference", "reference must have the mesh's faces (the same net)")
        rv = np.asarray(ref.vertices)
        rest = rest_scale * np.linalg.norm(rv[edges[:, 1]] - rv[edges[:, 0]], axis=1)
        if not (rest > 0).all():
            raise InputError("reference", "a spring has zero rest length (a repeated vertex)")
    fixed = list(anchors or [])
    if any(not -n <= a < n for a in fixed):
        bad = next(a for a in fixed if not -n <= a < n)
        raise InputError("anchors", f"anchor {bad} is not a vertex (the mesh has {n})")
    if anchor_boundary:
        fixed += np.unique(table.vertices[table.counts == 1]).tolist()
    ctx.guard(iterations * (n + len(edges)), "spring updates")
    triangles = kr.fan_triangles(mesh.face_indices, mesh.face_offsets) if pressure else None
    net = kr.network(
        n,
        edges,
        rest,
        stiffness=stiffness,
        load=np.asarray(load, dtype=np.float64),
        pressure=pressure,
        triangles=triangles,
        anchors=np.asarray(fixed, dtype=np.int64),
    )
    velocity = mesh.point_data.get(VELOCITY) if momentum else None
    if velocity is not None and np.shape(velocity) != (n, 3):
        velocity = None  # not ours: start at rest
    x, velocity = kr.relax(v, net, steps=iterations, velocity=velocity)
    if not (np.isfinite(x).all() and np.isfinite(velocity).all()):
        raise InputError("stiffness", "the relaxation diverged: the loads are too large")
    point_data = mesh.point_data.with_(VELOCITY, velocity) if momentum else mesh.point_data
    return Mesh.trusted(x, mesh.face_indices, mesh.face_offsets, point_data, mesh.face_data)
