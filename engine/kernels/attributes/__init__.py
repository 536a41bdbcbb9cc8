"""Kernels for per-element data: random numbers, noise, and how attributes follow geometry.

- ``random``: ``rand(key, seed)``, a counter-based hash to [0, 1) (no state; the same on
  every machine and in every order of evaluation);
- ``noise``: ``noise(x, y, z)``, 0.96 x Perlin's improved gradient noise (his 2002
  reference), in [-1, 1].

Plain arrays in, plain arrays out; nothing here knows the graph.
"""

from __future__ import annotations

from . import noise, random

__all__ = ["noise", "random"]
