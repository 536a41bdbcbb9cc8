"""Evaluation: the :class:`Graph` and how it cooks.

- ``graph``: the Graph (load, params, evaluate, save) and its plan
- ``run``: one evaluation run: cache keys, lookups, running nodes, stats
- ``items``: what runs more than once or elsewhere: repeated nodes (per-item keys) and
  subgraph nodes
- ``cache``: the bounded memory cache and the content-addressed disk cache
"""
