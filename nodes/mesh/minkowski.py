"""``mesh.minkowski``: the Minkowski sum of two closed solids
(:mod:`formgraph.kernels.mesh.minkowski`)."""

from __future__ import annotations

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.geometry import Mesh
from formgraph.kernels.mesh import boolean as kb
from formgraph.kernels.mesh import minkowski as km
from formgraph.nodes.mesh._common import clipping, mesh_arrays


@node("mesh.minkowski", version=1)
def minkowski(a: Mesh, b: Mesh, *, ctx: Context) -> Mesh:
    """The Minkowski sum of two closed solids: every point of ``a`` plus every point of
    ``b``.

    OpenSCAD's ``minkowski()``: a box summed with a small ball is the box with every edge
    and corner rounded, grown by the ball's radius. Through manifold3d: two convex solids
    are summed as the hull of their vertices' pairwise sums (fast); a non-convex one is
    summed piece by piece and the pieces united, which grows with the product of the
    sizes, so that work is counted before it starts (faces times vertices, see
    :func:`formgraph.kernels.mesh.minkowski.cost`) and refused past the element budget.
    Both inputs must be closed, outward solids (as for ``mesh.boolean``); put the small,
    convex one (the ball) second or first, it does not matter.

    Parameters
    ----------
    a : Mesh
        A closed, outward solid.
    b : Mesh
        Another (usually the small convex one: a sphere, a cylinder, a box).

    Example
    -------
    ``rounded: {type: mesh.minkowski, a: "@box", b: "@ball"}``
    """
    for port, m in (("a", a), ("b", b)):
        if m.n_faces == 0:
            raise InputError(port, "the mesh has no faces: there is no solid to sum")
    ca, cb = km.is_convex(*mesh_arrays(a)), km.is_convex(*mesh_arrays(b))
    work = km.cost(mesh_arrays(a), mesh_arrays(b), ca, cb)
    ctx.guard(work, "elements of Minkowski hulls (faces x vertices of the inputs)")
    mans = []
    for port, m in (("a", a), ("b", b)):
        try:
            mans.append(clipping(ctx, kb.to_manifold, *mesh_arrays(m), "the mesh"))
        except kb.NotSolidError as exc:
            raise InputError(port, str(exc)) from None
    try:
        kb.check_precision(mans, ("the mesh", "the mesh"))
    except kb.NotSolidError as exc:
        raise InputError("ab"[exc.operand or 0], str(exc)) from None
    out = Mesh(*km.minkowski(mesh_arrays(a), mesh_arrays(b), *mans, ca and cb))
    if out.n_faces == 0:
        ctx.warn("the Minkowski sum is empty (both solids bound no volume)")
    return out
