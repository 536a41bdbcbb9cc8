"""Layout kernels: parts put on sheets.

- ``nfp``: no-fit polygons (Minkowski sums by convolution, holes by erosion) on an integer
  grid, and the free region left for a part;
- ``nest``: bottom-left fill over the no-fit polygons and the search over the order the
  parts are placed in (:func:`nest`).
"""
