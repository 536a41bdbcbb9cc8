"""Early cutoff's comparison of a recomputed output with the previous one
(formgraph.evaluation.cutoff): it must agree with the content digests it replaces."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from formgraph.evaluation.cache import digest
from formgraph.evaluation.cutoff import same_content
from formgraph.geometry import Mesh, NurbsCurve, ParametricCurve
from formgraph.kernels.nurbs.curve import clamped_uniform_knots


def _square(z: float = 0.0) -> Mesh:
    v = np.array([[0, 0, z], [1, 0, z], [1, 1, z], [0, 1, z]], dtype=float)
    return Mesh(v, [[0, 1, 2, 3]])


@pytest.mark.parametrize(
    ("a", "b", "same"),
    [
        (np.array([0.0, 1.0]), np.array([0.0, 1.0]), True),
        (np.array([0.0, 1.0]), np.array([-0.0, 1.0]), False),  # other bits, other key
        (np.array([np.nan]), np.array([np.nan]), True),  # the same bits
        (np.array([1, 2], dtype=np.int32), np.array([1, 2], dtype=np.int64), False),
        (np.zeros((2, 3)), np.zeros((3, 2)), False),
        (np.arange(6.0).reshape(2, 3).T, np.arange(6.0).reshape(2, 3).T.copy(), True),
        (1.5, 1.5, True),
        (0.0, -0.0, False),
        ([1, "a", None], [1, "a", None], True),
        ({"x": 1.0}, {"x": 1.0, "y": 2}, False),
        (_square(), _square(), True),
        (_square(), _square(1e-12), False),
        (_square(), [_square()], False),
    ],
)
def test_same_content_agrees_with_the_digests(a, b, same):
    assert same_content(a, b) is same
    assert (digest(a) == digest(b)) is same


def test_outputs_without_content_are_never_the_same():
    # plain callables have no fingerprint: no cutoff unless it is the very same value
    a = ParametricCurve(lambda t: t, lambda t: 0 * t, lambda t: 0 * t, (0.0, 1.0))
    b = ParametricCurve(lambda t: t, lambda t: 0 * t, lambda t: 0 * t, (0.0, 1.0))
    assert not same_content(a, b)
    assert not same_content([a], [b])
    assert same_content(a, a)


@settings(max_examples=60, deadline=None)
@given(
    hnp.arrays(np.float64, st.integers(1, 40), elements=st.floats(-3, 3, width=32)),
    st.integers(0, 39),
    st.sampled_from([0.0, 1.0, -1e-9]),
)
def test_a_nurbs_curve_changed_anywhere_is_told_apart(cp, at, delta):
    pts = np.column_stack([cp, cp[::-1], np.zeros_like(cp)])
    pts = np.vstack([pts, pts + 1.0])  # at least two control points
    knots = clamped_uniform_knots(len(pts), 1)
    a = NurbsCurve(pts, 1, knots)
    moved = pts.copy()
    moved[at % len(pts), 2] += delta
    b = NurbsCurve(moved, 1, knots)
    assert same_content(a, b) is (digest(a) == digest(b))
    assert same_content(a, b) is (delta == 0.0)
