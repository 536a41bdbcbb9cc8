"""The shared sort of integer keys with their positions (kernels/mesh/keys.py)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from formgraph.kernels.mesh.keys import sort_keys


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.integers(0, 40), min_size=0, max_size=300),
    st.sampled_from([41, 2**30, 2**62]),
)
def test_sort_keys_is_a_stable_argsort(keys, bound):
    # small bounds pack key and position into one word; 2**62 leaves no room: argsort
    key = np.array(keys, dtype=np.int64)
    order, skey = sort_keys(key, bound)
    np.testing.assert_array_equal(order, np.argsort(key, kind="stable"))
    np.testing.assert_array_equal(skey, key[order])
    assert order.dtype == np.int64 and skey.dtype == np.int64


@pytest.mark.parametrize("bound", [2**20, 2**62])
def test_sort_keys_of_large_keys_with_runs(bound):
    rng = np.random.default_rng(3)
    key = np.repeat(rng.integers(0, min(bound, 2**40), 5000), rng.integers(1, 4, 5000))
    key = key[rng.permutation(key.size)] % bound
    order, skey = sort_keys(key, bound)
    np.testing.assert_array_equal(order, np.argsort(key, kind="stable"))
    np.testing.assert_array_equal(skey, np.sort(key))
