"""viewer/style.py's shading in numpy against the two VTK filters it stands in for
(vtkPolyDataNormals splitting at the feature angle, vtkFeatureEdges): the same points,
faces, lines and arrays in the same order, normals to float32 rounding."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pv = pytest.importorskip("pyvista")

from formgraph.viewer import style  # noqa: E402


def assert_same(mine, theirs) -> None:
    assert mine.n_points == theirs.n_points
    assert mine.points.dtype == theirs.points.dtype
    assert np.array_equal(mine.points, theirs.points)
    for cells in ("faces", "lines", "verts"):
        assert np.array_equal(getattr(mine, cells), getattr(theirs, cells)), cells
    for a, b in ((mine.point_data, theirs.point_data), (mine.cell_data, theirs.cell_data)):
        assert list(a.keys()) == list(b.keys())
        assert a.active_scalars_name == b.active_scalars_name
        assert a.active_normals_name == b.active_normals_name
        for name in a.keys():
            x, y = np.asarray(a[name]), np.asarray(b[name])
            assert x.dtype == y.dtype, name
            if name == "Normals":
                np.testing.assert_allclose(x, y, atol=2e-7)
            else:
                assert np.array_equal(x, y), name


def check(data) -> None:
    assert style._topology_of(data) is not None  # the numpy path applies
    mine = style.shaded(data.copy())
    theirs = style._shaded_vtk(data.copy())
    assert_same(mine[0], theirs[0])
    assert_same(mine[1], theirs[1])


def _clean(data):
    for name in ("Normals", "TCoords"):
        if name in data.point_data.keys():
            data.point_data.remove(name)
    return data


def _polys(points, cells) -> pv.PolyData:
    flat = np.concatenate([[len(c), *c] for c in cells])
    return pv.PolyData(np.asarray(points, dtype=float), faces=flat)


SHAPES = {
    "welded cube": lambda: _clean(pv.Cube().clean()),
    "unwelded cube (coincident points merged in the lines)": lambda: _clean(pv.Cube()),
    "sphere (float32 points, no lines)": lambda: _clean(pv.Sphere()),
    "cylinder": lambda: _clean(pv.Cylinder(resolution=30).clean()),
    "open plane": lambda: _clean(pv.Plane(i_resolution=5, j_resolution=4)),
    "three quads on an edge, a bowtie vertex": lambda: _polys(
        [[0, 0, 0], [0, 0, 1], [1, 0, 0], [1, 0, 1], [0, 1, 0], [0, 1, 1], [-1, -1, 0]]
        + [[-1, -1, 1], [2, 2, 2], [3, 2, 2], [2, 3, 2.5]],
        [[0, 1, 3, 2], [0, 4, 5, 1], [0, 6, 7, 1], [2, 8, 9], [2, 9, 10]],
    ),
    "a non-planar pentagon on triangles": lambda: _polys(
        [[0, 0, 0], [1, 0, 0.2], [1.3, 1, 0], [0.5, 1.6, 0.3], [-0.3, 1, 0], [0.5, 0.5, -1]],
        [[0, 1, 2, 3, 4], [0, 5, 1], [1, 5, 2], [2, 5, 3], [3, 5, 4], [4, 5, 0]],
    ),
}


@pytest.mark.parametrize("name", list(SHAPES))
def test_shaded_matches_the_vtk_filters(name):
    check(SHAPES[name]())


def test_arrays_and_their_roles_are_carried_over():
    data = _clean(pv.Sphere(theta_resolution=9, phi_resolution=7).clean())
    rng = np.random.default_rng(3)
    data.points += rng.normal(scale=0.03, size=data.points.shape).astype(np.float32)
    data.point_data["weight"] = rng.random(data.n_points)
    data.point_data["colour"] = rng.random((data.n_points, 3)).astype(np.float32)
    data.point_data.active_scalars_name = "colour"
    data.cell_data["face"] = np.arange(data.n_cells)
    check(data)


@settings(max_examples=25, deadline=None)
@given(
    nu=st.integers(2, 6),
    nv=st.integers(2, 6),
    bend=st.floats(0.0, 3.0),
    seed=st.integers(0, 2**16),
    flips=st.integers(0, 3),
)
def test_a_random_bent_grid_matches(nu, nv, bend, seed, flips):
    # a grid of quads and triangles folded by a random amount (edges on both sides of the
    # feature angle), some faces turned over (the filters do not reorder them)
    rng = np.random.default_rng(seed)
    u, v = np.meshgrid(np.arange(nu + 1.0), np.arange(nv + 1.0), indexing="ij")
    z = bend * np.abs(u - nu / 2) + rng.normal(scale=0.05, size=u.shape)
    pts = np.column_stack([u.ravel(), v.ravel(), z.ravel()])
    idx = np.arange(len(pts)).reshape(nu + 1, nv + 1)
    cells = []
    for i in range(nu):
        for j in range(nv):
            q = [idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]]
            cells += [q] if rng.random() < 0.5 else [q[:3], [q[0], q[2], q[3]]]
    for k in rng.choice(len(cells), size=min(flips, len(cells)), replace=False):
        cells[k] = cells[k][::-1]
    check(_polys(pts, cells))


def test_one_topology_serves_moved_points_and_a_changed_split():
    # the same faces, the vertices moved so that an edge crosses the feature angle: the
    # kept face structure gives what the filters give for each
    def folded(angle_deg: float):
        a = np.radians(angle_deg)
        pts = [[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0]]
        pts += [[-np.cos(a), 0, np.sin(a)], [-np.cos(a), 1, np.sin(a)]]
        return _polys(pts, [[0, 2, 3, 1], [0, 1, 5, 4]])

    gentle, sharp = folded(10.0), folded(60.0)
    assert style._topology_of(gentle) is style._topology_of(sharp)
    for data in (gentle, sharp, gentle):
        check(data)
    assert style.shaded(gentle)[0].n_points == 6  # no split: one normal per vertex
    assert style.shaded(sharp)[0].n_points == 8  # split along the fold


@pytest.mark.parametrize(
    "make",
    [
        lambda: pv.PolyData(  # a line beside the faces
            np.eye(3), faces=[3, 0, 1, 2], lines=[2, 0, 1]
        ),
        lambda: pv.Sphere(),  # normals of its own
        lambda: _polys([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2, 1]]),  # a vertex twice
    ],
)
def test_what_numpy_does_not_do_goes_through_the_filters(make):
    data = make()
    assert style._topology_of(data) is None
    style.shaded(data)  # (the filters' own output)


def test_a_mesh_too_large_to_keep_goes_through_the_filters(monkeypatch):
    plane = _clean(pv.Plane(i_resolution=10, j_resolution=10))  # 400 corners
    assert style._topology_of(plane) is not None
    monkeypatch.setattr(style, "_MAX_CORNERS", 399)
    assert style._topology_of(plane) is None
    assert_same(style.shaded(plane.copy())[0], style._shaded_vtk(plane.copy())[0])
