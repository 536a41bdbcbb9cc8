"""Files that are not regular files (a FIFO would block open() forever) and graph files nested
past any design: each ends as one located sentence, never a hang or a RecursionError."""

from __future__ import annotations

import contextlib
import io
import os
import signal
from pathlib import Path

import pytest

import formgraph as fg
from formgraph import viewer
from formgraph.cli import main as cli
from formgraph.core import safety


@contextlib.contextmanager
def _within(seconds: int):
    """Fail (instead of hanging the suite) when the body blocks: a block is forever, so the
    bound is far above what a busy machine can delay a few reads by."""

    def expire(*_):
        raise TimeoutError(f"blocked for {seconds} s")

    old = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def test_read_regular_refuses_a_fifo_a_folder_and_a_big_file(tmp_path):
    os.mkfifo(tmp_path / "pipe")
    (tmp_path / "big").write_bytes(b"x" * 101)
    with _within(60):
        with pytest.raises(OSError, match=r"FIFO \(named pipe\), not a regular file"):
            safety.read_regular(tmp_path / "pipe", max_bytes=100)
        with pytest.raises(OSError, match="a folder, not a regular file"):
            safety.read_regular(tmp_path, max_bytes=100)
        with pytest.raises(OSError, match="larger than 100 bytes"):
            safety.read_regular(tmp_path / "big", max_bytes=100)
    assert safety.read_regular(tmp_path / "big", max_bytes=101) == b"x" * 101


@pytest.mark.parametrize("command", ["check", "run", "graph", "nodes"])
def test_a_fifo_as_the_graph_is_a_sentence(tmp_path, capsys, command):
    os.mkfifo(tmp_path / "fifo.yaml")
    with _within(60):
        code = cli.main([command, str(tmp_path / "fifo.yaml")])
    err = capsys.readouterr().err
    assert code in (1, 2) and "FIFO (named pipe), not a regular file" in err, err
    assert "internal error" not in err


def test_a_fifo_as_a_subgraph_is_a_located_sentence(tmp_path, capsys):
    (tmp_path / "parts").mkdir()
    os.mkfifo(tmp_path / "parts" / "fifo.yaml")
    (tmp_path / "top.yaml").write_text("formgraph: 1\nnodes:\n  n: {type: parts/fifo.yaml}\n")
    with _within(60):
        code = cli.main(["check", str(tmp_path / "top.yaml")])
    err = capsys.readouterr().err
    assert code == 1
    assert (
        "top.yaml:3: node 'n': cannot read the subgraph file 'parts/fifo.yaml': it is a FIFO" in err
    )


def test_a_watched_fifo_is_reported_and_the_watch_goes_on(tmp_path):
    os.mkfifo(tmp_path / "w.yaml")
    err = io.StringIO()
    w = viewer.ScreenshotWatcher(
        tmp_path / "w.yaml", tmp_path / "w.png", out=io.StringIO(), err=err
    )
    with _within(60):
        assert w.reload() is False
    assert "FIFO (named pipe), not a regular file" in err.getvalue()
    assert not (tmp_path / "w.png").exists()


def _nest(folder: Path, depth: int) -> Path:
    (folder / "top.yaml").write_text("formgraph: 1\nnodes:\n  n: {type: p1.yaml}\n")
    for i in range(1, depth + 1):
        inner = f"{{type: p{i + 1}.yaml}}" if i < depth else "{type: points.circle, count: 3}"
        (folder / f"p{i}.yaml").write_text(
            f"formgraph: 1\nnodes:\n  n: {inner}\noutputs: {{out: '@n'}}\n"
        )
    return folder / "top.yaml"


@pytest.mark.parametrize("depth", [250, 1000])
def test_parts_nested_too_deep_are_one_clear_line(tmp_path, capsys, depth):
    top = _nest(tmp_path, depth)
    assert cli.main(["check", str(top)]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and len(err) < 400, err[:500]
    assert (
        "p50.yaml:3: node 'n': subgraph 'p51.yaml' would nest graph files more than 50 deep" in err
    )
    assert "Recursion" not in err and "(in the subgraph" not in err


def test_parts_nested_to_the_limit_still_run(tmp_path):
    g = fg.load(_nest(tmp_path, 50))
    assert len(g.evaluate("n")) == 3
