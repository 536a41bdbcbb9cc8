"""Doo-Sabin in its sparse cosine form (formgraph.kernels.mesh.subdivision) against the
per-size circulant weights it replaced (tests/doo_sabin_reference.py) and against the
uniform biquadratic B-spline it generalises, evaluated by scipy: on a regular quad grid a
Doo-Sabin level is knot insertion, so the refined mesh is the control net of the same
surface, and the centroid of each V-face is the surface at its vertex."""

from __future__ import annotations

import numpy as np
import pytest
from doo_sabin_reference import doo_sabin_points
from hypothesis import given, settings
from hypothesis import strategies as st
from mesh_shapes import antiprism, cube, grid, pillow, prism, quad_and_pentagon, split_quads, torus
from scipy.interpolate import BSpline

from formgraph.kernels.mesh import build_halfedges
from formgraph.kernels.mesh.subdivision import doo_sabin

RNG = np.random.default_rng(28)


def _mixed():
    v, fi, fo = torus(10, 8)
    return (v, *split_quads(fi, fo, RNG.random(fo.size - 1) < 0.4))


MESHES = {
    "cube": cube,
    "prism7": lambda: prism(7),
    "antiprism5": lambda: antiprism(5),
    "open grid": lambda: grid(5, 4),
    "pillow": pillow,
    "quad and pentagon": quad_and_pentagon,
    "triangles and quads": _mixed,
}


@pytest.mark.parametrize("name", MESHES)
def test_each_level_matches_the_per_size_weights(name):
    v, fi, fo = MESHES[name]()
    x = np.c_[np.asarray(v, float), RNG.normal(size=(len(v), 2))]  # two attribute columns
    for _ in range(3):
        expected = doo_sabin_points(x, build_halfedges(fi, fo, len(x)))
        x, fi, fo = doo_sabin(x, fi, fo, 1)
        np.testing.assert_allclose(x, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_a_face_of_thousands_of_corners_costs_four_entries_a_corner():
    """The circulant of a 20,000-gon would be 3.2 GB; the cosine form is exact as well."""
    v, fi, fo = prism(20_000)
    out, _, _ = doo_sabin(v, fi, fo, 1)
    small = prism(300)
    np.testing.assert_allclose(
        doo_sabin(*small, 1)[0],
        doo_sabin_points(np.asarray(small[0], float), build_halfedges(small[1], small[2], 600)),
        atol=1e-12,
    )
    # a cap's corner points are the cap's corners pulled a quarter of the way to its centre
    # plus the circulant's cosine terms: on a regular polygon, a circle of radius
    # (1/4 + 1/(2k) * k/2) r = r / 2 around the centre
    cap = out[:20_000]
    np.testing.assert_allclose(np.linalg.norm(cap[:, :2], axis=1), 0.5, atol=1e-12)


def _periodic_design(n: int, at: np.ndarray) -> np.ndarray:
    """Rows: the uniform periodic quadratic B-spline basis of ``n`` control points at ``at``
    (scipy), the control points wrapped."""
    knots = np.arange(-2.0, n + 3.0)
    m = BSpline.design_matrix(at, knots, 2).toarray()  # (len(at), n + 2)
    m[:, :2] += m[:, n:]
    return m[:, :n]


@settings(max_examples=12, deadline=None)
@given(
    nu=st.integers(4, 9),
    nv=st.integers(4, 9),
    seed=st.integers(0, 2**32 - 1),
    levels=st.integers(1, 2),
)
def test_regular_grid_refines_the_biquadratic_bspline(nu, nv, seed, levels):
    """The torus grid is regular (every vertex of valence 4 among quads), and so is every
    Doo-Sabin level of it: the centroid of each last-level V-face is the surface of the
    original net at that vertex's parameter, which scipy evaluates."""
    v, fi, fo = torus(nu, nv)
    v = v + np.random.default_rng(seed).normal(scale=0.3, size=v.shape)  # any net
    net = v.reshape(nu, nv, 3)
    # the surface at every vertex (i, j) of the original net: parameters i - 1/2, j - 1/2
    bu = _periodic_design(nu, np.mod(np.arange(nu) - 0.5, nu))
    bv = _periodic_design(nv, np.mod(np.arange(nv) - 0.5, nv))
    at_vertices = np.einsum("ia,jb,abd->ijd", bu, bv, net).reshape(-1, 3)

    x, sfi, sfo = v, fi, fo
    for _ in range(levels - 1):
        x, sfi, sfo = doo_sabin(x, sfi, sfo, 1)
    he = build_halfedges(sfi, sfo, len(x))
    out, ofi, ofo = doo_sabin(x, sfi, sfo, 1)
    assert np.all(np.diff(ofo) == 4) and len(ofo) - 1 == he.n_faces + he.n_edges + len(x)
    # the V-faces come last, one per vertex in the order of the fans (here one per vertex)
    vfaces = ofi[ofo[he.n_faces + he.n_edges] :].reshape(-1, 4)
    centroid = out[vfaces].mean(axis=1)
    fan_vertex = he.fans.vertex
    if levels == 1:
        np.testing.assert_allclose(centroid, at_vertices[fan_vertex], atol=1e-12)
    else:
        # level 2: the vertices of level 1 lie on the same surface net; check the tensor
        # rule (1/8, 3/4, 1/8) x (1/8, 3/4, 1/8) on the level-1 net instead, which is the
        # same spline: each V-face centroid is 9/16 of its vertex, 3/32 of each edge
        # neighbour and 1/64 of each diagonal one
        nxt = he.vertex
        h = np.arange(he.n_halfedges)
        edge_sum = np.zeros_like(x)
        np.add.at(edge_sum, he.origin, x[nxt])
        diagonal = he.vertex[he.next[h]]  # across the face from origin(h)
        diag_sum = np.zeros_like(x)
        np.add.at(diag_sum, he.origin, x[diagonal])
        rule = 9 / 16 * x + 3 / 32 * edge_sum + 1 / 64 * diag_sum
        np.testing.assert_allclose(centroid, rule[fan_vertex], atol=1e-12)
