"""Mesh measures (formgraph.kernels.mesh.measure): the column path of faces of a few corners
gives the per-corner path's numbers to the bit, and both agree with trimesh; the flat-sheet
count against a plane fitted part by part with numpy's SVD."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from mesh_shapes import cube, prism

from formgraph.kernels.io.meshdata import fan_triangles
from formgraph.kernels.mesh import measure as km
from formgraph.kernels.mesh import memo
from formgraph.kernels.mesh import repair as kr
from formgraph.kernels.mesh.grid import grid_faces


def _random_faces(seed: int, widest: int, n_faces: int = 150, n_vertices: int = 80):
    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.uniform(-3, 3)
    v = rng.normal(size=(n_vertices, 3)) * scale + rng.normal(size=3) * scale * 50
    sizes = rng.integers(3, widest + 1, n_faces)
    fo = np.r_[0, np.cumsum(sizes)]
    return v, rng.integers(0, n_vertices, fo[-1]), fo


def _per_corner(monkeypatch, fn, *args):
    """``fn`` with the column path switched off: the reduceat-over-corners formulas."""
    with monkeypatch.context() as m:
        m.setattr(km, "COLUMN_CORNERS", 2)
        assert km.FanColumns.of(*args[:3]) is None
        return fn(*args)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.integers(4, km.COLUMN_CORNERS))
def test_columns_give_the_per_corner_numbers_to_the_bit(seed, widest):
    v, fi, fo = _random_faces(seed, widest)  # warped, folded, far from the origin
    assert km.FanColumns.of(v, fi, fo) is not None
    mp = pytest.MonkeyPatch()
    try:
        for fn in (km.face_areas, km.face_vectors):
            assert np.array_equal(fn(v, fi, fo), _per_corner(mp, fn, v, fi, fo))
        per_face = np.random.default_rng(seed).normal(size=(fo.size - 1, 3))
        for origin in (None, v[0], per_face):
            got = km.signed_volume(v, fi, fo, origin)
            assert np.array_equal(got, _per_corner(mp, km.signed_volume, v, fi, fo, origin))
        face = np.repeat(np.arange(fo.size - 1), np.diff(fo))
        sums = km.FanColumns.of(v, fi, fo).corner_sums()
        for k in range(3):
            assert np.array_equal(sums[k], np.bincount(face, weights=v[fi, k]))
    finally:
        mp.undo()


def test_columns_leave_wide_faces_to_the_per_corner_path():
    v, fi, fo = _random_faces(3, km.COLUMN_CORNERS + 1)
    assert km.FanColumns.of(v, fi, fo) is None
    v, fi, fo = prism(12)  # two 12-gons: per corner; its quads alone: columns
    assert km.FanColumns.of(v, fi, fo) is None
    assert km.FanColumns.of(v, fi[24:], fo[2:] - 24) is not None


def _tube(around: int = 24, rows: int = 9):
    """An open, slightly warped tube of quads, capped: quads and triangles together."""
    fi, fo = grid_faces(around, rows + 1, True, False)
    a = np.linspace(0, 2 * np.pi, around, endpoint=False)[:, None]
    z = np.linspace(0, 2, rows + 1)[None, :]
    r = 1 + 0.2 * np.sin(3 * z + a)
    v = np.stack(np.broadcast_arrays(r * np.cos(a), r * np.sin(a), z), -1).reshape(-1, 3)
    return kr.cap(v, kr.orient(v, fi, fo)[0], fo)


def test_quads_and_triangles_measure_as_trimesh_does():
    v, fi, fo = _tube()
    sizes = set(np.diff(fo).tolist())
    assert sizes == {3, 4} and km.FanColumns.of(v, fi, fo) is not None
    t = trimesh.Trimesh(v, fan_triangles(fi, fo), process=False)
    assert t.is_watertight and t.is_winding_consistent
    face_of_tri = np.repeat(np.arange(fo.size - 1), np.diff(fo) - 2)
    np.testing.assert_allclose(
        km.face_areas(v, fi, fo), np.bincount(face_of_tri, t.area_faces), rtol=1e-12
    )
    assert km.signed_volume(v, fi, fo).sum() == pytest.approx(t.volume, rel=1e-12)
    newell = km.face_vectors(v, fi, fo)
    np.testing.assert_allclose(
        np.linalg.norm(newell, axis=1)[np.diff(fo) == 3] / 2,
        km.face_areas(v, fi, fo)[np.diff(fo) == 3],
        rtol=1e-12,
    )


def test_a_concave_quad_counts_its_folded_triangle_against_it():
    # an arrowhead: its fan from the reflex corner's neighbour folds over
    v = np.array([[0, 0, 0], [2, 1, 0], [4, 0, 0], [2, 3, 0.0]])
    for start in range(4):
        fi = np.roll([0, 1, 2, 3], -start)
        got = km.face_areas(v, fi, np.array([0, 4]))
        assert got[0] == pytest.approx(4.0, rel=1e-12)  # the shoelace area


def _flat_parts_by_svd(v, fi, fo, tol=1e-6):
    """Flat open parts, part by part: components by trimesh, the plane by numpy's SVD."""
    t = trimesh.Trimesh(v, fan_triangles(fi, fo), process=False)
    labels = trimesh.graph.connected_component_labels(t.face_adjacency, len(t.faces))
    count = 0
    for label in np.unique(labels):
        tris = t.faces[labels == label]
        ids = np.unique(tris)
        p = v[ids]
        d = p - p.mean(axis=0)
        normal = np.linalg.svd(d)[2][-1]
        flat = np.abs(d @ normal).max() <= tol * np.linalg.norm(p.max(0) - p.min(0))
        edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), 1)
        _, n = np.unique(edges, axis=0, return_counts=True)
        count += bool(flat and (n == 1).any())
    return count


@pytest.mark.parametrize("seed", range(4))
def test_flat_open_parts_match_a_plane_fitted_per_part(seed):
    rng = np.random.default_rng(seed)
    pieces = []
    for k in range(6):
        kind = rng.integers(3)
        if kind == 0:  # a flat sheet, tilted: flat and open
            fi, fo = grid_faces(5, 4)
            g = np.stack(np.meshgrid(np.arange(5.0), np.arange(4.0), indexing="ij"), -1)
            v = np.c_[g.reshape(-1, 2), np.zeros(20)]
        elif kind == 1:  # a bent sheet: open, not flat
            fi, fo = grid_faces(5, 4)
            g = np.stack(np.meshgrid(np.arange(5.0), np.arange(4.0), indexing="ij"), -1)
            v = np.c_[g.reshape(-1, 2), 0.3 * g[..., 0].reshape(-1) ** 2]
        else:  # a closed cube: not open
            v, fi, fo = cube()
        rot = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        pieces.append((v @ rot.T + 10 * k, fi, fo))
    # one mesh, the parts' vertices interleaved, so no part is a run of the vertex array
    v = np.concatenate([p[0] for p in pieces])
    starts = np.cumsum([0] + [len(p[0]) for p in pieces])
    fi = np.concatenate([p[1] + s for p, s in zip(pieces, starts, strict=False)])
    sizes = np.concatenate([np.diff(p[2]) for p in pieces])
    fo = np.r_[0, np.cumsum(sizes)]
    perm = rng.permutation(len(v))
    v, fi = v[perm], np.argsort(perm)[fi]
    memo.clear()
    assert km.flat_open_parts(v, fi, fo) == _flat_parts_by_svd(v, fi, fo)
    # a second call (the kept connectivity, new positions) agrees as well
    moved = v * 1.5 + 2.0
    assert km.flat_open_parts(moved, fi, fo) == _flat_parts_by_svd(moved, fi, fo)


def test_orient_shares_read_only_faces_that_need_no_change():
    v, fi, fo = _tube()
    frozen = fi.copy()
    frozen.flags.writeable = False
    out, conflicts = kr.orient(v, frozen, fo)
    assert out is frozen and conflicts == 0
    out, _ = kr.orient(v, fi, fo)  # a writable input is copied, never handed back
    assert out is not fi and np.array_equal(out, fi)
