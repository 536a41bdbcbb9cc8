"""Kernels on geometry of any type: affine maps and instancing.

- ``affine``: batched rotation matrices (x, then y, then z, fixed axes), the minimal
  rotation taking +z to a direction, and the composed scale-rotate-align frames;
- ``instancing``: copies of a point set or a mesh under many affine maps as one array
  operation (copy-to-points);
- ``meshdist``: the one closest-point code of the project: exact distance, closest point
  and barycentric weights from points to triangles or segments, its sign by the
  angle-weighted pseudonormal on a closed mesh or the generalized winding number (a
  Barnes-Hut tree of dipoles, Barill et al. 2018); used by ``field.from_mesh``,
  ``attr.distance``, ``attr.transfer``, remeshing and attribute propagation;
- ``proximity``: one geometry asked about another: nearest points, closest points on
  polylines, meshes and fields, signed distances.

Plain arrays in, plain arrays out; nothing here knows the graph.
"""

from __future__ import annotations

from . import affine, instancing

__all__ = ["MAX_COORDINATE", "affine", "instancing"]

# millimetres: past 1e15 a double no longer holds a tenth of a millimetre (its spacing there
# is 0.125), so a coordinate beyond it is an error of the input (a skew of 90 degrees, a
# text of size 1e308), refused by what reads or makes it rather than passed on to overflow
MAX_COORDINATE = 1e15
