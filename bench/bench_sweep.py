"""Sweeps on Dask against a plain loop of ``g.evaluate`` in one process, in wall time.

- 200 variants of the spiral tube (turns 1..10 x 20 radii), the capped solid built for
  each: ``fg.sweep`` on a running 2-worker LocalCluster against the loop (which shares the
  unvaried section through its memory cache, as any loop over one Graph does). The note
  gives the node evaluations the sweep's graph needed against variants x nodes.
- 2,000 variants of a light graph (a 16-point circle and its polyline, microseconds of
  work): the sweep's overhead per variant, Dask's scheduling and our planning included.

The embedded cluster (what ``fg.sweep`` starts when given no client) is started before
timing, its start-up reported apart, and closed after. Both its workers have run a sweep
before any timing (they import the node families then, as the loop's process has). The
loop and the sweep take turns (interleaved rounds), each call on a graph of its own
(cold: nothing cached from an earlier call). Wall time whatever ``BENCH_CLOCK`` says: the
row is about two processes working at once (on a 2-core machine, quote it from an idle
one).
"""

from __future__ import annotations

import time
from pathlib import Path

import formgraph as fg

ROOT = Path(__file__).resolve().parents[1]


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
        last: list = []

        def sweep():
            s = fg.sweep(fg.load(tube), vary, client=client, cache_dir=None)
            assert s.failed == 0, s.rows[0]["error"] if s.rows else ""
            last[:] = [s]

        def loop():
            h = fg.load(tube)
            for v in variants:
                h.evaluate(built, **v)

        sweep()
        t = last[0].totals
        table.compare(
            f"sweep: spiral tube, {len(variants)} variants, 2 workers",
            api=sweep,
            references={"plain g.evaluate loop (one process)": loop},
            rounds=5,
            clock="wall",
            warmup=False,
            note=f"{t.needed} of {t.naive} node evaluations needed; wall time; cluster "
            f"start {start:.1f} s apart",
        )

        vary = {"r": "1:50:2000"}
        light_variants = sample([domain(_light(), n, s) for n, s in vary.items()])

        def light_sweep():
            s = fg.sweep(_light(), vary, client=client, cache_dir=None)
            assert s.failed == 0

        def light_loop():
            h = _light()
            for v in light_variants:
                h.evaluate("ring", **v)

        stats = table.compare(
            f"sweep of a light graph x {len(light_variants)} (the overhead a variant)",
            api=light_sweep,
            references={"plain g.evaluate loop (one process)": light_loop},
            rounds=5,
            clock="wall",
            warmup=False,
        )
        per = stats["formgraph"].median - stats[next(iter(stats.keys() - {"formgraph"}))].median
        table.rows[
            -2
        ].note = f"on 2 workers; {per / len(light_variants) * 1e3:.3f} ms a variant over the loop"
    finally:
        embedded.__exit__(None, None, None)
