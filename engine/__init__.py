"""formgraph: a node-graph procedural design engine.

>>> import formgraph as fg
>>> g = fg.Graph()
>>> g.add("pts", "points.circle", count=8, radius=2)
>>> g.evaluate("pts").xyz.shape
(8, 3)
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from . import geometry
from .core.errors import (
    BudgetError,
    CycleError,
    ExpressionError,
    FormgraphError,
    FormgraphWarning,
    GraphError,
    InputError,
    NodeError,
    ParamError,
    PathError,
)
from .core.registry import node_types
from .drawgraph.layout import draw_graph
from .evaluation.graph import Graph, NodeStat, load
from .geometry import (
    Curve,
    Mesh,
    NurbsCurve,
    NurbsSurface,
    ParametricCurve,
    ParametricSurface,
    Points,
    Solid,
    Surface,
)
from .sweeps.api import Sweep, sweep
from .sweeps.optimize import Study, optimize


def show(source: Any, node: str | Iterable[str] | None = None, **kwargs: Any) -> Any:
    """Open the viewer on a graph (or file, or geometry): :func:`formgraph.viewer.show`.

    ``fg.show(g, ["ds", "cc"], layout="side")`` shows two nodes side by side; pyvista is
    imported only now.
    """
    from .viewer import show as _show

    return _show(source, node, **kwargs)


__version__ = "0.1.0"

__all__ = [
    "BudgetError",
    "Curve",
    "CycleError",
    "ExpressionError",
    "FormgraphError",
    "FormgraphWarning",
    "Graph",
    "GraphError",
    "InputError",
    "Mesh",
    "NodeError",
    "NodeStat",
    "NurbsCurve",
    "NurbsSurface",
    "ParamError",
    "ParametricCurve",
    "ParametricSurface",
    "PathError",
    "Points",
    "Solid",
    "Surface",
    "Sweep",
    "draw_graph",
    "geometry",
    "load",
    "node_types",
    "show",
    "sweep",
    "optimize",
    "Study",
]
