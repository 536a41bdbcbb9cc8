"""``brep.boolean``: union, difference and intersection of exact solids (OCC's general
fuse, :mod:`formgraph.kernels.brep.boolean`), failures said in words and no-ops warned."""

from __future__ import annotations

from enum import Enum

from formgraph.core.registry import Context, node
from formgraph.geometry import Solid

from ._common import call, requires, solid


class Operation(str, Enum):
    union = "union"
    difference = "difference"
    intersection = "intersection"


@node("brep.boolean", version=1, requires=requires)
def boolean(
    a: Solid, b: list[Solid], operation: Operation = Operation.union, *, ctx: Context
) -> Solid:
    """``a`` united with, minus, or intersected with ``b`` (one solid or several at once).

    Exact: the faces keep their surfaces and the new edges lie on both solids' faces. Solids
    that do not overlap are a warning, not an error (the union is then several solids; a
    difference cuts nothing; an intersection is empty), as are solids that only touch.

    Parameters
    ----------
    a : Solid
        The solid to change.
    b : list[Solid]
        The tool(s): added, cut away or kept in common, all at once.
    operation : Operation
        ``union``, ``difference`` (a minus b) or ``intersection``.

    Example
    -------
    ``drilled: {type: brep.boolean, a: "@block", b: ["@hole1", "@hole2"], operation:
    difference}``
    """
    from formgraph.kernels.brep import boolean as kboolean

    op = Operation(operation).value
    if not b:
        ctx.warn(f"b holds no solids: the {op} leaves a as it is")
        return a
    outcome = call("b", kboolean.boolean, a.shape, [x.shape for x in b], op)
    if outcome.warning:
        ctx.warn(outcome.warning)
    return solid(outcome.shape, "boolean", a=a, b=list(b), operation=op)
