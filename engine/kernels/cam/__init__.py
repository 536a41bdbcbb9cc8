"""CNC tool-path kernels: where the centre of a round tool runs to cut a region.

- ``paths``: pocket levels (contour-parallel offsets of the region, through the offset
  kernel :func:`formgraph.kernels.offset.offset_loops`), the check that no material is
  left standing between them, the material a tool cannot reach, and step-down depths;
- ``arcs``: the exact offset of a chain of circular arcs and straight pieces (a circle, a
  rounded rectangle), so a profile of exact curves stays exact and G-code writes arcs.
"""
