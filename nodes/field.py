"""Fields and implicit solids (family ``field``, and ``mesh.offset``).

A :class:`~formgraph.geometry.Field` is a signed distance function, negative inside, kept
as the recipe that built it: the nodes here build recipes (primitives, TPMS sheets, smooth
booleans, shells, offsets, transforms, distances to meshes and curves) and ``field.mesh``
turns one into a watertight, outward mesh by adaptive marching cubes
(:mod:`formgraph.kernels.field.mesher`). ``mesh.offset`` is ``field.from_mesh`` ->
``field.offset`` -> ``field.mesh`` in one node: the 3-D twin of ``offset.marching_squares``.
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Expression, Variables, Vec3
from formgraph.geometry import Curve, Field, Mesh, NurbsCurve
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.field import mesher
from formgraph.kernels.mesh.meshops import rotation_matrix

# ------------------------------------------------------------------------------ primitives


def _positive(port: str, value: float) -> float:
    if not value > 0:
        raise InputError(port, f"{port} must be > 0, got {value:g}")
    return float(value)


@node("field.sphere", version=1)
def sphere(radius: Annotated[float, Range(min=0)], center: Vec3 = (0.0, 0.0, 0.0)) -> Field:
    """The exact signed distance to a sphere: ``|p - center| - radius``.

    Parameters
    ----------
    radius : float
        Radius, > 0.
    center : Vec3
        Centre.

    Example
    -------
    ``ball: {type: field.sphere, radius: 10}``
    """
    return Field.sphere(_positive("radius", radius), center)


@node("field.box", version=1)
def box(
    size: Vec3, center: Vec3 = (0.0, 0.0, 0.0), radius: Annotated[float, Range(min=0)] = 0.0
) -> Field:
    """The exact signed distance to an axis-aligned box, its edges rounded by ``radius``.

    Parameters
    ----------
    size : Vec3
        Side lengths, each > 0 (the outside size, rounding included).
    center : Vec3
        Centre.
    radius : float
        Edge and corner rounding, 0 .. half the smallest side.
    """
    s = np.asarray(size, dtype=np.float64)
    if not (s > 0).all():
        raise InputError("size", f"every side must be > 0, got {s.tolist()}")
    if radius > s.min() / 2:
        raise InputError("radius", f"radius {radius:g} is more than half the smallest side")
    return Field.box(s, center, radius)


@node("field.cylinder", version=1)
def cylinder(
    radius: Annotated[float, Range(min=0)],
    height: Annotated[float, Range(min=0)],
    center: Vec3 = (0.0, 0.0, 0.0),
) -> Field:
    """The exact signed distance to a capped cylinder along z, centred on ``center``.

    Parameters
    ----------
    radius : float
        Radius, > 0.
    height : float
        Length along z, > 0.
    center : Vec3
        Centre.
    """
    return Field.cylinder(_positive("radius", radius), _positive("height", height), center)


@node("field.torus", version=1)
def torus(
    major: Annotated[float, Range(min=0)],
    minor: Annotated[float, Range(min=0)],
    center: Vec3 = (0.0, 0.0, 0.0),
) -> Field:
    """The exact signed distance to a torus round the z axis.

    Parameters
    ----------
    major : float
        Radius of the centre circle, > 0.
    minor : float
        Radius of the tube, > 0 (above ``major`` the torus has no hole).
    center : Vec3
        Centre.
    """
    return Field.torus(_positive("major", major), _positive("minor", minor), center)


@node("field.expression", version=1)
def expression(
    value: Annotated[Expression, Variables("x", "y", "z")],
    bounds: list[list[float]] | None = None,
    lipschitz: Annotated[float, Range(min=0)] = 1.0,
) -> Field:
    """A field from an expression in ``x y z`` (and the graph params), negative inside.

    The mesher discards a cell when the value at its centre is farther from zero than
    ``lipschitz`` times its half-diagonal, so ``lipschitz`` must bound the gradient's length
    (1 for a true distance such as ``sqrt(x*x + y*y + z*z) - 1``); a smaller one is faster
    but may miss thin parts.

    Parameters
    ----------
    value : Expression
        The field, e.g. ``"sqrt(x**2 + y**2) - 2 - 0.5 * sin(z)"``.
    bounds : list[list[float]] | None
        ``[[x0, y0, z0], [x1, y1, z1]]``, a box outside which the value is positive (so
        ``field.mesh`` needs none); none: unbounded.
    lipschitz : float
        A bound on the gradient's length, > 0.
    """
    box = _bounds("bounds", bounds) if bounds is not None else None
    return Field.expression(value, box, _positive("lipschitz", lipschitz))


class TPMSKind(str, Enum):
    """Which triply periodic minimal surface."""

    gyroid = "gyroid"  # sin x cos y + sin y cos z + sin z cos x
    schwarz_p = "schwarz_p"  # cos x + cos y + cos z
    diamond = "diamond"  # Schwarz D


@node("field.tpms", version=1)
def tpms(
    kind: TPMSKind = TPMSKind.gyroid,
    period: Annotated[float, Range(min=0)] = 10.0,
    thickness: Annotated[float, Range(min=0)] = 1.0,
) -> Field:
    """A triply periodic minimal surface thickened into a sheet: lattice infill.

    The surface's implicit function divided by its gradient's length is a distance to
    first order, so the sheet ``|f| / |grad f| - thickness / 2`` has an even wall of
    ``thickness`` in model units. Unbounded: intersect it with a solid (``field.intersection``)
    or give ``field.mesh`` bounds.

    Parameters
    ----------
    kind : TPMSKind
        ``gyroid`` (sin x cos y + sin y cos z + sin z cos x), ``schwarz_p`` (cos x + cos y +
        cos z) or ``diamond`` (Schwarz D).
    period : float
        The length of one unit cell, > 0.
    thickness : float
        The full wall thickness, > 0 (below half the period).

    Example
    -------
    ``infill: {type: field.tpms, kind: gyroid, period: 8, thickness: 0.8}``
    """
    _positive("period", period)
    _positive("thickness", thickness)
    if thickness >= period / 2:
        raise InputError("thickness", f"thickness {thickness:g} must be below half the period")
    return Field.tpms(TPMSKind(kind).value, period, thickness)


# ------------------------------------------------------------------------------ combinations


def _smooth(smooth: float) -> float:
    if smooth < 0:
        raise InputError("smooth", f"smooth must be >= 0, got {smooth:g}")
    return float(smooth)


@node("field.union", version=1)
def union(fields: list[Field], smooth: Annotated[float, Range(min=0)] = 0.0) -> Field:
    """The union of fields (min), blended over ``smooth`` by the polynomial smooth minimum.

    The blend ``min(a, b) - h^2 smooth / 4`` (``h = max(smooth - |a - b|, 0) / smooth``)
    adds at most ``smooth / 4`` where the shapes meet and keeps the field Lipschitz, so the
    mesher's culling stays exact (Quilez, "smooth minimum").

    Parameters
    ----------
    fields : list[Field]
        At least one field.
    smooth : float
        Blend radius, >= 0 (0: a sharp union).
    """
    if not fields:
        raise InputError("fields", "needs at least one field")
    return Field.union(list(fields), _smooth(smooth))


@node("field.intersection", version=1)
def intersection(fields: list[Field], smooth: Annotated[float, Range(min=0)] = 0.0) -> Field:
    """The intersection of fields (max), blended over ``smooth`` (a smooth maximum).

    Parameters
    ----------
    fields : list[Field]
        At least one field.
    smooth : float
        Blend radius, >= 0.
    """
    if not fields:
        raise InputError("fields", "needs at least one field")
    return Field.intersection(list(fields), _smooth(smooth))


@node("field.difference", version=1)
def difference(a: Field, b: Field, smooth: Annotated[float, Range(min=0)] = 0.0) -> Field:
    """``a`` with ``b`` cut away: ``max(a, -b)``, blended over ``smooth``.

    Parameters
    ----------
    a : Field
        What remains.
    b : Field
        What is removed.
    smooth : float
        Blend radius of the cut's edge, >= 0.
    """
    return Field.difference(a, b, _smooth(smooth))


@node("field.shell", version=1)
def shell(field: Field, thickness: Annotated[float, Range(min=0)]) -> Field:
    """A wall of ``thickness`` centred on the field's surface: ``|f| - thickness / 2``.

    Intersect with the solid (or offset by ``-thickness / 2`` first) for a wall inside it.

    Parameters
    ----------
    field : Field
        The surface to thicken.
    thickness : float
        Full wall thickness, > 0.
    """
    return Field.shell(field, _positive("thickness", thickness))


@node("field.offset", version=1)
def offset(field: Field, distance: float) -> Field:
    """The field grown by ``distance`` (``f - distance``; negative shrinks it).

    Parameters
    ----------
    field : Field
        A distance field (exact growth needs a true distance).
    distance : float
        How far the surface moves outward.
    """
    if not np.isfinite(distance):
        raise InputError("distance", "distance must be finite")
    return Field.offset(field, float(distance))


@node("field.transform", version=1)
def transform(
    field: Field,
    translate: Vec3 = (0.0, 0.0, 0.0),
    rotate: Vec3 = (0.0, 0.0, 0.0),
    scale: float | Vec3 = 1.0,
) -> Field:
    """The field's shape scaled, then rotated (degrees about x, y, z), then translated.

    The points are mapped back into the field's frame; a uniform scale multiplies the
    distance by ``scale`` so it stays a distance, a non-uniform one by its smallest factor.

    Parameters
    ----------
    field : Field
        The field to move.
    translate : Vec3
        Translation.
    rotate : Vec3
        Rotation in degrees about x, then y, then z (fixed axes), as mesh.transform.
    scale : float | Vec3
        Scale factors, each > 0.
    """
    s = np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))
    if not (s > 0).all():
        raise InputError("scale", f"scale factors must be > 0, got {s.tolist()}")
    return Field.transform(field, rotation_matrix(rotate), translate, s)


# ------------------------------------------------------------------------------ from geometry


@node("field.from_mesh", version=1)
def from_mesh(mesh: Mesh) -> Field:
    """The signed distance to a mesh: exact Euclidean distance to its nearest triangle, the
    sign by the generalized winding number (negative inside).

    The winding number (fast, by a tree of dipoles: Barill et al. 2018) is about 1 inside
    even where the mesh has small holes, so a slightly open scan still has an inside.

    Parameters
    ----------
    mesh : Mesh
        A closed (or nearly closed) outward mesh; polygons are fanned into triangles.
    """
    if mesh.n_faces == 0:
        raise InputError("mesh", "the mesh has no faces")
    return Field.from_mesh(mesh)


def _polyline(curve: Curve, samples: int) -> np.ndarray:
    """Points along a curve: a degree-1 NURBS exactly (its knots), others ``samples`` even t."""
    t0, t1 = curve.domain
    if isinstance(curve, NurbsCurve) and curve.degree == 1:
        knots = np.unique(np.asarray(curve.knots))
        t = knots[(knots >= t0) & (knots <= t1)]
    else:
        t = np.linspace(t0, t1, samples + 1)
    return np.asarray(curve.evaluate(t), dtype=np.float64)


@node("field.from_curves", version=1)
def from_curves(
    curves: list[Curve],
    radius: Annotated[float, Range(min=0)],
    samples: Annotated[int, Range(min=1)] = 256,
    *,
    ctx: Context,
) -> Field:
    """Tubes of ``radius`` round curves: the exact distance to their polylines less radius.

    Lattices of struts, frames, wire sculptures: every curve's tube, unioned (and sharp
    where tubes meet; ``field.union`` with ``smooth`` blends separate groups).

    Parameters
    ----------
    curves : list[Curve]
        The centre lines.
    radius : float
        Tube radius, > 0.
    samples : int
        Segments per curved curve (polylines keep their own vertices).
    """
    if not curves:
        raise InputError("curves", "needs at least one curve")
    ctx.guard(len(curves) * (samples + 1), "curve samples")
    segs = []
    for c in curves:
        p = _polyline(c, samples)
        if len(p) >= 2:
            segs.append(np.stack([p[:-1], p[1:]], axis=1))
    return Field.from_curves(list(curves), np.concatenate(segs), _positive("radius", radius))


# ------------------------------------------------------------------------------ meshing


def _bounds(port: str, bounds: Any) -> np.ndarray:
    b = np.asarray(bounds, dtype=np.float64)
    if b.shape != (2, 3) or not np.isfinite(b).all() or not (b[1] > b[0]).all():
        raise InputError(
            port, f"{port} must be [[x0, y0, z0], [x1, y1, z1]] with x0 < x1, y0 < y1, z0 < z1"
        )
    return b


def _thinnest(field: Field) -> tuple[str, float] | None:
    """The thinnest wall a field's construction names — a TPMS sheet, a shell, a tube's
    diameter — in the units it is meshed in (scaled by the transforms above it), with the
    words for it; None when none does. Walked without recursion: a field is a DAG that
    graphs of any depth build."""
    best: tuple[str, float] | None = None
    stack, seen = [(field, 1.0)], set()
    while stack:
        f, scale = stack.pop()
        if (id(f), scale) in seen:
            continue
        seen.add((id(f), scale))
        own = None
        if f.op == "tpms":
            own = (
                f"the {f.args['kind']} sheet ({f.args['thickness']:g} thick)",
                f.args["thickness"],
            )
        elif f.op == "shell":
            own = (f"the shell ({f.args['thickness']:g} thick)", f.args["thickness"])
        elif f.op == "from_curves":
            own = (
                f"the tubes round the curves ({2 * f.args['radius']:g} across)",
                2 * f.args["radius"],
            )
        if own is not None and (best is None or own[1] * scale < best[1]):
            best = (own[0] if scale == 1.0 else f"{own[0]} scaled by {scale:g}", own[1] * scale)
        if f.op == "transform":
            scale *= float(np.min(f.args["scale"]))
        stack.extend((c, scale) for c in f.children)
    return best


def mesh_of(
    field: Field, cell: float | None, bounds: Any, ctx: Context, port: str = "field"
) -> Mesh:
    """The zero set of ``field`` as a watertight outward Mesh (shared by mesh.offset)."""
    if bounds is not None:
        box = _bounds("bounds", bounds)
        clip = Field.box(box[1] - box[0], (box[0] + box[1]) / 2)
        if field.bounds is None or not (
            (field.bounds[0] >= box[0]).all() and (field.bounds[1] <= box[1]).all()
        ):
            field = Field.intersection([field, clip])
        box = box if field.bounds is None else field.bounds
    elif field.bounds is None:
        raise InputError(
            "bounds",
            f"this field ({field.op}) is unbounded: give bounds [[x0, y0, z0], [x1, y1, z1]], "
            "or intersect it with a bounded field",
        )
    else:
        box = field.bounds
    extent = float((box[1] - box[0]).max())
    if cell is None:
        cell = extent / 100 if extent > 0 else 1.0
    elif not cell > 0:
        raise InputError("cell", f"cell must be > 0, got {cell:g}")
    elif extent > 0 and cell > extent:
        raise InputError(
            "cell",
            f"cell {cell:g} is larger than the box to mesh (its largest side is {extent:g}): "
            f"nothing of the surface can be resolved; use a cell of {extent / 10:g} or less",
        )
    thin = _thinnest(field)
    if thin is not None and thin[1] < cell:
        ctx.warn(
            f"{thin[0]} is thinner than the cell {cell:g}: the mesh cannot resolve it and "
            f"comes out with holes or not at all; use a cell of {thin[1] / 2:g} or less"
        )
    # a box n cells wide has at least n^2 surface cells; refuse a hopeless grid up front
    ctx.guard(((extent / cell) + 2) ** 2, "surface cells")
    try:
        grid = field.evaluate_grid if field.separable else None  # lattices: tables
        lines = field.evaluate_lines if field.separable else None
        v, t = mesher.mesh_field(
            field.evaluate,
            box[0],
            box[1],
            cell,
            field.lipschitz,
            ctx.budget,
            grid=grid,
            lines=lines,
        )
    except mesher.BudgetExceeded as exc:
        ctx.guard(exc.count, exc.what)
        raise
    except ValueError as exc:
        raise InputError(port, str(exc)) from None
    if not len(t):
        ctx.warn("the field has no surface inside its bounds: the mesh is empty")
        return Mesh(np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(1, np.int64))
    return Mesh(v, t.reshape(-1), np.arange(0, 3 * len(t) + 1, 3))


@node("field.mesh", version=2)
def mesh(
    field: Field,
    cell: Annotated[float | None, Range(min=0)] = None,
    bounds: list[list[float]] | None = None,
    *,
    ctx: Context,
) -> Mesh:
    """The field's zero set as a triangle mesh: watertight, oriented outward.

    Adaptive: a coarse grid is refined (an octree) only where the surface can be (a cell
    whose centre value is within the field's Lipschitz reach of zero), so the work grows
    with the surface's area: halving ``cell`` costs about 4x. The finest cells are cut by
    marching cubes whose table decides an ambiguous face from its four corners alone
    (inside corners separated), so the cubes on either side agree and the surface has no
    cracks; each vertex is placed on the surface by root-finding on the field.

    Parameters
    ----------
    field : Field
        The field (negative inside).
    cell : float | None
        The finest cell's size; none: 1/100 of the bounds' largest side.
    bounds : list[list[float]] | None
        ``[[x0, y0, z0], [x1, y1, z1]]``: the box to mesh, the field cut by it (so the
        mesh is closed); needed for an unbounded field (a TPMS), else the field's own.

    Example
    -------
    ``solid: {type: field.mesh, field: "@blend", cell: 0.5}``
    """
    return mesh_of(field, cell, bounds, ctx)


@node("mesh.offset", version=3)
def mesh_offset(
    mesh: Mesh,
    distance: float,
    cell: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Mesh:
    """A closed mesh grown (or shrunk, ``distance`` < 0) by ``distance``: a 3-D offset.

    The mesh's signed distance field (``field.from_mesh``: exact distance, winding-number
    sign) less ``distance``, meshed adaptively (``field.mesh``): robust for any closed
    input, self-intersecting or not; convex edges come out rounded (a Minkowski sum with a
    ball), concave ones sharp up to the cell. Point attributes are interpolated at each new
    vertex's closest point of the input (the foot of its offset), face attributes come from
    the input face nearest each new face's centroid.

    Parameters
    ----------
    mesh : Mesh
        A closed (or nearly closed) outward mesh.
    distance : float
        Offset distance (positive grows).
    cell : float | None
        The finest cell; none: 1/100 of the grown box's largest side.
    """
    if mesh.n_faces == 0:
        raise InputError("mesh", "the mesh has no faces")
    if not np.isfinite(distance) or distance == 0:
        raise InputError("distance", f"distance must be finite and not 0, got {distance:g}")
    size = float((mesh.bounds[1] - mesh.bounds[0]).max())
    if distance < 0 and -distance * 2 >= size:
        ctx.warn(f"an inward offset of {-distance:g} may remove the whole mesh")
    f = Field.offset(Field.from_mesh(mesh), float(distance))
    out = mesh_of(f, cell, None, ctx, port="mesh")
    # attributes from the input's closest point (the offset's foot), faces' from the nearest
    faces = (out.face_indices, out.face_offsets)
    return Mesh(out.vertices, *faces, **carry.onto(mesh, out.vertices, faces, max_tests=ctx.budget))
