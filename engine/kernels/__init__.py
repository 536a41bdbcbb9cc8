"""Pure array kernels (numpy in, numpy out) that the geometry types and nodes stand on.

Nothing here knows about graphs, ports or caches: each function can be tested and
benchmarked alone. One package per family, mirroring ``nodes/``:

- ``nurbs``: basis functions, curves, surfaces, knot operations, fitting, constructions;
- ``curves``: Bezier and Catmull-Rom splines, polyline subdivision, resampling, offset;
- ``mesh``: half-edges, subdivision, mesh operations, structured grids;
- ``offset``: distance fields, marching squares, loop clean-up and refinement;
- ``field``: signed distance functions, mesh distances, adaptive meshing of zero sets;
- ``io``: STL, OBJ, PLY, SVG, PDF and DXF writers and their number formatting;
- ``buffers``: immutable ``bytes`` buffers filled in place (what frozen arrays stand on);
- ``finite``: whether an array is finite, in one pass.
"""
