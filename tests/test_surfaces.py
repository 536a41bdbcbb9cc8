"""The surfaces.* nodes: quad grids, parametric surfaces and bicubic Catmull-Rom surfaces."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg

RNG = np.random.default_rng(11)


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n")


def heights(nu: int, nv: int) -> np.ndarray:
    """A (nu, nv, 3) grid over the unit spacing with random heights."""
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    return np.stack([i, j, RNG.normal(size=(nu, nv))], axis=-1).astype(float)


def face_normals(mesh: fg.Mesh) -> np.ndarray:
    v = np.asarray(mesh.vertices)
    quads = np.asarray(mesh.face_indices).reshape(-1, 4)
    a, b, c = v[quads[:, 0]], v[quads[:, 1]], v[quads[:, 2]]
    return np.cross(b - a, c - a)


# --------------------------------------------------------------------------- grid


@pytest.mark.parametrize(
    "closed_u,closed_v,faces", [(False, False, 12), (True, False, 16), (True, True, 20)]
)
def test_grid_counts_and_orientation(closed_u, closed_v, faces):
    g = heights(4, 5)
    g[..., 2] = 0.0
    m = run("surfaces.grid", points=g.tolist(), closed_u=closed_u, closed_v=closed_v)
    assert m.n_vertices == 20 and m.n_faces == faces
    np.testing.assert_array_equal(np.asarray(m.vertices)[7], g[1, 2])  # row-major
    if not (closed_u or closed_v):
        assert np.all(face_normals(m)[:, 2] > 0)  # rows along +x, points along +y: up


def test_grid_closed_both_ways_is_a_closed_torus():
    a, b = np.meshgrid(np.linspace(0, 2 * np.pi, 12, endpoint=False),
                       np.linspace(0, 2 * np.pi, 8, endpoint=False), indexing="ij")  # fmt: skip
    pts = np.stack([(2 + np.cos(b)) * np.cos(a), (2 + np.cos(b)) * np.sin(a), np.sin(b)], -1)
    m = run("surfaces.grid", points=pts.tolist(), closed_u=True, closed_v=True)
    assert m.n_vertices - (2 * m.n_faces) + m.n_faces == 0  # V - E + F = 0 for a torus
    he = m.halfedges  # builds; raises on boundary-inconsistent or non-manifold input
    assert he is not None


def test_grid_errors_name_the_input():
    with pytest.raises(fg.NodeError, match=r"input 'points'.*row 0 has 3, row 1 has 2"):
        run("surfaces.grid", points=[[[0, 0], [1, 0], [2, 0]], [[0, 1], [1, 1]]])
    with pytest.raises(fg.NodeError, match=r"at least 2 points a row, got 1 .*3 row\(s\) of 1"):
        run("surfaces.grid", points=[[0, 0], [1, 0], [2, 0]])  # one row, written flat
    g = fg.Graph()
    g.add("c", "points.circle", count=5)
    g.add("m", "surfaces.grid", points="@c")
    with pytest.raises(fg.NodeError, match=r"input 'points'.*at least 2 rows, got 1"):
        g.evaluate("m")
    with pytest.raises(fg.NodeError, match=r"closed grid needs at least 3 points a row, got 2"):
        run("surfaces.grid", points=heights(3, 2).tolist(), closed_v=True)


def test_grid_rows_from_wires():
    g = fg.Graph()
    g.add("a", "points.circle", count=6, radius=1)
    g.add("b", "points.circle", count=6, radius=2)
    g.add("m", "surfaces.grid", points=["@a", "@b"], closed_v=True)
    m = g.evaluate("m")
    assert m.n_faces == 6


# --------------------------------------------------------------------------- parametric


def test_parametric_enneper_closed_form_and_tessellation():
    s = run(
        "surfaces.parametric",
        x="u - u**3/3 + u*v**2",
        y="v - v**3/3 + v*u**2",
        z="u**2 - v**2",
        u=[-2, 2],
        v=[-2, 2],
    )
    assert isinstance(s, fg.ParametricSurface) and s.domain_u == (-2.0, 2.0)
    u, v = 1.2, -0.7
    expect = [u - u**3 / 3 + u * v**2, v - v**3 / 3 + v * u**2, u**2 - v**2]
    np.testing.assert_allclose(s.evaluate(u, v), expect)
    m = s.tessellate(8, 6)
    assert m.n_vertices == 9 * 7 and m.n_faces == 48


def test_parametric_uses_graph_params(tmp_path):
    path = tmp_path / "torus.yaml"
    path.write_text(
        "formgraph: 1\nparams: {R: 3.0, r: 1.0}\nnodes:\n  t:\n    type: surfaces.parametric\n"
        "    x: (R + r*cos(v)) * cos(u)\n    y: (R + r*cos(v)) * sin(u)\n    z: r * sin(v)\n"
        '    u: ["=0", "=2*pi"]\n    v: ["=0", "=2*pi"]\n'
    )
    g = fg.load(path, out_dir=tmp_path)
    np.testing.assert_allclose(g.evaluate("t").evaluate(0.0, 0.0), [4, 0, 0], atol=1e-12)
    np.testing.assert_allclose(g.evaluate("t", R=5.0).evaluate(0.0, np.pi), [4, 0, 0], atol=1e-12)


def test_parametric_surface_errors():
    with pytest.raises(fg.NodeError, match=r"z = 'log\(u\)' is not finite at u = 0, v = 0"):
        run("surfaces.parametric", x="u", y="v", z="log(u)")
    with pytest.raises(fg.NodeError, match=r"input 'v'.*start < end, got \[1.0, 1.0\]"):
        run("surfaces.parametric", x="u", y="v", z="0", v=[1, 1])
    g = fg.Graph()
    g.add("s", "surfaces.parametric", x="u", y="w", z="0")
    with pytest.raises(fg.GraphError, match=r"input 'y'"):
        g.check()


# --------------------------------------------------------------------------- bicubic


@pytest.mark.parametrize("closed_u,closed_v", [(False, False), (True, False), (True, True)])
def test_bicubic_passes_through_every_point(closed_u, closed_v):
    grid = heights(4, 5) if not closed_u else RNG.normal(size=(4, 5, 3))
    s = run("surfaces.bicubic", points=grid.tolist(), closed_u=closed_u, closed_v=closed_v)
    assert isinstance(s, fg.NurbsSurface) and (s.degree_u, s.degree_v) == (3, 3)
    u = np.arange(4 + closed_u, dtype=float)
    v = np.arange(5 + closed_v, dtype=float)
    got = s.evaluate_grid(u, v)
    expect = grid
    if closed_u:
        expect = np.concatenate([expect, expect[:1]], axis=0)
    if closed_v:
        expect = np.concatenate([expect, expect[:, :1]], axis=1)
    np.testing.assert_allclose(got, expect, atol=1e-12)


def test_bicubic_is_c1_across_patch_lines_and_seams():
    grid = RNG.normal(size=(5, 4, 3))
    s = run("surfaces.bicubic", points=grid.tolist(), closed_u=True)
    assert s.domain_u == (0.0, 5.0)  # five segments around
    v = np.linspace(0, 3, 7)
    h = 1e-6

    def at(u):
        return s.evaluate(np.full_like(v, u), v)

    for u0 in (1.0, 2.0, 3.0, 4.0, 5.0):
        right_of = 0.0 if u0 == 5.0 else u0  # the seam continues at u = 0
        np.testing.assert_allclose(at(u0), at(right_of), atol=1e-12)
        left = (at(u0) - at(u0 - h)) / h
        right = (at(right_of + h) - at(right_of)) / h
        np.testing.assert_allclose(left, right, atol=1e-4)


def test_bicubic_rows_are_catmull_rom_curves():
    grid = heights(5, 4)
    s = run("surfaces.bicubic", points=grid.tolist(), tension=0.3)
    t = np.linspace(0, 4, 13)
    for j in range(4):
        c = run("curves.catmull_rom", points=grid[:, j].tolist(), ends="clamped", tension=0.3)
        np.testing.assert_allclose(s.evaluate(t, np.full_like(t, j)), c.evaluate(t), atol=1e-12)


def test_bicubic_errors_and_budget():
    with pytest.raises(fg.NodeError, match=r"input 'points'.*at least 3 rows, got 2"):
        run("surfaces.bicubic", points=heights(2, 4).tolist(), closed_u=True)
    g = fg.Graph(budget=100)
    g.add("s", "surfaces.bicubic", points=heights(5, 5).tolist())
    with pytest.raises(fg.BudgetError, match=r"control points, over the budget of 100"):
        g.evaluate("s")


@settings(max_examples=20, deadline=None)
@given(
    nu=st.integers(2, 6),
    nv=st.integers(2, 6),
    closed_u=st.booleans(),
    closed_v=st.booleans(),
    seed=st.integers(0, 2**31),
)
def test_bicubic_random_grids(nu, nv, closed_u, closed_v, seed):
    """Random grids (repeated points allowed): finite, through every point."""
    grid = np.random.default_rng(seed).integers(-2, 3, size=(nu, nv, 3)).astype(float)
    g = fg.Graph()
    g.add("s", "surfaces.bicubic", points=grid.tolist(), closed_u=closed_u, closed_v=closed_v)
    if (closed_u and nu < 3) or (closed_v and nv < 3):
        with pytest.raises(fg.NodeError, match="at least 3"):
            g.evaluate("s")
        return
    s = g.evaluate("s")
    assert np.isfinite(np.asarray(s.control_points)).all()
    got = s.evaluate_grid(np.arange(nu, dtype=float), np.arange(nv, dtype=float))
    np.testing.assert_allclose(got, grid, atol=1e-12)
