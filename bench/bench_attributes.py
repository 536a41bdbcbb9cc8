"""Attributes benchmark: rand and noise, the kernels behind per-element variation.

- ``rand`` of 1,000,000 keys (the indices 0..n-1, one seed) against numpy's
  ``Generator.random`` drawing 1,000,000 values from PCG64: ours hashes each key on its
  own (no state), numpy advances one stream, so numpy is the speed of light here;
- ``noise`` (Perlin's improved noise) at 97,336 points against opensimplex's array API on
  a 46 x 46 x 46 grid (the same number of evaluations; opensimplex evaluates only grids).
  opensimplex runs its loops in numba when numba is installed and in plain Python
  otherwise, which is what ``pip install opensimplex`` gives; the note says which ran.
  Ours also at 1,000,000 scattered points.
"""

from __future__ import annotations

import importlib.util

import numpy as np

from formgraph.kernels.attributes.noise import noise
from formgraph.kernels.attributes.random import rand


def run(table) -> None:
    n = 1_000_000
    keys = np.arange(n, dtype=np.float64)
    case = "rand: 1M keys"
    table.time(case, "formgraph", lambda: rand(keys, 7), repeat=5)
    gen = np.random.default_rng(7)
    table.time(case, "numpy Generator.random", lambda: gen.random(n), repeat=5)

    side = np.linspace(0.0, 20.0, 46)
    gx, gy, gz = np.meshgrid(side, side, side, indexing="ij")
    gx, gy, gz = gx.ravel(), gy.ravel(), gz.ravel()
    case = "noise: 97k points (46^3 grid)"
    table.time(case, "formgraph", lambda: noise(gx, gy, gz), repeat=3)
    try:
        import opensimplex
    except ImportError:
        table.add(case, "opensimplex", None, "not installed (opensimplex)")
    else:
        opensimplex.seed(0)
        jit = "numba" if importlib.util.find_spec("numba") else "no numba: plain Python"
        table.time(
            case,
            "opensimplex noise3array",
            lambda: opensimplex.noise3array(side, side, side),
            repeat=1,
            note=jit,
        )
    p = np.random.default_rng(1).uniform(-100, 100, (n, 3))
    table.time("noise: 1M scattered points", "formgraph", lambda: noise(*p.T), repeat=3)
