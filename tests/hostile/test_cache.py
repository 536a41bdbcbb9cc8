"""Hostile disk-cache entries: each is a miss (and is recomputed), never a crash."""

from __future__ import annotations

import hashlib
import io
import json
import zipfile

import numpy as np
import pytest

import formgraph as fg
from formgraph.evaluation import cache as _cache

KEY = "ab" + "0" * 38


def _npy(array: np.ndarray | None = None, header: dict | None = None, body: bytes = b"") -> bytes:
    fh = io.BytesIO()
    if header is None:
        np.lib.format.write_array(fh, array, allow_pickle=False)
        return fh.getvalue()
    np.lib.format.write_array_header_1_0(fh, header)
    return fh.getvalue() + body


def _meta(key: str, value: object, arrays: dict[str, bytes], depth: int = 0) -> bytes:
    check = hashlib.blake2b(digest_size=16)
    for name in sorted(arrays):
        a = np.load(io.BytesIO(arrays[name]), allow_pickle=False)
        check.update(name.encode())
        check.update(_cache._hash_bytes(a).encode())
    text = json.dumps(
        {"format": _cache.FORMAT, "key": key, "check": check.hexdigest(), "value": value}
    )
    if depth:  # a description nested absurdly deep
        text = text[:-1] + ', "x": ' + "[" * depth + "]" * depth + "}"
    return _npy(np.frombuffer(text.encode(), dtype=np.uint8))


def _entry(tmp_path, members: dict[str, bytes], compress: int = zipfile.ZIP_STORED) -> None:
    path = tmp_path / KEY[:2] / f"{KEY}.npz"
    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w", compression=compress) as zf:
        for name, data in members.items():
            zf.writestr(f"{name}.npy", data)


def _miss(tmp_path) -> None:
    hit, value, _ = _cache.DiskCache(tmp_path).get_entry(KEY)
    assert (hit, value) == (False, None)
    assert not (tmp_path / KEY[:2] / f"{KEY}.npz").exists()  # a bad entry is deleted


def test_a_header_that_claims_a_huge_array_is_a_miss(tmp_path):
    # 8 TB claimed by 16 bytes: numpy's reader would allocate the claim before reading
    huge = _npy(
        header={"descr": "<f8", "fortran_order": False, "shape": (10**12,)}, body=b"\0" * 16
    )
    meta = _meta(KEY, {"array": "a0"}, {})
    _entry(tmp_path, {"meta": meta, "a0": huge})
    _miss(tmp_path)


def test_an_entry_that_inflates_far_past_its_size_is_a_miss(tmp_path):
    zeros = _npy(np.zeros(5_000_000))  # 40 MB of zeros deflate to some 40 kB
    meta = _meta(KEY, {"array": "a0"}, {"a0": zeros})
    _entry(tmp_path, {"meta": meta, "a0": zeros}, compress=zipfile.ZIP_DEFLATED)
    _miss(tmp_path)


def test_a_deeply_nested_description_is_a_miss(tmp_path):
    meta = _meta(KEY, {"v": 1}, {}, depth=100_000)
    _entry(tmp_path, {"meta": meta})
    _miss(tmp_path)


@pytest.mark.parametrize(
    "member",
    [
        _npy(np.array(["1", "x"])),  # text, not coordinates
        _npy(header={"descr": "<f8", "fortran_order": False, "shape": (3,)}, body=b"\0" * 8),
        _npy(header={"descr": "|O", "fortran_order": False, "shape": (1,)}, body=b"\0" * 8),
        b"not an array at all",
    ],
)
def test_malformed_arrays_are_misses(tmp_path, member):
    meta = _meta(KEY, {"geom": "Points", "state": {"xyz": {"array": "a0"}}}, {})
    _entry(tmp_path, {"meta": meta, "a0": member})
    _miss(tmp_path)


def test_an_honest_entry_still_reads(tmp_path):
    disk = _cache.DiskCache(tmp_path)
    assert disk.put(KEY, fg.Points([[1, 2, 3]]))
    hit, value, _ = disk.get_entry(KEY)
    assert hit and value.xyz.tolist() == [[1.0, 2.0, 3.0]]


def test_a_graph_recomputes_over_a_hostile_entry(tmp_path):
    def graph() -> fg.Graph:
        g = fg.Graph(cache_dir=tmp_path)
        g.add("b", "mesh.box")
        return g

    graph().evaluate("b")
    (entry,) = tmp_path.glob("*/*.npz")
    meta = _meta(entry.stem, {"v": 1}, {}, depth=50_000)
    with zipfile.ZipFile(entry, "w") as zf:
        zf.writestr("meta.npy", meta)
    g = graph()
    assert g.evaluate("b").n_faces == 6
    assert g.stats["b"].status == "computed"


def test_a_description_full_of_escaped_quotes_is_a_miss(tmp_path):
    text = '{"format": 1, "key": "' + '\\"' * 200_000  # never closed
    _entry(tmp_path, {"meta": _npy(np.frombuffer(text.encode(), dtype=np.uint8))})
    _miss(tmp_path)
