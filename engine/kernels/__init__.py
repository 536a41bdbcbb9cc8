"""Pure array kernels (numpy in, numpy out) that the geometry types and nodes stand on.

Nothing here knows about graphs, ports or caches: each function can be tested and
benchmarked alone.
"""
