"""The ``attr.*`` nodes: per-element attributes set, measured and carried between geometries.

``set`` (expressions per point or face).
"""
