"""The layout kernels: Minkowski sums by convolution against shapely's union of the convex
pieces' sums (an independent construction), no-fit polygons with holes, and bottom-left
fill on the grid."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

from formgraph.kernels.curves.regions import even_odd_region
from formgraph.kernels.layout import nest as knest
from formgraph.kernels.layout import nfp


def _reference_sum(a: np.ndarray, b: np.ndarray) -> shapely.Geometry:
    """A (+) B as the union of the sums of their triangles (each the hull of 9 points)."""
    ta = shapely.get_parts(shapely.constrained_delaunay_triangles(shapely.Polygon(a)))
    tb = shapely.get_parts(shapely.constrained_delaunay_triangles(shapely.Polygon(b)))
    xa = np.stack([shapely.get_coordinates(t)[:3] for t in ta])
    xb = np.stack([shapely.get_coordinates(t)[:3] for t in tb])
    sums = (xa[:, None, :, None, :] + xb[None, :, None, :, :]).reshape(-1, 9, 2)
    return shapely.union_all(shapely.convex_hull(shapely.multipoints(sums)))


def _ours(paths: list[np.ndarray]) -> shapely.Geometry:
    return even_odd_region([p.astype(np.float64) for p in paths])


def _star(rng: np.random.Generator, n: int, centre: tuple[float, float]) -> np.ndarray:
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = rng.uniform(0.3, 1.0, n)
    return np.round(np.c_[np.cos(t) * r + centre[0], np.sin(t) * r + centre[1]] * 1000).astype(
        np.int64
    )


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(3, 16), st.integers(3, 16))
@example(0, 7, 3)  # a crossing of the cycle rounded onto a corner
def test_minkowski_sum_of_star_polygons_matches_the_union_of_convex_pieces(seed, n, m):
    rng = np.random.default_rng(seed)
    a, b = _star(rng, n, (0, 0)), _star(rng, m, (2, 1))
    if not (shapely.Polygon(a).is_valid and shapely.Polygon(b).is_valid):
        return
    ours, ref = _ours(nfp.minkowski_outer(a, b)), _reference_sum(a, b)
    # Clipper rounds the crossings of the cycle to the grid: within a unit
    assert shapely.hausdorff_distance(ours.boundary, ref.boundary) < 1.5
    # a corner moved by at most half a grid diagonal changes the area by at most that much
    # times the length of its two edges: over all corners, the perimeter times 0.71 (seed 0,
    # n 7, m 3 has a corner where the cycle crosses itself rounded by one unit: 375 of 3.17e6)
    sliver = shapely.symmetric_difference(ours, ref).area
    assert sliver <= np.sqrt(0.5) * ref.boundary.length


@pytest.mark.parametrize(
    "a",
    [
        [[0, 0], [40, 0], [40, 30], [0, 30]],  # parallel edges: the ties of the merge
        [[0, 0], [60, 0], [60, 12], [12, 12], [12, 40], [0, 40]],  # an L: reflex and parallel
        [[0, 0], [30, 0], [30, 30], [20, 30], [20, 10], [10, 10], [10, 30], [0, 30]],  # a U
    ],
)
def test_minkowski_sum_of_axis_parallel_shapes(a):
    a = np.array(a, dtype=np.int64) * 100
    for b in (a, -a, a[:, ::-1][::-1]):
        ours, ref = _ours(nfp.minkowski_outer(a, b)), _reference_sum(a, b)
        assert shapely.symmetric_difference(ours, ref).area < 1e-9 * ref.area + 1.0


def test_no_fit_polygon_has_the_pocket_of_a_hole_that_holds_the_part():
    ring = np.c_[
        np.cos(np.linspace(0, 2 * np.pi, 64, endpoint=False)),
        np.sin(np.linspace(0, 2 * np.pi, 64, endpoint=False)),
    ]
    outer = np.round(ring * 10000).astype(np.int64)
    hole = np.round(ring[::-1] * 6000).astype(np.int64)
    disc = np.round(ring * 2000).astype(np.int64)
    region = _ours(nfp.no_fit(outer, [hole], disc))
    # the disc's centre may go anywhere within 6000 - 2000 of the centre: the pocket
    assert not region.contains(shapely.Point(0, 0))
    assert not region.contains(shapely.Point(3900, 0))
    assert region.contains(shapely.Point(4200, 0))  # the disc would cut the ring
    assert region.contains(shapely.Point(11900, 0))
    assert not region.contains(shapely.Point(12100, 0))
    pocket = shapely.Polygon(region.interiors[0])
    assert pocket.area == pytest.approx(np.pi * 4000**2, rel=2e-3)


def test_a_disc_too_big_for_the_hole_gets_no_pocket():
    ring = np.c_[
        np.cos(np.linspace(0, 2 * np.pi, 48, endpoint=False)),
        np.sin(np.linspace(0, 2 * np.pi, 48, endpoint=False)),
    ]
    outer, hole = (
        np.round(ring * 10000).astype(np.int64),
        np.round(ring[::-1] * 3000).astype(np.int64),
    )
    region = _ours(nfp.no_fit(outer, [hole], np.round(ring * 3500).astype(np.int64)))
    assert len(region.interiors) == 0


def _placed(parts, result):
    out = []
    for i, rings in enumerate(parts):
        c, s = np.cos(result.angle[i]), np.sin(result.angle[i])
        rot = np.array([[c, -s], [s, c]])
        moved = [r @ rot.T + result.offset[i] for r in rings]
        out.append(shapely.Polygon(moved[0], moved[1:]))
    return out


def test_rectangles_fill_columns_without_overlap():
    rect = np.array([[0, 0], [80, 0], [80, 30], [0, 30]], dtype=float)
    parts = [[rect + [100 * i, 0]] for i in range(20)]
    result = knest.nest(parts, (600, 400), spacing=2, rotations=4)
    placed = _placed(parts, result)
    d = shapely.distance(np.array(placed)[:, None], np.array(placed)[None, :])
    np.fill_diagonal(d, np.inf)
    assert d.min() >= 2 - 1e-9
    sheet = shapely.box(0, 0, 600, 400)
    assert all(sheet.contains(p) for p in placed)
    assert result.sheets == 1
    # 12 plates (30 + 2 each) stand in a column of 400: two columns of 80 reach 162
    assert result.length < 165
    assert result.utilisation == pytest.approx(20 * 2400 / (400 * result.length))


def test_the_same_seed_and_effort_give_the_same_layout():
    rng = np.random.default_rng(3)
    parts = [[_star(rng, 8, (0, 0)).astype(float) / 50] for _ in range(12)]
    a = knest.nest(parts, (100, 60), 1, 4, seed=5, effort=6)
    b = knest.nest(parts, (100, 60), 1, 4, seed=5, effort=6)
    assert np.array_equal(a.offset, b.offset) and np.array_equal(a.angle, b.angle)
    assert a.evaluations == 6


def test_a_part_larger_than_the_sheet_is_named():
    small = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], dtype=float)
    big = np.array([[0, 0], [120, 0], [120, 10], [0, 10]], dtype=float)
    with pytest.raises(knest.PartTooLarge, match=r"part 1 \(120 x 10") as exc:
        knest.nest([[small], [big]], (100, 100))
    assert exc.value.part == 1
    # a quarter turn lets a tall part onto a wide sheet
    tall = np.array([[0, 0], [10, 0], [10, 90], [0, 90]], dtype=float)
    assert knest.nest([[tall]], (100, 20), rotations=4).sheets == 1
    with pytest.raises(knest.PartTooLarge):
        knest.nest([[tall]], (100, 20), rotations=1)


def _swept_pocket(hole: np.ndarray, moving: np.ndarray) -> shapely.Geometry:
    """The reference: (H - b0) less the sweep of -B's boundary along H's (Clipper's
    Minkowski sum of a pattern along a closed path: the union of edge parallelograms)."""
    import pyclipper

    swept = pyclipper.MinkowskiSum((-moving).tolist(), hole.tolist(), True)
    pc = pyclipper.Pyclipper()
    pc.AddPath((hole - moving[0]).tolist(), pyclipper.PT_SUBJECT, True)
    pc.AddPaths(swept, pyclipper.PT_CLIP, True)
    return _ours([np.asarray(r) for r in pc.Execute(pyclipper.CT_DIFFERENCE, 1, 1)])


@pytest.mark.parametrize(
    "hole",
    [
        [[0, 0], [30, 0], [30, 30], [20, 30], [20, 10], [10, 10], [10, 30], [0, 30]],  # a U
        [[0, 0], [40, 0], [40, 5], [25, 20], [40, 35], [40, 40], [0, 40]],  # a notch
    ],
)
@pytest.mark.parametrize("part", [[[0, 0], [6, 0], [6, 6], [0, 6]], [[0, 0], [7, 2], [3, 6]]])
def test_the_pocket_by_convolution_matches_the_swept_one_for_convex_parts(hole, part):
    hole = np.array(hole, dtype=np.int64) * 1000
    part = np.array(part, dtype=np.int64) * 1000
    ours = _ours(nfp.pocket(hole, -part))
    ref = _swept_pocket(hole, part)
    assert ref.area > 0
    assert shapely.symmetric_difference(ours, ref).area < 1e-6 * ref.area + 50
