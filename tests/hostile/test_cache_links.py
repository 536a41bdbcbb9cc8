"""The disk cache never follows a link inside its folder, and trusts an entry only when it
has the type of the node that reads it."""

from __future__ import annotations

import os
import warnings

import numpy as np

import formgraph as fg
from formgraph.cli import main as cli
from formgraph.evaluation import cache as _cache

GRAPH = "formgraph: 1\nnodes:\n  b: {type: mesh.box}\n  m: {type: mesh.measure, mesh: '@b'}\n"


def _every_shard_linked(cache: os.PathLike, elsewhere: os.PathLike) -> None:
    for i in range(256):
        os.symlink(elsewhere, os.path.join(cache, f"{i:02x}"))


def test_clear_and_run_never_touch_what_a_shard_link_points_to(tmp_path, monkeypatch, capsys):
    cache, elsewhere = tmp_path / "cache", tmp_path / "precious"
    cache.mkdir()
    elsewhere.mkdir()
    # files named like entries of every shard, in the folder the links point to
    bait = [elsewhere / f"{i:02x}{'0' * 38}.npz" for i in range(256)]
    for b in bait:
        b.write_bytes(b"keep me")
    _every_shard_linked(cache, elsewhere)
    (tmp_path / "g.yaml").write_text(GRAPH)
    run = ["run", str(tmp_path / "g.yaml"), "--cache-dir", str(cache), "--out", str(tmp_path)]
    assert cli.main(run) == 0
    assert sorted(elsewhere.iterdir()) == sorted(bait)  # nothing written there
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.delenv("FORMGRAPH_CACHE_DIR", raising=False)
    os.rename(cache, tmp_path / "formgraph")
    assert _cache.default_cache_dir() == tmp_path / "formgraph"
    assert cli.main(["cache", "clear"]) == 0
    assert all(b.read_bytes() == b"keep me" for b in bait)


def test_an_entry_that_is_a_link_is_not_read_or_deleted(tmp_path):
    cache = tmp_path / "cache"
    g = fg.Graph.from_text(GRAPH, file=str(tmp_path / "g.yaml"))
    g.disk = _cache.DiskCache(cache)
    g.evaluate("m")
    entries = _cache._entry_paths(cache)
    assert entries
    target = tmp_path / "target.npz"
    for e in entries:
        target.write_bytes(e.read_bytes())
        e.unlink()
        os.symlink(target, e)
    d = _cache.DiskCache(cache)
    assert d.info().entries == 0
    d.clear()
    assert target.is_file() and all(e.is_symlink() for e in entries)


def test_a_well_formed_entry_of_the_wrong_type_is_a_miss(tmp_path):
    cache = tmp_path / "cache"
    g = fg.Graph.from_text(GRAPH, file=str(tmp_path / "g.yaml"))
    g.disk = _cache.DiskCache(cache)
    expected = g.evaluate("m")
    key = g.plan("m")[-1].key
    points = fg.Points(np.zeros((4, 3)))
    for value in (points, [points] * 6, 3.5):
        assert _cache.DiskCache(cache).put(key, value)  # forged: well formed, wrong type
        fresh = fg.Graph.from_text(GRAPH, file=str(tmp_path / "g.yaml"))
        fresh.disk = _cache.DiskCache(cache)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            got = fresh.evaluate("m")
        assert got == expected and fresh.stats["m"].status == "computed"
