"""points.scatter (nodes/points/scatter.py, kernels/mesh/scatter.py): uniform by area (a KS
test), Poisson disk (no two closer than the spacing, maximal within a factor of 2),
attributes, exact surfaces, determinism, bad input."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy import stats
from scipy.spatial import cKDTree

import formgraph as fg
from formgraph.geometry import Mesh


def as_mesh(tm: trimesh.Trimesh, **point_data) -> Mesh:
    f = np.asarray(tm.faces)
    return Mesh(tm.vertices, f.reshape(-1), np.arange(0, f.size + 1, 3), point_data or None)


def scattered(geometry, budget=None, **inputs):
    g = fg.Graph() if budget is None else fg.Graph(budget=budget)
    g.add_param("g_", type="Mesh" if isinstance(geometry, Mesh) else "Surface")
    g.add("s", "points.scatter", geometry="=g_", **inputs)
    return g.evaluate("s", g_=geometry)


def strip() -> Mesh:
    # a 10 x 1 strip cut into triangles of very different sizes (uneven columns)
    xs = np.array([0, 0.1, 0.15, 2.0, 2.05, 6.0, 6.5, 10.0])
    v = np.array([[x, y, 0.0] for x in xs for y in (0.0, 1.0)])
    faces = []
    for k in range(len(xs) - 1):
        a, b, c, d = 2 * k, 2 * k + 2, 2 * k + 3, 2 * k + 1
        faces += [[a, b, c], [a, c, d]]
    return Mesh(v, faces)


def test_count_points_are_uniform_by_area_on_faces_of_any_size():
    out = scattered(strip(), count=4000, seed=1)
    assert len(out) == 4000
    x, y, z = out.xyz.T
    assert np.all(z == 0) and x.min() >= 0 and x.max() <= 10 and 0 <= y.min() and y.max() <= 1
    # x and y are uniform on [0, 10] x [0, 1] whatever the triangles
    assert stats.kstest(x / 10, "uniform").pvalue > 0.01
    assert stats.kstest(y, "uniform").pvalue > 0.01
    # each face gets its share of the area: a chi-squared test on the face counts
    face = out.point_data["face"].astype(int)
    m = strip()
    area = trimesh.Trimesh(m.vertices, np.asarray(m.face_indices).reshape(-1, 3)).area_faces
    expected = 4000 * area / area.sum()
    assert stats.chisquare(np.bincount(face, minlength=m.n_faces), expected).pvalue > 0.01


def test_the_same_seed_gives_the_same_points_and_another_seed_others():
    m = as_mesh(trimesh.creation.icosphere(subdivisions=2))
    a = scattered(m, count=50, seed=7)
    assert a == scattered(m, count=50, seed=7)
    assert not np.array_equal(a.xyz, scattered(m, count=50, seed=8).xyz)
    b = scattered(m, spacing=0.3, seed=7)
    assert b == scattered(m, spacing=0.3, seed=7)


@pytest.mark.parametrize("spacing", [0.15, 0.4])
def test_poisson_disk_keeps_the_spacing_and_is_maximal_within_a_factor_of_2(spacing):
    tm = trimesh.creation.torus(2.0, 0.7, 48, 24)
    out = scattered(as_mesh(tm), spacing=spacing, seed=3)
    d, _ = cKDTree(out.xyz).query(out.xyz, k=2)
    assert d[:, 1].min() >= spacing  # no two closer than the spacing
    # every point of the surface within twice the spacing of one (most within one)
    probe = trimesh.sample.sample_surface(tm, 50_000, seed=4)[0]
    gap, _ = cKDTree(out.xyz).query(probe)
    assert gap.max() <= 2 * spacing
    assert np.mean(gap <= spacing) > 0.97
    # as many as a random close packing holds: between 0.5 and the hexagonal 1.155 per s^2
    density = len(out) * spacing**2 / tm.area
    assert 0.5 < density < 1.155
    # on the surface
    assert trimesh.proximity.closest_point(tm, out.xyz)[1].max() < 1e-9


def test_points_carry_face_normals_faces_and_the_meshs_attributes():
    tm = trimesh.creation.box(extents=(1, 2, 3))
    v = tm.vertices
    m = as_mesh(tm, h=2 * v[:, 0] - v[:, 1] + 3 * v[:, 2]).with_data(
        {"h": 2 * v[:, 0] - v[:, 1] + 3 * v[:, 2]}, {"id": np.arange(12.0)}
    )
    out = scattered(m, count=500, seed=2)
    face = out.point_data["face"].astype(int)
    np.testing.assert_allclose(out.point_data["normal"], tm.face_normals[face], atol=1e-12)
    np.testing.assert_array_equal(out.point_data["id"], face.astype(float))
    x, y, z = out.xyz.T
    np.testing.assert_allclose(out.point_data["h"], 2 * x - y + 3 * z, atol=1e-12)
    # each point lies on its own face's plane
    np.testing.assert_allclose(
        np.einsum("ij,ij->i", out.xyz - tm.triangles[face, 0], tm.face_normals[face]), 0, atol=1e-12
    )


def test_on_an_exact_surface_the_points_and_normals_are_the_surfaces():
    g = fg.Graph()
    g.add("s", "surfaces.parametric", x="2 * cos(u)", y="2 * sin(u)", z="v", u=[0, 6], v=[0, 3])
    surf = g.evaluate("s")
    out = scattered(surf, spacing=0.25, seed=1)
    x, y, z = out.xyz.T
    np.testing.assert_allclose(np.hypot(x, y), 2.0, atol=1e-12)  # on the cylinder exactly
    n = out.point_data["normal"]
    np.testing.assert_allclose(
        np.abs(np.einsum("ij,ij->i", n, out.xyz * [0.5, 0.5, 0])), 1, atol=1e-9
    )
    d, _ = cKDTree(out.xyz).query(out.xyz, k=2)
    assert d[:, 1].min() >= 0.25
    u = out.point_data["u"]
    np.testing.assert_allclose(np.arctan2(y, x) % (2 * np.pi), u, atol=1e-9)


def test_count_or_spacing_one_of_them():
    m = as_mesh(trimesh.creation.box())
    with pytest.raises(fg.NodeError, match="give count .* or spacing .*, not both"):
        scattered(m, count=3, spacing=0.1)
    with pytest.raises(fg.NodeError, match="not neither"):
        scattered(m)


def test_a_spacing_too_small_for_the_budget_is_refused_before_it_runs():
    m = as_mesh(trimesh.creation.box(extents=(100, 100, 100)))
    with pytest.raises(fg.BudgetError, match=r"would make .* points, over the budget"):
        scattered(m, spacing=1e-3)
    # under the output bound but not the candidates': still refused, with a spacing to use
    with pytest.raises(
        fg.BudgetError,
        match=r"needs 7,500,000 candidate points, over the budget of 2,500,000: use a spacing "
        r"of 0.346",
    ):
        scattered(m, spacing=0.2, budget=2_500_000)
