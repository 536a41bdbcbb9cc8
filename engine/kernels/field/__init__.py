"""Field kernels: signed distance functions on point arrays and the meshing of their zero set.

- ``sdf``: exact distances to spheres, boxes (rounded), cylinders, tori; polynomial smooth
  min/max (Lipschitz-preserving blends); TPMS sheets (gyroid, Schwarz P, diamond) of even
  wall thickness; the same on lattices of points (outer sums and products of tables along
  the axes) and on the lines of a lattice;
- (the distance to a mesh that ``field.from_mesh`` evaluates is
  :mod:`formgraph.kernels.geometry.meshdist`, shared with ``attr.distance``);
- ``lattice``: the mesher's blocks: octree culling by the Lipschitz reach down to blocks
  of 8^3 cells, then dense per-block levels, corners owned by one block and signs
  inferred where the Lipschitz bound decides them (or every corner sampled on lattices);
- ``mesher``: marching cubes on the lattice's cells, vertices numbered by their edges'
  perfect hash group by group, placed by root-finding on the field (``roots``: a cubic
  guess from the samples along the edge, one sample, then inverse quadratic and regula
  falsi steps for the few it does not decide);
- ``mctable``: the marching-cubes table, built from one rule on each face (inside corners
  separated), so shared faces agree and the surface is watertight.

The modules are imported on use (``from formgraph.kernels.field import mesher``).
"""
