"""The ``geometry.*`` nodes: operations that take any geometry.

``transform`` and ``sample`` (sample_surface).
"""
