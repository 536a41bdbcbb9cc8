"""The ``mesh.*`` nodes: polygon meshes and the solids made of them.

``primitives`` (from_faces, box, cylinder, sphere, torus, plane), ``subdivide`` (Catmull-Clark,
Doo-Sabin), ``edit`` (triangulate, merge, transform), ``repair`` (weld, orient, flip, cap),
``offset`` (offset, solidify), ``boolean`` (boolean, union), ``measure``, ``process`` (smooth,
decimate, remesh), ``instance`` (copy_to_points) and ``relax`` (a simulation step).
"""
