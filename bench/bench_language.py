"""The graph language: copy-to-points against trimesh, and a repeated node against as many
hand-written nodes.

- ``mesh.copy_to_points`` of a 1,000-face mesh onto 10,000 points, each copy with its own
  rotation and scale, against trimesh: ``apply_transform`` on a copy per point, then
  ``trimesh.util.concatenate`` (the usual way to instance with it).
- One node with ``repeat: {i: 1000}`` against 1,000 hand-written nodes doing the same
  (``bench.item``, no work: the engine overhead alone), cold, and after one more item.
"""

from __future__ import annotations

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
    try:
        part = _part()
    except ImportError:
        part = None
    pts, rot, scale = _placements()
    if part is not None:
        mesh = Mesh(part.vertices, part.faces.reshape(-1), np.arange(0, 3001, 3))
        points, scales = Points(pts), scale.tolist()
        case = f"copy_to_points: 1,000 faces onto {N_COPIES:,} points"
        table.time(case, "formgraph", lambda: ours(mesh, points, rot, scales), repeat=3)
        table.time(case, "trimesh", lambda: with_trimesh(part, pts, rot, scale), repeat=1)

    names = [f"n{i}" for i in range(N_ITEMS)]
    fresh: list[fg.Graph] = []
    written: list[fg.Graph] = []
    for _ in range(6):  # building and checking untimed: cold evaluation only
        fresh.append(repeated_graph(N_ITEMS))
        fresh[-1].check()
        written.append(written_graph(N_ITEMS))
        written[-1].check()
    case = f"{N_ITEMS:,} items of one repeated node vs {N_ITEMS:,} nodes, cold"
    table.time(case, "formgraph", lambda: fresh.pop().evaluate("items"), repeat=5, number=1)
    table.time(
        case, "hand-written nodes", lambda: written.pop().evaluate(names), repeat=5, number=1
    )
    g = repeated_graph(N_ITEMS)
    g.evaluate("items")
    counts = iter(range(N_ITEMS + 1, 10**6))
    table.time(
        f"repeated node of {N_ITEMS:,} items: one more item",
        "formgraph",
        lambda: g.evaluate("items", n=next(counts)),
        repeat=3,
    )
