"""Marching squares against scikit-image's find_contours (a test-only dependency)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from skimage import measure

from formgraph.kernels.offset.contour import _cycles, marching_squares, unique_ids


def area(loop: np.ndarray) -> float:
    x, y = loop[:, 0], loop[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def blobs(n: int = 200, seed: int = 0, count: int = 12) -> np.ndarray:
    """A smooth field of Gaussian bumps that stays low along the border."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n].astype(float)
    field = np.zeros((n, n))
    for cx, cy, s, a in zip(
        rng.uniform(0.2 * n, 0.8 * n, count),
        rng.uniform(0.2 * n, 0.8 * n, count),
        rng.uniform(0.03 * n, 0.08 * n, count),
        rng.uniform(0.5, 1.5, count),
        strict=True,
    ):
        field += a * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * s * s))
    return field


def as_set(points: np.ndarray, digits: int = 9) -> set[tuple[float, float]]:
    return {tuple(p) for p in np.round(points, digits)}


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("level", [0.3, 0.71])
def test_same_contours_as_scikit_image(seed, level):
    field = blobs(seed=seed)
    ours = marching_squares(field, level)
    theirs = measure.find_contours(field, level)
    # scikit-image gives (row, col) with the first point repeated on closed contours.
    assert all(np.allclose(c[0], c[-1]) for c in theirs)
    theirs = [c[:-1, ::-1] for c in theirs]
    assert len(ours) == len(theirs)
    # The same vertices (linear interpolation on the same edges), loop by loop.
    mine = sorted((as_set(loop) for loop in ours), key=lambda s: min(s))
    ref = sorted((as_set(c) for c in theirs), key=lambda s: min(s))
    assert mine == ref


def bilinear(field: np.ndarray, pts: np.ndarray) -> np.ndarray:
    j0 = np.clip(np.floor(pts[:, 0]).astype(int), 0, field.shape[1] - 2)
    i0 = np.clip(np.floor(pts[:, 1]).astype(int), 0, field.shape[0] - 2)
    s, t = pts[:, 0] - j0, pts[:, 1] - i0
    return (
        field[i0, j0] * (1 - s) * (1 - t)
        + field[i0, j0 + 1] * s * (1 - t)
        + field[i0 + 1, j0] * (1 - s) * t
        + field[i0 + 1, j0 + 1] * s * t
    )


def test_loops_run_counter_clockwise_around_the_inside():
    field = blobs(seed=3)
    loops = marching_squares(field, 0.5)
    assert loops
    for loop in loops:
        # Just left of each edge's midpoint the field is above the level, just right below.
        step = np.roll(loop, -1, axis=0) - loop
        mid = loop + step / 2
        left = np.stack([-step[:, 1], step[:, 0]], axis=-1) / np.hypot(*step.T)[:, None]
        assert (bilinear(field, mid + 0.02 * left) > 0.5).mean() > 0.95
        assert (bilinear(field, mid - 0.02 * left) < 0.5).mean() > 0.95
    # Below: the same loops reversed (as holes), inside one loop round the border.
    below = marching_squares(field, 0.5, below=True)
    areas = sorted(round(area(x), 9) for x in below)
    assert areas[-1] == pytest.approx(199.0 * 199.0)
    assert sorted(-a for a in areas[:-1]) == sorted(round(area(x), 9) for x in loops)


def test_ring_gives_an_island_and_a_hole():
    y, x = np.mgrid[-20:21, -20:21].astype(float)
    r = np.hypot(x, y)
    field = np.exp(-((r - 10) ** 2) / 8)  # a ring-shaped ridge
    loops = marching_squares(field, 0.5, origin=(-20, -20))
    assert len(loops) == 2
    outer, inner = sorted(loops, key=lambda lp: -abs(area(lp)))
    assert area(outer) > 0 > area(inner)
    assert np.allclose(np.hypot(*outer.T), 12.35, atol=0.1)


def test_origin_and_cell_place_the_vertices():
    y, x = np.mgrid[-5:6, -5:6].astype(float)
    field = 3.0 - np.hypot(x, y)
    (unit,) = marching_squares(field, 0.0, origin=(-5, -5))
    (scaled,) = marching_squares(field, 0.0, origin=(10.0, 20.0), cell=0.5)
    assert np.allclose(scaled, (unit + 5) * 0.5 + [10.0, 20.0])


def test_a_region_touching_the_border_is_closed_along_it():
    field = np.ones((6, 8))
    field[:, 5:] = -1.0
    (loop,) = marching_squares(field, 0.0)
    # Columns 0..4 are inside; the boundary between columns 4 and 5 is at x = 4.5.
    assert area(loop) == pytest.approx(4.5 * 5)
    assert loop[:, 0].min() == 0 and loop[:, 1].min() == 0 and loop[:, 1].max() == 5


def test_saddle_is_decided_by_the_cell_centre():
    field = np.zeros((4, 4))
    field[1:3, 1:3] = [[1.0, 0.2], [0.2, 1.0]]  # mean 0.6 at the centre: joined
    assert len(marching_squares(field, 0.5)) == 1
    field[1:3, 1:3] = [[1.0, 0.0], [0.0, 0.9]]  # mean 0.475: apart
    assert len(marching_squares(field, 0.5)) == 2


def test_no_contour_gives_no_loops():
    assert marching_squares(np.zeros((5, 5)), 1.0) == []


def test_errors():
    with pytest.raises(ValueError, match=r"2-D array of at least 2 x 2 samples, got \(5,\)"):
        marching_squares(np.zeros(5), 0.0)
    with pytest.raises(ValueError, match="field contains NaN"):
        marching_squares(np.array([[0.0, np.nan], [1.0, 1.0]]), 0.5)
    with pytest.raises(ValueError, match="cell must be a positive finite number, got 0"):
        marching_squares(np.zeros((3, 3)), 0.0, cell=0)
    with pytest.raises(ValueError, match="level must be a finite number"):
        marching_squares(np.zeros((3, 3)), np.inf)
    with pytest.raises(ValueError, match="origin must be two finite numbers"):
        marching_squares(np.zeros((3, 3)), 0.0, origin=(0.0,))


@settings(max_examples=50, deadline=None)
@given(st.permutations(list(range(40))))
def test_cycles_of_a_permutation(perm):
    succ = np.array(perm)
    order, offsets = _cycles(succ)
    assert sorted(order.tolist()) == list(range(40))
    for k in range(offsets.size - 1):
        cycle = order[offsets[k] : offsets[k + 1]]
        # Each cycle starts at its smallest element and follows the successors round.
        assert cycle[0] == cycle.min()
        assert (succ[cycle] == np.roll(cycle, -1)).all()


@given(
    st.lists(st.integers(-50, 10**12), max_size=200),
    st.booleans(),
    st.booleans(),
)
def test_unique_ids_is_np_unique(values, inverse, counts):
    ids = np.array(values, dtype=np.int64)
    expected = np.unique(ids, return_inverse=inverse, return_counts=counts)
    got = unique_ids(ids, return_inverse=inverse, return_counts=counts)
    if not (inverse or counts):
        expected, got = (expected,), (got,)
    assert len(got) == len(expected)
    for g, e in zip(got, expected, strict=True):
        np.testing.assert_array_equal(g, e.reshape(-1))
