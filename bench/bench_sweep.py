"""Sweeps on Dask vs a plain loop of ``g.evaluate`` in one process.

- 200 variants of the spiral tube (turns 1..10 x 20 radii), the capped solid built for
  each: a sweep on a running 2-worker LocalCluster vs the loop (which shares the
  unvaried section through its memory cache, as any loop over one Graph does). The note
  gives the node evaluations the sweep's graph needed against variants x nodes.
- 2,000 variants of a light graph (a 16-point circle and its polyline, microseconds of
  work): the sweep's overhead per variant, Dask's scheduling and our planning included.

The embedded cluster (what ``fg.sweep`` starts when given no client) is started before
timing, its start-up reported apart, and closed after. Both its workers have run a sweep
before any timing (they import the node families then, as the loop's process has).

The loop and the sweep take turns, each on a graph of its own (cold: nothing cached from
an earlier round), and each row is the best of its rounds (``ROUNDS`` for the light
graph, 2 for the tube).

Under ``BENCH_CLOCK=cpu`` both sides are CPU seconds: the loop's process, and for the sweep
this process plus every worker process of the cluster (read from the operating system
before and after: a sweep's work is done in the workers, so this process's own CPU time
alone would flatter it). The idle cluster's own ticks (heartbeats) fall on both sides.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import formgraph as fg

ROOT = Path(__file__).resolve().parents[1]
CPU = os.environ.get("BENCH_CLOCK", "wall") == "cpu"
ROUNDS = 5


def _clock() -> float:
    """Wall seconds, or under BENCH_CLOCK=cpu the CPU seconds of this process and of its
    children (the cluster's nanny and worker processes)."""
    if not CPU:
        return time.perf_counter()
    import psutil

    me = psutil.Process()
    total = time.process_time()
    for child in me.children(recursive=True):
        try:
            t = child.cpu_times()
            total += t.user + t.system
        except psutil.Error:  # a process that ended meanwhile
            pass
    return total


def _loop(g: fg.Graph, node: str, variants: list[dict]) -> float:
    t0 = _clock()
    for v in variants:
        g.evaluate(node, **v)
    return _clock() - t0


def _sweep(g: fg.Graph, vary: dict, client) -> tuple[float, fg.Sweep]:
    t0 = _clock()
    s = fg.sweep(g, vary, client=client, cache_dir=None)
    seconds = _clock() - t0
    assert s.failed == 0, s.rows[0]["error"] if s.rows else ""
    return seconds, s


def _light() -> fg.Graph:
    light = fg.Graph()
    light.add_param("r", 1.0, min=0.1, max=100)
    light.add("pts", "points.circle", count=16, radius="=r")
    light.add("ring", "curves.polyline", points="@pts", closed=True)
    return light


def run(table) -> None:
    from formgraph.sweeps.cluster import connect
    from formgraph.sweeps.sampling import domain, sample

    t0 = time.perf_counter()
    embedded = connect(None, workers=2)  # the cluster fg.sweep starts when given none
    client = embedded.__enter__()
    start = time.perf_counter() - t0
    # the loop's process has imported every node family already: so do both workers, before
    # any timing (a few variants to a task, several tasks each)
    fg.sweep(_light(), {"r": "1:2:64"}, client=client, cache_dir=None)
    try:
        tube = ROOT / "graphs" / "spiral_tube.yaml"
        vary = {"turns": "1:10", "radius": "0.5:5:20"}
        g = fg.load(tube)
        variants = sample([domain(g, n, s) for n, s in vary.items()])
        built = g.plan("print")[-1].upstream[0]  # what a sweep builds: the exported solid
        loops, sweeps = [], []
        for _ in range(2):
            loops.append(_loop(fg.load(tube), built, variants))
            seconds, s = _sweep(fg.load(tube), vary, client)
            sweeps.append(seconds)
        loop, ours = min(loops), min(sweeps)
        t = s.totals
        case = f"sweep: spiral tube, {len(variants)} variants, 2 workers"
        note = (
            f"{t.needed} of {t.naive} node evaluations needed ({t.naive - t.needed} saved); "
            f"loop/sweep {loop / ours:.2f}x; best of 2; cluster start {start:.1f} s apart"
        )
        table.add(case, "formgraph", ours, note)
        table.add(case, "plain g.evaluate loop", loop, "one process")

        vary = {"r": "1:50:2000"}
        variants = sample([domain(_light(), n, s) for n, s in vary.items()])
        loops, sweeps = [], []
        for _ in range(ROUNDS):
            loops.append(_loop(_light(), "ring", variants) / len(variants))
            sweeps.append(_sweep(_light(), vary, client)[0] / len(variants))
        loop, ours = min(loops), min(sweeps)
        case = f"sweep overhead per variant, light graph x {len(variants)}"
        each = ", ".join(f"{(a - b) * 1e3:.3f}" for a, b in zip(sweeps, loops, strict=True))
        table.add(
            case,
            "formgraph",
            ours,
            f"best of {ROUNDS} on 2 workers"
            + (" (CPU, workers included)" if CPU else "")
            + f"; overhead {(ours - loop) * 1e3:.3f} ms a variant (each round: {each})",
        )
        table.add(case, "plain g.evaluate loop", loop, "one process")
    finally:
        embedded.__exit__(None, None, None)
