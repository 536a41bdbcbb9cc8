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
  attributes (two scalars), and with a scalar, a 3-vector colour and a face attribute:
  the attributes ride the same stencils as the coordinates (each level two sparse
  products over all the point columns at once), so a column more costs a small part of a
  level, plus its copy into the result. The node is timed through a graph (``g.evaluate``
  on a fresh graph each call, no cache);
- carrying attributes onto a surface made anew (``propagate.onto``: each new vertex's
  nearest input triangle and its barycentric weights, each new face's nearest input face),
  for the vertices of the torus decimated to 20 %, against trimesh's ``closest_point`` for
  the same vertices (closest points only); and ``mesh.decimate`` with and without them.

The rand, Catmull-Clark and decimate rows time ours and the reference in turns, round after
round: the times are each one's best round, the note's ratio the median over rounds of the
two times of the same round (a shared machine's slow spells fall on both alike).
"""

from __future__ import annotations

import importlib.util
import time
from collections.abc import Callable

import numpy as np
from harness import CLOCK

import formgraph as fg
from formgraph.geometry import Mesh
from formgraph.kernels.attributes.noise import noise
from formgraph.kernels.attributes.random import rand
from formgraph.kernels.mesh import primitives

_now = time.process_time if CLOCK == "cpu" else time.perf_counter


def interleaved(
    fns: dict[str, Callable[[], object]], rounds: int
) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    """Each function's best time (s) over ``rounds`` rounds that call every one in turn
    (in a turning order), and every round's times (for ratios within a round)."""
    for fn in fns.values():
        fn()  # warm up
    times: dict[str, list[float]] = {name: [] for name in fns}
    names = list(fns)
    for r in range(rounds):
        # the order turns each round: a call's time depends on what ran just before it
        # (freed and new large buffers: page faults), so every one takes every place
        for name in names[r % len(names) :] + names[: r % len(names)]:
            t0 = _now()
            fns[name]()
            times[name].append(_now() - t0)
    return {k: min(t) for k, t in times.items()}, {k: np.array(t) for k, t in times.items()}


def ratio(times: dict[str, np.ndarray], name: str, base: str) -> float:
    """The median over rounds of ``name``'s time over ``base``'s in the same round:
    steadier on a busy machine than the ratio of two bests."""
    return float(np.median(times[name] / times[base]))


def extra(times: dict[str, np.ndarray], name: str, base: str) -> str:
    return f"{100 * (ratio(times, name, base) - 1):+.0f}%"


def run(table) -> None:
    n = 1_000_000
    keys = np.arange(n, dtype=np.float64)
    gen = np.random.default_rng(7)
    best, times = interleaved({"ours": lambda: rand(keys, 7), "numpy": lambda: gen.random(n)}, 30)
    case = "rand: 1M keys"
    note = f"{ratio(times, 'ours', 'numpy'):.2f}x numpy's (median of rounds)"
    table.add(case, "formgraph", best["ours"], note)
    table.add(case, "numpy Generator.random", best["numpy"])

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

    best, times = interleaved(
        {
            "plain": lambda: subdivide(m),
            "two": lambda: subdivide(two),
            "more": lambda: subdivide(more),
        },
        rounds=30,
    )
    case = "catmull_clark 10k-quad torus 2 lvl, 2 point attributes"
    table.add(case, "plain mesh", best["plain"])
    table.add(case, "formgraph", best["two"], f"{extra(times, 'two', 'plain')} for two scalars")
    case = "catmull_clark 10k-quad torus 2 lvl, h + color + face id"
    table.add(case, "plain mesh", best["plain"])
    note = f"{extra(times, 'more', 'plain')} for 4 point columns, 1 face"
    table.add(case, "formgraph", best["more"], note)

    # a surface made anew carries attributes from the input's closest points: the query
    # (exact nearest triangle, barycentric weights, faces' nearest) against trimesh's
    # closest_point for the same vertices, and the decimate node with and without them
    import trimesh

    from formgraph.kernels.attributes import propagate as carry
    from formgraph.kernels.mesh import meshops

    def decimate(mesh: Mesh) -> Mesh:
        g = fg.Graph()
        g.add_param("m", type="Mesh")
        g.add("d", "mesh.decimate", mesh="=m", ratio=0.2)
        return g.evaluate("d", m=mesh)

    tri = meshops.triangulate(*m.arrays)[1].reshape(-1, 3)
    out = decimate(m)
    faces = (out.face_indices, out.face_offsets)
    tm = trimesh.Trimesh(m.vertices, tri, process=False)
    best, times = interleaved(
        {
            "ours": lambda: carry.onto(more, out.vertices, faces, tri),
            "trimesh": lambda: trimesh.proximity.closest_point(tm, out.vertices),
            "plain": lambda: decimate(m),
            "more": lambda: decimate(more),
        },
        rounds=5,
    )
    case = f"attributes onto the decimated torus ({out.n_vertices} vertices)"
    table.add(case, "formgraph", best["ours"], "nearest triangles, weights, faces' nearest")
    table.add(case, "trimesh closest_point", best["trimesh"], "the closest points only")
    case = "mesh.decimate 10k-quad torus to 20%, h + color + face id"
    table.add(case, "plain mesh", best["plain"])
    note = f"{extra(times, 'more', 'plain')} for the attributes"
    table.add(case, "formgraph", best["more"], note)
