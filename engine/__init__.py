"""formgraph: a node-graph procedural design engine.

>>> import formgraph as fg
>>> g = fg.Graph()
>>> g.add("pts", "points.circle", count=8, radius=2)
>>> g.evaluate("pts").xyz.shape
(8, 3)
"""

from __future__ import annotations

from . import geometry
from .errors import (
    BudgetError,
    CycleError,
    ExpressionError,
    FormgraphError,
    GraphError,
    InputError,
    NodeError,
    ParamError,
    PathError,
)
from .geometry import (
    Curve,
    Mesh,
    NurbsCurve,
    NurbsSurface,
    ParametricCurve,
    ParametricSurface,
    Points,
    Surface,
)
from .graph import Graph, NodeStat, load
from .registry import node_types
from .sweep import Sweep, sweep

__version__ = "0.1.0"

__all__ = [
    "BudgetError",
    "Curve",
    "CycleError",
    "ExpressionError",
    "FormgraphError",
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
    "Surface",
    "Sweep",
    "geometry",
    "load",
    "node_types",
    "sweep",
]
