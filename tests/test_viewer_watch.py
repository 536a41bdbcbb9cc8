"""Watch mode: a window that follows the file through broken edits, and the headless
watch that writes a PNG and a status line per good save."""

from __future__ import annotations

import re

import pytest

pv = pytest.importorskip("pyvista")
pv.OFF_SCREEN = True

from test_viewer import RING, SIZE, assert_not_blank, write  # noqa: E402

from formgraph import viewer  # noqa: E402


@pytest.fixture
def plotter():
    p = pv.Plotter(off_screen=True, window_size=list(SIZE))
    yield p
    p.close()


def test_watch_reloads_after_an_edit_and_survives_a_broken_one(tmp_path, plotter, capsys):
    f = tmp_path / "ring.yaml"
    write(f, RING.format(count=5))
    w = viewer.Watcher(f, plotter=plotter, out_dir=tmp_path / "out")
    assert w.reload() is True
    assert w.poll() is None  # nothing changed
    outline = w.scene.layers["outline"].parts["curves"]
    assert outline.data.n_points == 6

    write(f, RING.format(count=8))
    assert w.poll() is True
    assert outline.data.n_points == 9 and w.scene.layers["outline"].parts["curves"] is outline
    # the new version of the file shares the cache: the untouched grid is not recomputed
    assert w.session.graph.stats["grid"].status == "cached"
    assert w.session.graph.stats["ring"].status == "computed"

    write(f, RING.format(count=8).replace("points.circle", "points.circel"))
    assert w.poll() is False
    assert "unknown node type 'points.circel'" in w.error_text()
    assert "points.circel" in w.scene.texts()["error"]
    assert "unknown node type" in capsys.readouterr().err
    assert outline.data.n_points == 9  # the last good geometry stays

    write(f, "formgraph: 1\nnodes: [unclosed\n")
    assert w.poll() is False and w.error_text()

    write(f, RING.format(count=4))
    assert w.poll() is True
    assert w.error_text() is None and "error" not in w.scene.texts()
    assert outline.data.n_points == 5


def test_watch_starts_on_a_broken_file_and_recovers(tmp_path, plotter):
    f = tmp_path / "ring.yaml"
    write(f, RING.format(count=2))  # the default is below the param's min
    w = viewer.Watcher(f, plotter=plotter)
    assert w.reload() is False and w.session is None
    assert "param 'count': default must be >= 3, got 2" in w.error_text()
    write(f, RING.format(count=6))
    assert w.poll() is True and w.error_text() is None
    assert "error" not in w.scene.texts()
    assert w.scene.layers["outline"].parts["curves"].data.n_points == 7


def test_watch_applies_sets_to_each_version(tmp_path, plotter):
    f = tmp_path / "ring.yaml"
    write(f, RING.format(count=5))
    w = viewer.Watcher(f, "ring", plotter=plotter, sets=["count=9"])
    assert w.reload() and len(w.session.evaluate()[0][1]) == 9
    write(
        f, RING.format(count=5).replace("  count: {", "  corners: {").replace("=count", "=corners")
    )
    assert w.poll() is False
    assert "--set count: unknown param; params are corners" in w.error_text()


def test_watch_survives_the_file_disappearing(tmp_path, plotter):
    f = tmp_path / "ring.yaml"
    write(f, RING.format(count=5))
    w = viewer.Watcher(f, plotter=plotter)
    assert w.reload()
    f.unlink()
    assert w.poll() is None  # mid-save: look again later
    assert w.reload() is False and "cannot read" in w.error_text()


# --------------------------------------------------------------------- headless watch

STATUS = re.compile(r"^ring\.yaml: evaluated in [\d.]+ ms \((\d+) computed, (\d+) cached\), wrote ")


def test_headless_watch_writes_a_png_per_change_and_keeps_the_last_good_one(tmp_path):
    import io

    f, png = tmp_path / "ring.yaml", tmp_path / "shots" / "ring.png"
    write(f, RING.format(count=5))
    out, err = io.StringIO(), io.StringIO()
    w = viewer.ScreenshotWatcher(f, png, "outline", size=SIZE, out=out, err=err)
    assert w.reload() is True and png.is_file()
    assert_not_blank(png)
    first = png.read_bytes()
    assert w.poll() is None  # nothing changed: nothing written
    write(f, RING.format(count=12))
    assert w.poll() is True
    second = png.read_bytes()
    assert second != first
    lines = out.getvalue().splitlines()
    assert len(lines) == 2 and all(STATUS.match(line) for line in lines)
    assert STATUS.match(lines[1]).groups() == ("2", "0")  # ring and outline recomputed

    write(f, RING.format(count=12).replace("points.circle", "points.circel"))
    assert w.poll() is False
    assert png.read_bytes() == second, "a broken edit must keep the last good picture"
    assert "unknown node type 'points.circel'" in err.getvalue()
    assert f"(kept {png}, the last version that worked)" in err.getvalue()
    assert len(out.getvalue().splitlines()) == 2
    assert not list(png.parent.glob(".*tmp*")), "no temporary file left behind"

    write(f, RING.format(count=12).replace("radius: 2", "radius: 3"))
    assert w.poll() is True and png.read_bytes() != second
    # the new version shares the cache: only what the edit reaches recomputes
    assert STATUS.match(out.getvalue().splitlines()[-1]).groups() == ("2", "0")


def test_headless_watch_starting_on_a_broken_file_writes_nothing(tmp_path):
    import io

    f, png = tmp_path / "ring.yaml", tmp_path / "ring.png"
    write(f, "formgraph: 1\nnodes: [unclosed\n")
    err = io.StringIO()
    w = viewer.ScreenshotWatcher(f, png, out=io.StringIO(), err=err)
    assert w.reload() is False and not png.exists()
    assert f"({png} not written)" in err.getvalue()


def test_watch_without_a_display_or_screenshot_says_what_to_do(tmp_path, capsys, monkeypatch):
    from formgraph.cli.main import main

    f = tmp_path / "ring.yaml"
    write(f, RING.format(count=5))
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["watch", str(f)]) == 2
    err = capsys.readouterr().err
    assert "there is no display" in err and "--screenshot FILE.png" in err
    assert main(["view", str(f)]) == 2
    assert "xvfb-run formgraph view" in capsys.readouterr().err
    monkeypatch.setenv("DISPLAY", ":4711")  # no X server there
    assert "no X server listens" in viewer.display_problem()


def test_cli_watch_screenshot_runs_until_stopped(tmp_path):
    import subprocess
    import sys
    import time

    f, png = tmp_path / "ring.yaml", tmp_path / "ring.png"
    write(f, RING.format(count=5))
    cmd = [sys.executable, "-m", "formgraph.cli.main", "watch", str(f), "outline"]
    cmd += ["--screenshot", str(png), "--size", "320x240", "--interval", "0.05"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert STATUS.match(proc.stdout.readline()), proc.stderr.read() if proc.poll() else ""
        stamp = png.stat().st_mtime_ns
        time.sleep(0.05)
        write(f, RING.format(count=9))
        assert STATUS.match(proc.stdout.readline())
        assert png.stat().st_mtime_ns != stamp
        assert proc.poll() is None  # still watching
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def test_headless_watch_follows_the_subgraph_files_too(tmp_path):
    import io
    import shutil
    from pathlib import Path

    graphs = Path(__file__).resolve().parents[1] / "graphs"
    shutil.copy(graphs / "lamp.yaml", tmp_path / "lamp.yaml")
    (tmp_path / "parts").mkdir()
    part = tmp_path / "parts" / "ring.yaml"
    shutil.copy(graphs / "parts" / "ring.yaml", part)
    png, out, err = tmp_path / "lamp.png", io.StringIO(), io.StringIO()
    w = viewer.ScreenshotWatcher(
        tmp_path / "lamp.yaml", png, "upper", size=SIZE, out=out, err=err, out_dir=tmp_path / "o"
    )
    assert w.reload() is True and part in w.files
    first = png.read_bytes()
    assert w.poll() is None
    text = part.read_text()
    write(part, text.replace("u: 12", "u: 4"))  # a coarser tube in the part file
    assert w.poll() is True and png.read_bytes() != first
    write(part, text.replace('radius: "=radius"', 'radius: "=radiu"'))
    assert w.poll() is False and "radiu" in err.getvalue()
    write(part, text)  # the broken part is still watched: fixing it writes again
    assert w.poll() is True
    assert len(out.getvalue().splitlines()) == 3


def test_display_problem_names_what_is_missing(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setenv("WAYLAND_DISPLAY", "wayland-0")
    assert "Wayland display but no X display" in viewer.display_problem()
    monkeypatch.delenv("WAYLAND_DISPLAY")
    assert viewer.display_problem() == "there is no display (DISPLAY is not set)"
    monkeypatch.setenv("DISPLAY", "remote.example:0")  # a remote display: trusted
    assert viewer.display_problem() is None
