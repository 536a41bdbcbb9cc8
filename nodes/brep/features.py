"""``brep.fillet``, ``brep.chamfer`` and ``brep.shell``: the features a machinist asks for,
on the edges or faces a per-element selector picks, each failure explained
(:mod:`formgraph.kernels.brep.features`)."""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import PerElement, Range
from formgraph.geometry import Solid

from ._common import call, requires, select
from ._common import solid as _solid

Selector = Annotated[bool | None, PerElement("solid")]


def _edges(s: Solid, edges: Any, ctx: Context) -> tuple[Any, list[int]]:
    """The adjacency of ``s`` and the selected edges that have a corner (others warned)."""
    from formgraph.kernels.brep import topology
    from formgraph.kernels.brep.diagnose import Adjacency, numbers
    from formgraph.kernels.brep.features import usable_edges

    table = topology.edge_table(s.shape)
    chosen = select(edges, table, "edges", "edges", ctx)
    adj = Adjacency(s.shape)
    keep, smooth = usable_edges(adj, chosen)
    if smooth and edges is not None and edges is not True:
        one = len(smooth) == 1
        ctx.warn(
            f"{'edge' if one else 'edges'} {numbers(smooth)} {'joins its' if one else 'join their'}"
            " faces smoothly (or bounds one face only): no corner there, left as "
            f"{'it is' if one else 'they are'}"
        )
    return adj, keep


def _faces(s: Solid, faces: Any, ctx: Context) -> tuple[Any, list[int]]:
    from formgraph.kernels.brep import topology
    from formgraph.kernels.brep.diagnose import Adjacency

    table = topology.face_table(s.shape)
    chosen = select(faces, table, "faces", "faces", ctx)
    return Adjacency(s.shape), chosen


def _single(s: Solid, port: str) -> None:
    if s.is_empty:
        raise InputError(port, "the solid is empty (a boolean that left nothing?)")


def _edge_feature(op: str, s: Solid, port: str, size: float, edges: Any, ctx: Context) -> Solid:
    """The fillet or chamfer (``op``) of ``size`` on the selected edges of ``s``."""
    from formgraph.kernels.brep import features

    _single(s, "solid")
    if not (size > 0 and np.isfinite(size)):
        raise InputError(port, f"must be finite and > 0, got {size:g}")
    adj, keep = _edges(s, edges, ctx)
    if not keep:
        return s
    shape = call("edges", getattr(features, op), s.shape, float(size), keep, adj)
    return _solid(shape, op, solid=s, **{port: float(size)}, edges=keep)


@node("brep.fillet", version=1, requires=requires)
def fillet(
    solid: Solid,
    radius: Annotated[float, Range(min=0)],
    edges: Selector = None,
    *,
    ctx: Context,
) -> Solid:
    """The solid with the selected edges rounded: a circular round of ``radius`` tangent
    to both faces at each edge (OCC's ``BRepFilletAPI_MakeFillet``), exact.

    A failure names the edges and the reason in measures of the part: "the radius 6 is
    larger than the narrowest adjacent face (face 4), which is 4 wide between edges 3 and
    7". Edges where the faces meet smoothly are left (a warning); a selector that picks no
    edge is a warning naming it.

    Parameters
    ----------
    solid : Solid
        The solid to round.
    radius : float
        The round's radius, > 0.
    edges : bool | None
        Which edges: all (default), or a per-element test over each edge's centre ``x y
        z``, ``length``, ``kind`` (``line``, ``circle``, ``bspline``, ...), ``i``, ``count``:
        ``"=z > 9"``, ``"=kind == circle"``.

    Example
    -------
    ``rounded: {type: brep.fillet, solid: "@block", radius: 2, edges: "=z > 9"}``
    """
    return _edge_feature("fillet", solid, "radius", radius, edges, ctx)


@node("brep.chamfer", version=1, requires=requires)
def chamfer(
    solid: Solid,
    distance: Annotated[float, Range(min=0)],
    edges: Selector = None,
    *,
    ctx: Context,
) -> Solid:
    """The solid with the selected edges cut off flat, ``distance`` back along both faces
    (a 45-degree chamfer where they meet square; OCC's ``BRepFilletAPI_MakeChamfer``).

    Parameters
    ----------
    solid : Solid
        The solid to chamfer.
    distance : float
        How far back along each face the cut starts, > 0.
    edges : bool | None
        Which edges: all (default), or a per-element test over each edge's centre ``x y
        z``, ``length``, ``kind``, ``i``, ``count``: ``"=abs(z) < 1"`` (the vertical
        edges of a box centred at 0, whose centres sit at z = 0).

    Example
    -------
    ``cut: {type: brep.chamfer, solid: "@block", distance: 1, edges: "=kind == line"}``
    """
    return _edge_feature("chamfer", solid, "distance", distance, edges, ctx)


@node("brep.shell", version=1, requires=requires)
def shell(
    solid: Solid,
    thickness: float,
    faces: Selector = False,
    *,
    ctx: Context,
) -> Solid:
    """The solid hollowed to walls of ``thickness``, the selected faces removed to open it
    (OCC's ``BRepOffsetAPI_MakeThickSolid``): a cup from a cylinder with its top removed.

    Parameters
    ----------
    solid : Solid
        The solid to hollow.
    thickness : float
        The wall's thickness: > 0 inward (the outside kept), < 0 outward (the inside
        kept); not 0.
    faces : bool | None
        Which faces to remove: none (default: a sealed cavity), or a per-element test over
        each face's centre ``x y z``, ``area``, ``kind`` (``plane``, ``cylinder``, ...),
        the outward normal ``nx ny nz``, ``i``, ``count``: ``"=nz > 0.9"`` (the top).

    Example
    -------
    ``cup: {type: brep.shell, solid: "@body", thickness: 2, faces: "=nz > 0.9"}``
    """
    from formgraph.kernels.brep import features

    _single(solid, "solid")
    if thickness == 0 or not np.isfinite(thickness):
        raise InputError("thickness", f"must be finite and not 0, got {thickness:g}")
    if faces is False:
        adj, chosen = _faces(solid, True, ctx)
        chosen = []
    else:
        adj, chosen = _faces(solid, faces, ctx)
        if not chosen:
            return solid
    shape = call("thickness", features.shell, solid.shape, float(thickness), chosen, adj)
    return _solid(shape, "shell", solid=solid, thickness=float(thickness), faces=chosen)
