"""Vertices on cell edges (engine/kernels/field/roots.py): the cubic guess, the root steps."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from formgraph.kernels.field import roots


@settings(max_examples=50, deadline=None)
@given(st.floats(0.05, 0.95), st.floats(-0.5, 0.5), st.floats(-0.3, 0.3), st.floats(0.5, 2.0))
def test_the_guess_is_the_root_of_a_cubic_sampled_at_four_points(r, b, c, k):
    # g(t) = k (t - r) (1 + b (t - r) + c (t - r)^2), increasing on [0, 1] for these
    # coefficients: the cubic through g(-1), g(0), g(1), g(2) is g, so its root is r
    def g(t):
        u = t - r
        return k * u * (1 + b * u + c * u * u)

    ts = np.linspace(0, 1, 201)
    if np.any(np.diff(g(ts)) <= 0):
        return
    fm, fa, fb, fq = (np.array([g(t)]) for t in (-1.0, 0.0, 1.0, 2.0))
    t = roots.guess(fm, fa, fb, fq)
    assert abs(t[0] - r) < 2e-3  # two Newton steps from the linear guess
    lin = roots.guess(np.array([np.nan]), fa, fb, np.array([np.nan]))
    assert lin[0] == fa[0] / (fa[0] - fb[0])  # neither neighbour known: linear


def test_roots_land_on_the_sphere_within_the_accepted_error():
    rng = np.random.default_rng(3)
    d = rng.normal(size=(2000, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    axis = rng.integers(0, 3, 2000)
    cell = 0.1
    # edges of length `cell` along an axis that cross the unit sphere
    hit = d - np.eye(3)[axis] * cell * rng.uniform(0.01, 0.99, 2000)[:, None]
    pa, pb = hit, hit + np.eye(3)[axis] * cell
    f = lambda p: np.linalg.norm(p, axis=1) - 1.0  # noqa: E731
    fa, fb = f(pa), f(pb)
    ok = (fa < 0) != (fb < 0)
    v = roots.roots_on_segments(f, pa[ok], pb[ok], fa[ok], fb[ok], 8, cell)
    assert np.abs(f(v)).max() <= roots.ACCEPT * cell
    t = np.einsum("ij,ij->i", v - pa[ok], (pb - pa)[ok]) / cell**2
    assert (t >= roots.END_GAP - 1e-12).all() and (t <= 1 - roots.END_GAP + 1e-12).all()
