"""The ``surfaces.*`` nodes: surfaces through grids of points and expressions (``construct``)."""
