"""What every room of formgraph stands on: the errors (``errors``), the port types
(``types``), the node registry and its budget (``registry``), the path and atomic-write
rules (``safety``) and the one-line terminal progress (``terminal``).

It imports nothing of formgraph but :mod:`formgraph.geometry` (for the port types).
"""
