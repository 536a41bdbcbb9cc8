"""The ``field.*`` nodes: signed distance fields, combined lazily and meshed on demand.

``primitives`` (sphere, box, cylinder, torus, expression, tpms), ``combine`` (union,
intersection, difference, shell, offset, transform), ``convert`` (from_mesh, from_curves) and
``mesh`` (the field meshed within a tolerance).
"""
