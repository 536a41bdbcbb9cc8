"""Hostile CPU: parameters that used to cost minutes (or never end) are fast, capped, or
counted against the budget."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg
from formgraph.kernels import nurbs as K


def _star(k: int) -> list[list[float]]:
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    r = np.where(np.arange(k) % 2 == 0, 10.0, 4.0)
    return np.column_stack([r * np.cos(t), r * np.sin(t), np.zeros(k)]).tolist()


def test_elevating_a_long_curve_by_29_keeps_it_exactly():
    # took 27 s as 29 one-degree steps; one step of 29 is a single pass
    rng = np.random.default_rng(4)
    cp = rng.normal(size=(1000, 3))
    knots = K.clamped_uniform_knots(1000, 3)
    g = fg.Graph()
    g.add("c", "nurbs.curve", points=cp.tolist())
    g.add("e", "nurbs.elevate_degree", curve="@c", times=29)
    e = g.evaluate("e")
    assert e.degree == 32
    t = rng.uniform(0, 1, 300)
    ref = K.curve_evaluate(cp, 3, knots, None, t)
    assert np.abs(np.asarray(e.evaluate(t)) - ref).max() < 1e-9
    values, counts = np.unique(np.asarray(e.knots), return_counts=True)
    assert np.all(counts[1:-1] == 30) and counts[0] == counts[-1] == 33


def test_triangulating_a_concave_star_is_counted_against_the_budget():
    g = fg.Graph(budget=10_000)
    g.add("m", "mesh.from_faces", vertices=_star(1200), faces=[list(range(1200))])
    g.add("t", "mesh.triangulate", mesh="@m")
    with pytest.raises(fg.BudgetError, match="triangle-corner tests of ear clipping"):
        g.evaluate("t")


@pytest.mark.parametrize("k", [1200, 10_000])
def test_large_concave_stars_triangulate(k):
    # 1,200 corners took 29 s (n^3 ear clipping)
    g = fg.Graph()
    g.add("m", "mesh.from_faces", vertices=_star(k), faces=[list(range(k))])
    g.add("t", "mesh.triangulate", mesh="@m")
    t = g.evaluate("t")
    assert t.n_faces == k - 2
    v = np.asarray(t.vertices)
    tri = np.asarray(t.face_indices).reshape(-1, 3)
    cross = np.cross(v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]])[:, 2]
    assert np.all(cross > 0)
    x, y = v[:, 0], v[:, 1]
    area = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    assert 0.5 * cross.sum() == pytest.approx(area, rel=1e-12)


def test_marching_squares_smoothing_is_capped():
    g = fg.Graph()
    g.add("c", "nurbs.circle")
    g.add("o", "offset.marching_squares", curves=["@c"], distance=0.5, smooth=100_000)
    with pytest.raises(fg.GraphError, match=r"input 'smooth': must be <= 100"):
        g.evaluate("o")


def test_marching_squares_smoothing_passes_are_budgeted():
    g = fg.Graph(budget=10_000)  # the grid has 2,704 cells, the loop about 190 vertices
    g.add("c", "nurbs.circle")
    g.add("o", "offset.marching_squares", curves=["@c"], distance=0.5, smooth=100)
    # the distance queries (each (point, segment) pair they test counts) come before the
    # smoothing and reach this small budget first: either way the work is refused up front
    with pytest.raises(fg.FormgraphError, match="input '(smooth|curves)'.*(vertex moves|pairs)"):
        g.evaluate("o")


def test_elevation_work_is_budgeted():
    g = fg.Graph(budget=100_000)
    g.add("pts", "points.random", count=1000, seed=2)
    g.add("c", "nurbs.curve", points="@pts")
    g.add("e", "nurbs.elevate_degree", curve="@c", times=29)
    with pytest.raises(fg.BudgetError, match="blossom steps"):
        g.evaluate("e")


def test_many_small_concave_faces_are_budgeted_too():
    star = np.array(_star(20))
    verts = np.concatenate([star + [30.0 * i, 0, 0] for i in range(200)])
    faces = [list(range(20 * i, 20 * i + 20)) for i in range(200)]
    g = fg.Graph(budget=1_000_000)  # 200 faces x 20^3 = 1.6M corner tests at worst
    g.add("m", "mesh.from_faces", vertices=verts.tolist(), faces=faces)
    g.add("t", "mesh.triangulate", mesh="@m")
    with pytest.raises(fg.BudgetError, match="triangle-corner tests"):
        g.evaluate("t")
    g2 = fg.Graph()
    g2.add("m", "mesh.from_faces", vertices=verts.tolist(), faces=faces)
    g2.add("t", "mesh.triangulate", mesh="@m")
    assert g2.evaluate("t").n_faces == 200 * 18
