"""The graph language: copy-to-points against trimesh, and a repeated node against as many
hand-written nodes.

- ``mesh.copy_to_points`` of a 1,000-face mesh onto 10,000 points, each copy with its own
  rotation and scale, against trimesh: ``apply_transform`` on a copy per point, then
  ``trimesh.util.concatenate`` (the usual way to instance with it).
- One node with ``repeat: {i: 1000}`` against 1,000 hand-written nodes doing the same
  (``bench.item``, no work: the engine overhead alone), cold, and after one more item.
"""

from __future__ import annotations

import itertools

import numpy as np

import formgraph as fg
from formgraph.core.registry import Context, node
from formgraph.geometry import Mesh, Points
from formgraph.kernels.mesh.meshops import rotation_matrix

N_COPIES = 10_000
N_ITEMS = 1_000


@node("bench.item", version=1)
def item(a: float, b: float = 1.0) -> float:
    """a + b (no work: the per-node or per-item overhead alone)."""
    return a + b


def _part():
    import trimesh

    part = trimesh.creation.cylinder(radius=0.1, height=0.3, sections=250)
    assert len(part.faces) == 1000
    return part


def _placements():
    rng = np.random.default_rng(0)
    return (
        rng.uniform(-50, 50, size=(N_COPIES, 3)),
        rng.uniform(-180, 180, size=(N_COPIES, 3)),
        rng.uniform(0.5, 2.0, size=N_COPIES),
    )


def ours(mesh: Mesh, points: Points, rotate: np.ndarray, scale: list[float]) -> Mesh:
    from formgraph.nodes.mesh.instance import mesh_copy_to_points

    ctx = Context("bench", out_dir=None, budget=10**9)  # type: ignore[arg-type]
    return mesh_copy_to_points(mesh, points, scale=scale, rotate=rotate, ctx=ctx)


def with_trimesh(part, pts: np.ndarray, rot: np.ndarray, scale: np.ndarray):
    import trimesh

    copies = []
    for p, r, s in zip(pts, rot, scale, strict=True):
        t = np.eye(4)
        t[:3, :3] = rotation_matrix(r) * s
        t[:3, 3] = p
        copies.append(part.copy().apply_transform(t))
    return trimesh.util.concatenate(copies)


def repeated_graph(n: int) -> fg.Graph:
    g = fg.Graph()
    g.add_param("n", n)
    g.add("x", "bench.item", a=0.0)
    g.add("items", "bench.item", repeat={"i": "=n"}, a="@x", b="=i")
    return g


def written_graph(n: int) -> fg.Graph:
    g = fg.Graph()
    g.add("x", "bench.item", a=0.0)
    for i in range(n):
        g.add(f"n{i}", "bench.item", a="@x", b=float(i))
    return g


def run(table) -> None:
    pts, rot, scale = _placements()
    try:
        part = _part()
    except ImportError:
        part = None
    if part is not None:
        mesh = Mesh(part.vertices, part.faces.reshape(-1), np.arange(0, 3001, 3))
        points, scales, rots = Points(pts), scale.tolist(), rot.tolist()
        g = fg.Graph()
        g.add_param("m", type="Mesh")
        g.add_param("p", type="Points")
        g.add("c", "mesh.copy_to_points", mesh="=m", points="=p", scale=scales, rotate=rots)
        steps = itertools.count(1)

        def ours_graph():
            # the points moved a hair each call (made and hashed in our time); each copy's
            # rotation and scale literal lists (keyed once, with the graph)
            return g.evaluate("c", m=mesh, p=Points(pts * (1 + next(steps) * 1e-12)))

        table.compare(
            f"mesh.copy_to_points: 1,000 faces onto {N_COPIES:,} points",
            api=ours_graph,
            kernel=lambda: ours(mesh, points, rot, scales),
            references={"trimesh": lambda: with_trimesh(part, pts, rot, scale)},
            notes={"trimesh": "apply_transform on a copy per point + util.concatenate"},
            rounds=3,
            note="each copy its own rotation and scale",
        )

    names = [f"n{i}" for i in range(N_ITEMS)]
    repeated = [repeated_graph(N_ITEMS) for _ in range(40)]
    written = [written_graph(N_ITEMS) for _ in range(40)]
    for g in repeated + written:  # building and checking untimed: cold evaluation only
        g.check()
    table.compare(
        f"{N_ITEMS:,} items of one repeated node vs {N_ITEMS:,} nodes, cold",
        api=lambda: repeated.pop().evaluate("items"),
        references={"hand-written nodes": lambda: written.pop().evaluate(names)},
        rounds=5,
        min_seconds=0.0,
        note="a new checked graph each call",
    )
    g = repeated_graph(N_ITEMS)
    g.evaluate("items")
    counts = iter(range(N_ITEMS + 1, 10**6))
    table.compare(
        f"repeated node of {N_ITEMS:,} items: one more item",
        api=lambda: g.evaluate("items", n=next(counts)),
        rounds=5,
    )
