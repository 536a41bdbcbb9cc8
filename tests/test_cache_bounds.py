"""The disk cache is bounded: least recently used entries go first; info, prune and clear
from Python and from ``formgraph cache``; the sweep command's refusals."""

from __future__ import annotations

import os
import textwrap
from pathlib import Path

import pytest

from formgraph.cli.main import main
from formgraph.evaluation.cache import DiskCache, key_of, parse_size


@pytest.fixture
def cli(capsys, monkeypatch):
    """``formgraph ARGS`` in this process: (exit code, stdout, stderr)."""

    def run(*args: str, env: dict[str, str] | None = None) -> tuple[int, str, str]:
        for k, v in (env or {}).items():
            monkeypatch.setenv(k, v)
        code = main(list(args))
        out, err = capsys.readouterr()
        for k in env or {}:
            monkeypatch.delenv(k)
        return code, out, err

    return run


def filled(root: Path, count: int = 5) -> tuple[DiskCache, list[str], int]:
    """``count`` entries of 1,000 floats, last used one second apart, oldest first."""
    cache = DiskCache(root)
    keys = [key_of(["entry", i]) for i in range(count)]
    for i, k in enumerate(keys):
        assert cache.put(k, [float(x) for x in range(1000)])
        path = root / k[:2] / f"{k}.npz"
        os.utime(path, (1_000_000 + i, 1_000_000 + i))
    size = (root / keys[0][:2] / f"{keys[0]}.npz").stat().st_size
    return cache, keys, size


@pytest.mark.parametrize(
    "text, size",
    [("1048576", 1 << 20), ("500M", 500 << 20), ("2GiB", 2 << 30), ("1.5 GB", 1_500_000_000)],
)
def test_sizes_as_people_write_them(text, size):
    assert parse_size(text) == size


@pytest.mark.parametrize("text", ["", "lots", "2 parsecs", "-1G"])
def test_bad_sizes(text):
    with pytest.raises(ValueError, match="is not a size"):
        parse_size(text)


def test_prune_removes_the_least_recently_used_first(tmp_path):
    cache, keys, size = filled(tmp_path)
    assert cache.get(keys[0])[0]  # reading marks the oldest entry used: now the newest
    removed, freed = cache.prune(3 * size)
    assert (removed, freed) == (2, 2 * size)
    left = {p.stem for p in tmp_path.rglob("*.npz")}
    assert left == {keys[0], keys[3], keys[4]}
    info = cache.info()
    assert (info.entries, info.bytes) == (3, 3 * size)


def test_the_cache_prunes_itself_after_writing_a_tenth_of_its_limit(tmp_path):
    _, _, size = filled(tmp_path, 1)
    cache = DiskCache(tmp_path, max_bytes=4 * size)
    for i in range(12):
        cache.put(key_of(["more", i]), [float(x) for x in range(1000)])
    assert cache.info().bytes <= 4 * size + cache.max_bytes // 10 + size


def test_clear_leaves_other_files_alone(tmp_path):
    cache, _, _ = filled(tmp_path)
    (tmp_path / "notes.txt").write_text("mine")
    (tmp_path / "ab").mkdir(exist_ok=True)
    (tmp_path / "ab" / "not-an-entry.npz").write_text("mine too")
    assert cache.clear()[0] == 5
    assert cache.info().entries == 0
    assert (tmp_path / "notes.txt").read_text() == "mine"
    assert (tmp_path / "ab" / "not-an-entry.npz").exists()


def test_cache_command(tmp_path, cli):
    _, _, size = filled(tmp_path)
    code, out, err = cli("cache", "info", "--cache-dir", str(tmp_path))
    assert code == 0, err
    assert f"cache: {tmp_path}" in out and "entries: 5" in out and "of 2.0 GiB" in out
    _, out, _ = cli(
        "cache", "info", "--cache-dir", str(tmp_path), env={"FORMGRAPH_CACHE_MAX_SIZE": "1G"}
    )
    assert "of 1.0 GiB" in out
    code, out, err = cli(
        "cache", "prune", "--max-size", str(2 * size), "--cache-dir", str(tmp_path)
    )
    assert code == 0, err
    assert "removed 3 entries" in out and "2 left" in out
    _, out, _ = cli("cache", "clear", "--cache-dir", str(tmp_path))
    assert "removed 2 entries" in out
    code, _, err = cli("cache", "prune", "--max-size", "lots", "--cache-dir", str(tmp_path))
    assert code == 2 and "--max-size: 'lots' is not a size" in err


def test_sweep_command_refusals(tmp_path, cli):
    graph = tmp_path / "g.yaml"
    graph.write_text(
        textwrap.dedent(
            """
            formgraph: 1
            params:
              n: {default: 4, min: 3, max: 12}
            nodes:
              pts: {type: points.circle, count: "=n"}
            """
        ).lstrip()
    )
    code, _, err = cli("sweep", str(graph), "--vary", "n")
    assert code == 2 and "--vary takes NAME=SPEC" in err
    code, _, err = cli("sweep", str(graph), "--vary", "n=3:4", "n=5")
    assert code == 2 and "--vary n is given twice" in err
    code, _, err = cli("sweep", str(graph), "--vary", "n=1:20", "--out", str(tmp_path / "o"))
    assert code == 1
    assert "g.yaml:3: param 'n': vary n=1:20: goes down to 1, below the param's min 3" in err
    assert "Traceback" not in err and not (tmp_path / "o").exists()
    code, _, err = cli("sweep", str(graph), "--vary", "n=3:5", "--method", "lhs")
    assert code == 2 and "method lhs needs a sample count" in err
    code, _, err = cli("sweep", str(graph), "--vary", "n=3:5", "--measure", "pts")
    assert code == 1 and "measure: 'pts' gives Points, not a number" in err
