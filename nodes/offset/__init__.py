"""The ``offset.*`` nodes: ``marching_squares``, the offset of curves by a distance field."""
