"""Kernels on geometry of any type: affine maps and instancing.

- ``affine``: batched rotation matrices (x, then y, then z, fixed axes), the minimal
  rotation taking +z to a direction, and the composed scale-rotate-align frames;
- ``instancing``: copies of a point set or a mesh under many affine maps as one array
  operation (copy-to-points).

Plain arrays in, plain arrays out; nothing here knows the graph.
"""

from __future__ import annotations

from . import affine, instancing

__all__ = ["affine", "instancing"]
