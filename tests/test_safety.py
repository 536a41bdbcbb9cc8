"""Exports write atomically and only inside the output directory."""

from __future__ import annotations

import os

import numpy as np
import pytest

import formgraph as fg
from formgraph.core.safety import path_problem, write_atomic


@pytest.mark.parametrize(
    "path", ["/etc/passwd", "../x.stl", "a/../../x.stl", "~/x.stl", "C:\\x.stl", "..\\x.stl", ""]
)
def test_escaping_paths_are_refused_at_load(tmp_path, path):
    assert path_problem(path) is not None
    g = fg.Graph(out_dir=tmp_path)
    g.add("w", "stub.write", text="hi", path=path)
    with pytest.raises(fg.GraphError, match="node 'w', input 'path'"):
        g.check()


def test_symlink_out_of_the_output_directory_is_refused(tmp_path):
    out = tmp_path / "out"
    outside = tmp_path / "elsewhere"
    out.mkdir()
    outside.mkdir()
    (out / "link").symlink_to(outside)
    g = fg.Graph(out_dir=out)
    g.add("w", "stub.write", text="hi", path="link/x.txt")
    with pytest.raises(fg.PathError, match="leads outside the output directory"):
        g.evaluate("w")
    assert not (outside / "x.txt").exists()
    (out / "file.txt").symlink_to(outside / "target.txt")
    g.add("v", "stub.write", text="hi", path="file.txt")
    with pytest.raises(fg.PathError, match="outside"):
        g.evaluate("v")
    assert not (outside / "target.txt").exists()


def test_write_creates_folders_and_returns_the_path(tmp_path):
    g = fg.Graph(out_dir=tmp_path / "out")
    g.add("w", "stub.write", text="hello", path="deep/er/file.txt")
    path = g.evaluate("w")
    assert path == str(tmp_path / "out" / "deep" / "er" / "file.txt")
    assert open(path).read() == "hello"


def test_identical_bytes_leave_the_file_untouched(tmp_path):
    target = write_atomic(tmp_path, "a.txt", b"same")
    os.utime(target, (1_000_000, 1_000_000))
    write_atomic(tmp_path, "a.txt", b"same")
    assert target.stat().st_mtime == 1_000_000
    write_atomic(tmp_path, "a.txt", b"different")
    assert target.read_bytes() == b"different"
    assert target.stat().st_mtime != 1_000_000


def test_big_buffers_are_compared_and_written_without_copies(tmp_path):
    # Several read chunks (1 MiB), a read-only view as the STL writer hands out, and a
    # difference in the very last byte only.
    data = np.arange(3 * 2**20 + 5, dtype=np.uint32).view(np.uint8)
    data.flags.writeable = False
    target = write_atomic(tmp_path, "big.bin", memoryview(data))
    assert target.read_bytes() == data.tobytes()
    os.utime(target, (1_000_000, 1_000_000))
    write_atomic(tmp_path, "big.bin", memoryview(data))
    assert target.stat().st_mtime == 1_000_000
    changed = data.copy()
    changed[-1] ^= 1
    write_atomic(tmp_path, "big.bin", changed.tobytes())
    assert target.read_bytes() == changed.tobytes()
    assert target.stat().st_mtime != 1_000_000


def test_failed_write_keeps_the_old_file(tmp_path, monkeypatch):
    target = write_atomic(tmp_path, "a.txt", b"old")

    def broken_replace(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        write_atomic(tmp_path, "a.txt", b"new")
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]  # no temp file left


def test_deleted_export_is_written_again(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("w", "stub.write", text="hello", path="f.txt")
    path = g.evaluate("w")
    os.unlink(path)
    g.evaluate("w")
    assert os.path.exists(path)
    assert g.stats["w"].status == "computed"


def test_write_atomic_takes_pieces_and_keeps_an_identical_file(tmp_path):
    pieces = [b"solid x\n", memoryview(b"facet " * 1000), b"endsolid x\n"]
    target = write_atomic(tmp_path, "a/b.stl", iter(pieces))
    assert target.read_bytes() == b"".join(bytes(p) for p in pieces)
    os.utime(target, (1, 1))
    write_atomic(tmp_path, "a/b.stl", (p for p in pieces))  # the same bytes: untouched
    assert target.stat().st_mtime == 1
    write_atomic(tmp_path, "a/b.stl", (p for p in pieces[:2]))  # different: replaced
    assert target.read_bytes() == b"".join(bytes(p) for p in pieces[:2])
    assert sorted(p.name for p in target.parent.iterdir()) == ["b.stl"]


def test_a_failing_piece_leaves_the_old_file_and_no_temp(tmp_path):
    write_atomic(tmp_path, "c.txt", b"old")

    def pieces():
        yield b"new"
        raise RuntimeError("the exporter failed mid-way")

    with pytest.raises(RuntimeError, match="mid-way"):
        write_atomic(tmp_path, "c.txt", pieces())
    assert (tmp_path / "c.txt").read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.txt"]
