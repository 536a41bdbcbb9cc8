"""The ``nurbs.*`` nodes: exact NURBS curves and surfaces (The NURBS Book).

``curves`` (curve, circle, arc, interpolate), ``knots`` (insert_knot, elevate_degree) and
``surfaces`` (surface, loft, extrude, revolve, sweep, tessellate).
"""
