"""Hostile smoothing: mesh.smooth's strength, and keep_volume on parts with no volume."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg


def _smooth(mesh, **inputs):
    g = fg.Graph()
    g.add("s", "mesh.smooth", mesh=mesh, **inputs)
    return g.evaluate("s")


def _noisy_torus() -> fg.Mesh:
    """A torus of 32 x 16 quads (a bipartite graph: its umbrella operator reaches
    eigenvalue 2) with a little noise, so every frequency is present."""
    g = fg.Graph()
    g.add("t", "mesh.torus", major=3, minor=1, segments_u=32, segments_v=16)
    t = g.evaluate("t")
    rng = np.random.default_rng(0)
    return fg.Mesh(
        t.vertices + rng.normal(0, 1e-3, t.vertices.shape), t.face_indices, t.face_offsets
    )


def test_an_unstable_taubin_strength_is_refused_not_blown_up():
    # at 0.72 the old node returned coordinates of 1e78 after 2,000 steps
    with pytest.raises(
        fg.NodeError, match=r"input 'strength'.*stable up to strength 0\.7; at 0\.72"
    ):
        _smooth(_noisy_torus(), strength=0.72, iterations=2000, keep_volume=False)


def test_the_largest_taubin_strength_and_a_full_laplacian_stay_bounded():
    m = _noisy_torus()
    for inputs in ({"strength": 0.7}, {"strength": 1.0, "method": "laplacian"}):
        out = _smooth(m, iterations=2000, **inputs)
        # bounded: the torus's own extent (3 + 1), nothing grows out of it
        assert np.abs(out.vertices).max() <= 4.01


def test_keep_volume_leaves_a_closed_part_of_no_volume_as_the_filter_makes_it():
    # a triangle and its back face: every edge on two faces, a volume of 0 (nothing to
    # scale to, no division by it); and a tetrahedron wound inside out (negative volume)
    flat = fg.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 1]])
    out = _smooth(flat, iterations=50)
    assert np.isfinite(out.vertices).all()
    np.testing.assert_array_equal(
        out.vertices, _smooth(flat, iterations=50, keep_volume=False).vertices
    )
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    inside_out = fg.Mesh(v, [[0, 1, 2], [0, 3, 1], [1, 3, 2], [0, 2, 3]])
    assert inside_out.volume == pytest.approx(-1 / 6)
    assert _smooth(inside_out, iterations=50).volume == pytest.approx(-1 / 6, rel=1e-12)
