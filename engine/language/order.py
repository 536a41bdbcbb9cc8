"""The order of a graph's nodes: each after its inputs (Kahn's algorithm), and its cycles
named by their paths when there is none."""

from __future__ import annotations

from collections.abc import Mapping

from ..core.errors import Problem, Where
from .model import NodeDef

__all__ = ["acyclic", "cycle_problems", "kahn_order"]


def acyclic(nodes: Mapping[str, NodeDef]) -> bool:
    """True when every node can be ordered after its inputs."""
    return len(kahn_order(nodes)) == len(nodes)


def kahn_order(nodes: Mapping[str, NodeDef]) -> list[str]:
    """Kahn's algorithm: the nodes each after its inputs (those on or after a cycle left
    out)."""
    indegree = {n: 0 for n in nodes}
    users: dict[str, list[str]] = {n: [] for n in nodes}
    for nd in nodes.values():
        for up in nd.upstream():
            if up in indegree:
                indegree[nd.name] += 1
                users[up].append(nd.name)
    ready = [n for n, d in indegree.items() if d == 0]
    ordered = []
    while ready:
        n = ready.pop()
        ordered.append(n)
        for user in users[n]:
            indegree[user] -= 1
            if indegree[user] == 0:
                ready.append(user)
    return ordered


def cycle_problems(nodes: Mapping[str, NodeDef], file_label: str) -> list[Problem]:
    """The cycles of a graph, each named by its path from the node written first."""
    if acyclic(nodes):
        return []
    import networkx as nx  # only to name the cycles' paths; keeps `import formgraph` quick

    dag = nx.DiGraph()
    for nd in nodes.values():
        dag.add_node(nd.name)
        for up in nd.upstream():
            if up in nodes:
                dag.add_edge(up, nd.name)
    problems = []
    seen: set[frozenset[str]] = set()
    for cycle in nx.simple_cycles(dag):
        key = frozenset(cycle)
        if key in seen:
            continue
        seen.add(key)
        # start the path at the node written first in the file
        order = list(nodes)
        start = min(range(len(cycle)), key=lambda i: order.index(cycle[i]))
        path = cycle[start:] + cycle[:start]
        problems.append(Problem(Where(file_label), "cycle: " + " -> ".join(path + [path[0]])))
        if len(problems) >= 10:
            break
    return problems
