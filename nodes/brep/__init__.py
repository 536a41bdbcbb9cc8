"""The ``brep.*`` nodes: exact solids through OpenCASCADE (the extra ``formgraph[brep]``).

``primitives`` (box, cylinder), ``construct`` (extrude, revolve, loft, from_surfaces),
``boolean``, ``features`` (fillet, chamfer, shell) and ``measure`` (mesh, measure). Edge
and face selectors are per-element expressions over each edge's or face's centre, size and
kind. Without OpenCASCADE installed, a graph using them fails at check time, saying how to
install it.
"""
