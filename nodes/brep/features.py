"""``brep.fillet``, ``brep.chamfer`` and ``brep.shell``: the features a machinist asks for,
on the edges or faces a per-element selector picks, each failure explained
(:mod:`formgraph.kernels.brep.features`)."""

from __future__ import annotations

from typing import Annotated, Any

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import PerElement, Range
from formgraph.geometry import Solid

from ._common import call, requires, select, solid

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
        ctx.warn(
            f"edges {numbers(smooth)} join their faces smoothly (or bound one face only): "
            "no corner there, left as they are"
        )
    return adj, keep


@node("brep.fillet", version=1, requires=requires)
def fillet(
    solid_: Annotated[Solid, "solid"] = None,  # type: ignore[assignment]
    *,
    ctx: Context,
) -> Solid:  # pragma: no cover - replaced below
    raise NotImplementedError
