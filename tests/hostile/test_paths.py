"""Hostile output paths and writes: lost exports, symlink loops, absurd paths, stale temps."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import formgraph as fg
from formgraph.cli import main as cli
from formgraph.core import safety

BOX = """\
formgraph: 1
nodes:
  box: {type: mesh.box}
  stl:
    type: export.stl
    mesh: "@box"
    path: PATH
"""


def _graph(tmp_path: Path, path: str = "box.stl") -> Path:
    g = tmp_path / "box.yaml"
    g.write_text(BOX.replace("PATH", path))
    return g


def _run(tmp_path: Path, capsys, *extra: str) -> tuple[int, str, str]:
    code = cli.main(
        [
            "run",
            str(tmp_path / "box.yaml"),
            "--out",
            str(tmp_path / "out"),
            "--cache-dir",
            str(tmp_path / "cache"),
            *extra,
        ]
    )
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_deleted_export_is_rewritten_with_a_warm_disk_cache(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _graph(tmp_path)
    target = tmp_path / "out" / "box.stl"
    assert _run(tmp_path, capsys)[0] == 0
    assert target.is_file()
    target.unlink()
    code, out, _ = _run(tmp_path, capsys)  # a new graph, as a new process: only the disk is warm
    assert code == 0
    assert target.is_file(), "the export said nothing or 'wrote' but left no file"
    assert "wrote out/box.stl" in out


def test_an_export_that_differs_is_rewritten(tmp_path):
    _graph(tmp_path)
    kwargs = {"out_dir": tmp_path / "out", "cache_dir": tmp_path / "cache"}
    fg.load(tmp_path / "box.yaml", **kwargs).evaluate_all()
    target = tmp_path / "out" / "box.stl"
    good = target.read_bytes()
    target.write_bytes(b"someone else's bytes")
    fg.load(tmp_path / "box.yaml", **kwargs).evaluate_all()
    assert target.read_bytes() == good


def test_an_export_edited_under_a_live_graph_is_rewritten(tmp_path):
    _graph(tmp_path)
    g = fg.load(tmp_path / "box.yaml", out_dir=tmp_path / "out")
    g.evaluate_all()
    target = tmp_path / "out" / "box.stl"
    good = target.read_bytes()
    target.write_bytes(b"x" * len(good))  # same size
    os.utime(target, ns=(1, 1))
    g.evaluate_all()
    assert target.read_bytes() == good
    assert g.stats["stl"].status == "computed"


def test_wrote_is_said_only_of_a_file_that_exists(tmp_path):
    missing = str(tmp_path / "gone.stl")
    assert not cli._describe(missing).startswith("wrote")
    (tmp_path / "here.stl").write_bytes(b"x")
    assert cli._describe(str(tmp_path / "here.stl")).startswith("wrote")


def test_an_output_path_through_a_symlink_loop_is_a_located_error(tmp_path):
    (tmp_path / "out").mkdir()
    os.symlink("loop", tmp_path / "out" / "loop")
    _graph(tmp_path, "loop/box.stl")
    g = fg.load(tmp_path / "box.yaml", out_dir=tmp_path / "out")
    with pytest.raises(fg.PathError, match=r"box.yaml:\d+: node 'stl'.*cannot be followed"):
        g.evaluate_all()


@pytest.mark.parametrize(
    ("path", "why"),
    [
        ("a/" * 2000 + "box.stl", "characters long"),
        ("a/" * 40 + "box.stl", "folders deep"),
        ("n" * 250 + ".stl", "longer than 200 characters"),
    ],
)
def test_absurd_output_paths_are_refused_at_check(tmp_path, path, why):
    _graph(tmp_path, path)
    with pytest.raises(fg.GraphError, match=rf"box.yaml:7: node 'stl', input 'path': .*{why}"):
        fg.load(tmp_path / "box.yaml", out_dir=tmp_path / "out")
    with pytest.raises(fg.PathError, match=why):
        safety.write_atomic(tmp_path / "out", path, b"x")


def test_a_temp_file_left_by_a_killed_write_is_removed_by_the_next(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    killed = (
        "import os, sys\n"
        "from formgraph.core import safety\n"
        "os.replace = lambda *a: os._exit(9)  # killed between writing and renaming\n"
        "safety.write_atomic(sys.argv[1], 'box.stl', b'x' * 100000)\n"
    )
    r = subprocess.run([sys.executable, "-c", killed, str(out)], timeout=60)
    assert r.returncode == 9
    left = [p.name for p in out.iterdir()]
    assert len(left) == 1 and left[0].startswith(".box.stl.") and left[0].endswith(".tmp")
    safety.write_atomic(out, "other.stl", b"y")
    assert sorted(p.name for p in out.iterdir()) == ["other.stl"]


def test_a_temp_file_of_a_running_writer_is_kept(tmp_path):
    live = tmp_path / f".box.stl.fgtmp-{os.getppid()}-abc.tmp"
    live.write_bytes(b"half")
    foreign = tmp_path / ".notes.tmp"  # not of our naming
    foreign.write_bytes(b"x")
    assert safety.remove_stale_temps(tmp_path) == []
    assert live.exists() and foreign.exists()
    old = 1_000_000_000
    os.utime(live, (old, old))  # a day old: stale whoever wrote it
    assert safety.remove_stale_temps(tmp_path) == [live]
    assert foreign.exists()


def test_an_output_directory_that_is_a_file_is_a_located_error(tmp_path):
    (tmp_path / "afile").write_text("x")
    _graph(tmp_path)
    g = fg.load(tmp_path / "box.yaml", out_dir=tmp_path / "afile")
    assert g.evaluate("box").n_faces == 6  # nothing to write: no complaint
    with pytest.raises(fg.PathError, match=r"box.yaml:\d+: node 'stl': .* is not a folder"):
        g.evaluate_all()


def test_an_output_directory_in_a_symlink_loop_is_a_located_error(tmp_path):
    os.symlink("loop", tmp_path / "loop")
    _graph(tmp_path)
    g = fg.load(tmp_path / "box.yaml", out_dir=tmp_path / "loop")
    with pytest.raises(fg.PathError, match=r"node 'stl': .*cannot be followed"):
        g.evaluate_all()


def test_an_output_path_through_a_file_is_a_located_error(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "afile").write_text("x")
    _graph(tmp_path, "afile/box.stl")
    g = fg.load(tmp_path / "box.yaml", out_dir=tmp_path / "out")
    with pytest.raises(fg.PathError, match=r"node 'stl', input 'path': .*runs through a file"):
        g.evaluate_all()


@pytest.mark.parametrize(
    ("path", "why"),
    [
        ("sub/", r"output path 'sub/' names a folder, not a file"),
        ("sub/.", r"output path 'sub/\.' names a folder, not a file"),
        ("sub\\", r"output path .sub.* names a folder, not a file"),
        (".x.fgtmp-123-y.tmp", r"output path .* is named like formgraph's temporary files"),
        (
            "parts/.box.stl.fgtmp-99999999-abc.tmp",
            r"output path .* is named like formgraph's temporary files",
        ),
    ],
)
def test_a_folder_or_a_temp_file_name_is_refused_as_an_output_path(tmp_path, path, why):
    _graph(tmp_path, json.dumps(path))
    with pytest.raises(fg.GraphError, match=rf"box.yaml:7: node 'stl', input 'path': {why}"):
        fg.load(tmp_path / "box.yaml", out_dir=tmp_path / "out")
    with pytest.raises(fg.PathError, match=why):
        safety.write_atomic(tmp_path / "out", path, b"x")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*"))


PARAM_PATH = """\
formgraph: 1
params:
  name: {default: box.stl}
nodes:
  box: {type: mesh.box}
  stl:
    type: export.stl
    mesh: "@box"
    path: "=name"
"""


@pytest.mark.parametrize("name", ["sub/", ".box.stl.fgtmp-1-x.tmp"])
def test_a_computed_path_is_refused_located_on_its_input(tmp_path, name):
    (tmp_path / "box.yaml").write_text(PARAM_PATH)
    g = fg.load(tmp_path / "box.yaml", out_dir=tmp_path / "out")
    with pytest.raises(fg.PathError, match=r"box.yaml:9: node 'stl', input 'path': output path"):
        g.evaluate_all(name=name)
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*"))
    assert g.evaluate_all(name="box.stl")  # a file's name is still fine


def test_a_file_named_like_a_temp_file_is_not_written_to_be_deleted(tmp_path):
    # today's failure: the export is written, then the next write into its folder takes it
    # for a dead writer's temp file (pid 1 is never ours... but a gone pid is) and deletes it
    out = tmp_path / "out"
    with pytest.raises(fg.PathError):
        safety.write_atomic(out, ".a.stl.fgtmp-999999999-x.tmp", b"solid")
    safety.write_atomic(out, "b.stl", b"solid")
    assert sorted(p.name for p in out.iterdir()) == ["b.stl"]
