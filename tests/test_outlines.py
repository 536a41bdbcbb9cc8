"""nodes._outlines: the region plumbing of the cutting nodes (the knots of the outlines; the
rest is tested through the nodes in test_cutting.py and hostile/test_cutting.py)."""

from __future__ import annotations

import numpy as np
import pytest

from formgraph.nodes import _outlines


@pytest.mark.parametrize("rings", [1, 5, _outlines._FEW, _outlines._FEW + 1, 200])
def test_chord_knots_are_each_rings_running_length_with_doubled_ends(rings):
    # both ways of making them (a ring at a time, one scatter for many) against the
    # definition, one ring at a time: [0, 0, running chord length, its last value again]
    rng = np.random.default_rng(rings)
    sizes = rng.integers(4, 40, rings)
    offsets = np.r_[0, np.cumsum(sizes)]
    seg = rng.uniform(0.0, 2.0, offsets[-1] - 1)  # the jumps between rings are ignored
    knots = _outlines.chord_knots(seg, offsets)
    atol = 1e-14 * seg.sum()  # many rings: one running sum, each ring's start taken off
    assert len(knots) == offsets[-1] + 2 * rings
    for i in range(rings):
        a, b = offsets[i], offsets[i + 1]
        run = np.r_[0.0, np.cumsum(seg[a : b - 1])]
        np.testing.assert_allclose(
            knots[a + 2 * i : b + 2 * i + 2], np.r_[0.0, run, run[-1]], rtol=1e-13, atol=atol
        )
