"""Optimisation studies on Dask: a known constrained optimum, a two-objective front checked
both ways, the same trials whatever the number of workers, a study resumed to a larger
budget (and equal to one run straight through), a killed worker, Ctrl-C and a rerun, and
bad objectives and constraints refused with their place in the file.

The Dask clusters here have at most two single-threaded worker processes, each closed by
its fixture or test. Worker processes import ``sweep_stubs`` by name.
"""

from __future__ import annotations

import csv
import math
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import sweep_stubs
from distributed import Client, LocalCluster
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.cli.main import main as cli_main
from formgraph.sweeps.objectives import non_dominated

ROOT = Path(__file__).resolve().parents[1]
pytest.importorskip("optuna")


def cluster(n: int, processes: bool = True) -> LocalCluster:
    if not processes:  # in-process workers talk inproc://, no socket at all
        return LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=False,
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
        )
    return LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
        silence_logs=40,
    )


@pytest.fixture(scope="module")
def client():
    """Two workers in this process (threads): nothing to import or start per worker, so
    the studies below take seconds; the tests of worker processes start their own."""
    with cluster(2, processes=False) as c, Client(c) as cl:
        yield cl


CAN = """\
formgraph: 1
params:
  r: {default: 5.0, min: 0.5, max: 20}
  h: {default: 10.0, min: 0.5, max: 40}
nodes:
  can:
    type: mesh.cylinder
    radius: "=r"
    height: "=h"
    segments: 256
  size:
    type: mesh.measure
    mesh: "@can"
"""


def can_graph(tmp_path: Path) -> Path:
    path = tmp_path / "can.yaml"
    path.write_text(CAN)
    return path


def test_the_least_area_can_holding_1000_is_found(client, tmp_path):
    """min 2 pi r^2 + 2 pi r h subject to pi r^2 h >= 1000: r = (1000 / 2 pi)^(1/3), h = 2r
    (the Lagrange condition); a 256-gon cylinder is within 1e-4 of the circle's values."""
    s = fg.optimize(
        can_graph(tmp_path),
        vary={"r": "1:15", "h": "1:30"},
        minimize=["size.area"],
        constraints=["size.volume >= 1000"],
        budget=100,
        batch=10,
        seed=3,
        client=client,
        cache_dir=None,
        out=tmp_path / "out",
    )
    r0 = (1000 / (2 * math.pi)) ** (1 / 3)
    best = s.best
    assert best["feasible"] and best["size.volume"] >= 1000
    assert best["size.area"] == pytest.approx(6 * math.pi * r0**2, rel=0.04)
    assert best["r"] == pytest.approx(r0, rel=0.06)
    assert best["h"] == pytest.approx(2 * r0, rel=0.08)
    feasible = [r for r in s.trials if r["feasible"]]
    assert best["size.area"] == min(r["size.area"] for r in feasible)
    infeasible = [r for r in s.trials if not r["feasible"]]
    assert infeasible and all(r["size.volume"] < 1000 for r in infeasible)
    assert min(r["size.area"] for r in infeasible) < best["size.area"]  # never reported
    with open(tmp_path / "out" / "trials.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0]) == [
        "trial", "r", "h", "status", "error", "seconds", "size.area", "size.volume",
        "feasible", "pareto",
    ]  # fmt: skip
    assert [int(t["trial"]) for t in table] == list(range(100))
    assert [t["trial"] for t in table if t["pareto"] == "true"] == [str(best["trial"])]
    with open(tmp_path / "out" / "pareto.csv", newline="") as fh:
        assert [int(t["trial"]) for t in csv.DictReader(fh)] == [best["trial"]]
    assert (tmp_path / "out" / "progress.png").stat().st_size > 10_000
    assert "best: trial" in s.summary()


def dominates(a, b) -> bool:
    return all(x <= y for x, y in zip(a, b, strict=True)) and any(
        x < y for x, y in zip(a, b, strict=True)
    )


def test_a_two_objective_front_is_non_dominated_both_ways(client, tmp_path):
    s = fg.optimize(
        can_graph(tmp_path),
        vary={"r": "1:10", "h": "1:20"},
        minimize=["size.area"],
        maximize=["size.volume"],
        constraints=["h - 3 * r <= 0"],
        method="nsga2",
        budget=48,
        batch=16,
        client=client,
        cache_dir=None,
    )
    pts = {r["trial"]: (r["size.area"], -r["size.volume"]) for r in s.trials if r["feasible"]}
    front = {r["trial"] for r in s.pareto}
    assert front and all(r["h"] <= 3 * r["r"] for r in s.pareto)
    for t in front:  # nothing feasible dominates a front trial
        assert not any(dominates(pts[u], pts[t]) for u in pts)
    for t in set(pts) - front:  # and a front trial dominates every other feasible one
        assert any(dominates(pts[u], pts[t]) for u in front)
    with pytest.raises(ValueError, match="has a front, not a best"):
        _ = s.best


@settings(max_examples=60, deadline=None)
@given(
    st.integers(1, 3).flatmap(
        lambda k: st.lists(st.tuples(*[st.integers(0, 5)] * k), max_size=40).map(
            lambda pts: (k, pts)
        )
    )
)
def test_non_dominated_matches_the_definition(case):
    # one objective (the least), two (the sorted sweep) and three (pairwise), ties included
    k, points = case
    keep = non_dominated(np.array(points, dtype=float).reshape(len(points), k))
    assert keep.shape == (len(points),) and keep.dtype == bool
    for i, p in enumerate(points):
        assert keep[i] == (not any(dominates(q, p) for q in points))


def trial_params(s):
    return [(r["trial"], r["r"], r["h"]) for r in s.trials]


def test_the_same_seed_gives_the_same_trials_on_one_worker_or_two(client, tmp_path):
    kw = dict(
        vary={"r": "1:15", "h": "1:30"},
        minimize=["size.area"],
        constraints=["size.volume >= 1000"],
        budget=24,
        batch=8,
        seed=5,
        cache_dir=None,
    )
    two = fg.optimize(can_graph(tmp_path), client=client, **kw)  # two threads
    with cluster(1) as c, Client(c) as one_client:  # one process
        one = fg.optimize(can_graph(tmp_path), client=one_client, **kw)
    assert trial_params(one) == trial_params(two)
    assert [r["size.area"] for r in one.trials] == [r["size.area"] for r in two.trials]
    other = fg.optimize(can_graph(tmp_path), client=client, **{**kw, "seed": 6})
    assert trial_params(other) != trial_params(two)


def test_a_study_resumed_to_a_larger_budget_keeps_its_trials(client, tmp_path):
    kw = dict(
        vary={"r": "1:15", "h": "1:30"},
        minimize=["size.area"],
        constraints=["size.volume >= 1000"],
        batch=8,
        seed=2,
        client=client,
        cache_dir=None,
    )
    out = tmp_path / "out"
    first = fg.optimize(can_graph(tmp_path), budget=16, out=out, **kw)
    again = fg.optimize(can_graph(tmp_path), budget=16, out=out, **kw)  # done: nothing runs
    assert again.resumed == 16 and trial_params(again) == trial_params(first)
    more = fg.optimize(can_graph(tmp_path), budget=32, out=out, **kw)
    assert more.resumed == 16 and len(more.trials) == 32
    assert trial_params(more)[:16] == trial_params(first)
    straight = fg.optimize(can_graph(tmp_path), budget=32, **kw)  # one run, no journal
    assert trial_params(straight) == trial_params(more)
    with pytest.raises(ValueError, match="holds a study of another question"):
        fg.optimize(can_graph(tmp_path), budget=40, out=out, **{**kw, "seed": 9})


@pytest.mark.parametrize("method", ["nsga2", "cmaes"])
def test_a_resumed_study_asks_what_a_straight_one_asks_whatever_the_sampler(
    client, tmp_path, method
):
    """The rerun replays the journal's last batch as running trials and tells it after
    asking the next batch, as the first run did (batch b asked while b - 1 runs): NSGA-II's
    generations and CMA-ES's populations count running trials their own way."""
    if method == "cmaes":
        pytest.importorskip("cmaes")  # optuna's CMA-ES sampler needs it (not a dependency)
    kw = dict(
        vary={"r": "1:15", "h": "1:30"},
        minimize=["size.area"],
        maximize=["size.volume"] if method == "nsga2" else [],
        method=method,
        batch=4,
        seed=3,
        client=client,
        cache_dir=None,
    )
    out = tmp_path / "out"
    fg.optimize(can_graph(tmp_path), budget=20, out=out, **kw)  # past NSGA-II's first 16
    more = fg.optimize(can_graph(tmp_path), budget=28, out=out, **kw)
    straight = fg.optimize(can_graph(tmp_path), budget=28, **kw)
    assert more.resumed == 20 and trial_params(more) == trial_params(straight)


def test_the_journal_holds_back_its_last_batch_until_the_next_is_asked(tmp_path):
    import optuna
    from optuna.distributions import FloatDistribution

    from formgraph.sweeps.journal import Journal, replay, tell_recorded

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    space = {"x": FloatDistribution(0.0, 1.0)}
    study = optuna.create_study()
    journal = Journal(tmp_path / "study.journal")
    journal.start("q")
    for first in (0, 3):  # batches of 3, then of 2 (a budget of 5)
        asked = [study.ask(space) for _ in range(3 if first == 0 else 2)]
        for t in asked:
            t.set_user_attr("row", {"trial": t.number})
            t.set_constraint("c0", t.params["x"] - 0.5)
            study.tell(t, t.params["x"] ** 2)
        journal.append((study.trials[t.number] for t in asked), first)
    question, records = journal.read()
    assert question == "q" and [r["batch"] for r in records] == [0, 0, 0, 3, 3]
    for rec in records[3:]:
        del rec["batch"]  # a journal that does not say its batches: counted from the size
    again = optuna.create_study()
    held = replay(optuna, again, records, 3)
    running = optuna.trial.TrialState.RUNNING
    assert [rec["number"] for _, rec in held] == [3, 4]
    assert [t.state == running for t in again.trials] == [False, False, False, True, True]
    assert all("constraints:c0" not in again.trials[n].system_attrs for n in (3, 4))
    assert again.ask(space).number == 5  # the next batch is asked first
    for trial_id, rec in held:
        tell_recorded(optuna, again, trial_id, rec)
    for old, new in zip(study.trials, again.trials, strict=False):
        assert (new.state, new.params, new.values) == (old.state, old.params, old.values)
        assert (new.user_attrs, new.system_attrs) == (old.user_attrs, old.system_attrs)


def logged(tmp_path: Path, seconds: float) -> fg.Graph:
    g = fg.Graph()
    g.add_param("a", 1.0, min=0, max=10)
    g.add("per", "stub.logged", x="=a", log=str(tmp_path / "calls.log"), seconds=seconds)
    return g


def test_a_worker_killed_during_a_study_is_survived(tmp_path):
    killed = []
    with cluster(2) as c, Client(c) as cl:
        pids = list(cl.run(os.getpid).values())

        def kill_one() -> None:
            os.kill(pids[0], signal.SIGKILL)
            killed.append(pids[0])

        timer = threading.Timer(0.8, kill_one)  # mid-study: trials take 0.1 s each
        timer.start()
        try:
            s = fg.optimize(
                logged(tmp_path, 0.1),
                vary={"a": "0:10"},
                minimize=["per"],
                budget=32,
                batch=8,
                client=cl,
                cache_dir=None,
            )
        finally:
            timer.cancel()
    assert killed
    assert len(s.trials) == 32 and all(r["status"] == "ok" for r in s.trials)
    assert all(r["per"] == r["a"] for r in s.trials)
    assert s.best["a"] == min(r["a"] for r in s.trials)


def test_ctrl_c_and_a_rerun_continue_the_study(tmp_path):
    graph = tmp_path / "slow.yaml"
    log, hold = tmp_path / "calls.log", tmp_path / "hold"
    # two batches run, the third waits while `hold` exists: the interrupt always comes
    # mid-study (a loaded machine could finish all sixteen trials before it)
    hold.touch()
    graph.write_text(
        "formgraph: 1\nparams:\n  a: {default: 1.0, min: 0, max: 10}\nnodes:\n"
        f'  per: {{type: stub.logged, x: "=a", log: "{log}", label: per, seconds: 0.05, '
        f'hold: "{hold}", after: 8}}\n'
    )
    out = tmp_path / "out"
    code = (
        "import sys; sys.path.insert(0, sys.argv[1]); import sweep_stubs; "
        "from formgraph.cli.main import main; sys.exit(main(sys.argv[2:]))"
    )
    args = [sys.executable, "-c", code, str(ROOT / "tests"), "optimize", str(graph)]
    args += ["--vary", "a=0:10", "--minimize", "per", "--budget", "16", "--batch", "4"]
    args += ["--workers", "1", "--out", str(out), "--no-cache"]
    # Ctrl-C heard even when the suite itself runs with SIGINT ignored (started with `&`
    # from a script: the shell ignores it for background jobs, and Python keeps that)
    proc = subprocess.Popen(
        args,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:  # until a few batches are told
            if (out / "trials.csv").exists() and (out / "trials.csv").read_text().count("\n") > 4:
                break
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        time.sleep(0.5)
        hold.unlink()  # the waiting trials end, so the cluster closes without a kill
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130 and "interrupted" in err and "Traceback" not in err
    with open(out / "trials.csv", newline="") as fh:
        partial = list(csv.DictReader(fh))
    assert 4 <= len(partial) < 16 and all(r["status"] == "ok" for r in partial)
    done = subprocess.run(args, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert f"({len(partial)} kept from an earlier run)" in done.stdout
    with open(out / "trials.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [int(r["trial"]) for r in table] == list(range(16))
    assert [(r["a"], r["per"]) for r in table[: len(partial)]] == [
        (r["a"], r["per"]) for r in partial
    ]
    assert all(float(r["per"]) == float(r["a"]) for r in table)
    calls = sweep_stubs.calls(log)
    # kept trials are not run again; the batches in flight when it was cut short may be
    # (two of them: batch b is asked while b - 1 still runs)
    assert len(calls) <= 16 + 2 * 4


def test_bad_objectives_and_constraints_are_located_errors(tmp_path):
    path = can_graph(tmp_path)
    with pytest.raises(fg.ParamError) as info:
        fg.optimize(
            path,
            vary={"r": "1:25", "h": "1:30"},
            minimize=["can", "size.nope"],
            constraints=["size.volume >= ", "size.volume + + <= 3", "size.volume >= 1000"],
            budget=10,
        )
    text = str(info.value)
    assert f"{path}:6: node 'can': minimize 'can' gives Mesh, not a number" in text
    assert f"{path}:11: node 'size': minimize 'size.nope': no such output; use size.area," in text
    assert "constraint 'size.volume >= ': write EXPR <= NUMBER or EXPR >= NUMBER" in text
    assert "constraint 'size.volume + + <= 3': expression 'size.volume + +' is not valid" in text
    assert f"{path}:3: param 'r': vary r=1:25: reaches 25, above the param's max 20" in text


def test_constraints_name_params_and_outputs_or_say_what_is_wrong(tmp_path):
    path = can_graph(tmp_path)
    bad = {
        "radius <= 3": "'radius' is neither a param nor a node output",
        "size.volume >= big": "'big' is not a number",
        "__import__('os') <= 1": "not allowed|not in the language|cannot",
        "size.center <= 1": "gives Vec3, not a number",
    }
    for text, message in bad.items():
        with pytest.raises(fg.ParamError, match=message):
            fg.optimize(path, vary={"r": "1:5"}, minimize=["size.area"], constraints=[text],
                        budget=4)  # fmt: skip


def test_the_command_line_refuses_a_mesh_objective_and_names_a_missing_optuna(
    tmp_path, capsys, monkeypatch
):
    path = can_graph(tmp_path)
    args = ["optimize", str(path), "--vary", "r=1:5", "--minimize", "can", "--budget", "5"]
    assert cli_main([*args, "--out", str(tmp_path / "o")]) == 1
    assert "minimize 'can' gives Mesh, not a number" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "optuna", None)
    assert cli_main([*args, "--out", str(tmp_path / "o")]) == 2
    assert "pip install 'formgraph[optimize]'" in capsys.readouterr().err


def test_the_progress_line_says_trials_the_best_and_the_time_left():
    import io

    from formgraph.cli.optimize import _Progress, progress_text

    text = progress_text(40, 100, "best size.area = 571.2", 2.0)
    assert text == "optimize 40/100 trials, best size.area = 571.2, 2.0/s, ETA 0:30"

    class Tty(io.StringIO):
        def isatty(self):
            return True

    tty, pipe = Tty(), io.StringIO()
    _Progress(tty)(100, 100, "best x = 1", 5.0)
    _Progress(pipe)(100, 100, "best x = 1", 5.0)
    assert "optimize 100/100 trials, best x = 1" in tty.getvalue() and pipe.getvalue() == ""
