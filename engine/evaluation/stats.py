"""The records of an evaluation: what happened to each node (:class:`NodeStat`, in
``Graph.stats``) and the steps of a plan (:class:`Step`, from ``Graph.plan``)."""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["NodeStat", "Step"]


@dataclass
class NodeStat:
    """What happened to one node in the last evaluation."""

    status: str  # 'computed' or 'cached'
    seconds: float = 0.0
    nbytes: int = 0
    warnings: list[str] = field(default_factory=list)
    source: str = ""  # where a cached value came from: 'memory' or 'disk'
    items: int | None = None  # a repeated node: how many items it has
    computed_items: int = 0  # ... and how many of them were computed (not cached)
    unit: str = "items"  # what the items are: 'steps' for a simulated node
    inner: dict[str, NodeStat] | None = None  # a subgraph node: its own nodes' stats


@dataclass(frozen=True)
class Step:
    """One node of an evaluation plan (see :meth:`formgraph.Graph.plan`)."""

    name: str
    key: str  # the node's cache key for the planned params
    upstream: tuple[str, ...]  # the nodes whose outputs it reads, each once
    export: bool  # an export node (writes a file into the output directory)
    upstream_keys: tuple[str, ...] = ()  # their keys, in the same order
