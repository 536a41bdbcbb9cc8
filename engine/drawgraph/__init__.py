"""The drawing of a graph (``formgraph graph``): nodes, types, wires, and after a run which
were computed or cached and how long each took.

- ``layout``: the graph laid out as shapes
- ``shapes``: the primitives (rectangles, circles, wires, text) and their SVG
- ``drawing``: the page of shapes: SVG, PNG, save
- ``png``: the shapes rasterized to PNG
"""
