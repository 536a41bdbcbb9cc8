"""The exchange kernels on random inputs: every writer's file read back by our readers
equal, the text scanner's integers and the exact arcs and degree raising of chains."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from formgraph.geometry import NurbsCurve
from formgraph.kernels.io.chains import Chain, arc_pieces, bezier_piece, line_piece
from formgraph.kernels.io.exporters import obj_bytes, ply_binary, stl_binary
from formgraph.kernels.io.gltf import read_gltf, write_glb
from formgraph.kernels.io.mesh_read import read_obj, read_off, read_stl
from formgraph.kernels.io.ply_read import read_ply
from formgraph.kernels.io.textscan import ints_at, token_starts
from formgraph.kernels.io.threemf import write_3mf
from formgraph.kernels.io.threemf_read import read_3mf

FAST = settings(max_examples=40, deadline=None)

coords = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False) | st.sampled_from(
    [0.0, -0.0, 1e-300, -2.5e-12, 123456789.123456789, 1e15 + 0.5]
)


@st.composite
def polygon_meshes(draw):
    n = draw(st.integers(3, 30))
    v = np.array(draw(st.lists(st.tuples(coords, coords, coords), min_size=n, max_size=n)))
    sizes = draw(st.lists(st.integers(3, 7), min_size=1, max_size=12))
    fi = np.array([draw(st.integers(0, n - 1)) for _ in range(sum(sizes))], dtype=np.int64)
    return v, fi, np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)


@FAST
@given(polygon_meshes())
def test_obj_and_ply_round_trip_bit_for_bit(mesh):
    v, fi, fo = mesh
    for back in (read_obj(obj_bytes(v, fi, fo)), read_ply(ply_binary(v, fi, fo))):
        assert np.array_equal(back[0], v + 0.0)  # -0.0 may come back as 0.0: equal anyway
        assert np.array_equal(back[1], fi) and np.array_equal(back[2], fo)


@FAST
@given(polygon_meshes())
def test_stl_binary_round_trips_as_float32_facets(mesh):
    v, fi, fo = mesh
    tri = fi[: (fi.size // 3) * 3]
    fo3 = np.arange(0, tri.size + 1, 3)
    back_v, back_fi, _ = read_stl(stl_binary(v, tri, fo3))
    np.testing.assert_array_equal(back_v[back_fi], v[tri].astype(np.float32).astype(np.float64))


@FAST
@given(polygon_meshes(), st.sampled_from(["millimeter", "inch"]))
def test_3mf_round_trips_exactly(mesh, unit):
    v, fi, _ = mesh
    tris = fi[: (fi.size // 3) * 3].reshape(-1, 3)
    back, t, _, items = read_3mf(write_3mf([(v, tris)], unit=unit))
    assert items == 1
    scale = {"millimeter": 1.0, "inch": 25.4}[unit]
    assert np.array_equal(back, v * scale) and np.array_equal(t, tris)


@FAST
@given(polygon_meshes())
def test_glb_round_trips_in_float32(mesh):
    v, fi, _ = mesh
    tris = fi[: (fi.size // 3) * 3].reshape(-1, 3)
    ((_, back, t, _),) = read_gltf(write_glb([(v, tris)], scale=1.0), scale=1.0)
    assert np.array_equal(back, v.astype(np.float32).astype(np.float64))
    assert np.array_equal(t, tris)


def test_off_reads_meshio_style_text():
    text = b"OFF\n# comment\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n4 0 1 2 3 255 0 0\n"
    v, fi, fo = read_off(text)
    assert v.shape == (4, 3) and fi.tolist() == [0, 1, 2, 0, 1, 2, 3] and fo.tolist() == [0, 3, 7]


@FAST
@given(
    st.lists(st.integers(-(10**17), 10**17), min_size=1, max_size=50),
    st.lists(st.sampled_from([" ", "  ", "\t", "/", "/7/", "\n"]), min_size=50, max_size=50),
)
def test_ints_at_reads_every_integer(values, seps):
    text = " " + "".join(f"{x}{s}" for x, s in zip(values, seps, strict=False))
    buf = np.frombuffer(text.encode(), np.uint8)
    starts = token_starts(buf)
    got, _ = ints_at(buf, starts)
    firsts = [int(t.split("/")[0]) for t in text.split()]
    assert got.tolist() == firsts


@FAST
@given(
    st.floats(-10, 10),
    st.floats(0.1, 10),
    st.floats(0.1, 10),
    st.floats(-math.pi, math.pi),
    st.floats(-2 * math.pi, 2 * math.pi).filter(lambda s: abs(s) > 1e-3),
)
def test_arc_pieces_lie_on_the_ellipse_and_end_where_asked(cx, rx, ry, t0, sweep):
    a = np.array([rx * math.cos(0.3), rx * math.sin(0.3), 0.0])
    b = np.array([-ry * math.sin(0.3), ry * math.cos(0.3), 0.0]) * 0.8 + a * 0.2  # skewed
    chain = Chain()
    chain.add(arc_pieces(np.array([cx, 1.0, 0.0]), a, b, t0, t0 + sweep))
    curve = NurbsCurve(*chain.curve())
    p = curve.evaluate(np.linspace(curve.knots[0], curve.knots[-1], 97))
    basis = np.column_stack([a[:2], b[:2]])
    uv = np.linalg.solve(basis, (p[:, :2] - [cx, 1.0]).T).T  # conjugate-diameter coordinates
    np.testing.assert_allclose(np.hypot(uv[:, 0], uv[:, 1]), 1.0, atol=1e-12)
    end = np.array([cx, 1.0, 0]) + a * math.cos(t0 + sweep) + b * math.sin(t0 + sweep)
    np.testing.assert_allclose(p[-1], end, atol=1e-12)


def test_a_chain_raises_lower_pieces_without_moving_them():
    cubic = np.array([[0, 0, 0], [1, 2, 0], [3, 2, 0], [4, 0, 0.0]])
    chain = Chain()
    chain.add(line_piece(np.array([-2.0, 0, 0]), np.array([0.0, 0, 0])))
    chain.add(bezier_piece(cubic))
    curve = NurbsCurve(*chain.curve())
    assert curve.degree == 3 and not curve.rational
    t = np.linspace(0, 1, 11)
    np.testing.assert_allclose(curve.evaluate(t), np.outer(1 - t, [-2, 0, 0]), atol=1e-15)
    bern = np.stack([(1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t**2 * (1 - t), t**3], axis=1)
    np.testing.assert_allclose(curve.evaluate(1 + t), bern @ cubic, atol=1e-14)


def test_empty_and_face_free_files_read_as_empty_parts():
    v, fi, fo = read_obj(b"v 0 0 0\nv 1 0 0\n")  # a point cloud as OBJ: no faces
    assert v.shape == (2, 3) and fi.size == 0 and fo.tolist() == [0]
    v, fi, fo = read_obj(b"")
    assert v.shape == (0, 3) and fo.tolist() == [0]
