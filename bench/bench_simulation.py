"""Simulation: one differential-growth step (``curves.grow``) at 1k / 10k / 100k vertices (its cost
should grow as n log n) against a straightforward all-pairs numpy step at 10k, and 1,000
dynamic-relaxation steps of a 100 x 100 spring net (and the same through ``simulate:``).

The growth states are dense meanders like a grown curve's (folds about 2.5 split lengths
apart, vertices half a split apart), so each vertex has the neighbours it would have.
"""

from __future__ import annotations

import itertools

import numpy as np

from formgraph.kernels.curves import growth
from formgraph.kernels.mesh import relax as kr

SPLIT, RADIUS = 1.0, 2.0


def meander(n: int) -> np.ndarray:
    """A simple closed curve of n vertices ~0.5 apart, folded like a grown one."""
    # k folds of radial depth 0.7 R add ~1.4 k R of length, so scaled to n / 2 the folds
    # are 2 pi R / k * (n / 2) / (1.4 k R) apart: k = sqrt(0.45 n) makes that ~5
    folds = max(8, int(np.sqrt(0.45 * n)))
    t = np.linspace(0.0, 2 * np.pi, 64 * n, endpoint=False)
    r = 1.0 + 0.35 * np.sin(folds * t)
    fine = np.c_[r * np.cos(t), r * np.sin(t)]
    ring = np.vstack([fine, fine[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(ring, axis=0), axis=1))])
    at = np.linspace(0.0, s[-1], n, endpoint=False)
    out = np.c_[np.interp(at, s, ring[:, 0]), np.interp(at, s, ring[:, 1])]
    return out * (0.5 * n / s[-1])  # vertices 0.5 apart


def all_pairs_step(p: np.ndarray, chunk: int = 250) -> np.ndarray:
    """The straightforward step: every pair's distance (in row blocks, to bound memory),
    the same attraction, alignment and repulsion, edge division; no neighbour search and
    no guard against crossing."""
    n = len(p)
    nxt, prv = np.roll(np.arange(n), -1), np.roll(np.arange(n), 1)
    v = p[nxt] - p
    length = np.linalg.norm(v, axis=1)
    pull = v * (0.5 * 0.2 * (length - 0.5 * SPLIT) / length)[:, None]
    d = pull - np.roll(pull, 1, axis=0) + 0.1 * (0.5 * (p[prv] + p[nxt]) - p)
    idx = np.arange(n)
    for lo in range(0, n, chunk):
        rows = slice(lo, min(lo + chunk, n))
        dv = p[rows, None, :] - p[None, :, :]
        dist = np.sqrt((dv * dv).sum(axis=2))
        gap = np.abs(idx[rows, None] - idx[None, :])
        near = (dist < RADIUS) & (dist > 0) & (gap != 1) & (gap != n - 1)
        w = np.where(near, 0.5 * 0.5 * (RADIUS - dist) / np.where(dist > 0, dist, 1), 0.0)
        d[rows] += (dv * w[:, :, None]).sum(axis=1)
    return growth.divide_long_edges(p + d, True, SPLIT)


def square_net(n: int) -> tuple[np.ndarray, np.ndarray, list[int]]:
    idx = np.arange(n * n).reshape(n, n)
    g = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    x = np.c_[g.astype(float), np.zeros(n * n)]
    edges = np.r_[
        np.c_[idx[:-1].ravel(), idx[1:].ravel()], np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()]
    ]
    return x, edges, [idx[0, 0], idx[0, -1], idx[-1, 0], idx[-1, -1]]


def run(table) -> None:
    from harness import through

    import formgraph as fg

    for n in (1_000, 10_000, 100_000):
        p = meander(n)
        refs = {"numpy all pairs": lambda p=p: all_pairs_step(p)} if n == 10_000 else {}
        xyz = np.c_[p, np.zeros(n)]
        table.compare(
            f"curves.grow, one step of a {n:,}-vertex curve",
            api=through(
                "curves.grow",
                {"c": lambda k, xyz=xyz: fg.NurbsCurve.polyline(xyz * (1 + k * 1e-12), True)},
                curve="=c",
                split=SPLIT,
                radius=RADIUS,
            ),
            kernel=lambda p=p: growth.grow_step(p, True, split=SPLIT, radius=RADIUS, jitter=0.3),
            references=refs,
            rounds=3 if n < 100_000 else 1,
            warmup=n < 100_000,
            note="hash grid, crossing guard",
        )
        if n == 10_000:

            def kdtree(p=p):
                from scipy.spatial import cKDTree

                return cKDTree(p).query_pairs(RADIUS, output_type="ndarray")

            table.compare(
                "neighbour pairs within 2, 10,000-vertex curve",
                api=lambda p=p: growth.pairs_within(p, RADIUS),
                references={"scipy cKDTree": kdtree},
                notes={"scipy cKDTree": "tree built each step, as a step would"},
                rounds=5,
                note="the kernel (formgraph.kernels.curves.growth.pairs_within)",
            )

    x, edges, corners = square_net(100)
    rest = 0.95 * np.linalg.norm(x[edges[:, 1]] - x[edges[:, 0]], axis=1)
    net = kr.network(len(x), edges, rest, stiffness=10.0, load=[0, 0, -0.01], anchors=corners)

    text = """\
formgraph: 1
params:
  sag: -0.01
nodes:
  net: {type: mesh.plane, size: [99, 99], divisions: [99, 99]}
  hang:
    type: mesh.relax
    simulate: {state: mesh, from: "@net", steps: 1000}
    reference: "@net"
    anchors: [0, 99, 9900, 9999]
    load: [0, 0, "=sag"]
    iterations: 1
"""
    g = fg.Graph.from_text(text)
    sags = itertools.count(1)
    table.compare(
        "mesh.relax, simulate: 1,000 steps of 1 iteration, 100 x 100 net",
        api=lambda: g.evaluate("hang", sag=-0.01 * (1 + next(sags) * 1e-9)),
        kernel=lambda: kr.relax(x, net, steps=1000),
        rounds=1,
        warmup=False,
        note="through simulate: (engine + caches per step); the kernel: 1,000 steps at once",
    )
