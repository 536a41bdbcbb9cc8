"""Optimisation studies: what the study loop adds to a sweep, how much work trials share,
and what a second worker buys.

- Per-trial overhead: a 200-trial study of a light graph (a 16-point circle and its
  polyline, microseconds of work) against a sweep of the same number of variants on the
  same running 2-worker cluster (interleaved rounds, wall clock): the difference is what
  asking, telling, the batches' extra Dask round trips, the tables (trials.csv, pareto.csv,
  the journal) and the progress picture cost. Beside it, the study's own work alone
  (``Study.overhead``: CPU time of the client thread outside the sweep runs), which a busy
  machine does not inflate. Random sampling (optuna's cheapest sampler) and TPE.
- The lamp shade (graphs/lamp_shade.yaml, 15 nodes), a 200-trial TPE study of wall,
  window and height: node evaluations computed against 200 x its node count (the shared
  fraction: the revolved band no varied param reaches, each window size's bores, ...).
- A 100-trial study on 1 worker and on 2, wall clock, with the machine's load average
  beside it: of the lamp shade (~100 ms a trial, mostly its booleans), and of the heavy
  graph, the lamp shade at 4x the faces (~330 ms a trial), where a trial's compute
  dominates the study's own work on the client (~20 ms a trial).

The embedded cluster is started before timing and its workers warmed (they import the node
families), as in bench_sweep. No disk cache: every node is computed or shared in-study.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import formgraph as fg

ROOT = Path(__file__).resolve().parents[1]
LAMP = ROOT / "graphs" / "lamp_shade.yaml"
LAMP_VARY = {"wall": "0.02:0.3", "window": "0.05:0.5", "height": "0.6:2.2"}


def _light() -> fg.Graph:
    light = fg.Graph()
    light.add_param("r", 1.0, min=0.1, max=100)
    light.add("pts", "points.circle", count=16, radius="=r")
    light.add("ring", "curves.polyline", points="@pts", closed=True)
    light.add("size", "curves.measure", curve="@ring")
    return light


def _study(graph, vary, client, budget, method="tpe", **kw):
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        s = fg.optimize(
            graph, vary, minimize=[kw.pop("objective", "size.length")], budget=budget,
            method=method, client=client, cache_dir=None, out=tmp, **kw,
        )  # fmt: skip
        return time.perf_counter() - t0, s


def _optuna_alone(method: str, n: int) -> float:
    """CPU seconds a trial of optuna's own ask and tell, in batches of 8 as a study runs."""
    import math

    import optuna
    from optuna.distributions import FloatDistribution

    from formgraph.sweeps.optimize import _sampler

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    space = {"r": FloatDistribution(1.0, 50.0)}
    study = optuna.create_study()
    t0 = time.thread_time()
    while len(study.trials) < n:
        study.sampler = _sampler(optuna, method, len(study.trials), 16)
        for t in [study.ask(space) for _ in range(8)]:
            study.tell(t, [2 * math.pi * t.params["r"]])
    return (time.thread_time() - t0) / n


def run(table) -> None:
    import matplotlib.figure  # noqa: F401  (imported once a process: not a trial's cost)

    from formgraph.sweeps.cluster import connect

    embedded = connect(None, workers=2)
    client = embedded.__enter__()
    try:
        fg.sweep(_light(), {"r": "1:2:64"}, ["size"], client=client, cache_dir=None)  # warm
        fg.sweep(fg.load(LAMP), {"wall": "0.05:0.1:4"}, ["size"], client=client, cache_dir=None)
        n = 200
        for method in ("random", "tpe"):
            own: list[float] = []

            def study(method=method, own=own):
                s = _study(_light(), {"r": "1:50"}, client, n, method)[1]
                own.append(s.overhead / n)

            def sweep():
                fg.sweep(_light(), {"r": "1:50"}, ["size"], method="random", samples=n,
                         client=client, cache_dir=None)  # fmt: skip

            case = f"optimize: light graph x {n} trials, {method}, batches of 8, 2 workers"
            table.compare(
                case,
                api=study,
                references={"sweep of as many variants, same cluster": sweep},
                rounds=3,
                min_seconds=0.0,
                note="the whole study (asks and tells between batches of 8)",
            )
            own.sort()
            alone = sorted(_optuna_alone(method, n) for _ in range(3))
            case = f"optimize: the study's own CPU a trial, {n} trials, {method}"
            table.add(
                case,
                "formgraph",
                own,
                f"median of {len(own)}: ask, tell, journal, tables, progress.png "
                "(Study.overhead, client thread CPU time)",
            )
            table.add(case, "optuna ask and tell alone", alone, "same batches and space")

        seconds, s = _study(fg.load(LAMP), LAMP_VARY, client, 200, objective="size.volume")
        t = s.totals
        table.add(
            "optimize: lamp shade, 200 TPE trials, 2 workers",
            "formgraph study",
            [seconds],
            f"{t.computed:,} nodes computed for 200 x {t.naive // max(t.variants, 1)} = "
            f"{t.naive:,} ({1 - t.computed / t.naive:.0%} shared)",
        )
    finally:
        embedded.__exit__(None, None, None)
    _workers(table)


# The heavy graph: the lamp shade with its band tessellated 64 x 192 (4x the faces of
# graphs/lamp_shade.yaml) and 64-segment bores, so its booleans take ~330 ms a trial and a
# trial's compute dominates the study's own work (~20 ms a trial on the client: optuna's
# TPE ask, planning, Dask's round trips)
FINE = {("band_mesh", "u"): 64, ("band_mesh", "v"): 192, ("bore", "segments"): 64}


def _lamp(fine: bool) -> fg.Graph:
    g = fg.load(LAMP)
    if fine:
        for (node, port), value in FINE.items():
            g.set_input(node, port, value)
    return g


def _trial_ms(g: fg.Graph) -> float:
    """CPU milliseconds of one trial evaluated alone (median of 5 random designs)."""
    import random
    import statistics

    rnd = random.Random(7)
    times = []
    for _ in range(5):
        params = {"wall": rnd.uniform(0.02, 0.3), "window": rnd.uniform(0.05, 0.5)}
        t0 = time.thread_time()
        g.evaluate("size", height=rnd.uniform(0.6, 2.2), **params)
        times.append(time.thread_time() - t0)
    return 1000 * statistics.median(times)


def _workers(table, rounds: int = 2) -> None:
    """100 TPE trials on 1 worker and on 2, wall clock, in interleaved rounds (1 2, 2 1,
    ...), each cluster started and warmed once; the ratio is taken round by round."""
    from formgraph.sweeps.cluster import connect

    for fine in (False, True):
        name = "lamp shade, 4x the faces" if fine else "lamp shade"
        ms = _trial_ms(_lamp(fine))
        walls: dict[int, list[float]] = {1: [], 2: []}
        loads: list[float] = []
        with connect(None, workers=1) as one, connect(None, workers=2) as two:
            clients = {1: one, 2: two}
            for c in clients.values():  # warm: node families imported, graph built
                fg.sweep(_lamp(fine), {"wall": "0.05:0.1:4"}, ["size"], client=c, cache_dir=None)
            for r in range(rounds):
                for workers in (1, 2) if r % 2 == 0 else (2, 1):
                    loads.append(os.getloadavg()[0])
                    walls[workers].append(
                        _study(
                            _lamp(fine), LAMP_VARY, clients[workers], 100,
                            objective="size.volume", seed=4,
                        )[0]
                    )  # fmt: skip
        ratios = sorted(a / b for a, b in zip(walls[1], walls[2], strict=True))
        case = f"optimize: {name} (~{ms:.0f} ms a trial), 100 TPE trials, wall clock"
        table.add(
            case,
            "2 workers",
            walls[2],
            f"1 worker / 2 workers = {ratios[len(ratios) // 2]:.2f}x (per round "
            f"{ratios[0]:.2f}-{ratios[-1]:.2f}); load average {min(loads):.1f}-"
            f"{max(loads):.1f} at the studies' starts",
        )
        table.add(case, "1 worker", walls[1], "same seed, so the same 100 trials")
