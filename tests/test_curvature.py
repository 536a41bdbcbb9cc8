"""attr.curvature (nodes/attr/curvature.py, kernels/mesh/curvature.py): closed forms on a
sphere and a cylinder, Gauss-Bonnet on closed meshes, trimesh's angle defects."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import formgraph as fg
from formgraph.geometry import Mesh
from formgraph.kernels.mesh import curvature as kcurv


def as_mesh(tm: trimesh.Trimesh) -> Mesh:
    f = np.asarray(tm.faces)
    return Mesh(tm.vertices, f.reshape(-1), np.arange(0, f.size + 1, 3))


def curved(m: Mesh) -> Mesh:
    g = fg.Graph()
    g.add_param("m_", type="Mesh")
    g.add("k", "attr.curvature", mesh="=m_")
    return g.evaluate("k", m_=m)


@pytest.mark.parametrize("r", [0.5, 3.0])
def test_a_sphere_has_mean_curvature_one_over_r_and_gaussian_one_over_r_squared(r):
    out = curved(as_mesh(trimesh.creation.icosphere(subdivisions=4, radius=r)))
    np.testing.assert_allclose(out.point_data["mean_curvature"], 1 / r, rtol=2e-3)
    np.testing.assert_allclose(out.point_data["gaussian_curvature"], 1 / r**2, rtol=5e-3)
    # faces turned inward: the mean curvature changes sign, the Gaussian does not
    tm = trimesh.creation.icosphere(subdivisions=4, radius=r)
    inward = curved(as_mesh(trimesh.Trimesh(tm.vertices, tm.faces[:, ::-1], process=False)))
    np.testing.assert_allclose(inward.point_data["mean_curvature"], -1 / r, rtol=2e-3)
    np.testing.assert_allclose(inward.point_data["gaussian_curvature"], 1 / r**2, rtol=5e-3)


def test_gauss_bonnet_four_pi_on_a_sphere_and_zero_on_a_torus():
    for tm, chi in [
        (trimesh.creation.icosphere(subdivisions=3), 2),
        (trimesh.creation.box(extents=(1, 2, 3)), 2),
        (trimesh.creation.torus(1.0, 0.3, 40, 16), 0),
    ]:
        v, t = tm.vertices, tm.faces
        out = curved(as_mesh(tm))
        area = kcurv.mixed_areas(v, t)
        np.testing.assert_allclose(area.sum(), tm.area, rtol=1e-12)  # the mixed areas tile it
        total = float(np.sum(out.point_data["gaussian_curvature"] * area))
        assert abs(total - 2 * np.pi * chi) < 1e-9
        # the angle defects are trimesh's, vertex by vertex
        np.testing.assert_allclose(
            out.point_data["gaussian_curvature"] * area, tm.vertex_defects, atol=1e-12
        )


def test_a_cylinder_has_mean_curvature_one_over_2r_and_no_gaussian_curvature():
    # an open tube, a grid of near-square cells (rows as far apart as the columns), each
    # cell split along a diagonal
    r, cols, rows = 2.0, 96, 40
    h = 2 * np.pi * r / cols
    a, z = np.meshgrid(np.arange(cols) * 2 * np.pi / cols, np.arange(rows) * h)
    v = np.column_stack([r * np.cos(a.ravel()), r * np.sin(a.ravel()), z.ravel()])
    i, j = np.meshgrid(np.arange(cols), np.arange(rows - 1))
    p, q = j * cols + i, j * cols + (i + 1) % cols
    t = np.concatenate([np.stack([p, q, q + cols], -1), np.stack([p, q + cols, p + cols], -1)])
    with pytest.warns(fg.FormgraphWarning, match="open or non-manifold edge"):
        out = curved(Mesh(v, t.reshape(-1), np.arange(0, t.size + 1, 3)))
    inner = slice(cols, (rows - 1) * cols)  # all but the two rims
    np.testing.assert_allclose(out.point_data["mean_curvature"][inner], 1 / (2 * r), rtol=1e-3)
    np.testing.assert_allclose(out.point_data["gaussian_curvature"][inner], 0, atol=1e-9)


def test_an_open_boundary_gets_zero_and_a_warning():
    tm = trimesh.creation.icosphere(subdivisions=2)
    open_ = trimesh.Trimesh(tm.vertices, tm.faces[tm.vertices[tm.faces].mean(axis=1)[:, 2] > -0.5])
    with pytest.warns(fg.FormgraphWarning, match=r"\d+ points lie on an open or non-manifold edge"):
        out = curved(as_mesh(open_))
    edges = open_.edges_sorted[trimesh.grouping.group_rows(open_.edges_sorted, require_count=1)]
    rim = np.unique(edges)
    assert np.all(out.point_data["mean_curvature"][rim] == 0)
    assert np.all(out.point_data["gaussian_curvature"][rim] == 0)
    inner = np.setdiff1d(np.arange(len(open_.vertices)), rim)
    assert np.all(out.point_data["gaussian_curvature"][inner] > 0)
