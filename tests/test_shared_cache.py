"""One disk cache folder shared by many processes at once (a folder on a shared filesystem
that every Dask worker and colleague mounts): entries renamed into place whole, no lock a
dead process could leave held, and a reader that never trusts a partial entry. A second
study over the same folder computes nothing the first one did.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest
from distributed import Client, LocalCluster

import formgraph as fg
from formgraph.evaluation.cache import DiskCache

HAMMER = textwrap.dedent(
    """
    import sys, numpy as np
    from formgraph.evaluation.cache import DiskCache
    root, who, rounds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    cache = DiskCache(root, max_bytes=1 << 20)
    rng = np.random.default_rng(who)
    wrong = hits = 0
    for i in range(rounds):
        k = int(rng.integers(0, 24))
        key = f"{k:02x}" * 20
        expected = np.arange(2000 + 500 * k, dtype=np.float64) * k
        if who == 0 and i % 25 == 0:
            cache.prune(60_000)  # one process keeps evicting under the others' feet
        if rng.random() < 0.5:
            cache.put(key, expected)
        else:
            hit, value = cache.get(key)
            hits += hit
            wrong += hit and not (value.shape == expected.shape and (value == expected).all())
    print(hits, wrong)
    """
)


def test_processes_writing_reading_and_pruning_one_folder_never_see_a_bad_entry(tmp_path):
    root = tmp_path / "shared"
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", HAMMER, str(root), str(who), "250"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for who in range(3)
    ]
    results = [p.communicate(timeout=120) for p in procs]
    assert all(p.returncode == 0 for p in procs), [err for _, err in results]
    counts = [tuple(map(int, out.split())) for out, _ in results]
    assert sum(h for h, _ in counts) > 50  # they did read each other's entries
    assert all(w == 0 for _, w in counts)
    cache = DiskCache(root)
    leftovers = [p for p in root.rglob("*") if p.is_file() and p.suffix != ".npz"]
    assert leftovers == []  # every temp file was renamed into place or removed
    for path, _, _ in cache.entries():  # and every entry left is whole
        key = path.stem
        k = int(key[:2], 16)
        hit, value = cache.get(key)
        assert hit and value.shape == (2000 + 500 * k,)


def test_a_half_written_entry_in_the_folder_is_a_miss(tmp_path):
    cache = DiskCache(tmp_path)
    key = "ab" * 20
    cache.put(key, list(range(10)))
    path = tmp_path / "ab" / f"{key}.npz"
    path.write_bytes(path.read_bytes()[:-30])  # a writer on another machine cut short
    assert cache.get(key) == (False, None)


def test_releases_of_two_entry_formats_sharing_a_folder_keep_each_others_entries(
    tmp_path, monkeypatch
):
    # a colleague on a release with a newer entry format shares the team's cache: each
    # release reads its own entries and leaves the other's (they were deleted as foreign)
    from formgraph.evaluation import cache as _cache

    key = "cd" * 20
    cache = DiskCache(tmp_path)
    assert cache.put(key, [1.0, 2.0])
    monkeypatch.setattr(_cache, "FORMAT", _cache.FORMAT + 1)
    assert cache.get(key) == (False, None)  # not its format: a miss ...
    assert cache.put(key, [3.0])
    assert cache.get(key) == (True, [3.0])
    monkeypatch.undo()
    assert cache.get(key) == (True, [1.0, 2.0])  # ... that deleted nothing
    names = sorted(p.name for p, _, _ in cache.entries())
    assert names == [f"{key}.f{_cache.FORMAT + 1}.npz", f"{key}.npz"]  # both bounded, pruned
    assert cache.clear()[0] == 2


CAN = """\
formgraph: 1
params:
  r: {default: 5.0, min: 0.5, max: 20}
  h: {default: 10.0, min: 0.5, max: 40}
nodes:
  can: {type: mesh.cylinder, radius: "=r", height: "=h", segments: 64}
  size: {type: mesh.measure, mesh: "@can"}
"""


def test_a_second_study_over_the_shared_folder_computes_nothing_again(tmp_path):
    pytest.importorskip("optuna")
    (tmp_path / "can.yaml").write_text(CAN)
    shared = tmp_path / "shared-cache"
    kw = dict(
        vary={"r": "1:15", "h": "1:30"},
        minimize=["size.area"],
        budget=16,
        batch=8,
        cache_dir=shared,
        shared_cache=True,
    )
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
        first = fg.optimize(tmp_path / "can.yaml", client=cl, **kw)
        second = fg.optimize(tmp_path / "can.yaml", client=cl, **kw)  # a colleague's rerun
    assert first.totals.computed == 2 * 16 and first.totals.cached == 0
    assert second.totals.computed == 0 and second.totals.cached == 16  # the measured nodes
    assert [r["size.area"] for r in second.trials] == [r["size.area"] for r in first.trials]
    assert "0 computed, 16 from the disk cache" in second.summary()
