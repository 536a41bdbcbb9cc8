"""Fields: adaptive meshing, mesh distances, offsets, smoothing, decimation.

- a gyroid lattice (period 10, wall 1) cut by a 50 mm cube at 0.25 mm cells (8M cells
  dense): ``field.tpms`` -> ``field.box`` -> ``field.intersection`` -> ``field.mesh``
  through a graph (each call the cube a hair larger, so everything below the box runs),
  the kernel (``mesher.mesh_field`` on the field) beside, against the same field written
  the way a numpy user writes it -- the dense lattice by broadcasting (``np.ix_``: sines
  of each axis once, the gyroid's value and gradient, the box, their maximum) -- and
  meshed by scikit-image's ``marching_cubes``;
- the same gyroid in a 10 mm cube against manifold3d's ``level_set``, which calls a Python
  function once per grid point: its users write that function in plain ``math``;
- the cost of halving the cell (a sphere of radius 20 at 0.4 and 0.2 mm): about 4x for a
  method whose work is in the surface's area, 8x for a dense grid;
- the signed distance of a 102,400-triangle torus at 100,000 random points in its box
  through ``field.from_mesh`` and ``Field.evaluate`` against trimesh's
  ``proximity.signed_distance`` on 5,000 of the points (its time scaled to 100,000), and
  pysdf where it is installed;
- ``mesh.offset`` of that torus by 0.05 at the default cell, through the node;
- quadric decimation of a 327,680-triangle sphere to 10 % through ``mesh.decimate``
  against fast-simplification called directly;
- Taubin smoothing of a 1.3M-vertex mesh (two closed spheres), 10 lambda|mu steps through
  ``mesh.smooth`` (each closed part kept to its volume, its default), beside its kernel and
  the filter alone, against trimesh's ``filter_taubin`` with the same 20 passes (volume
  not kept).

``BENCH_FIELD_SCALE`` (default 1) divides the sizes for a busy machine (2: a 25 mm cube,
fewer points and vertices).
"""

from __future__ import annotations

import itertools
import math
import os

import numpy as np

import formgraph as fg
from formgraph.geometry import Field, Mesh
from formgraph.kernels.field import mesher, sdf

SCALE = float(os.environ.get("BENCH_FIELD_SCALE", "1"))
PERIOD, WALL = 10.0, 1.0


def _gyroid_box(side: float) -> Field:
    """The gyroid sheet cut by a cube: ``max(tpms, box)``, as ``field.mesh`` meshes it."""
    return Field.intersection([Field.tpms("gyroid", PERIOD, WALL), Field.box([side] * 3)])


def _kernel(f: Field, side: float, cell: float = 0.25):
    lo, hi = [-side / 2] * 3, [side / 2] * 3
    return mesher.mesh_field(
        f.evaluate, lo, hi, cell, 2.0, grid=f.evaluate_grid, lines=f.evaluate_lines
    )


def _graph(side: float, cell: float = 0.25):
    g = fg.Graph()
    g.add_param("s", side)
    g.add("t", "field.tpms", kind="gyroid", period=PERIOD, thickness=WALL)
    g.add("b", "field.box", size=["=s", "=s", "=s"])
    g.add("i", "field.intersection", fields=["@t", "@b"])
    g.add("m", "field.mesh", field="@i", cell=cell)
    steps = itertools.count(1)
    return lambda: g.evaluate("m", s=side * (1 + next(steps) * 1e-9))


def numpy_gyroid(side: float, cell: float):
    """The gyroid sheet in a cube, sampled densely by numpy broadcasting and meshed by
    scikit-image: what a numpy user writes (the same field as ``field.tpms``: Taubin's
    distance |f| / |grad f| capped at a quarter period, less half the wall; the box's
    exact distance; their maximum)."""
    from skimage.measure import marching_cubes

    n = int(round(side / cell)) + 3
    ax = (np.arange(n) - (n - 1) / 2) * cell
    x, y, z = np.ix_(ax, ax, ax)
    w = 2 * np.pi / PERIOD
    sx, cx, sy, cy, sz, cz = (fn(w * a) for a in (x, y, z) for fn in (np.sin, np.cos))
    f = sx * cy + sy * cz + sz * cx
    grad = w * np.sqrt(
        (cx * cy - sz * sx) ** 2 + (cy * cz - sx * sy) ** 2 + (cz * cx - sy * sz) ** 2
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.minimum(np.where(grad > 0, np.abs(f) * w / grad, PERIOD / 4), PERIOD / 4) - WALL / 2
    q = [np.abs(a) - side / 2 for a in (x, y, z)]
    outside = np.sqrt(sum(np.maximum(c, 0) ** 2 for c in q))
    box = outside + np.minimum(np.maximum(np.maximum(q[0], q[1]), q[2]), 0)
    return marching_cubes(np.maximum(d, box), 0.0, spacing=(cell,) * 3)


def _gyroid_math(x: float, y: float, z: float, side: float) -> float:
    """The same field at one point in plain ``math``: what manifold3d's level_set calls."""
    w = 2 * math.pi / PERIOD
    sx, cx = math.sin(w * x), math.cos(w * x)
    sy, cy = math.sin(w * y), math.cos(w * y)
    sz, cz = math.sin(w * z), math.cos(w * z)
    f = (sx * cy + sy * cz + sz * cx) / w
    g = math.sqrt((cx * cy - sz * sx) ** 2 + (cy * cz - sx * sy) ** 2 + (cz * cx - sy * sz) ** 2)
    d = min(abs(f) / g, PERIOD / 4) if g > 0 else PERIOD / 4
    qx, qy, qz = abs(x) - side / 2, abs(y) - side / 2, abs(z) - side / 2
    box = math.sqrt(max(qx, 0) ** 2 + max(qy, 0) ** 2 + max(qz, 0) ** 2) + min(max(qx, qy, qz), 0)
    return max(d - WALL / 2, box)


def _manifold(side: float, cell: float):
    import manifold3d

    h = side / 2 + cell
    # manifold3d keeps where its function is positive: the negative of our field
    return manifold3d.Manifold.level_set(
        lambda x, y, z: -_gyroid_math(x, y, z, side), [-h, -h, -h, h, h, h], cell
    )


def run(table) -> None:
    side = 50.0 / SCALE
    f = _gyroid_box(side)
    table.compare(
        f"gyroid lattice, {side:g} mm cube at 0.25 mm cells ({(side / 0.25) ** 3 / 1e6:.1f}M "
        "dense)",
        api=_graph(side),
        kernel=lambda: _kernel(f, side),
        references={
            "numpy broadcasting + skimage marching_cubes": lambda: numpy_gyroid(side, 0.25)
        },
        rounds=5,
    )
    small = 10.0
    fs = _gyroid_box(small)
    table.compare(
        f"gyroid lattice, {small:g} mm cube at 0.25 mm cells",
        api=_graph(small),
        kernel=lambda: _kernel(fs, small),
        references={"manifold3d level_set (a plain math callback)": lambda: _manifold(small, 0.25)},
        rounds=3,
    )
    _halving(table)
    _distance(table)
    _offset(table)
    _decimate(table)
    _smooth(table)


def _halving(table) -> None:
    def ball(p):
        return sdf.sphere(p, 20.0, np.zeros(3))

    def mesh(cell: float):
        g = fg.Graph()
        g.add_param("r", 20.0)
        g.add("s", "field.sphere", radius="=r")
        g.add("m", "field.mesh", field="@s", cell=cell)
        steps = itertools.count(1)
        return lambda: g.evaluate("m", r=20.0 * (1 + next(steps) * 1e-9))

    table.compare(
        "sphere r = 20: cell 0.2 against cell 0.4 (the cost of halving the cell)",
        api=mesh(0.2),
        kernel=lambda: mesher.mesh_field(ball, [-20] * 3, [20] * 3, 0.2),
        references={"formgraph at cell 0.4": mesh(0.4)},
        rounds=3,
        note="ours/theirs is the cost of halving: ~4 for work in the area, 8 for a grid",
    )


def _torus(sections: int = 320):
    import trimesh

    return trimesh.creation.torus(1.0, 0.4, major_sections=sections, minor_sections=sections // 2)


def _distance(table) -> None:
    tor = _torus()
    mesh = Mesh(tor.vertices, tor.faces.reshape(-1), np.arange(0, tor.faces.size + 1, 3))
    rng = np.random.default_rng(0)
    n, n_ref = int(100_000 / SCALE), int(5_000 / SCALE)
    p = rng.uniform(-1.5, 1.5, (n, 3)) * [1, 1, 0.4]
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("f", "field.from_mesh", mesh="=m")
    field = g.evaluate("f", m=mesh)  # the trees built once, as a graph's field keeps them

    def trimesh_scaled():
        import trimesh

        for _ in range(n // n_ref):  # the same number of points as ours
            trimesh.proximity.signed_distance(tor, p[:n_ref])

    def pysdf():
        from pysdf import SDF

        return SDF(tor.vertices, tor.faces)(p)

    table.compare(
        f"signed distance to a {len(tor.faces):,}-triangle torus at {n:,} random points",
        api=lambda: field.evaluate(p),
        references={
            f"trimesh proximity ({n_ref:,} points, x{n // n_ref})": trimesh_scaled,
            "pysdf (its tree built each call)": pysdf,
        },
        rounds=3,
        note="field.from_mesh's field (trees built once), Field.evaluate",
        warmup=False,
    )


def _offset(table) -> None:
    tor = _torus()
    mesh = Mesh(tor.vertices, tor.faces.reshape(-1), np.arange(0, tor.faces.size + 1, 3))
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add_param("d", 0.05)
    g.add("o", "mesh.offset", mesh="=m", distance="=d")
    steps = itertools.count(1)
    table.compare(
        f"mesh.offset of a {len(tor.faces):,}-triangle torus by 0.05, default cell",
        api=lambda: g.evaluate("o", m=mesh, d=0.05 * (1 + next(steps) * 1e-9)),
        rounds=1,
        warmup=False,
    )


def _decimate(table) -> None:
    import trimesh

    s = trimesh.creation.icosphere(int(7 - np.log2(SCALE) / 2))
    mesh = Mesh(s.vertices, s.faces.reshape(-1), np.arange(0, s.faces.size + 1, 3))
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add_param("r", 0.1)
    g.add("d", "mesh.decimate", mesh="=m", ratio="=r")
    steps = itertools.count(1)

    def direct():
        import fast_simplification

        return fast_simplification.simplify(s.vertices, s.faces, target_reduction=0.9, agg=7.0)

    from formgraph.kernels.mesh import simplify as ksimp

    table.compare(
        f"mesh.decimate of a {len(s.faces):,}-triangle sphere to 10 %",
        api=lambda: g.evaluate("d", m=mesh, r=0.1 + next(steps) * 1e-12),
        kernel=lambda: ksimp.decimate(s.vertices, s.faces, len(s.faces) // 10),
        references={"fast-simplification directly": direct},
        rounds=3,
    )


def _smooth(table) -> None:
    import trimesh

    from formgraph.kernels.mesh import smooth as ksm

    big = trimesh.creation.icosphere(int(8 - np.log2(SCALE) / 2))  # 655k vertices at 8
    big = trimesh.Trimesh(
        np.concatenate([big.vertices, big.vertices + 3]),
        np.concatenate([big.faces, big.faces + len(big.vertices)]),
        process=False,
    )
    fi = big.faces.reshape(-1)
    fo = np.arange(0, fi.size + 1, 3)
    mesh = Mesh(big.vertices, fi, fo)
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("s", "mesh.smooth", mesh="=m", iterations=10)
    moved = (
        Mesh.trusted(mesh.vertices * (1 + k * 1e-12), mesh.face_indices, mesh.face_offsets)
        for k in itertools.count(1)
    )
    table.compare(
        f"mesh.smooth (Taubin, keep_volume), {len(big.vertices):,} vertices, 10 steps",
        api=lambda: g.evaluate("s", m=next(moved)),
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
