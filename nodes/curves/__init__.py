"""The ``curves.*`` nodes: polylines, splines and regions in the plane.

``construct`` (polyline, bezier, catmull_rom, subdivide, parametric), ``sample`` (resample,
divide, measure), ``offset``, ``regions`` (rectangle, polygon, boolean, union), ``text``,
``instance`` (copy_to_points) and ``grow`` (differential growth, a simulation step).
"""
