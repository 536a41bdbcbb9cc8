"""Knot insertion on surfaces, in u and in v (A5.3), against geomdl's insert_knot."""

from __future__ import annotations

import numpy as np
import pytest
from geomdl import operations
from hypothesis import given, settings
from hypothesis import strategies as st
from nurbs_shapes import geomdl_surface

from formgraph.kernels import nurbs as K


def random_surface(rng, pu, pv, rational):
    nu, nv = pu + 1 + int(rng.integers(0, 4)), pv + 1 + int(rng.integers(0, 4))
    cp = rng.normal(size=(nu, nv, 3))
    w = rng.uniform(0.4, 2.5, (nu, nv)) if rational else None
    ku = np.concatenate(
        [np.zeros(pu + 1), np.sort(rng.uniform(0, 1, nu - pu - 1)), np.ones(pu + 1)]
    )
    kv = np.concatenate(
        [np.zeros(pv + 1), np.sort(rng.uniform(0, 1, nv - pv - 1)), np.ones(pv + 1)]
    )
    return cp, pu, pv, ku, kv, w


@settings(max_examples=30, deadline=None)
@given(
    pu=st.integers(1, 4),
    pv=st.integers(1, 4),
    direction=st.sampled_from(["u", "v"]),
    times=st.integers(1, 3),
    t=st.floats(0.05, 0.95),
    rational=st.booleans(),
    seed=st.integers(0, 10_000),
)
def test_surface_knot_insertion_matches_geomdl(pu, pv, direction, times, t, rational, seed):
    surf = random_surface(np.random.default_rng(seed), pu, pv, rational)
    times = min(times, pu if direction == "u" else pv)
    cp, qu, qv, ku, kv, w = K.insert_knot_surface(*surf, t, times, direction)
    ref = geomdl_surface(*surf)
    operations.insert_knot(ref, [t, None] if direction == "u" else [None, t],
                           [times, 0] if direction == "u" else [0, times])  # fmt: skip
    np.testing.assert_allclose(ku, ref.knotvector_u, atol=1e-14)
    np.testing.assert_allclose(kv, ref.knotvector_v, atol=1e-14)
    size = (ref.ctrlpts_size_u, ref.ctrlpts_size_v)
    assert cp.shape[:2] == size
    np.testing.assert_allclose(cp.reshape(-1, 3), np.array(ref.ctrlpts), atol=1e-10)
    if rational:
        np.testing.assert_allclose(w.reshape(-1), ref.weights, atol=1e-10)
    # the surface itself does not change
    uv = np.random.default_rng(seed + 1).uniform(0, 1, (50, 2))
    before = K.surface_evaluate(*surf, uv[:, 0], uv[:, 1])
    after = K.surface_evaluate(cp, qu, qv, ku, kv, w, uv[:, 0], uv[:, 1])
    np.testing.assert_allclose(after, before, atol=1e-12)


def test_surface_knot_insertion_refuses_too_many_and_outside():
    surf = random_surface(np.random.default_rng(0), 2, 3, False)
    with pytest.raises(ValueError, match="exceed the degree 2"):
        K.insert_knot_surface(*surf, 0.5, 3, "u")
    with pytest.raises(ValueError, match="outside"):
        K.insert_knot_surface(*surf, 1.5, 1, "v")
    with pytest.raises(ValueError, match="direction"):
        K.insert_knot_surface(*surf, 0.5, 1, "w")
