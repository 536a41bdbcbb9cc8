"""The graph language: what a graph file says and whether it is right.

- ``yamlread``, ``yamlio``: reading a graph file (with lines) and writing it back
- ``model``: the parsed form (params, nodes, inputs: literals, wires, expressions)
- ``expr``: the whitelisting expression compiler
- ``check``: the whole-graph check (types, wires, params, repeats, simulations) over an
  outline; ``params``: param types, values and ranges; ``order``: node order and cycles
- ``simulation``: what a ``simulate:`` node's state and step count must be
- ``subgraph``: graph files used as node types (includes, their specs)
- ``catalogue``: the node catalogue, its text and markdown, and the JSON Schema
"""
