"""Nodes made to step (with ``simulate:``): differential growth of a curve and form finding
of a spring network. Each node is one step: its output, fed back as its input, is the next.

Thin adapters over :mod:`formgraph.kernels.curves.growth` and
:mod:`formgraph.kernels.mesh.relax`.
"""

from __future__ import annotations

import zlib
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Vec3
from formgraph.geometry import Curve, Mesh, NurbsCurve
from formgraph.kernels.curves import growth as kg
from formgraph.kernels.mesh import relax as kr

#: the point attribute that carries a relaxation's velocities from one step to the next
VELOCITY = "relax_velocity"

#: what one point of a growth step costs against the element budget: its neighbour pairs
#: and the arrays over them (about 50 numbers a point); the default budget allows a step of
#: a million points, a few seconds
GROWTH_POINT_ELEMENTS = 50


def _polygon(curve: Curve, spacing: float, port: str) -> tuple[np.ndarray, bool]:
    """A curve's vertices (the control polygon of a polyline, else points about
    ``spacing`` apart), without a closing repeat, and whether it is closed."""
    closed = curve.closed
    if isinstance(curve, NurbsCurve) and curve.degree == 1:
        p = np.asarray(curve.control_points)
    else:
        fine = np.asarray(curve.display_points())
        length = float(np.linalg.norm(np.diff(fine, axis=0), axis=1).sum())
        count = int(min(max(16, np.ceil(length / spacing)), 100_000))
        p = curve.sample(count + (1 if closed else 0))
    if closed and len(p) > 1 and np.allclose(p[0], p[-1], rtol=0, atol=1e-12):
        p = p[:-1]
    z = p[:, 2]
    scale = max(1.0, float(np.abs(p).max()))
    if np.ptp(z) > 1e-9 * scale:
        raise InputError(
            port,
            f"{port} must lie in a plane z = constant (growth is in the XY plane); its z "
            f"runs from {z.min():g} to {z.max():g}",
        )
    return p, closed


@node("curves.grow", version=1)
def grow(
    curve: Curve,
    split: Annotated[float, Range(min=1e-9)] = 1.0,
    repulsion: Annotated[float, Range(min=0)] = 0.5,
    radius: Annotated[float | None, Range(min=1e-9)] = None,
    bounds: Curve | None = None,
    jitter: Annotated[float, Range(min=0)] = 0.3,
    seed: int = 0,
    *,
    ctx: Context,
) -> NurbsCurve:
    """One step of differential growth of a curve in the XY plane.

    Neighbours nearer than ``radius`` repel, springs along the edges pull toward half of
    ``split``, each vertex is drawn toward its neighbours' midpoint, and edges longer than
    ``split`` divide: the curve lengthens and folds (Nervous System's and inconvergent's
    differential growth). Neighbours come from a spatial hash grid, so a step costs
    O(n log n). The curve never crosses itself or ``bounds``: each vertex moves less than a
    quarter of the clearance around its edges. Use with ``simulate:``; with the defaults a
    few dozen steps visibly lengthen a curve of unit-spaced points.

    Parameters
    ----------
    curve : Curve
        A simple curve (closed or open) in a plane z = constant; a polyline's vertices are
        used as they are, another curve is sampled about ``split / 2`` apart.
    split : float
        Edges longer than this divide; the scale of the pattern (model units).
    repulsion : float
        How hard near vertices push apart: a pair at distance d moves apart by
        ``repulsion * (radius - d)`` per step (before the limit).
    radius : float | None
        How near is near (default ``2 * split``).
    bounds : Curve | None
        A closed curve around ``curve`` that it stays inside (its edges repel too).
    jitter : float
        A random push per vertex, up to about ``jitter * split / 2``, which breaks a
        regular seed's symmetry; the same on every run (drawn from ``seed`` and the state).
    seed : int
        Chooses the jitter's pattern.

    Example
    -------
    ``grown: {type: curves.grow, simulate: {state: curve, from: "@seed", steps: 40}}``
    """
    radius = 2.0 * split if radius is None else radius
    p, closed = _polygon(curve, 0.5 * split, "curve")
    fence = None
    if bounds is not None:
        if not bounds.closed:
            raise InputError("bounds", "bounds must be a closed curve")
        fence, _ = _polygon(bounds, 0.5 * split, "bounds")
    edges = np.diff(np.vstack([p, p[:1]]) if closed else p, axis=0)
    pieces = np.ceil(np.linalg.norm(edges[:, :2], axis=1) / split).sum()
    # a step at most doubles a divided edge, and each point costs its neighbour pairs
    ctx.guard(GROWTH_POINT_ELEMENTS * 2 * max(pieces, len(p)), "elements (growing points)")
    mixed = zlib.crc32(np.ascontiguousarray(p[:, :2]).tobytes())
    try:
        out = kg.grow_step(
            p[:, :2],
            closed,
            split=split,
            radius=radius,
            repulsion=repulsion,
            bounds=None if fence is None else fence[:, :2],
            jitter=jitter,
            seed=int(np.random.SeedSequence([abs(seed), mixed]).generate_state(1)[0]),
        )
    except ValueError as exc:
        message = str(exc)
        port = "radius" if "search radius" in message else "curve"
        raise InputError("bounds" if "bounds" in message else port, message) from None
    xyz = np.c_[out, np.full(len(out), p[0, 2])]
    return NurbsCurve.polyline(xyz, closed=closed)


@node("mesh.relax", version=1)
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
    ``simulate:``; with the defaults a few hundred steps bring a small net to rest.

    Parameters
    ----------
    mesh : Mesh
        The network: every edge of its faces is a spring.
    anchors : list[int] | None
        Indices of vertices held fixed.
    rest_length : float | None
        One rest length for every spring; by default each spring's length in
        ``reference`` times ``rest_scale``.
    stiffness : float
        Force per unit strain of each spring (EA): tension = stiffness * (length - rest)
        / rest.
    load : Vec3
        The force on every vertex (gravity: [0, 0, -w]).
    pressure : float
        Force per unit area along the outward normals (closed, outward meshes inflate).
    reference : Mesh | None
        The mesh whose edge lengths are the rest lengths (default ``mesh``; in a
        simulation wire the first state here, e.g. ``"@net"``, so they stay put).
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
    ref = mesh if reference is None else reference
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
