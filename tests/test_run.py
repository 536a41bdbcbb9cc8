"""Keys kept per graph version (engine/evaluation/run.py, ``_Run.replay``): a fully cached
re-evaluation reuses the last run's order and keys, and every change forgets them."""

from __future__ import annotations

import pytest
from stubs import CALLS

import formgraph as fg
from formgraph.evaluation import cache


def chain(n: int = 30) -> fg.Graph:
    g = fg.Graph()
    g.add_param("k", 1.0)
    g.add("n0", "stub.value", x="=k", label="0")
    for i in range(1, n):
        g.add(f"n{i}", "stub.add", a=f"@n{i - 1}", b=1.0, label=str(i))
    return g


@pytest.fixture
def counted(monkeypatch):
    """How many cache keys are built (each one is a key text and a hash)."""
    calls = []
    real = cache.key_of

    def key_of(parts):
        calls.append(1)
        return real(parts)

    monkeypatch.setattr(cache, "key_of", key_of)
    return calls


def test_a_cached_reevaluation_builds_no_key(counted):
    g = chain()
    assert g.evaluate("n29") == 30.0
    assert len(counted) == 30
    keys = {n: s.source for n, s in g.stats.items()}
    counted.clear()
    for _ in range(3):
        assert g.evaluate("n29") == 30.0
    assert counted == []
    assert all(s.status == "cached" for s in g.stats.values())
    assert set(g.stats) == set(keys)


def test_a_param_change_rebuilds_the_keys_and_the_values(counted):
    g = chain()
    g.evaluate("n29")
    CALLS.clear()
    assert g.evaluate("n29", k=2.0) == 31.0
    assert "add:29" in CALLS
    assert g.evaluate("n29") == 30.0  # back: cached values, keys rebuilt for these params
    counted.clear()
    assert g.evaluate("n29") == 30.0
    assert counted == []
    g.set(k=-0.0)  # -0.0 is not 0.0 to the keys (their text holds the float's bits)
    assert g.evaluate("n29") == 29.0


def test_every_change_to_the_graph_forgets_the_kept_keys():
    g = chain(5)
    assert g.evaluate("n4") == 5.0
    g.set_input("n2", "b", 10.0)
    assert g.evaluate("n4") == 14.0
    g.add("n5", "stub.add", a="@n4", b=2.0, label="5")
    assert g.evaluate("n5") == 16.0
    g.remove("n5")
    g.add("n5", "stub.add", a="@n4", b=3.0, label="5")
    assert g.evaluate("n5") == 17.0
    assert g.evaluate(["n4", "n5"]) == {"n4": 14.0, "n5": 17.0}


def test_a_value_dropped_from_the_cache_is_computed_again():
    g = chain(5)
    g.evaluate("n4")
    g.memory.clear()
    g._identity.clear()  # as the bounded identity table does past a million keys
    CALLS.clear()
    assert g.evaluate("n4") == 5.0
    assert "add:4" in CALLS


def test_an_export_is_checked_on_every_run(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("w", "stub.write", text="hello", path="a.txt")
    g.evaluate("w")
    g.evaluate("w")
    (tmp_path / "a.txt").unlink()
    g.evaluate("w")  # the file is gone: written again, kept keys or not
    assert (tmp_path / "a.txt").read_text() == "hello"
    g.out_dir = tmp_path / "other"  # another output folder: another key
    g.evaluate("w")
    assert (tmp_path / "other" / "a.txt").read_text() == "hello"


def test_a_changed_input_file_is_read_again(tmp_path):
    # A read node's key holds its file's bytes: such runs never reuse kept keys.
    (tmp_path / "p.xyz").write_bytes(b"1 2 3\n")
    (tmp_path / "g.yaml").write_text(
        "formgraph: 1\nnodes:\n  p: {type: read.points, path: p.xyz}\n"
    )
    g = fg.load(tmp_path / "g.yaml")
    assert g.evaluate("p").xyz.tolist() == [[1, 2, 3]]
    assert g.evaluate("p").xyz.tolist() == [[1, 2, 3]]
    (tmp_path / "p.xyz").write_bytes(b"4 5 6\n")
    assert g.evaluate("p").xyz.tolist() == [[4, 5, 6]]
