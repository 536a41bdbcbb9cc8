"""The on-disk cache: survives processes, shrugs off corruption, tolerates concurrent writers."""

from __future__ import annotations

import enum
import json
import multiprocessing as mp
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from stubs import CALLS

import formgraph as fg
from formgraph.evaluation.cache import (
    DiskCache,
    MemoryCache,
    canonical,
    digest,
    key_of,
    key_text,
)


def graph(cache_dir: Path) -> fg.Graph:
    g = fg.Graph(cache_dir=cache_dir)
    g.add_param("n", 50)
    g.add("p", "stub.points", n="=n", scale=0.5)
    return g


def test_survives_a_new_graph_object(tmp_path):
    first = graph(tmp_path)
    a = first.evaluate("p")
    CALLS.clear()
    second = graph(tmp_path)  # a new process would start like this: empty memory
    b = second.evaluate("p")
    assert CALLS == []
    assert second.stats["p"].status == "cached"
    assert second.stats["p"].source == "disk"
    np.testing.assert_array_equal(a.xyz, b.xyz)
    assert not b.xyz.flags.writeable


def entries(root: Path) -> list[Path]:
    return sorted(root.rglob("*.npz"))


@pytest.mark.parametrize("damage", ["truncate", "garbage", "empty", "flip"])
def test_corrupt_entries_are_recomputed(tmp_path, damage):
    graph(tmp_path).evaluate("p")
    (entry,) = entries(tmp_path)
    data = entry.read_bytes()
    if damage == "truncate":
        entry.write_bytes(data[: len(data) // 2])
    elif damage == "garbage":
        entry.write_bytes(os.urandom(len(data)))
    elif damage == "empty":
        entry.write_bytes(b"")
    else:  # one flipped bit in the middle of the array data
        b = bytearray(data)
        b[len(b) // 2] ^= 0x10
        entry.write_bytes(bytes(b))
    CALLS.clear()
    g = graph(tmp_path)
    pts = g.evaluate("p")
    assert CALLS == ["points"]
    assert g.stats["p"].status == "computed"
    np.testing.assert_allclose(pts.xyz[:, 0], np.arange(50) * 0.5)
    # and the bad entry was replaced by a good one
    CALLS.clear()
    graph(tmp_path).evaluate("p")
    assert CALLS == []


def test_entry_under_another_key_is_not_trusted(tmp_path):
    cache = DiskCache(tmp_path)
    cache.put("aa" + "0" * 38, [1.0, 2.0])
    src = tmp_path / "aa" / ("aa" + "0" * 38 + ".npz")
    dst = tmp_path / "aa" / ("aa" + "1" * 38 + ".npz")
    dst.write_bytes(src.read_bytes())
    assert cache.get("aa" + "1" * 38) == (False, None)
    assert cache.get("aa" + "0" * 38) == (True, [1.0, 2.0])


def test_round_trip_of_every_storable_value(tmp_path):
    cache = DiskCache(tmp_path)
    mesh = fg.Mesh([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1, 2, 3]])
    values = [1.5, 3, "text", True, None, [1.0, [2, "x"]], fg.Points([[1, 2, 3]]), mesh]
    for i, v in enumerate(values):
        k = key_of(i)
        assert cache.put(k, v)
        hit, back = cache.get(k)
        assert hit
        if isinstance(v, fg.Mesh):
            np.testing.assert_array_equal(back.face_indices, v.face_indices)
        elif isinstance(v, fg.Points):
            np.testing.assert_array_equal(back.xyz, v.xyz)
        else:
            assert back == v


def _writer(root: str, seed: int, out: mp.Queue) -> None:
    import stubs  # noqa: F401  (register the stub nodes in the child)

    g = fg.Graph(cache_dir=root)
    g.add_param("n", 1000)
    g.add("p", "stub.points", n="=n", scale=0.25)
    total = 0.0
    for i in range(20):
        total += float(g.evaluate("p", n=1000 + (i + seed) % 5).xyz.sum())
        g.memory.clear()  # force the disk path every time
    out.put(total)


def test_two_processes_at_once(tmp_path):
    ctx = mp.get_context("spawn")
    q = ctx.Queue()
    procs = [ctx.Process(target=_writer, args=(str(tmp_path), s, q)) for s in (0, 2)]
    for p in procs:
        p.start()
    results = [q.get(timeout=120) for _ in procs]
    for p in procs:
        p.join(timeout=60)
        assert p.exitcode == 0
    expected = [
        sum((0.25 * np.arange(1000 + (i + s) % 5)).sum() for i in range(20)) for s in (0, 2)
    ]
    assert sorted(results) == pytest.approx(sorted(expected))
    assert not list(tmp_path.rglob("*.tmp"))  # no temp files left behind
    for entry in entries(tmp_path):
        assert DiskCache(tmp_path).get(entry.stem)[0]


def test_memory_cache_lru_order():
    c = MemoryCache(max_bytes=3 * (64 + 8) + 10)
    for k in "abc":
        c.put(k, 1.0)
    c.get("a")  # a is now the most recent
    c.put("d", 2.0)
    assert "a" in c and "b" not in c


_PLAIN = st.recursive(
    st.none()
    | st.booleans()
    | st.integers()
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=4)
        | st.tuples(inner, inner)
        | st.dictionaries(st.text(max_size=4), inner, max_size=4)
        | st.dictionaries(st.integers(-3, 3), inner, max_size=3)
    ),
    max_leaves=20,
)


@given(_PLAIN)
def test_key_text_is_the_json_of_the_canonical_form(value):
    # Keys are built in one pass over plain values; they must stay what they were (disk
    # caches written before keep their keys).
    expected = json.dumps(canonical(value), sort_keys=True, separators=(",", ":"))
    assert key_text(value) == expected


def test_key_text_of_other_values_goes_through_canonical():
    class Shape(enum.Enum):
        ROUND = "round"

    value = {"e": Shape.ROUND, "a": np.arange(3), "g": np.float32(0.5), "p": fg.Points([[1, 2]])}
    expected = json.dumps(canonical(value), sort_keys=True, separators=(",", ":"))
    assert key_text(value) == expected
    with pytest.raises(TypeError):
        key_text({1: 2, "1": 3})  # keys that cannot be ordered, as canonical() refuses


def test_a_node_key_is_pinned():
    # The key of a typical node, as computed before the one-pass text: unchanged.
    parts = {"type": "bench.work", "version": 1, "inputs": {"points": {"wire": "ab" * 20}}}
    parts["inputs"]["points"]["output"] = None
    parts["inputs"]["k"] = 0.5
    assert key_of(parts) == "d2f95f5a5424d0b22be338ac64470fb0af31448e"


def test_a_long_literal_is_keyed_once_and_by_its_content():
    from formgraph.evaluation.cache import KEYED_INLINE, Keyed

    pts = [[float(i), i * 0.5, 0.0] for i in range(500)]
    short, long_ = Keyed([1.5, 2.0]), Keyed(pts)
    assert short.text == key_text([1.5, 2.0])  # short: its own text, unchanged keys
    assert len(key_text(pts)) > KEYED_INLINE and long_.text.startswith('{"keyed":')
    assert Keyed(json.loads(json.dumps(pts))).text == long_.text  # content, not identity
    assert Keyed(pts[:-1] + [[499.0, 249.5, 1e-300]]).text != long_.text
    assert json.dumps(canonical({"p": long_}), sort_keys=True, separators=(",", ":")) == (
        key_text({"p": long_})
    )

    g = fg.Graph()
    g.add("p", "points.list", points=pts)
    first = g.evaluate("p")
    g.node_inputs("p")["points"][0][0] = 99.0  # a copy: the graph's literal is untouched
    assert g.evaluate("p") is first and g.stats["p"].status == "cached"
    changed = [list(row) for row in pts]
    changed[0][0] = 99.0
    g.set_input("p", "points", changed)  # through the graph: a new literal, a new key
    assert g.evaluate("p").xyz[0, 0] == 99.0 and g.stats["p"].status == "computed"


def test_a_geometry_value_is_hashed_once(monkeypatch):
    m = fg.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    calls = []
    real = fg.Mesh.fingerprint
    monkeypatch.setattr(fg.Mesh, "fingerprint", lambda self: calls.append(1) or real(self))
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("t", "mesh.transform", mesh="=m", translate=[1, 0, 0])
    g.evaluate("t", m=m)
    g.evaluate("t", m=m)
    assert digest(m) == key_of({"type": "Mesh", "state": real(m)})
    assert len(calls) == 1  # kept with the value (immutable), whatever asks for it
    other = fg.Mesh(m.vertices + 1, m.face_indices, m.face_offsets)
    assert digest(other) != digest(m)
