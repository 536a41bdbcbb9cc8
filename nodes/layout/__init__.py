"""The ``layout.*`` nodes: ``nest``, parts put on sheets for cutting (no-fit polygons and
bottom-left fill, :mod:`formgraph.kernels.layout`)."""
