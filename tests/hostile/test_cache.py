"""Hostile disk-cache entries: each is a miss (and is recomputed), never a crash."""

from __future__ import annotations

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
    loaded = {name: np.load(io.BytesIO(data), allow_pickle=False) for name, data in arrays.items()}
    meta = {"format": _cache.FORMAT, "key": key, "value": value}
    meta["check"] = _cache.entry_checksum(meta, loaded)
    text = json.dumps(meta)
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


# ----------------------------------------------------------------- edited real entries


def _members(entry) -> dict[str, bytes]:
    with zipfile.ZipFile(entry) as zf:
        return {i.filename: zf.read(i) for i in zf.infolist()}


def _rewrite(entry, members: dict[str, bytes]) -> None:
    """The entry as a well-formed archive again (every CRC right), its checksum as it was:
    what a hand edit of an unpacked entry leaves."""
    with zipfile.ZipFile(entry, "w") as zf:
        for name, data in members.items():
            zf.writestr(name, data)


def _edit_description(entry, old: str, new: str) -> None:
    members = _members(entry)
    text = bytes(np.load(io.BytesIO(members["meta.npy"]))).decode()
    assert old in text
    members["meta.npy"] = _npy(np.frombuffer(text.replace(old, new, 1).encode(), np.uint8))
    _rewrite(entry, members)


def _edit_array(entry, name: str, change) -> None:
    members = _members(entry)
    a = np.load(io.BytesIO(members[f"{name}.npy"])).copy()
    change(a)
    members[f"{name}.npy"] = _npy(a)
    _rewrite(entry, members)


def _only_entry(root, before: set) -> object:
    (entry,) = set(root.rglob("*.npz")) - before
    return entry


def _served(tmp_path, text: str, node: str):
    """Evaluate ``node`` in a fresh graph over the cache: (value, where it came from)."""
    g = fg.Graph.from_text(text, file="c.yaml", cache_dir=tmp_path / "cache")
    value = g.evaluate(node)
    return value, g.stats[node].source if g.stats[node].status == "cached" else "computed"


def test_an_edited_measure_is_recomputed_not_served(tmp_path):
    text = (
        "formgraph: 1\nnodes:\n  b: {type: mesh.box, size: [1, 2, 3]}\n"
        "  m: {type: mesh.measure, mesh: '@b'}\n"
    )
    first, _ = _served(tmp_path, text, "b")
    before = set((tmp_path / "cache").rglob("*.npz"))
    m, _ = _served(tmp_path, text, "m")
    assert m.volume == pytest.approx(6.0)
    entry = _only_entry(tmp_path / "cache", before)
    _edit_description(entry, json.dumps((6.0).hex()), json.dumps((7.0).hex()))
    m, source = _served(tmp_path, text, "m")
    assert source == "computed" and m.volume == pytest.approx(6.0)
    m, source = _served(tmp_path, text, "m")  # the bad entry was replaced by a good one
    assert source == "disk" and m.volume == pytest.approx(6.0)


def test_an_edited_mesh_is_recomputed_not_served(tmp_path):
    text = "formgraph: 1\nnodes:\n  b: {type: mesh.box, size: [1, 2, 3]}\n"
    box, _ = _served(tmp_path, text, "b")
    (entry,) = (tmp_path / "cache").rglob("*.npz")
    meta = json.loads(bytes(np.load(io.BytesIO(_members(entry)["meta.npy"]))).decode())
    ref = meta["value"]["state"]["vertices"]["array"]

    def move(a):
        a[0, 0] += 1.0

    _edit_array(entry, ref, move)
    again, source = _served(tmp_path, text, "b")
    assert source == "computed"
    np.testing.assert_array_equal(again.vertices, box.vertices)
    # and the identity recorded with it edited (what its descendants are keyed by)
    _edit_description(entry, '"identity": "', '"identity": "0')
    assert _served(tmp_path, text, "b")[1] == "computed"


def test_edited_curves_are_recomputed_not_served(tmp_path):
    text = (
        "formgraph: 1\nnodes:\n  c: {type: curves.rectangle, size: [4, 2]}\n"
        "  p: {type: points.grid, nx: 3, ny: 1, spacing: 10}\n"
        "  cs: {type: curves.copy_to_points, curve: '@c', points: '@p'}\n"
    )
    _served(tmp_path, text, "c")
    _served(tmp_path, text, "p")
    before = set((tmp_path / "cache").rglob("*.npz"))
    curves, _ = _served(tmp_path, text, "cs")
    assert len(curves) == 3
    entry = _only_entry(tmp_path / "cache", before)
    # the description of the list, one curve of it dropped: every array still as it was
    meta = json.loads(bytes(np.load(io.BytesIO(_members(entry)["meta.npy"]))).decode())
    kept = json.dumps(meta["value"]["list"][:2])
    whole = json.dumps(meta["value"]["list"])
    members = _members(entry)
    members["meta.npy"] = _npy(
        np.frombuffer(json.dumps(meta).replace(whole, kept).encode(), np.uint8)
    )
    _rewrite(entry, members)
    again, source = _served(tmp_path, text, "cs")
    assert source == "computed" and len(again) == 3


def test_an_edited_text_is_recomputed_not_served(tmp_path):
    disk = _cache.DiskCache(tmp_path)
    assert disk.put(KEY, "out/part.stl")
    _edit_description(tmp_path / KEY[:2] / f"{KEY}.npz", "out/part.stl", "../../etc/x")
    _miss(tmp_path)


def test_a_field_recipe_is_never_on_disk_so_never_served_from_it(tmp_path):
    text = "formgraph: 1\nnodes:\n  s: {type: field.sphere, radius: 2}\n"
    field, _ = _served(tmp_path, text, "s")
    assert not list((tmp_path / "cache").rglob("*.npz"))  # rebuilt, never read back
    again, source = _served(tmp_path, text, "s")
    assert source == "computed" and _cache.digest(again) == _cache.digest(field)
