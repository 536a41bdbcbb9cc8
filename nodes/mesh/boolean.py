"""Mesh booleans through manifold3d: ``mesh.boolean`` and ``mesh.union``, attributes carried."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.geometry import Mesh
from formgraph.kernels.attributes import booleans as kab
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import boolean as kb
from formgraph.nodes.mesh._common import (
    clipping,
    mesh_arrays,
)


def _solid(port: str, fn: Callable[..., Any], *args: Any) -> Any:
    try:
        return fn(*args)
    except kb.NotSolidError as exc:
        raise InputError(port, str(exc)) from None


@node("mesh.boolean", version=1)
def boolean(
    a: Mesh, b: Mesh, operation: kb.Operation = kb.Operation.union, *, ctx: Context
) -> Mesh:
    """Union, difference (a minus b) or intersection of two solids, through manifold3d.

    Both meshes must be closed, manifold and outward; anything else is refused with the
    count of open or non-manifold edges and where one is. The result is a manifold
    triangle mesh.

    Parameters
    ----------
    a : Mesh
        The first solid.
    b : Mesh
        The second solid (the one removed by difference).
    operation : Operation
        union, difference or intersection.
    """
    attributed = bool(a.point_data or b.point_data or a.face_data or b.face_data)
    if attributed:
        points, faces = _joined([a, b], ctx)
        pa, pb = _split_props(points, [a.n_vertices, b.n_vertices])
        ma = _solid("a", clipping, ctx, kab.to_manifold, *mesh_arrays(a), pa, 0, "the mesh")
        mb = _solid("b", clipping, ctx, kab.to_manifold, *mesh_arrays(b), pb, a.n_faces, "the mesh")
    else:
        ma = _solid("a", clipping, ctx, kb.to_manifold, *mesh_arrays(a), "the mesh")
        mb = _solid("b", clipping, ctx, kb.to_manifold, *mesh_arrays(b), "the mesh")
    for port, mesh, m in (("a", a, ma), ("b", b, mb)):
        if m.is_empty() and mesh.n_faces:
            ctx.warn(f"input {port} bounds no volume (its faces collapsed): an empty solid")
    try:
        both = kb.combine(ma, mb, operation, whats=("the mesh", "the mesh"))
    except kb.NotSolidError as exc:
        raise InputError("ab"[exc.operand or 0], str(exc)) from None
    if attributed:
        out = _attributed(*kab.from_manifold(both, pa.shape[1]), points, faces)
    else:
        out = Mesh(*kb.from_manifold(both))
    if out.n_faces == 0:
        ctx.warn(f"the {kb.Operation(operation).value} is empty")
    return out


@node("mesh.union", version=1)
def union(meshes: list[Mesh], *, ctx: Context) -> Mesh:
    """The union of several solids at once, through manifold3d.

    Parameters
    ----------
    meshes : list[Mesh]
        Closed, manifold, outward meshes; they may overlap.
    """
    ctx.guard(sum(m.n_faces for m in meshes), "faces")
    if not any(m.point_data or m.face_data for m in meshes):
        out = Mesh(*_solid("meshes", clipping, ctx, kb.union, [mesh_arrays(m) for m in meshes]))
    else:
        points, faces = _joined(meshes, ctx)
        props = _split_props(points, [m.n_vertices for m in meshes])
        v, fi, fo, p, face = _solid(
            "meshes", clipping, ctx, kab.union, [mesh_arrays(m) for m in meshes], props
        )
        out = _attributed(v, fi, fo, p, face, points, faces)
    if out.n_faces == 0 and any(m.n_faces for m in meshes):
        ctx.warn("the union is empty: every mesh bounds no volume (their faces collapsed)")
    return out


def _joined(meshes: list[Mesh], ctx: Context) -> tuple[dict, dict]:
    points, p_bad = carry.concat([m.point_data for m in meshes], [m.n_vertices for m in meshes])
    faces, f_bad = carry.concat([m.face_data for m in meshes], [m.n_faces for m in meshes])
    for name in p_bad + f_bad:
        ctx.warn(f"attribute {name!r} has different shapes on the inputs; it was dropped")
    return points, faces


def _split_props(points: dict, sizes: list[int]) -> list[np.ndarray]:
    stacked = carry.columns(np.zeros((sum(sizes), 3)), points)[:, 3:]
    return np.split(stacked, np.cumsum(sizes)[:-1])


def _attributed(
    v: np.ndarray,
    fi: np.ndarray,
    fo: np.ndarray,
    props: np.ndarray,
    face: np.ndarray,
    points: dict,
    faces: dict,
) -> Mesh:
    """A boolean's result with its point attributes (interpolated by manifold3d) and face
    attributes (from each triangle's source face)."""
    _, point_data = carry.split_columns(np.column_stack([v, props]), points)
    face_data = {k: a[face] for k, a in faces.items()}
    return Mesh(v, fi, fo, point_data, face_data)
