"""Per-element attributes on Points and Mesh: frozen, validated, part of the value."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from formgraph.evaluation.cache import DiskCache, digest
from formgraph.geometry import Mesh, Points, from_state
from formgraph.geometry.base import AttributeMap, attribute_map


def _tri(**kw) -> Mesh:
    return Mesh([[0, 0], [1, 0], [0, 1], [1, 1]], [[0, 1, 2], [1, 3, 2]], **kw)


def _cannot_be_made_writable(a: np.ndarray) -> None:
    with pytest.raises(ValueError):
        a.flags.writeable = True
    base = a.base
    while isinstance(base, np.ndarray):
        with pytest.raises(ValueError):
            base.flags.writeable = True
        base = base.base


def test_attributes_are_frozen_float_arrays():
    source = np.arange(8.0).reshape(4, 2)
    m = _tri(point_data={"uv": source, "h": [0, 1, 2, 3]}, face_data={"id": [5, 6]})
    source[0, 0] = 99.0  # the mesh holds its own copy
    assert m.point_data["uv"][0, 0] == 0.0
    for a in (*m.point_data.values(), *m.face_data.values()):
        assert a.dtype == np.float64
        _cannot_be_made_writable(a)
    with pytest.raises(TypeError):
        m.point_data["h"] = np.zeros(4)  # a read-only mapping
    with pytest.raises(AttributeError):
        m.point_data._data = {}
    assert list(m.point_data) == ["h", "uv"] and m.face_data["id"].tolist() == [5.0, 6.0]
    assert _tri().point_data == {} and len(Points([[0, 0]]).point_data) == 0


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"h": [1, 2]}, r"point attribute 'h' has shape \(2,\); it needs one value .* \(4,\)"),
        ({"h": np.zeros((4, 2, 2))}, r"has shape \(4, 2, 2\)"),
        ({"h": ["a", "b", "c", "d"]}, r"point attribute 'h' must be numbers"),
        ({"h": [0, 1, np.nan, 3]}, r"point attribute 'h' is not finite at element 2"),
        ({"2x": [0, 1, 2, 3]}, r"name '2x' must be a name as in expressions"),
        ({"_h": [0, 1, 2, 3]}, r"name '_h' must be"),
        ({"h": np.zeros((4, 0))}, r"has 0 components"),
    ],
)
def test_bad_attributes_are_refused_by_name(data, message):
    with pytest.raises(ValueError, match=message):
        _tri(point_data=data)


def test_a_number_is_repeated_and_pairs_are_accepted():
    m = _tri(face_data=[["k", 2.5]])
    assert m.face_data["k"].tolist() == [2.5, 2.5]
    with pytest.raises(ValueError, match="'k' is given twice"):
        _tri(face_data=[["k", 1], ["k", 2]])


def test_attributes_are_part_of_equality_hash_and_digest():
    a = _tri(point_data={"h": [0, 1, 2, 3]})
    b = _tri(point_data={"h": [0, 1, 2, 3]})
    c = _tri(point_data={"h": [0, 1, 2, 4]})
    plain = _tri()
    assert a == b and hash(a) == hash(b) and digest(a) == digest(b)
    assert a != c and digest(a) != digest(c)
    assert a != plain and digest(a) != digest(plain)
    assert _tri(face_data={"h": [1, 2]}) != _tri(point_data={"h": [1, 2, 3, 4]})
    # a plain value's state is what it always was, so existing cache keys stay valid
    assert set(plain.state()) == {"vertices", "face_indices", "face_offsets"}
    assert set(Points([[1, 2]]).state()) == {"xyz"}
    p = Points([[0, 0], [1, 1]], {"w": [1, 2]})
    assert p == Points([[0, 0], [1, 1]], {"w": [1, 2]}) != Points([[0, 0], [1, 1]])
    assert len({a, b, c}) == 2


def test_attributes_survive_state_pickle_and_the_disk_cache(tmp_path):
    m = _tri(point_data={"c": np.eye(4)[:, :3]}, face_data={"f": [1, 2]})
    p = Points(np.ones((3, 3)), {"t": [0.0, 0.5, 1.0], "n": np.eye(3)})
    for value in (m, p):
        assert from_state(type(value).__name__, value.state()) == value
        assert pickle.loads(pickle.dumps(value)) == value
    cache = DiskCache(tmp_path)
    cache.put("ab" * 20, [m, p])
    hit, back = cache.get("ab" * 20)
    assert hit and back[0] == m and back[1] == p
    for a in back[0].point_data.values():
        _cannot_be_made_writable(a)


def test_to_pyvista_carries_attributes():
    m = _tri(point_data={"c": np.eye(4)[:, :3]}, face_data={"f": [1, 2]})
    poly = m.to_pyvista()
    np.testing.assert_array_equal(poly.point_data["c"], m.point_data["c"])
    np.testing.assert_array_equal(poly.cell_data["f"], [1, 2])
    pts = Points(np.ones((3, 3)), {"t": [0.0, 0.5, 1.0]}).to_pyvista()
    np.testing.assert_array_equal(pts.point_data["t"], [0.0, 0.5, 1.0])


def test_attribute_map_take_and_with():
    m = attribute_map({"h": [10.0, 11.0, 12.0], "v": np.arange(6.0).reshape(3, 2)}, 3)
    t = m.take([2, 0, 2, 1])
    assert t.n == 4 and t["h"].tolist() == [12.0, 10.0, 12.0, 11.0]
    assert t["v"].tolist() == [[4, 5], [0, 1], [4, 5], [2, 3]]
    w = m.with_("h", [1, 2, 3])
    assert w["h"].tolist() == [1, 2, 3] and m["h"].tolist() == [10, 11, 12]
    assert isinstance(w, AttributeMap) and w != m
    assert "v: (2,)" in repr(m)
    assert m.nbytes == 9 * 8


def test_with_data_shares_the_arrays_and_still_checks_the_attributes():
    m = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 1, 2], [0, 1, 3]])
    h = m.with_data({"h": [1.0, 2.0, 3.0, 4.0]}, {"id": [0.0, 1.0]})
    assert h.vertices is m.vertices and h.face_indices is m.face_indices
    assert h.face_offsets is m.face_offsets and h == Mesh(*m.arrays, h.point_data, h.face_data)
    with pytest.raises(ValueError, match="'h' is not finite at element 2"):
        m.with_data({"h": [1.0, 2.0, np.nan, 4.0]})
    p = Points([[0, 0, 0], [1, 1, 1]])
    q = p.with_point_data({"w": [5.0, 6.0]})
    assert q.xyz is p.xyz and q.point_data["w"].tolist() == [5.0, 6.0]
    with pytest.raises(ValueError, match="has shape"):
        p.with_point_data({"w": [5.0]})
