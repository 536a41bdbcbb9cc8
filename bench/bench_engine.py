"""Engine overhead: the graph machinery vs calling the node functions directly.

Two bench-only node types are registered here (not part of the catalogue): ``bench.source``
makes a 10,000-point polyline, ``bench.work`` does real work on it (arc-length resampling
plus a smoothing pass, about a millisecond). Graphs of 200 of them, chained or fanned out,
are evaluated cold, fully cached, and after changing one param at the top or at the bottom.
"""

from __future__ import annotations

import numpy as np

import formgraph as fg
from formgraph.core.registry import node
from formgraph.geometry import Points

N_POINTS = 10_000
N_NODES = 200


@node("bench.source", version=1)
def source(n: int = N_POINTS, seed: int = 0) -> Points:
    """A wiggly polyline of n points."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 20 * np.pi, n)
    xyz = np.stack([t, np.sin(t), rng.normal(0, 0.01, n)], axis=-1)
    return Points(xyz)


@node("bench.work", version=1)
def work(points: Points, k: float = 0.5) -> Points:
    """Resample evenly by arc length, then one Laplacian smoothing step of weight k."""
    p = points.xyz
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    u = np.linspace(0.0, s[-1], len(p))
    q = np.stack([np.interp(u, s, p[:, i]) for i in range(3)], axis=-1)
    q[1:-1] += k * (0.5 * (q[:-2] + q[2:]) - q[1:-1])
    return Points(q)


@node("bench.add", version=1)
def add(a: float, b: float = 1.0) -> float:
    """a + b (no work: the per-node overhead alone)."""
    return a + b


def chain_graph(kind: str) -> fg.Graph:
    g = fg.Graph()
    g.add_param("seed", 0)
    g.add_param("k_last", 0.5)
    if kind == "light":
        g.add("n0", "bench.add", a="=seed")
        for i in range(1, N_NODES):
            g.add(f"n{i}", "bench.add", a=f"@n{i - 1}", b="=k_last" if i == N_NODES - 1 else 1.0)
        return g
    g.add("src", "bench.source", seed="=seed")
    prev = "src"
    for i in range(N_NODES):
        g.add(f"n{i}", "bench.work", points=f"@{prev}", k="=k_last" if i == N_NODES - 1 else 0.5)
        prev = f"n{i}"
    return g


def fan_graph() -> fg.Graph:
    g = fg.Graph()
    g.add_param("seed", 0)
    g.add_param("k_last", 0.5)
    g.add("src", "bench.source", seed="=seed")
    for i in range(N_NODES):
        k = "=k_last" if i == N_NODES - 1 else 0.5 + i * 1e-4  # distinct nodes, no sharing
        g.add(f"n{i}", "bench.work", points="@src", k=k)
    return g


def direct_chain() -> list[Points]:
    # every result is kept, as any cache must keep them (dropping them lets the allocator
    # hand the same hot pages back each step, which a cached graph cannot have)
    out = [source(N_POINTS, 0)]
    for _ in range(N_NODES):
        out.append(work(out[-1], 0.5))
    return out


def direct_fan() -> list[Points]:
    p = source(N_POINTS, 0)
    return [work(p, 0.5 + i * 1e-4) for i in range(N_NODES)]


def direct_light() -> float:
    a = 0.0
    for _ in range(N_NODES):
        a = add(a, 1.0)
    return a


def run(table) -> None:
    last = f"n{N_NODES - 1}"
    cases = [
        ("chain", lambda: chain_graph("heavy"), direct_chain, lambda g: g.evaluate(last)),
        ("fan-out", fan_graph, direct_fan, lambda g: g.evaluate_all()),
        ("light chain", lambda: chain_graph("light"), direct_light, lambda g: g.evaluate(last)),
    ]
    for label, make, direct, ev in cases:
        # cold: a new, checked graph each call (building and checking it untimed: the
        # graphs are made before the clock starts, one per call)
        pool = _Pool(make)
        table.compare(
            f"{label} of {N_NODES} nodes, cold",
            api=lambda ev=ev, pool=pool: ev(pool.take()),
            references={"direct calls": direct},
            rounds=5,
            min_seconds=0.0,
            note="a new checked graph each call",
        )
        table.compare(
            f"{label} of {N_NODES} nodes: build and check",
            api=lambda make=make: make().check(),
            rounds=5,
        )
        g = make()
        ev(g)
        g2 = make()
        ev(g2)
        table.compare(
            f"{label} of {N_NODES} nodes: fully cached / a param changed at the top / bottom",
            api=lambda g=g, ev=ev: ev(g),
            references={
                "the top param changed (all recompute)": _changing(
                    g2, ev, "seed", iter(range(1, 10**6))
                ),
                "the bottom param changed (one recomputes)": _changing(
                    g2, ev, "k_last", iter(np.linspace(0.1, 0.9, 10**6).tolist())
                ),
            },
            rounds=5,
            note="fully cached (keys kept per graph version)",
        )


class _Pool:
    """Checked graphs made ahead, one handed out a call (refilled between rounds' calls
    untimed would need a hook: so a large pool, made before the clock starts)."""

    def __init__(self, make, size: int = 40):
        self.make, self.graphs = make, []
        for _ in range(size):
            self._add()

    def _add(self) -> None:
        g = self.make()
        g.check()
        self.graphs.append(g)

    def take(self):
        if not self.graphs:  # (only if the rounds ask for more calls than made ahead)
            self._add()
        return self.graphs.pop()


def _changing(g, ev, param, values):
    """A call that sets ``param`` to its next value, then evaluates."""

    def call():
        g.set(**{param: next(values)})
        return ev(g)

    return call
