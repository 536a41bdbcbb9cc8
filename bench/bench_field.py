"""Fields benchmark: adaptive meshing, mesh distances, offsets, smoothing, decimation.

- a gyroid lattice (period 10, wall 1) cut by a 50 mm cube at 0.25 mm cells (8M cells
  dense): ``mesher.mesh_field`` against the same field sampled densely with numpy and
  meshed by scikit-image's ``marching_cubes`` (the issue's reference: the field sampled
  point by point, as ``Field.evaluate`` does), and, for what the sampling API alone is
  worth, the same with the dense grid sampled on ``Field.evaluate_grid``'s tables; and
  against manifold3d's ``level_set`` (which calls the field once per point from C++; run
  on a smaller cube, scaled by the cell count);
- the cost of halving the cell (a sphere of radius 20 at 0.4 and 0.2 mm): about 4x for a
  method whose work is in the surface's area, 8x for a dense grid;
- the signed distance of a 102,400-triangle torus at random points in its box against
  trimesh's ``proximity.signed_distance`` (per point: trimesh gets fewer points);
- ``mesh.offset`` of that torus by 0.05 at the default cell;
- quadric decimation of a 327,680-triangle sphere to 10 %: ``mesh.decimate``'s kernel
  (the library, the zero-length edges it leaves, the closedness checks) against
  fast-simplification called directly, best of three rounds taken in turn;
- Taubin smoothing of a 1M-vertex mesh, 10 lambda|mu steps, against trimesh's
  ``filter_taubin`` with the same 20 passes; and ``mesh.smooth`` as a graph calls it (each
  closed part's volume kept), beside its kernel with and without ``keep_volume``.

``BENCH_FIELD_SCALE`` (default 1) divides the sizes for a busy machine (2: a 25 mm cube,
fewer points and vertices).
"""

from __future__ import annotations

import os

import numpy as np

from formgraph.geometry import Field, Mesh
from formgraph.kernels.field import mesher, sdf
from formgraph.kernels.mesh import simplify as ksimp
from formgraph.kernels.mesh import smooth as ksm

SCALE = float(os.environ.get("BENCH_FIELD_SCALE", "1"))


def _gyroid_box(side: float) -> Field:
    """The gyroid sheet cut by a cube: ``max(tpms, box)``, as ``field.mesh`` meshes it."""
    return Field.intersection([Field.tpms("gyroid", 10.0, 1.0), Field.box([side] * 3)])


def _ours(f: Field, side: float, cell: float = 0.25):
    lo, hi = [-side / 2] * 3, [side / 2] * 3
    return mesher.mesh_field(
        f.evaluate, lo, hi, cell, 2.0, grid=f.evaluate_grid, lines=f.evaluate_lines
    )


def _dense_skimage(f, side: float, cell: float):
    from skimage.measure import marching_cubes

    n = int(round(side / cell)) + 3
    ax = (np.arange(n) - (n - 1) / 2) * cell
    grid = np.stack(np.meshgrid(ax, ax, ax, indexing="ij"), -1).reshape(-1, 3)
    vol = f(grid).reshape(n, n, n)
    return marching_cubes(vol, 0.0, spacing=(cell,) * 3)


def _dense_tables_skimage(f: Field, side: float, cell: float):
    """The dense reference with the sampling on the lattice tables (``evaluate_grid``,
    32 planes a call): what the sampling API alone is worth to a dense mesher."""
    from skimage.measure import marching_cubes

    n = int(round(side / cell)) + 3
    ax = (np.arange(n) - (n - 1) / 2) * cell
    planes = np.stack([ax, np.full(n, ax[0]), np.full(n, ax[0])], axis=1)
    vol = np.concatenate(
        [f.evaluate_grid(planes[i : i + 32], cell, (1, n, n)) for i in range(0, n, 32)]
    )
    return marching_cubes(vol.reshape(n, n, n), 0.0, spacing=(cell,) * 3)


def _manifold(f, side: float, cell: float):
    import manifold3d

    h = side / 2 + cell
    # manifold3d keeps the negative side of its function as solid? It keeps f > 0: negate
    return manifold3d.Manifold.level_set(
        lambda x, y, z: -float(f(np.array([[x, y, z]]))[0]), [-h, -h, -h, h, h, h], cell
    )


def _torus(sections: int = 320):
    import trimesh

    return trimesh.creation.torus(1.0, 0.4, major_sections=sections, minor_sections=sections // 2)


def run(table) -> None:
    side = 50.0 / SCALE
    f = _gyroid_box(side)
    case = (
        f"gyroid lattice, {side:g} mm cube at 0.25 mm cells ({(side / 0.25) ** 3 / 1e6:.1f}M dense)"
    )
    table.time_together(  # alternating rounds: a burst of load falls on all three
        case,
        [
            ("formgraph", lambda: _ours(f, side), ""),
            ("numpy dense + skimage marching_cubes", lambda: _dense_skimage(f, side, 0.25), ""),
            (
                "numpy dense on the lattice tables + skimage (not the target's reference)",
                lambda: _dense_tables_skimage(f, side, 0.25),
                "",
            ),
        ],
        rounds=3,
    )
    small = 10.0
    case_m = (
        f"gyroid lattice, {small:g} mm cube at 0.25 mm cells (manifold3d's level_set is per point)"
    )
    fs = _gyroid_box(small)
    table.time(
        case_m,
        "formgraph",
        lambda: _ours(fs, small),
        repeat=1,
    )
    table.time(case_m, "manifold3d level_set", lambda: _manifold(fs, small, 0.25), repeat=1)

    def ball(p):
        return sdf.sphere(p, 20.0, np.zeros(3))

    for cell in (0.4, 0.2):
        table.time(
            "sphere r = 20: cell 0.4 then 0.2 (the ratio is the cost of halving)",
            f"formgraph, cell {cell}",
            lambda cell=cell: mesher.mesh_field(ball, [-20] * 3, [20] * 3, cell),
            repeat=1,
        )

    import trimesh

    tor = _torus()
    mesh = Mesh(tor.vertices, tor.faces.reshape(-1), np.arange(0, tor.faces.size + 1, 3))
    rng = np.random.default_rng(0)
    n_ours, n_ref = int(100_000 / SCALE), int(5_000 / SCALE)
    p = rng.uniform(-1.5, 1.5, (n_ours, 3)) * [1, 1, 0.4]
    field = Field.from_mesh(mesh)
    field.evaluate(p[:10])  # build the trees outside the timing
    case = (
        f"signed distance to a {len(tor.faces):,}-triangle torus, per 100k random points in its box"
    )
    t = table.time(case, f"formgraph ({n_ours:,} points)", lambda: field.evaluate(p), repeat=1)
    table.time(
        case,
        "trimesh proximity",
        lambda: [trimesh.proximity.signed_distance(tor, p[:n_ref]) for _ in range(1)],
        repeat=1,
    )
    if t is not None and table.rows[-1].seconds is not None:
        table.rows[-1].seconds *= n_ours / n_ref  # the same number of points as ours

    from pathlib import Path

    from formgraph.core.registry import Context
    from formgraph.nodes.field.mesh import mesh_of

    ctx = Context("offset", Path("."), budget=10**9)
    table.time(
        f"mesh.offset of a {len(tor.faces):,}-triangle torus by 0.05, default cell",
        "formgraph",
        lambda: mesh_of(Field.offset(Field.from_mesh(mesh), 0.05), None, None, ctx),
        repeat=1,
    )

    s = trimesh.creation.icosphere(int(7 - np.log2(SCALE) / 2))
    case = f"decimate a {len(s.faces):,}-triangle sphere to 10 % (best of 3, interleaved)"

    def ours():
        return ksimp.decimate(s.vertices, s.faces, len(s.faces) // 10)

    def direct():
        import fast_simplification

        return fast_simplification.simplify(s.vertices, s.faces, target_reduction=0.9, agg=7.0)

    from harness import best_time

    times = {"formgraph": [], "fast-simplification directly": []}
    for _ in range(3):  # alternate, so a busy spell of the machine falls on both
        for impl, fn in (("formgraph", ours), ("fast-simplification directly", direct)):
            times[impl].append(best_time(fn, repeat=1))
    for impl, ts in times.items():
        table.add(case, impl, min(ts))

    _smoothing(table)


def _smoothing(table) -> None:
    import trimesh

    import formgraph as fg

    big = trimesh.creation.icosphere(int(8 - np.log2(SCALE) / 2))  # 655k vertices at 8
    big = trimesh.Trimesh(
        np.concatenate([big.vertices, big.vertices + 3]),
        np.concatenate([big.faces, big.faces + len(big.vertices)]),
        process=False,
    )
    fi = big.faces.reshape(-1)
    fo = np.arange(0, fi.size + 1, 3)
    case = f"Taubin smoothing, {len(big.vertices):,} vertices, 10 lambda-mu steps"
    table.time(case, "formgraph", lambda: ksm.smooth(big.vertices, fi, fo, 10), repeat=1)
    table.time(
        case,
        "trimesh filter_taubin (20 passes)",
        lambda: trimesh.smoothing.filter_taubin(big.copy(), iterations=20),
        repeat=1,
    )

    # keep_volume (mesh.smooth's default): each closed part scaled back to its volume after
    # every step, through the public API; beside the kernel with and without it
    mesh = Mesh(big.vertices, fi, fo)

    def through_graph():
        g = fg.Graph()
        g.add_param("m", type="Mesh")
        g.add("s", "mesh.smooth", mesh="=m", iterations=10)
        return g.evaluate("s", m=mesh)

    table.compare(
        f"mesh.smooth (Taubin, keep_volume), {len(big.vertices):,} vertices, 10 steps",
        api=through_graph,
        kernel=lambda: ksm.smooth(big.vertices, fi, fo, 10, keep_volume=True),
        references={
            "formgraph kernel, the filter alone": lambda: ksm.smooth(big.vertices, fi, fo, 10),
            "trimesh filter_taubin (20 passes, volume not kept)": (
                lambda: trimesh.smoothing.filter_taubin(big.copy(), iterations=20)
            ),
        },
        rounds=3,
        note="two closed spheres, each kept to its volume",
    )
