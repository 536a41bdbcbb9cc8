"""The command line (``formgraph ...``).

- ``main``: the parser and the commands (run, check, view, watch, graph, nodes, schema, cache)
- ``sweep``: ``formgraph sweep``
- ``serve``: ``formgraph serve`` (the studio itself is :mod:`formgraph.studio`)
- ``options``: what every command shares (usage errors, graph options, ``--set`` parsing)
"""
