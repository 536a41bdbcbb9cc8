"""Evaluation: the :class:`Graph` and how it cooks.

- ``graph``: the Graph (load, params, evaluate, save) and its plan
- ``run``: one evaluation run: cache keys, lookups, running nodes
- ``stats``: the records of a run (NodeStat per node) and of a plan (Step)
- ``simulation``: nodes that step their own output (per-step keys, frames)
- ``arguments``: what Python callers hand the Graph, checked (names, budgets, plain values)
- ``items``: what runs more than once or elsewhere: repeated nodes (per-item keys) and
  subgraph nodes
- ``cache``: the bounded memory cache and the content-addressed disk cache
"""
