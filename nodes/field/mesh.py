"""``field.mesh``: a field turned into a watertight, outward mesh by adaptive marching cubes
(:mod:`formgraph.kernels.field.mesher`), with the checks on its cell and bounds.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Field, Mesh
from formgraph.geometry.base import as_xyz
from formgraph.kernels.buffers import frozen_arange
from formgraph.kernels.field import mesher, planar
from formgraph.nodes.field import _blend
from formgraph.nodes.field._common import bounds_box


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


SAMPLES = 24  # lattice points along the box's longest side for the Lipschitz check


def _lipschitz_contradicted(field: Field, box: np.ndarray) -> str | None:
    """Why the field's samples contradict its Lipschitz bound, naming what to raise; None
    when they do not, or when the bound is not the user's (only an expression's is).

    The mesher discards a cell whose centre value is farther from zero than the bound
    times its half-diagonal, so a bound below the field's real slope makes it discard the
    cells that hold the surface, and the mesh comes out empty or with parts missing. The
    field sampled on a lattice of about :data:`SAMPLES` points along the box's longest
    side shows a lower bound of the slope (the largest change between neighbours over
    their distance): when that is over the bound, the bound is wrong.
    """
    given = [p for p in field.parts if p.op == "expression"]
    if not given:
        return None
    lo, hi = box
    h = max(float((hi - lo).max()) / (SAMPLES - 1), 1e-300)
    shape = tuple(int(k) for k in np.clip(np.ceil((hi - lo) / h), 1, SAMPLES - 1) + 1)
    step = (hi - lo) / np.maximum(np.array(shape) - 1, 1)
    try:
        values = field.evaluate_grid(lo, step, shape)
    except ValueError:
        return None  # not finite somewhere: the mesher has said so already, or will
    slope = 0.0
    for axis in range(3):
        if shape[axis] > 1:
            d = np.abs(np.diff(values, axis=axis)).max() / step[axis]
            slope = max(slope, float(d))
    bound = field.lipschitz
    if not slope > bound * (1 + 1e-9):
        return None
    factor = slope / bound
    names = ", ".join(
        (f"node '{p.made_by}'" if p.made_by else "the field.expression")
        + f" ({getattr(p.args['value'], 'text', 'the expression')!r}: {p.lipschitz:g})"
        for p in given
    )
    need = _round_up(max(p.lipschitz for p in given) * factor * 1.25)
    return (
        f"the field's samples contradict its Lipschitz bound {bound:g}: its values change by "
        f"up to {slope:.3g} per unit length between neighbouring samples, so the mesher "
        f"discarded cells that hold its surface; raise 'lipschitz' of {names} to about "
        f"{need:g} or more"
    )


def _round_up(x: float) -> float:
    """``x`` rounded up to two significant digits (a bound to suggest: never below)."""
    unit = 10.0 ** (math.floor(math.log10(x)) - 1)
    return math.ceil(x / unit) * unit


def mesh_of(
    field: Field, cell: float | None, bounds: Any, ctx: Context, port: str = "field"
) -> Mesh:
    """The zero set of ``field`` as a watertight outward Mesh (shared by mesh.offset)."""
    if bounds is not None:
        box = bounds_box("bounds", bounds)
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
    contradicted = _lipschitz_contradicted(field, box)
    if not len(t):
        if contradicted is not None:
            raise InputError(port, f"no surface was found, but {contradicted}")
        ctx.warn("the field has no surface inside its bounds: the mesh is empty")
        return Mesh(np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(1, np.int64))
    try:  # the mesher's triangles index its own vertices: only the positions are checked
        v = as_xyz(v, "vertices")
    except ValueError as exc:
        raise InputError(port, f"the field gives a surface that is not finite: {exc}") from None
    if contradicted is not None:
        ctx.warn(f"parts of the surface may be missing: {contradicted}")
    _warn_moved_faces(field, v, cell, ctx)
    return Mesh.trusted(v, t.reshape(-1), frozen_arange(len(t) + 1, 3))  # shared, no copy


def _face_words(normal: np.ndarray, offset: float) -> str:
    """'the face at z = 0 (facing -z)' for an axis-aligned plane, else by its normal."""
    k = int(np.argmax(np.abs(normal)))
    if abs(abs(normal[k]) - 1) < 1e-9:
        side = "+" if normal[k] > 0 else "-"
        return f"the face at {'xyz'[k]} = {offset * normal[k] + 0.0:.4g} (facing {side}{'xyz'[k]})"
    n = ", ".join(f"{x:.3g}" for x in normal)
    return f"the face on the plane n . p = {offset:.4g}, n = [{n}]"


def _warn_moved_faces(field: Field, vertices: np.ndarray, cell: float, ctx: Context) -> None:
    """Warn when a smooth union pushed a flat face of its inputs past its plane, where the
    sharp union stayed behind it (a flat bottom no longer on the bed): see
    :mod:`formgraph.kernels.field.planar`. Tolerance: a tenth of the cell."""
    radii = _blend.smooth_unions(field)
    if not radii:
        return
    normals, offsets = _blend.flat_faces(field)
    if not len(normals):
        return
    moved = planar.overshoots(
        vertices,
        _blend.sharpened(field).evaluate,
        normals,
        offsets,
        tol=cell / 10,
    )
    if not moved:
        return
    faces = "; ".join(
        f"{_face_words(m.normal, m.offset)} by {m.excess:.3g}, at "
        f"({', '.join(f'{x:.4g}' for x in m.where)}) ({m.count} vertices)"
        for m in moved[:4]
    )
    more = f"; and {len(moved) - 4} more" if len(moved) > 4 else ""
    ctx.warn(
        f"the smooth union (its input smooth: {', '.join(f'{r:g}' for r in radii)}) pushes "
        f"flat faces of its inputs past their planes (by more than a tenth of the cell "
        f"{cell:g}) where the sharp union stays behind them: {faces}{more}. A part meant to "
        "stand on such a face no longer does: use a smaller smooth, or intersect the blend "
        "with a box (field.intersection) to cut it back to the plane"
    )


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
