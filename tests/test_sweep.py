"""Sweeps on Dask: rows equal to a plain loop, shared work done once, failures recorded,
a killed worker survived, an interrupted sweep resumed, a scheduler reached over loopback,
a contact sheet with a cell per variant.

The Dask clusters here have at most two single-threaded worker processes, and each is
closed by its fixture or test. Worker processes import ``sweep_stubs`` by name.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import sweep_stubs
from distributed import Client, LocalCluster

import formgraph as fg
from formgraph.cli.main import main as cli_main
from formgraph.viewer.sheet import CELL, FAILED, LABEL_HEIGHT

ROOT = Path(__file__).resolve().parents[1]


def cluster(n: int = 2) -> LocalCluster:
    return LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # its HTTP routes, off 8787
        silence_logs=40,
    )


@pytest.fixture(scope="module")
def client():
    with cluster(2) as c, Client(c) as cl:
        yield cl


def curves_graph() -> fg.Graph:
    """Params of every kind a sweep varies: int, float, bool and enum (a text param)."""
    g = fg.Graph()
    g.add_param("n", 5, min=3, max=12)
    g.add_param("r", 1.0, min=0.5, max=4.0)
    g.add_param("closed", False)
    g.add_param("spacing", "uniform")
    g.add("pts", "points.circle", count="=n", radius="=r")
    g.add("c", "curves.catmull_rom", points="@pts", closed="=closed", spacing="=spacing")
    g.add("stats", "stub.curve_stats", curve="@c", samples=50)
    return g


def logged_graph(log: Path, seconds: float = 0.0) -> fg.Graph:
    """'shared' reads only b, 'per' reads a: the sweep varies a."""
    g = fg.Graph()
    g.add_param("a", 1.0, min=0, max=100)
    g.add_param("b", 2.0)
    g.add("shared", "stub.logged", x="=b", log=str(log), label="shared")
    g.add("per", "stub.logged", x="=a", log=str(log), label="per", seconds=seconds)
    g.add("sum", "stub.add", a="@per", b="@shared")
    return g


def test_rows_equal_a_plain_loop_and_the_csv_has_the_documented_columns(client, tmp_path):
    g = curves_graph()
    vary = {"n": "4:6", "r": [1, 2.5], "closed": "true,false", "spacing": "uniform,chordal"}
    s = fg.sweep(g, vary, ["stats"], client=client, out=tmp_path, cache_dir=None)
    assert len(s.rows) == 3 * 2 * 2 * 2
    assert [r["variant"] for r in s.rows] == list(range(24))
    for row in s.rows:
        params = {k: row[k] for k in vary}
        expected = g.evaluate("stats", **params)
        assert row["status"] == "ok" and row["error"] == ""
        assert row["stats.length"] == pytest.approx(expected.length, rel=1e-12)
        assert row["stats.closed"] is expected.closed
        assert row["stats.samples"] == 50
    assert (s.rows[0]["n"], s.rows[0]["r"], s.rows[0]["closed"]) == (4, 1.0, True)
    with open(tmp_path / "sweep.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0]) == [
        "variant",
        "n",
        "r",
        "closed",
        "spacing",
        "status",
        "error",
        "seconds",
        "stats.length",
        "stats.closed",
        "stats.samples",
    ]
    assert len(table) == 24
    for row, cells in zip(s.rows, table, strict=True):
        assert float(cells["stats.length"]) == row["stats.length"]
        assert cells["closed"] in ("true", "false") and float(cells["seconds"]) >= 0


def test_shared_upstream_is_computed_once(client, tmp_path):
    log = tmp_path / "calls.log"
    s = fg.sweep(logged_graph(log), {"a": "1:6:6"}, ["sum"], client=client, cache_dir=None)
    assert [r["sum"] for r in s.rows] == [3.0, 4.0, 5.0, 6.0, 7.0, 8.0]
    calls = sweep_stubs.calls(log)
    assert sorted(calls) == sorted(["shared:2", *(f"per:{a}" for a in range(1, 7))])
    assert (s.totals.naive, s.totals.needed, s.totals.computed) == (18, 13, 13)


def test_plan_keys_are_the_cache_keys_of_an_evaluation(tmp_path):
    g = fg.Graph(cache_dir=tmp_path)
    g.add_param("a", 1.0)
    g.add("p", "points.circle", count=5, radius="=a")
    g.add("c", "curves.polyline", points="@p", closed=True)
    g.evaluate("c", a=2.0)
    stored = {p.stem for p in tmp_path.rglob("*.npz")}
    assert {s.key for s in g.plan("c", a=2.0)} == stored
    assert not {s.key for s in g.plan("c", a=3.0)} & stored


def test_a_failing_variant_is_a_row_and_the_others_go_on(client, tmp_path):
    g = fg.Graph()
    g.add_param("a", 1.0)
    g.add("f", "stub.fail_at", x="=a", bad=3.0)
    s = fg.sweep(g, {"a": "1,2,3,4"}, ["f"], client=client, out=tmp_path, cache_dir=None)
    assert [r["status"] for r in s.rows] == ["ok", "ok", "failed", "ok"]
    assert [r["f"] for r in s.rows] == [1.0, 2.0, None, 4.0]
    error = s.rows[2]["error"]
    assert "node 'f'" in error and "3 is the bad value" in error and "\n" not in error
    assert s.failed == 1
    with open(tmp_path / "sweep.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert table[2]["status"] == "failed" and table[2]["error"] == error


def test_a_worker_killed_mid_sweep_is_survived(tmp_path):
    log = tmp_path / "calls.log"
    g = logged_graph(log, seconds=0.25)
    killed = []
    with cluster(2) as c, Client(c) as cl:
        pids = list(cl.run(os.getpid).values())

        def kill_one(row):
            if not killed:  # both workers are busy with the next variants by now
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])

        s = fg.sweep(g, {"a": "1:10:10"}, ["sum"], client=cl, cache_dir=None, on_row=kill_one)
    assert killed
    assert [r["variant"] for r in s.rows] == list(range(10))
    assert all(r["status"] == "ok" for r in s.rows)
    assert [r["sum"] for r in s.rows] == [a + 2.0 for a in range(1, 11)]


def test_a_variant_that_kills_its_worker_fails_alone(tmp_path):
    """Variants go several to a task; when one of them ends its worker's process each time
    it runs (Dask gives up: KilledWorker), the task's rows are run again one a task, so only
    that variant fails and the others of its task come back."""
    import dask

    g = fg.Graph()
    g.add_param("a", 1.0)
    g.add("d", "stub.die_at", x="=a", bad=7.0)
    with dask.config.set({"distributed.scheduler.allowed-failures": 1}):
        with cluster(2) as c, Client(c) as cl:
            s = fg.sweep(g, {"a": "1:160:160"}, ["d"], client=cl, cache_dir=None)
    failed = [r["a"] for r in s.rows if r["status"] != "ok"]
    assert failed == [7.0]
    assert "kept dying" in next(r["error"] for r in s.rows if r["status"] != "ok")
    assert [r["d"] for r in s.rows if r["status"] == "ok"] == [a for a in range(1, 161) if a != 7]


def test_a_gather_that_never_returns_is_run_again_on_new_keys(client, tmp_path, monkeypatch):
    """dask/distributed#3196: a worker killed at the wrong moment can leave a gather of
    finished tasks waiting forever (a full suite at load 20 sat an hour in one). The sweep
    waits a bounded time, then runs the task's rows again, each on a new key."""
    from formgraph.sweeps import cluster as kcluster

    monkeypatch.setattr(kcluster, "GATHER_SECONDS", 1.0)
    real, calls = Client._gather, []

    async def deadlocked_once(self, futures, *args, **kwargs):
        calls.append(len(futures))
        if len(calls) == 1:
            import asyncio

            await asyncio.sleep(3600)
        return await real(self, futures, *args, **kwargs)

    monkeypatch.setattr(Client, "_gather", deadlocked_once)
    g = logged_graph(tmp_path / "calls.log", seconds=0.0)
    s = fg.sweep(g, {"a": "1:40:40"}, ["sum"], client=client, cache_dir=None)
    assert len(calls) >= 2
    assert all(r["status"] == "ok" for r in s.rows)
    assert [r["sum"] for r in s.rows] == [a + 2.0 for a in range(1, 41)]


def test_an_interrupted_sweep_resumes_with_every_row_once(client, tmp_path):
    log = tmp_path / "calls.log"
    out = tmp_path / "out"
    args = dict(client=client, out=out, cache_dir=tmp_path / "cache")
    seen = []

    def interrupt(row):
        seen.append(row["variant"])
        if len(seen) == 3:
            raise KeyboardInterrupt

    g = logged_graph(log, seconds=0.05)
    with pytest.raises(KeyboardInterrupt):
        fg.sweep(g, {"a": "1:12:12"}, ["sum"], on_row=interrupt, **args)
    with open(out / "sweep.csv", newline="") as fh:
        partial = list(csv.DictReader(fh))
    assert sorted(int(r["variant"]) for r in partial) == sorted(seen)
    s = fg.sweep(logged_graph(log, seconds=0.05), {"a": "1:12:12"}, ["sum"], **args)
    assert s.resumed == 3
    with open(out / "sweep.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [r["error"] for r in table] == [""] * 12
    assert [int(r["variant"]) for r in table] == list(range(12))
    assert [float(r["sum"]) for r in table] == [a + 2.0 for a in range(1, 13)]
    calls = sweep_stubs.calls(log)
    for v in seen:  # the rows kept were not run again
        assert calls.count(f"per:{v + 1}") == 1


def scheduler_address(path: Path) -> str:
    """The address in a scheduler file, once the scheduler has written it whole."""
    deadline = time.monotonic() + 180  # a bound against a hang: a loaded box starts slowly
    while time.monotonic() < deadline:
        try:
            return json.loads(path.read_text())["address"]
        except (OSError, ValueError, KeyError):
            time.sleep(0.1)
    raise AssertionError("the Dask scheduler did not start")


def test_a_sweep_against_a_scheduler_on_loopback(tmp_path):
    graph = tmp_path / "ring.yaml"
    graph.write_text(
        textwrap.dedent(
            """
            formgraph: 1
            params:
              n: {default: 4, min: 3, max: 32}
            nodes:
              pts: {type: points.circle, count: "=n"}
              ring: {type: curves.polyline, points: "@pts", closed: true}
              tube: {type: nurbs.extrude, curve: "@ring"}
              mesh: {type: nurbs.tessellate, surface: "@tube", u: 8, v: 2}
              save: {type: export.obj, mesh: "@mesh", path: ring.obj}
            """
        ).lstrip()
    )
    bin_dir = Path(sys.executable).parent
    elsewhere = tmp_path / "worker-cwd"  # the worker shares no folder with the client
    elsewhere.mkdir()
    address_file = tmp_path / "scheduler.json"
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    procs = [
        subprocess.Popen(
            [
                bin_dir / "dask",
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                address_file,
            ],
            cwd=elsewhere,
            env=env,
            stderr=subprocess.DEVNULL,
        )
    ]
    try:
        address = scheduler_address(address_file)
        assert address.startswith("tcp://127.0.0.1:")
        procs.append(
            subprocess.Popen(
                [
                    bin_dir / "dask",
                    "worker",
                    address,
                    "--nthreads",
                    "1",
                    "--no-nanny",
                    "--no-dashboard",
                ],
                cwd=elsewhere,
                env=env,
                stderr=subprocess.DEVNULL,
            )
        )
        with Client(address, timeout="30s") as cl:
            cl.wait_for_workers(1, timeout=60)
        out = tmp_path / "out"
        code = cli_main(
            [
                "sweep",
                str(graph),
                "--vary",
                "n=3:6",
                "--export",
                "--scheduler",
                address,
                "--out",
                str(out),
                "--no-cache",
            ]
        )
    finally:
        for p in reversed(procs):  # the worker first, then its scheduler
            p.terminate()
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:  # a graceful close that hangs on a busy machine
                p.kill()
                p.wait(timeout=20)
    assert code == 0
    with open(out / "sweep.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [r["save"] for r in table] == [f"variants/{i:04d}/ring.obj" for i in range(4)]
    g = fg.load(graph)
    for i, row in enumerate(table):
        lines = (out / row["save"]).read_text().splitlines()
        vertices = sum(1 for ln in lines if ln.startswith("v "))
        assert vertices == g.evaluate("mesh", n=i + 3).n_vertices
    assert not list(elsewhere.rglob("*.obj"))


def test_the_contact_sheet_has_a_cell_per_variant(client, tmp_path):
    g = curves_graph()
    s = fg.sweep(g, {"n": "3:7"}, render="c", client=client, out=tmp_path, cache_dir=None)
    assert s.sheets == [tmp_path / "sheet.png"]
    from PIL import Image

    with Image.open(tmp_path / "sheet.png") as im:
        sheet = np.asarray(im.convert("RGB")).astype(float)
    w, h = CELL
    assert sheet.shape == (2 * (h + LABEL_HEIGHT), 3 * w, 3)  # 5 cells: 3 columns, 2 rows
    assert [r["status"] for r in s.rows] == ["failed"] + ["ok"] * 4  # 3 points: too few
    for i in range(6):
        cell = sheet[(i // 3) * (h + LABEL_HEIGHT) :][:h, (i % 3) * w :][:, :w]
        failed = np.all(cell == FAILED, axis=2).mean()
        drawn = (cell.std(axis=2) > 20).mean()  # coloured pixels: the curve, the axes
        blank = np.all(cell == 255, axis=2).mean()
        if i == 0:
            assert failed > 0.9
        elif i < 5:
            assert drawn > 0.001 and failed == 0 and blank < 1, i
        else:
            assert blank == 1  # the grid's unused sixth place
    for i in range(1, 5):
        assert (tmp_path / f"variants/{i:04d}/c.png").is_file()


def test_sheets_page_past_the_cell_cap(tmp_path):
    from formgraph.viewer.sheet import contact_sheet

    cells = [(f"#{i}", None) for i in range(7)]
    paths = contact_sheet(cells, tmp_path / "sheet.png", per_sheet=3)
    assert [p.name for p in paths] == ["sheet.png", "sheet-2.png", "sheet-3.png"]


def test_bad_sweeps_are_refused_before_anything_runs():
    g = curves_graph()
    with pytest.raises(fg.ParamError) as info:
        fg.sweep(
            g,
            {"n": "1:20", "r": "0.5:9:3", "spacing": "uniform,loose", "m": "1,2"},
            ["nothing", "c"],
            client="tcp://127.0.0.1:1",
        )
    text = str(info.value)
    assert "<graph>: param 'n': vary n=1:20: goes down to 1, below the param's min 3" in text
    assert "param 'r': vary r=0.5:9:3: reaches 9, above the param's max 4" in text
    assert "'loose' is not one of its choices uniform, centripetal, chordal" in text
    assert "vary: unknown param 'm'" in text
    assert "measure: no node 'nothing'" in text
    assert "measure: 'c' gives NurbsCurve, not a number" in text
    with pytest.raises(ValueError, match="a grid needs values for 'r': give a count"):
        fg.sweep(g, {"r": "1:2"}, client="tcp://127.0.0.1:1")


def test_repeated_and_subgraph_nodes_sweep_like_a_plain_loop(client):
    lamp = fg.load(ROOT / "graphs" / "lamp.yaml")
    lamp.add("stats", "stub.mesh_stats", mesh="@lamp")
    vase = fg.load(ROOT / "graphs" / "vase_repeat.yaml")
    vase.add("stats", "stub.mesh_stats", mesh="@mesh")
    cases = [
        (lamp, {"top": "0.4,0.8", "height": "1:2:2"}),
        (vase, {"sections": "4:7", "swell": [0.5, 1.0]}),
        (vase, {"around": "8:64:3"}),  # the repeated sections and the loft: shared
    ]
    for g, vary in cases:
        s = fg.sweep(g, vary, ["stats"], client=client, cache_dir=None)
        assert [r["status"] for r in s.rows] == ["ok"] * len(s.rows)
        for row in s.rows:
            expected = g.evaluate("stats", **{k: row[k] for k in vary})
            assert row["stats.vertices"] == expected.vertices
            assert row["stats.extent"] == pytest.approx(expected.extent, rel=1e-12)
    assert (s.totals.naive, s.totals.needed) == (3 * 4, 2 + 3 * 2)


def test_subgraph_files_travel_with_the_graph(tmp_path):
    from formgraph.sweeps.cluster import blueprint
    from formgraph.sweeps.tasks import _graph_file

    for rel in ("lamp.yaml", "parts/ring.yaml"):
        (tmp_path / rel).parent.mkdir(exist_ok=True)
        (tmp_path / rel).write_text((ROOT / "graphs" / rel).read_text())
    bp = blueprint(fg.load(tmp_path / "lamp.yaml"), None, False)
    assert set(bp.files) == {"parts/ring.yaml"}
    assert _graph_file(bp) == bp.path  # this machine has the same files
    (tmp_path / "parts" / "ring.yaml").unlink()  # another machine would not
    elsewhere = Path(_graph_file(bp))
    assert elsewhere != tmp_path / "lamp.yaml"
    assert (elsewhere.parent / "parts" / "ring.yaml").read_text() == bp.files["parts/ring.yaml"]


def test_the_embedded_cluster_is_started_and_closed_by_the_sweep(tmp_path, capsys):
    import multiprocessing

    graph = tmp_path / "ring.yaml"
    graph.write_text(
        "formgraph: 1\nparams:\n  n: {default: 4, min: 3, max: 32}\nnodes:\n"
        '  pts: {type: points.circle, count: "=n"}\n'
        '  ring: {type: curves.polyline, points: "@pts", closed: true}\n'
    )
    out = tmp_path / "out"
    args = ["sweep", str(graph), "--vary", "n=3:6", "--workers", "2", "--out", str(out)]
    args += ["--cache-dir", str(tmp_path / "cache")]
    before = {p.pid for p in multiprocessing.active_children()}  # another test's cluster
    assert cli_main(args) == 0
    assert {p.pid for p in multiprocessing.active_children()} <= before  # its workers: gone
    first = capsys.readouterr().out
    assert "4 variants: 4 ok, 0 failed" in first
    assert "node evaluations: 8 needed for 4 variants x their nodes = 8" in first
    with open(out / "sweep.csv", newline="") as fh:
        assert [r["n"] for r in csv.DictReader(fh)] == ["3", "4", "5", "6"]
    assert cli_main(args) == 0  # everything done: kept, no cluster started
    assert "(4 kept from an earlier run)" in capsys.readouterr().out


def test_ctrl_c_leaves_a_valid_table_and_the_rerun_completes_it(tmp_path):
    graph = tmp_path / "slow.yaml"
    log, hold = tmp_path / "calls.log", tmp_path / "hold"
    # three variants run, the fourth waits while `hold` exists: the interrupt always comes
    # mid-sweep (a fixed pace let a loaded machine finish all twelve before it)
    hold.touch()
    graph.write_text(
        "formgraph: 1\nparams:\n  a: {default: 1.0, min: 0, max: 100}\nnodes:\n"
        f'  per: {{type: stub.logged, x: "=a", log: "{log}", label: per, seconds: 0.15, '
        f'hold: "{hold}", after: 3}}\n'
    )
    out = tmp_path / "out"
    code = (
        "import sys; sys.path.insert(0, sys.argv[1]); import sweep_stubs; "
        "from formgraph.cli.main import main; sys.exit(main(sys.argv[2:]))"
    )
    args = [sys.executable, "-c", code, str(ROOT / "tests"), "sweep", str(graph)]
    args += ["--vary", "a=1:12:12", "--measure", "per", "--workers", "1", "--out", str(out)]
    args += ["--cache-dir", str(tmp_path / "cache")]
    # Ctrl-C heard even when the suite itself runs with SIGINT ignored (started with `&`
    # from a script: the shell ignores it for background jobs, and Python keeps that)
    proc = subprocess.Popen(
        args,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        deadline = time.monotonic() + 300  # a bound against a hang
        while time.monotonic() < deadline and proc.poll() is None:  # until three rows are in
            if (out / "sweep.csv").exists() and (out / "sweep.csv").read_text().count("\n") > 3:
                break
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        time.sleep(0.5)
        hold.unlink()  # the waiting variant ends, so the cluster closes without a kill
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 130 and "interrupted" in err and "Traceback" not in err
    with open(out / "sweep.csv", newline="") as fh:
        partial = list(csv.DictReader(fh))
    assert 3 <= len(partial) < 12 and all(r["status"] == "ok" for r in partial)
    done = subprocess.run(args, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert f"({len(partial)} kept from an earlier run)" in done.stdout
    with open(out / "sweep.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [int(r["variant"]) for r in table] == list(range(12))
    assert [float(r["per"]) for r in table] == [float(a) for a in range(1, 13)]
    calls = sweep_stubs.calls(log)
    for r in partial:  # the rows kept were not run again
        assert calls.count(f"per:{float(r['a']):g}") == 1


def test_an_export_that_variants_share_runs_once_and_lands_in_each_folder(client, tmp_path):
    g = fg.Graph()
    g.add_param("a", 1.0)
    g.add("pts", "points.circle", count=5, radius=2)
    g.add("ring", "curves.polyline", points="@pts", closed=True)
    g.add("drawing", "export.svg", curves="@ring", path="ring.svg")
    g.add("v", "stub.value", x="=a")
    s = fg.sweep(g, {"a": "1,2,3"}, ["v"], export=True, client=client, out=tmp_path)
    assert [r["drawing"] for r in s.rows] == [f"variants/{i:04d}/ring.svg" for i in range(3)]
    assert [r["v"] for r in s.rows] == [1.0, 2.0, 3.0]
    assert (s.totals.naive, s.totals.needed) == (3 * 4, 3 + 3)  # pts, ring, drawing once
    files = [(tmp_path / r["drawing"]).read_bytes() for r in s.rows]
    assert files[0].startswith(b"<?xml") and files[0] == files[1] == files[2]


def test_measured_boxes_match_their_closed_forms(client):
    g = fg.Graph()
    g.add_param("w", 1.0, min=0.1, max=10)
    g.add_param("d", 2.0, min=0.1, max=10)
    g.add("box", "mesh.box", size=["=w", "=d", 3.0])
    g.add("m", "mesh.measure", mesh="@box")
    s = fg.sweep(g, {"w": "0.5:2:4", "d": "1,3"}, ["m"], client=client, cache_dir=None)
    assert len(s.rows) == 8
    for r in s.rows:
        w, d = r["w"], r["d"]
        assert r["m.volume"] == pytest.approx(w * d * 3.0, rel=1e-12)
        assert r["m.area"] == pytest.approx(2 * (w * d + 3 * w + 3 * d), rel=1e-12)
        assert r["m.watertight"] is True and r["m.faces"] == 6
    assert "m.size" not in s.columns  # a vector: not a column
