"""Attributes: ``rand`` and ``noise`` through ``attr.set``, attributes through Catmull-Clark
and decimation.

- ``rand`` of 1,000,000 points through ``attr.set`` (``value: "=rand(i, s)"`` on a cached
  ``points.random``; each call a new seed ``s``, so the node runs and its attribute is
  stored on a new, frozen ``Points``) against numpy's ``Generator.random(1_000_000)``
  (PCG64 advancing one stream in C, the array discarded: the speed of light here; ours
  hashes each key on its own, with no state);
- ``noise`` (Perlin's improved noise) at the 1,000,000 points of a 100^3 grid through
  ``attr.set`` (``"=noise(x + s, y, z)"``, a new ``s`` each call) against opensimplex's
  ``noise3array`` on the same 100 x 100 x 100 grid (it evaluates grids only), with numba
  when numba is installed (the note says which ran; opensimplex without numba runs its
  loops in plain Python, thousands of times slower);
- ``mesh.catmull_clark`` of the 10,000-quad torus, 2 levels, through a graph whose mesh is
  a param: a plain mesh, two point attributes, and a scalar, a 3-vector colour and a face
  attribute (each call the points moved by a new tiny amount, as a slider's step moves
  them: the mesh is new content, hashed once, and the node runs);
- ``mesh.decimate`` of that torus to 20 % with and without the attributes, and the
  carrying of attributes onto the decimated surface (``propagate.onto``: each new vertex's
  nearest input triangle and barycentric weights, each new face's nearest input face)
  against trimesh's ``closest_point`` for the same vertices (the closest points only).
"""

from __future__ import annotations

import importlib.util
import itertools

import numpy as np

import formgraph as fg
from formgraph.geometry import Mesh
from formgraph.kernels.attributes.noise import noise
from formgraph.kernels.attributes.random import rand
from formgraph.kernels.mesh import primitives

N = 1_000_000


def _attr_graph(points: str, value: str) -> fg.Graph:
    g = fg.Graph()
    g.add_param("s", 0.0)
    if points == "random":
        g.add("pts", "points.random", count=N)
    else:
        g.add("pts", "points.grid", nx=100, ny=100, nz=100, spacing=0.2)
    g.add("attr", "attr.set", geometry="@pts", name="v", value=value)
    g.evaluate("attr")  # the points made once and cached, as a slider's steps find them
    return g


def _fresh(g: fg.Graph, scale: float = 1.0):
    seeds = itertools.count(1)
    return lambda: g.evaluate("attr", s=next(seeds) * scale)


def run(table) -> None:
    keys = np.arange(N, dtype=np.float64)
    gen = np.random.default_rng(7)
    table.compare(
        "rand through attr.set, 1M points",
        api=_fresh(_attr_graph("random", "=rand(i, s)")),
        kernel=lambda: rand(keys, 7.0),
        references={"numpy Generator.random": lambda: gen.random(N)},
        rounds=9,
        note="a new seed each call: the attribute made and frozen on a new Points",
    )

    side = np.arange(100) * 0.2
    grid = np.stack(np.meshgrid(side, side, side, indexing="ij"), -1).reshape(-1, 3)
    gx, gy, gz = (np.ascontiguousarray(c) for c in grid.T)

    def opensimplex_grid():
        import opensimplex

        return opensimplex.noise3array(side, side, side)

    jit = "numba" if importlib.util.find_spec("numba") else "no numba: plain Python loops"
    table.compare(
        "noise through attr.set, 1M points (100^3 grid)",
        api=_fresh(_attr_graph("grid", "=noise(x + s, y, z)"), 1e-3),
        kernel=lambda: noise(gx, gy, gz),
        references={f"opensimplex noise3array ({jit})": opensimplex_grid},
        rounds=7,
        note="a new offset s each call",
    )

    _catmull_clark(table)
    _decimate(table)


def _torus_with_attributes() -> tuple[Mesh, Mesh, Mesh]:
    m = Mesh(*primitives.torus(2.0, 0.7, 100, 100))  # 10,000 quads
    v = m.vertices
    two = m.with_data({"h": v[:, 2], "w": v[:, 0] * v[:, 1]})
    rgb = (v - v.min(axis=0)) / np.ptp(v, axis=0)
    more = m.with_data({"h": v[:, 2], "color": rgb}, {"id": np.arange(m.n_faces)})
    return m, two, more


def _through(node: str, **inputs):
    """``make(mesh)``: a call evaluating ``node(mesh=param m)`` on ``mesh`` with its points
    moved by a new tiny amount each call (a slider's step: new content, so the node runs;
    the faces the same, as a slider leaves them)."""
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("n", node, mesh="=m", **inputs)

    def make(mesh: Mesh):
        steps = itertools.count(1)

        def call():
            v = mesh.vertices * (1.0 + next(steps) * 1e-12)
            moved = Mesh.trusted(v, mesh.face_indices, mesh.face_offsets, *mesh_data(mesh))
            return g.evaluate("n", m=moved)

        return call

    return make


def mesh_data(mesh: Mesh) -> tuple:
    return mesh.point_data, mesh.face_data


def _catmull_clark(table) -> None:
    from formgraph.kernels.mesh.subdivision import catmull_clark

    m, two, more = _torus_with_attributes()
    cc = _through("mesh.catmull_clark", levels=2)
    arrays = m.arrays
    table.compare(
        "catmull_clark 10k-quad torus 2 lvl, attributes",
        api=cc(two),
        kernel=lambda: catmull_clark(*arrays, 2),
        references={"plain mesh through the graph": cc(m), "h + color + face id": cc(more)},
        rounds=9,
        note="two point scalars; ours/theirs against the plain mesh is their cost",
    )


def _decimate(table) -> None:
    from formgraph.kernels.attributes import propagate as carry
    from formgraph.kernels.mesh import meshops

    m, _, more = _torus_with_attributes()
    dec = _through("mesh.decimate", ratio=0.2)
    table.compare(
        "mesh.decimate 10k-quad torus to 20%, h + color + face id",
        api=dec(more),
        references={"plain mesh through the graph": dec(m)},
        rounds=7,
    )
    tri = meshops.triangulate(*m.arrays)[1].reshape(-1, 3)
    out = dec(m)()
    faces = (out.face_indices, out.face_offsets)

    def trimesh_closest():
        import trimesh

        tm = trimesh.Trimesh(m.vertices, tri, process=False)
        return trimesh.proximity.closest_point(tm, out.vertices)

    table.compare(
        f"attributes onto the decimated torus ({out.n_vertices:,} vertices)",
        api=lambda: carry.onto(more, out.vertices, faces, tri),
        references={"trimesh closest_point": trimesh_closest},
        rounds=7,
        note="the kernel: nearest triangles, weights, faces' nearest",
        notes={"trimesh closest_point": "the closest points only (its tree built each call)"},
    )
