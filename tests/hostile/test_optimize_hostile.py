"""Hostile optimisation studies: code in a constraint, absurd budgets, a journal that is
not ours, a trial that fails every time, a design's text param written as a formula."""

from __future__ import annotations

import csv

import pytest
import sweep_stubs  # noqa: F401  (registers stub.fail_at)
from distributed import Client, LocalCluster

import formgraph as fg

pytest.importorskip("optuna")

CAN = """\
formgraph: 1
params:
  r: {default: 5.0, min: 0.5, max: 20}
nodes:
  can: {type: mesh.cylinder, radius: "=r", height: 2, segments: 16}
  size: {type: mesh.measure, mesh: "@can"}
"""


@pytest.fixture
def can(tmp_path):
    path = tmp_path / "can.yaml"
    path.write_text(CAN)
    return path


@pytest.mark.parametrize(
    "constraint, message",
    [
        ("__import__('os').system('touch pwned') <= 1", "not valid|not allowed|cannot"),
        ("size.volume.__class__ <= 1", "attribute is not allowed"),
        ("(" * 300 + "r" + ")" * 300 + " <= 1", "nested too deeply|too large|not valid"),
        ("r + " * 2000 + "r <= 1", "characters long|too large"),
        ("r <= 1e999", "is not a number"),
        ("r <= nan", "is not a number"),
        ("r < 3", "write EXPR <= NUMBER or EXPR >= NUMBER"),
    ],
)
def test_a_hostile_constraint_is_refused_before_anything_runs(can, tmp_path, constraint, message):
    with pytest.raises(fg.GraphError, match=message):
        fg.optimize(can, vary={"r": "1:5"}, minimize=["size.area"], constraints=[constraint],
                    budget=4)  # fmt: skip
    assert not (tmp_path / "pwned").exists()


@pytest.mark.parametrize(
    "kw, message",
    [
        ({"budget": 0}, "budget must be 1 to"),
        ({"budget": 10**9}, "budget must be 1 to"),
        ({"budget": 4, "batch": 0}, "batch must be 1 to"),
        ({"budget": 4, "method": "genetic"}, "unknown method 'genetic'"),
        ({"budget": 4, "method": "cmaes", "maximize": ["size.volume"]}, "cmaes optimises one"),
        ({"budget": 4, "render": "can"}, "give out="),
    ],
)
def test_absurd_settings_are_refused(can, kw, message):
    with pytest.raises(ValueError, match=message):
        fg.optimize(can, vary={"r": "1:5"}, minimize=["size.area"], **kw)


def test_a_journal_that_is_not_ours_is_refused_and_left_alone(can, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "study.journal").write_text("not json at all\n{}\n")
    with pytest.raises(ValueError, match="is not a formgraph study journal"):
        fg.optimize(can, vary={"r": "1:5"}, minimize=["size.area"], budget=4, out=out)
    assert (out / "study.journal").read_text() == "not json at all\n{}\n"


def test_failing_trials_are_recorded_never_best_and_text_cells_stay_inert(tmp_path):
    g = fg.Graph()
    g.add_param("a", 1.0, min=0, max=10)
    g.add_param("note", '=HYPERLINK("http://x")')
    g.add("f", "stub.fail_at", x="=a", bad=2.0)
    with (
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=False,
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
        ) as c,
        Client(c) as cl,
    ):
        s = fg.optimize(g, vary={"a": "1,2,3"}, minimize=["f"], budget=12, batch=4, client=cl,
                        cache_dir=None, out=tmp_path / "out")  # fmt: skip
    failed = [r for r in s.trials if r["status"] == "failed"]
    assert failed and all(r["a"] == 2.0 and "2 is the bad value" in r["error"] for r in failed)
    assert all(not r["feasible"] and not r["pareto"] for r in failed)
    assert s.best["a"] == 1.0
    with open(tmp_path / "out" / "trials.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert {t["note"] for t in table} == {'\'=HYPERLINK("http://x")'}
