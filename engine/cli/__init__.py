"""The command line (``formgraph ...``).

- ``main``: the parser and the commands (run, check, view, watch, graph, nodes, schema, cache)
- ``sweep``: ``formgraph sweep``
- ``options``: what every command shares (usage errors, graph options, ``--set`` parsing)
"""
