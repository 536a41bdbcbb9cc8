"""Optimisation studies: search a design space for the best designs, on Dask.

>>> import formgraph as fg
>>> s = fg.optimize("graphs/lamp_shade.yaml", vary={"wall": "0.02:0.3"},
...                 minimize=["size.volume"], budget=40)          # doctest: +SKIP
>>> s.best["size.volume"]                                       # doctest: +SKIP

optuna (Akiba et al., "Optuna: a next-generation hyperparameter optimization framework",
KDD 2019) proposes the trials by ask-and-tell from this module's own loop: ask ``batch``
trials, run them as one sweep (:func:`formgraph.sweeps.cluster.start`: keys planned on the
client, shared nodes computed once, the disk cache reused, failures recorded as rows),
tell their results in trial order. Batch b is asked once batch b - 2 is told, while
b - 1 runs (its trials running in optuna: TPE's constant liar counts them), so the workers
go from one batch to the next without waiting for the client to tell, ask and plan. That
schedule is fixed and the sampler is seeded afresh before each batch from the seed and
the number of trials asked, so the same seed gives the same trials whatever the number of
workers, and a study interrupted and continued gives the trials an uninterrupted one would
have.

With ``out``, the study lives in ``out/study.journal`` (:mod:`formgraph.sweeps.journal`:
each batch's told trials appended in one write), so running the same study again replays
it into optuna and continues to the new budget; a batch an interrupted run had asked but
not told is asked again, identically, and run. ``trials.csv`` and
``pareto.csv`` are rewritten whole (atomically) after a batch at most once a second (and
in at most 5% of the time), and at the end; ``progress.png`` is drawn at the end.
"""

from __future__ import annotations

import json
import math
import os
import time
import warnings
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import ParamError, Problem
from ..evaluation.graph import Graph
from .api import _GRAPH_CACHE, EACH_WORKER, _cell, _label, _table_text, _tabular, _targets
from .api import _write_atomic as write_atomic
from .cluster import RowResult, Targets, Totals
from .journal import Journal, replay, tell_recorded
from .objectives import (
    Constraint,
    Objective,
    constraints_of,
    non_dominated,
    objectives_of,
    space_of,
)
from .sampling import domain, param_kind

__all__ = ["METHODS", "Study", "optimize", "require_optuna"]

METHODS = ("tpe", "nsga2", "cmaes", "random")
MAX_BUDGET = 1_000_000
TABLE_INTERVAL = 1.0  # seconds between rewrites of trials.csv and pareto.csv mid-study
AHEAD = 1  # batches asked beyond the one being waited for (see the loop in optimize)


def require_optuna() -> Any:
    """optuna, or an ImportError that says which extra installs it."""
    try:
        import optuna
    except ImportError:
        raise ImportError(
            "optimisation needs optuna, which formgraph installs as an extra: "
            "pip install 'formgraph[optimize]'"
        ) from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    return optuna


@dataclass
class Study:
    """A finished (or interrupted) study: every trial as a row, the front, what it cost.

    ``trials`` are dicts: ``trial``, the params, ``status`` ('ok' or 'failed'), ``error``,
    ``seconds``, each measured column (objectives first), ``feasible`` and ``pareto``.
    ``overhead`` is the CPU time (of the calling thread) the study spent on its own work
    beside the sweep runs: asking and telling optuna, the journal, the tables, the progress
    callback and ``progress.png``.
    """

    trials: list[dict[str, Any]]
    columns: list[str]
    objectives: list[Objective]
    constraints: list[Constraint]
    totals: Totals = field(default_factory=Totals)
    seconds: float = 0.0
    resumed: int = 0
    files: list[Path] = field(default_factory=list)
    overhead: float = 0.0  # CPU seconds of the study's own work (see optimize)

    @property
    def pareto(self) -> list[dict[str, Any]]:
        """The feasible trials no other feasible trial dominates (the best, for one objective)."""
        return [r for r in self.trials if r["pareto"]]

    @property
    def best(self) -> dict[str, Any] | None:
        """The best feasible trial of a one-objective study (the first of equals); None
        when no trial is feasible.

        Raises
        ------
        ValueError
            For a study of several objectives (see ``pareto``).
        """
        if len(self.objectives) != 1:
            raise ValueError("a study of several objectives has a front, not a best: use .pareto")
        front = self.pareto
        return front[0] if front else None

    def summary(self) -> str:
        ok = [r for r in self.trials if r["status"] == "ok"]
        feasible = sum(1 for r in ok if r["feasible"])
        lines = [
            f"{len(self.trials)} trials: {len(ok)} ok ({feasible} feasible), "
            f"{len(self.trials) - len(ok)} failed, in {self.seconds:.1f} s"
            + (f" ({self.resumed} kept from an earlier run)" if self.resumed else "")
        ]
        front = self.pareto
        if len(self.objectives) == 1 and front:
            o = self.objectives[0]
            lines.append(f"best: trial {front[0]['trial']}, {o.column} = {front[0][o.column]:.6g}")
        elif front:
            lines.append(f"Pareto front: {len(front)} trials")
        else:
            lines.append("no feasible trial yet")
        t = self.totals
        if t.naive:
            lines.append(
                f"node evaluations: {t.computed:,} computed, {t.cached:,} from the disk cache, "
                f"for {t.variants:,} trials x their nodes = {t.naive:,} "
                f"({1 - (t.computed + t.cached) / t.naive:.0%} shared)"
            )
        lines += [f"wrote {p}" for p in self.files]
        return "\n".join(lines)


@dataclass
class _Batch:
    """Trials asked together and run as one sweep (or, ``held``, a journal's last batch,
    replayed as running trials and told from its records)."""

    first: int  # the number of its first trial
    asked: list[Any] = field(default_factory=list)  # optuna Trials
    params_of: dict[int, dict[str, Any]] = field(default_factory=dict)
    got: dict[int, RowResult] = field(default_factory=dict)
    running: Any = None  # cluster.Running while its tasks are on the cluster
    held: list[tuple[int, dict[str, Any]]] = field(default_factory=list)


def _violations(constraints: Sequence[Constraint], row: Mapping[str, Any]) -> list[float]:
    return [c.violation(row) for c in constraints]


def _sampler(optuna: Any, method: str, seed: int, population: int) -> Any:
    """optuna's sampler; tpe and nsga2 read each trial's constraints (``set_constraint``)."""
    s = optuna.samplers
    if method == "tpe":
        return s.TPESampler(seed=seed, n_startup_trials=10, multivariate=True)
    if method == "nsga2":
        return s.NSGAIISampler(seed=seed, population_size=population)
    if method == "cmaes":
        return s.CmaEsSampler(seed=seed, warn_independent_sampling=False)
    return s.RandomSampler(seed=seed)


def optimize(
    graph: Graph | str | os.PathLike[str],
    vary: Mapping[str, Any],
    minimize: Sequence[str] = (),
    maximize: Sequence[str] = (),
    constraints: Sequence[str] = (),
    *,
    budget: int,
    method: str = "tpe",
    seed: int = 0,
    batch: int = 8,
    out: str | os.PathLike[str] | None = None,
    client: Any = None,
    workers: int | None = None,
    cache_dir: Any = _GRAPH_CACHE,
    shared_cache: bool = False,
    export: bool = False,
    render: str | None = None,
    size: tuple[int, int] = (256, 192),
    progress: Callable[[int, int, str, float], None] | None = None,
    on_batch: Callable[[int], None] | None = None,
) -> Study:
    """Search ``vary`` for the designs that minimise / maximise the objectives.

    Parameters
    ----------
    graph : Graph or path
        The graph; its current param values are the fixed ones.
    vary : mapping
        Param name -> SPEC text as for :func:`formgraph.sweep` (``"0.5:2"`` an interval,
        an int param's ``"1:12"`` its whole numbers, ``"1,2,5"`` a choice), or values.
    minimize, maximize : list of str
        ``node.output`` number outputs (``size.volume``).
    constraints : list of str
        ``"EXPR <= NUMBER"`` or ``"EXPR >= NUMBER"`` over params and ``node.output`` values;
        no infeasible trial is ever reported as best or on the front.
    budget : int
        Trials in all (an earlier run's in ``out`` count).
    method : {'tpe', 'nsga2', 'cmaes', 'random'}
        optuna's sampler (cmaes: one objective).
    seed : int
        The same seed gives the same trials, whatever the number of workers.
    batch : int
        Trials asked, run together and told at a time (nsga2: the population size is
        ``max(batch, 16)``).
    out : path, optional
        ``study.journal`` (rerunning continues the study), ``trials.csv``, ``pareto.csv``,
        ``progress.png``; with ``export`` the front's files in ``front/NNNN/``, with
        ``render`` the front drawn in ``front.png``.
    client, workers, cache_dir
        As for :func:`formgraph.sweep`.
    shared_cache : bool
        ``cache_dir`` is a folder the client and every worker see (a shared filesystem).
    progress : callable, optional
        Called with (trials done, budget, best so far as text, trials per second).
    on_batch : callable, optional
        Called with the number of trials done after each batch is told.

    Raises
    ------
    ParamError
        For bad varied params, objectives, constraints, export or render (all at once).
    ValueError
        For a bad method, budget or batch, or an ``out`` holding another study.
    ImportError
        When optuna is not installed.
    """
    from ..evaluation.graph import load
    from . import cluster as run_dask

    optuna = require_optuna()
    g = load(graph) if isinstance(graph, (str, os.PathLike)) else graph
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; use one of {', '.join(METHODS)}")
    if not isinstance(budget, int) or not 1 <= budget <= MAX_BUDGET:
        raise ValueError(f"the budget must be 1 to {MAX_BUDGET:,} trials, got {budget!r}")
    if not isinstance(batch, int) or not 1 <= batch <= 10_000:
        raise ValueError(f"the batch must be 1 to 10,000 trials, got {batch!r}")
    problems: list[Problem] = []
    domains = []
    for name, spec in vary.items():
        try:
            domains.append(domain(g, name, spec))
        except ParamError as exc:
            problems += exc.problems
    objectives, found = objectives_of(g, list(minimize), list(maximize))
    problems += found
    cons, found = constraints_of(g, list(constraints))
    problems += found
    measured = [o.column for o in objectives] + [c for k in cons for c in k.columns]
    try:
        targets, kinds = _targets(g, list(dict.fromkeys(measured)), export, render)
    except ParamError as exc:
        problems += exc.problems
    if problems:
        raise ParamError(problems)
    if not domains:
        raise ValueError("vary at least one param")
    if method == "cmaes" and len(objectives) > 1:
        raise ValueError("cmaes optimises one objective; use nsga2 or tpe for several")
    if (export or render) and out is None:
        raise ValueError("export and render write files: give out=")
    defs = g.param_defs
    space = space_of(domains, {d.name: param_kind(defs[d.name]) is int for d in domains})
    base = g.params
    columns = ["trial", *[n for n, v in base.items() if n in vary or _tabular(v)]]
    columns += ["status", "error", "seconds", *kinds, "feasible", "pareto"]
    out_dir = None if out is None else Path(out)
    question = json.dumps(
        {
            "vary": {d.name: [d.values, d.low, d.high] for d in domains},
            "minimize": list(minimize),
            "maximize": list(maximize),
            "constraints": list(constraints),
            "method": method,
            "seed": seed,
            "batch": batch,
            "fixed": {n: _cell(v) for n, v in base.items() if n not in vary},
        },
        sort_keys=True,
    )
    if isinstance(client, str):
        # before the out folder is touched: an unreachable scheduler leaves no file behind
        run_dask.probe_scheduler(client)
    journal = None if out_dir is None else Journal(out_dir / "study.journal")
    asked_before, records = (None, []) if journal is None else journal.read()
    if asked_before is not None and asked_before != question:
        raise ValueError(
            f"{out_dir} holds a study of another question (other params, objectives, "
            f"constraints, method, seed or batch); give another out folder, or delete "
            f"{out_dir / 'study.journal'} to start again"
        )
    if journal is not None and asked_before is None:
        journal.start(question)
    study = optuna.create_study(directions=[o.direction for o in objectives])
    held = replay(optuna, study, records, batch)
    population = max(batch, 16)
    rows: dict[int, dict[str, Any]] = {
        t.number: t.user_attrs["row"]
        for t in study.get_trials(deepcopy=False)
        if t.state != optuna.trial.TrialState.RUNNING
    }
    rows.update((rec["number"], rec["user_attrs"]["row"]) for _, rec in held)
    resumed = len(rows)
    totals = Totals()
    t0 = time.perf_counter()
    own = 0.0  # thread CPU seconds outside the sweep runs (Study.overhead)
    written = [-math.inf]  # when the tables may next be written
    files: list[Path] = []
    if cache_dir is _GRAPH_CACHE:
        cache_dir = g.disk.root if g.disk is not None else None
    worker_cache = cache_dir is EACH_WORKER
    cache_path = None if worker_cache else cache_dir
    bp = run_dask.blueprint(g, None if cache_path is None else str(cache_path), worker_cache)
    signs = np.array([-1.0 if o.maximize else 1.0 for o in objectives])

    def best_text() -> str:
        front = [r for r in rows.values() if r.get("feasible")]
        if not front:
            return "no feasible trial yet"
        if len(objectives) == 1:
            o = objectives[0]
            pick = min if not o.maximize else max
            return f"best {o.column} = {pick(r[o.column] for r in front):.6g}"
        return f"{len(_front(list(rows.values()), objectives, signs))} on the front"

    def write_tables() -> None:
        ordered = [rows[i] for i in sorted(rows)]
        flags = _front(ordered, objectives, signs)
        for r in ordered:
            r["pareto"] = r["trial"] in flags
        if out_dir is None:
            return
        write_atomic(out_dir / "trials.csv", _table_text(columns, ordered))
        front = [r for r in ordered if r["pareto"]]
        write_atomic(out_dir / "pareto.csv", _table_text(columns, front))

    def tell(trial: Any, params: Mapping[str, Any], result: RowResult) -> dict[str, Any]:
        row: dict[str, Any] = {"trial": trial.number}
        row.update({c: params[c] for c in columns if c in params})
        row.update(status="ok", error="", seconds=round(result.seconds, 6))
        row.update({c: result.values.get(c) for c in kinds})
        error = result.error
        values: list[float] = []
        if error is None:
            for o in objectives:
                v = row[o.column]
                if not isinstance(v, (int, float)) or not math.isfinite(v):
                    error = f"objective {o.column} is {v!r}, not a finite number"
                    break
                values.append(float(v))
        violations = _violations(cons, {**params, **row}) if error is None else []
        row["feasible"] = error is None and all(v <= 0 for v in violations)
        row["pareto"] = False
        if error is not None:
            row.update(status="failed", error=error)
        trial.set_user_attr("row", row)
        for k, v in enumerate(violations):  # optuna's convention: <= 0 holds
            trial.set_constraint(f"c{k}", v)
        if error is None:
            study.tell(trial, values)
        else:
            study.tell(trial, state=optuna.trial.TrialState.FAIL)
        return row

    inflight: deque[_Batch] = deque()
    if held:  # the journal's last batch: told after the next is asked, as it was
        inflight.append(_Batch(held[0][1]["number"], held=held))
    try:
        with run_dask.connect(client, workers) as c:
            embedded = client is None
            try:
                while True:
                    # the schedule: batch b is asked once batch b - 2 is told, while b - 1
                    # runs, so the workers go from one batch to the next without waiting for
                    # the client's tell, ask and planning; fixed, whatever the workers, so a
                    # seed gives the same trials on one worker or many
                    while len(inflight) <= AHEAD and len(study.trials) < budget:
                        mark = time.thread_time()
                        n = len(study.trials)
                        # a sampler seeded by the seed and the trials asked so far: the same
                        # history gives the same batch, in one run or across an interruption
                        study.sampler = _sampler(
                            optuna, method, (seed * 1_000_003 + n) % 2**32, population
                        )
                        with warnings.catch_warnings():
                            warnings.simplefilter("ignore")  # optuna's experimental notes
                            asked = [study.ask(space) for _ in range(min(batch, budget - n))]
                        b = _Batch(n, asked, {t.number: {**base, **t.params} for t in asked})
                        own += time.thread_time() - mark  # the sweep's own work is not ours
                        b.running = run_dask.start(
                            g,
                            [(t.number, b.params_of[t.number]) for t in asked],
                            Targets(targets.measures, (), None, size),
                            b.got.__setitem__,
                            c,
                            cache_dir=cache_path,
                            worker_cache=worker_cache,
                            shared_disk=(embedded or shared_cache) and not worker_cache,
                            embedded=embedded,
                            bp=bp,
                        )
                        inflight.append(b)
                    if not inflight:
                        break
                    b = inflight[0]
                    part = b.running.wait() if b.running is not None else Totals()
                    mark = time.thread_time()
                    inflight.popleft()
                    if b.held:
                        for trial_id, rec in b.held:
                            tell_recorded(optuna, study, trial_id, rec)
                        told = {rec["number"]: rows[rec["number"]] for _, rec in b.held}
                    else:
                        told = {  # told in trial order: deterministic
                            t.number: tell(t, b.params_of[t.number], b.got[t.number])
                            for t in sorted(b.asked, key=lambda t: t.number)
                        }
                        if journal is not None:
                            trials = study.get_trials(deepcopy=False)
                            journal.append((trials[t.number] for t in b.asked), b.first)
                    # the rows count once the journal holds them: a Ctrl-C before that leaves
                    # the tables and the journal agreeing, and the rerun asks the batch again
                    rows.update(told)
                    for name in ("variants", "naive", "needed", "computed", "cached"):
                        setattr(totals, name, getattr(totals, name) + getattr(part, name))
                    if time.perf_counter() >= written[0]:
                        # whole tables at most once a second, and at most a twentieth of
                        # the time: a long study of quick trials does not spend its time
                        # rewriting ever longer tables after every small batch
                        began = time.perf_counter()
                        write_tables()
                        ended = time.perf_counter()
                        written[0] = ended + max(TABLE_INTERVAL, 19 * (ended - began))
                    if progress is not None:
                        rate = (len(rows) - resumed) / max(time.perf_counter() - t0, 1e-9)
                        progress(len(rows), budget, best_text(), rate)
                    own += time.thread_time() - mark
                    if on_batch is not None:
                        on_batch(len(rows))
            finally:
                for b in inflight:  # an interrupted study's batches in flight: withdrawn
                    if b.running is not None:
                        b.running.cancel()
            flags = _front(list(rows.values()), objectives, signs)
            if out_dir is not None and (export or render):
                files += _front_files(
                    g, [rows[i] for i in sorted(flags)], targets, vary, base, out_dir, c,
                    cache_path, worker_cache, size, export, render,
                )  # fmt: skip
    finally:
        mark = time.thread_time()
        write_tables()  # an interrupted study leaves its tables and picture as they stand
        ordered = [rows[i] for i in sorted(rows)]
        if out_dir is not None and rows:
            from .progress_plot import draw_progress

            shown = draw_progress(ordered, objectives, out_dir / "progress.png")
            files[:0] = [out_dir / "trials.csv", out_dir / "pareto.csv", shown]
        own += time.thread_time() - mark
    result = Study(
        ordered, columns, objectives, cons, totals, resumed=resumed, files=files, overhead=own
    )
    result.seconds = time.perf_counter() - t0
    return result


def _front(
    rows: Sequence[Mapping[str, Any]], objectives: Sequence[Objective], signs: Any
) -> set[int]:
    """Trial numbers of the feasible rows no other feasible row dominates."""
    feasible = [r for r in rows if r.get("feasible")]
    if not feasible:
        return set()
    values = np.array([[r[o.column] for o in objectives] for r in feasible], dtype=np.float64)
    keep = non_dominated(values * signs)
    return {r["trial"] for r, k in zip(feasible, keep, strict=True) if k}


def _front_files(
    g: Graph,
    front: list[dict[str, Any]],
    targets: Targets,
    vary: Mapping[str, Any],
    base: Mapping[str, Any],
    out_dir: Path,
    client: Any,
    cache_path: Any,
    worker_cache: bool,
    size: tuple[int, int],
    export: bool,
    render: str | None,
) -> list[Path]:
    """The front's designs once more (from the cache): their exports in ``front/NNNN/`` and
    their pictures tiled into ``front.png``."""
    from ..core import safety
    from . import cluster as run_dask

    if not front:
        return []
    width = max(4, len(str(max(r["trial"] for r in front))))
    images: dict[int, Path] = {}
    written: list[Path] = []

    def finished(i: int, result: RowResult) -> None:
        folder = f"front/{i:0{width}d}"
        for _name, (main, data) in result.exports.items():
            for rel, blob in data.items():
                safety.write_atomic(out_dir, f"{folder}/{rel}", blob)
            written.append(out_dir / folder / main)
        if result.image is not None:
            safety.write_atomic(out_dir, f"{folder}/{render}.png", result.image)
            images[i] = out_dir / folder / f"{render}.png"

    run_dask.run(
        g,
        [(r["trial"], {**base, **{n: r[n] for n in vary}}) for r in front],
        Targets((), targets.exports if export else (), render, size),
        finished,
        client=client,
        cache_dir=cache_path,
        worker_cache=worker_cache,
    )
    if render is None:
        return written
    from formgraph.viewer.sheet import contact_sheet

    cells = [(_label({**r, "variant": r["trial"]}, vary), images.get(r["trial"])) for r in front]
    return written + list(contact_sheet(cells, out_dir / "front.png", size=size))
