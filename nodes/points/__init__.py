"""The ``points.*`` nodes: point sources (``sources``: list, grid, circle, random)."""
