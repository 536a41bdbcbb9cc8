"""Attributes benchmark: rand and noise, the kernels behind per-element variation.

- ``rand`` of 1,000,000 keys (the indices 0..n-1, one seed) against numpy's
  ``Generator.random`` drawing 1,000,000 values from PCG64: ours hashes each key on its
  own (no state), numpy advances one stream, so numpy is the speed of light here;
- ``noise`` (Perlin's improved noise) at 97,336 points against opensimplex's array API on
  a 46 x 46 x 46 grid (the same number of evaluations; opensimplex evaluates only grids).
  opensimplex runs its loops in numba when numba is installed and in plain Python
  otherwise, which is what ``pip install opensimplex`` gives; the note says which ran.
  Ours also at 1,000,000 scattered points;
- ``mesh.catmull_clark`` of the 10,000-quad torus, 2 levels, with and without two point
  attributes (a scalar and a 3-vector colour) and a face attribute carried: the attributes
  ride the same stencils as the coordinates, so the cost is the extra columns only. The
  node is timed through a graph (``g.evaluate`` on a fresh graph each call, no cache).
"""

from __future__ import annotations

import importlib.util

import numpy as np

import formgraph as fg
from formgraph.geometry import Mesh
from formgraph.kernels.attributes.noise import noise
from formgraph.kernels.attributes.random import rand
from formgraph.kernels.mesh import primitives


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

    m = Mesh(*primitives.torus(2.0, 0.7, 100, 100))  # 10,000 quads
    v = m.vertices
    two = m.with_data({"h": v[:, 2], "w": v[:, 0] * v[:, 1]})
    rgb = (v - v.min(axis=0)) / np.ptp(v, axis=0)
    more = m.with_data({"h": v[:, 2], "color": rgb}, {"id": np.arange(m.n_faces)})

    def subdivide(mesh: Mesh) -> object:
        g = fg.Graph()
        g.add_param("m", type="Mesh")
        g.add("cc", "mesh.catmull_clark", mesh="=m", levels=2)
        return g.evaluate("cc", m=mesh)

    case = "catmull_clark 10k-quad torus 2 lvl, 2 point attributes"
    plain = table.time(case, "plain mesh", lambda: subdivide(m), repeat=5)
    ours = table.time(case, "formgraph", lambda: subdivide(two), repeat=5)
    if plain and ours:
        table.rows[-1].note = f"+{100 * (ours / plain - 1):.0f}% for two scalars"
    case = "catmull_clark 10k-quad torus 2 lvl, h + color + face id"
    table.time(case, "plain mesh", lambda: subdivide(m), repeat=5)
    more_s = table.time(case, "formgraph", lambda: subdivide(more), repeat=5)
    if plain and more_s:
        table.rows[-1].note = f"+{100 * (more_s / plain - 1):.0f}% for 4 point columns, 1 face"
