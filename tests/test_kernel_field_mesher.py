"""The marching-cubes table (engine/kernels/field/mctable.py) and the block mesher's topology."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from formgraph.kernels.field import lattice, mctable, mesher, sdf

O = np.zeros(3)


def _mid(e: int) -> tuple[float, ...]:
    c = int(mctable.EDGE_START[e])
    p = [c >> 2 & 1, c >> 1 & 1, c & 1]
    p[int(mctable.EDGE_AXIS[e])] += 0.5
    return tuple(float(x) for x in p)


def _face_segments(case: int, axis: int, side: int) -> set[tuple[tuple, tuple]]:
    """The directed triangle edges of a case that lie in one face of the cube, as points
    in the face (the other coordinate dropped)."""
    out = set()
    for t in mctable.TRI_EDGES[case, : mctable.TRI_COUNT[case]]:
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            pa, pb = _mid(a), _mid(b)
            if pa[axis] == pb[axis] == side:
                drop = lambda p: p[:axis] + p[axis + 1 :]  # noqa: E731
                out.add((drop(pa), drop(pb)))
    return out


def _corner_sign(case: int, x: int, y: int, z: int) -> int:
    return case >> (x << 2 | y << 1 | z) & 1


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_shared_face_gets_the_same_segments_from_both_cubes_reversed(axis):
    # every pair of cubes meeting on a face (the low cube's face side 1, the high cube's
    # side 0) with the same four signs there: the same segments, opposite directions, so
    # every segment is the edge of one triangle on each side (watertight and oriented)
    cases = range(256)
    by_face: dict[tuple, set] = {}
    for case in cases:
        for side in (0, 1):
            face = []
            for u, v in itertools.product((0, 1), repeat=2):
                p = [u, v]
                p.insert(axis, side)
                face.append(_corner_sign(case, *p))
            segs = _face_segments(case, axis, side)
            key = (side, tuple(face))
            if key in by_face:
                assert by_face[key] == segs, (case, axis, side)  # only the face's signs count
            by_face[key] = segs
    for face in itertools.product((0, 1), repeat=4):
        low, high = by_face[(1, face)], by_face[(0, face)]
        assert low == {(b, a) for a, b in high}
        # two crossings on the face make one segment; four (the ambiguous face) make two
        crossings = sum(face[i] != face[j] for i, j in ((0, 1), (1, 3), (3, 2), (2, 0)))
        assert len(low) == crossings // 2


def test_every_case_closes_inside_the_cube():
    # each edge of a case's triangles that crosses the cube's inside is used twice, in
    # opposite directions (the rest lie in faces: the test above), and no edge twice the
    # same way
    for case in range(1, 255):
        tri = mctable.TRI_EDGES[case, : mctable.TRI_COUNT[case]]
        directed = [(a, b) for t in tri for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))]
        inner = [(a, b) for a, b in directed if not _on_one_face(a, b)]
        assert sorted(inner) == sorted((b, a) for a, b in inner)
        assert len(set(directed)) == len(directed)


@pytest.mark.parametrize("corner", range(8))
def test_a_lone_corner_is_cut_off_with_the_normal_outward(corner):
    c = np.array([corner >> 2 & 1, corner >> 1 & 1, corner & 1], dtype=float)
    for case, away in ((1 << corner, 1.0), (255 ^ (1 << corner), -1.0)):
        assert mctable.TRI_COUNT[case] == 1
        p = np.array([_mid(e) for e in mctable.TRI_EDGES[case, 0]])
        n = np.cross(p[1] - p[0], p[2] - p[0])
        assert away * np.dot(n, p.mean(axis=0) - c) > 0


def _on_one_face(a: int, b: int) -> bool:
    pa, pb = np.array(_mid(a)), np.array(_mid(b))
    return bool(np.any((pa == pb) & ((pa == 0) | (pa == 1))))


def _lattices(f):
    """A field's lattices sampled point by point: the mesher's dense-block path."""

    def grid(origin, step, shape):
        ijk = np.stack(np.meshgrid(*(np.arange(k) for k in shape), indexing="ij"), -1)
        p = origin[:, None, None, None, :] + ijk[None] * step
        return f(p.reshape(-1, 3)).reshape(len(origin), *shape)

    return grid


def _edge_use(t: np.ndarray) -> np.ndarray:
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    _, count = np.unique(e, axis=0, return_counts=True)
    return count


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.6, 2.0), st.booleans())
def test_random_fields_are_two_manifold_closed_and_oriented(seed, scale, dense):
    # a random sum of bumps (many ambiguous faces at this cell), cut by a ball so the
    # surface closes: every edge on exactly two triangles, consistent winding, even Euler
    rng = np.random.default_rng(seed)
    c = rng.uniform(-1, 1, (12, 3))
    w = rng.uniform(-1, 1, 12)

    def f(p):
        d2 = ((p[:, None, :] - c[None]) ** 2).sum(-1)
        g = (w * np.exp(-d2 * 4 * scale)).sum(1) - 0.05
        return np.maximum(g, sdf.sphere(p, 1.2, O))

    grid = _lattices(f) if dense else None
    v, t = mesher.mesh_field(f, [-1.3] * 3, [1.3] * 3, 0.1, lipschitz=8.0 * scale, grid=grid)
    if not len(t):
        return
    assert (_edge_use(t) == 2).all()
    m = trimesh.Trimesh(v, t, process=False)
    assert m.is_watertight and m.is_winding_consistent
    assert m.euler_number % 2 == 0
    assert len(np.unique(t)) == len(v)
    assert m.volume > 0


@pytest.mark.parametrize("dense", [False, True])
def test_a_field_of_near_saddles_everywhere_meshes_closed(dense):
    # sin x sin y sin z at about two cells a half period: ambiguous faces on every side
    k = np.pi / 0.23

    def f(p):
        s = np.sin(k * p[:, 0]) * np.sin(k * p[:, 1]) * np.sin(k * p[:, 2]) / k + 0.01
        return np.maximum(s, sdf.box(p, np.array([2.0, 2.0, 2.0]), O))

    grid = _lattices(f) if dense else None
    v, t = mesher.mesh_field(f, [-1] * 3, [1] * 3, 0.1, lipschitz=2.0, grid=grid)
    assert (_edge_use(t) == 2).all()
    m = trimesh.Trimesh(v, t, process=False)
    assert m.is_watertight and m.is_winding_consistent and m.volume > 0


@pytest.mark.parametrize("lattices", [False, True])
def test_gyroid_cube_agrees_with_scikit_image_marching_cubes(lattices):
    # point by point (signs inferred inside the blocks) and on the blocks' lattices
    # (separable tables, every corner sampled): the same surface as a dense grid's
    skimage = pytest.importorskip("skimage.measure")
    side, cell = 10.0, 0.25
    box = np.array([side] * 3)

    def f(p):
        return np.maximum(sdf.tpms(p, "gyroid", 10.0, 1.0), sdf.box(p, box, O))

    def grid(origin, step, shape):
        axes = [origin[:, k, None] + np.arange(shape[k]) * step for k in range(3)]
        v = np.maximum(sdf.tpms_grid(axes, "gyroid", 10.0, 1.0), sdf.box_grid(axes, box, O))
        return np.moveaxis(v, -1, 0)  # the kernels' (a, b, c, n) as (n, a, b, c)

    def lines(origin, step, ijk, axis, t):
        at = sdf.Lines(origin, step, ijk, axis, t)
        return np.maximum(sdf.tpms_lines(at, "gyroid", 10.0, 1.0), sdf.box_lines(at, box, O))

    lo, hi = [-side / 2] * 3, [side / 2] * 3
    if lattices:
        v, t = mesher.mesh_field(f, lo, hi, cell, 2.0, grid=grid, lines=lines)
        on_edges = f(v)
        assert np.abs(on_edges).max() < 1e-3 * cell  # the roots are on the field's zero set
    else:
        v, t = mesher.mesh_field(f, lo, hi, cell, 2.0)
    ours = trimesh.Trimesh(v, t, process=False)
    n = int(round(side / cell)) + 3
    ax = (np.arange(n) - (n - 1) / 2) * cell
    grid = np.stack(np.meshgrid(ax, ax, ax, indexing="ij"), -1).reshape(-1, 3)
    rv, rt, _, _ = skimage.marching_cubes(f(grid).reshape(n, n, n), 0.0, spacing=(cell,) * 3)
    ref = trimesh.Trimesh(rv, rt)
    ref.update_faces(ref.nondegenerate_faces())  # skimage leaves zero-area slivers
    ref.merge_vertices()
    assert ours.is_watertight and ref.is_watertight
    assert ours.euler_number == ref.euler_number  # the same genus
    # the same surface to the cell's error (the grids differ by a fraction of a cell)
    assert ours.area == pytest.approx(ref.area, rel=0.01)
    assert ours.volume == pytest.approx(abs(ref.volume), rel=0.01)


def test_samples_grow_with_the_area_not_the_volume():
    calls = []

    def ball(p):
        calls.append(len(p))
        return sdf.sphere(p, 1.0, O)

    counts = []
    for cell in (0.04, 0.02):
        calls.clear()
        mesher.mesh_field(ball, [-1] * 3, [1] * 3, cell)
        counts.append(sum(calls))
    # halving the cell: 4x the surface's cells; a dense grid would sample 8x
    assert 3.5 < counts[1] / counts[0] < 4.8
    assert max(calls) <= mesher.CHUNK  # the field is sampled in chunks that stay cached


@pytest.mark.parametrize("dense", [False, True])
def test_many_groups_of_blocks_number_every_vertex_once(dense):
    # more kept blocks than one group holds, the last group partial, and a surface that
    # leaves the box (a field not positive on its boundary), so the touched slots that
    # are not kept hold used edges too: every vertex numbered and placed once
    def ball(p):
        return sdf.sphere(p, 1.0, O)

    lo, hi, cell = [-0.8] * 3, [0.8] * 3, 0.03
    lat = lattice.Lattice(ball, lo, hi, cell, 1.0, 10**8)
    nk = len(lat.blocks)
    assert nk > mesher.GROUP and nk % mesher.GROUP and len(lat.touched) > nk
    grid = _lattices(ball) if dense else None
    v, t = mesher.mesh_field(ball, lo, hi, cell, grid=grid)
    use = _edge_use(t)
    assert use.max() == 2 and len(np.unique(t)) == len(v)
    assert np.abs(np.linalg.norm(v, axis=1) - 1).max() <= 5e-4 * cell  # ACCEPT of a cell
    # the open sphere's rims (where it leaves the grid) are its only edges used once
    m = trimesh.Trimesh(v, t, process=False)
    assert m.is_winding_consistent and (use == 1).any()


@pytest.mark.parametrize("dense", [False, True])
def test_the_outputs_are_frozen_and_a_mesh_shares_them(dense):
    # written straight into immutable buffers: a Mesh made of them copies nothing
    from formgraph.geometry import Mesh, is_frozen
    from formgraph.kernels.buffers import frozen_arange

    def ball(p):
        return sdf.sphere(p, 1.0, O)

    grid = _lattices(ball) if dense else None
    v, t = mesher.mesh_field(ball, [-1] * 3, [1] * 3, 0.05, grid=grid)
    assert len(v) > 1000 and is_frozen(v) and is_frozen(t) and t.dtype == np.int64
    m = Mesh.trusted(v, t.reshape(-1), frozen_arange(len(t) + 1, 3))
    assert m.vertices is v and np.shares_memory(m.face_indices, t)
    assert np.abs(np.linalg.norm(v, axis=1) - 1).max() <= 5e-4 * 0.05
    with pytest.raises(ValueError):
        v[0] = 0.0
