"""Offset kernel against shapely's exact buffers, through both paths.

Every test runs twice: once on the distance field and marching squares (`offset_polylines`)
and once through `offset_loops`, which takes GEOS's buffer where no cell or smoothing is
asked (the node's default path); tests of the marching path's own machinery run once.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import formgraph.kernels.offset as koffset
from formgraph.kernels.offset import default_cell
from formgraph.kernels.offset.distance import RowParity, SegmentTree, point_segment

# Tests of the marching path's own machinery (its sample store, grids, trace, smoothing).
_MARCHING_ONLY = {
    "test_sparse_sample_store_gives_the_same_loops",
    "test_kerf_traces_on_the_first_grid",
    "test_a_trace_failure_says_where_and_what_to_do",
    "test_messy_input_is_charged_against_the_budget",
}


def offset_polylines(*args, **kwargs):
    return _PATH["offset"](*args, **kwargs)


_PATH = {"offset": koffset.offset_polylines}


@pytest.fixture(autouse=True, params=["marching", "default"])
def path(request):
    """Run the test on the marching path, then on the default path (GEOS where it can)."""
    if request.param == "default" and request.function.__name__ in _MARCHING_ONLY:
        pytest.skip("a test of the marching path's machinery")
    _PATH["offset"] = (
        koffset.offset_polylines
        if request.param == "marching"
        else lambda *a, **k: koffset.offset_loops(*a, **k).loops
    )
    yield request.param
    _PATH["offset"] = koffset.offset_polylines


def circle(r: float, n: int = 2000, c=(0.0, 0.0)) -> np.ndarray:
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[c[0] + r * np.cos(a), c[1] + r * np.sin(a)]


def area(loop: np.ndarray) -> float:
    x, y = loop[:, 0], loop[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def as_shape(loops: list[np.ndarray]):
    """Our loops as a shapely region: even-odd union of the rings (they never cross)."""
    region = shapely.Polygon()
    for loop in loops:
        region = region.symmetric_difference(shapely.Polygon(loop))
    return region


def hausdorff(loops: list[np.ndarray], reference, step: float = 0.01) -> float:
    """Hausdorff distance between our loops and a shapely region's boundary, sampled."""
    ours = shapely.segmentize(
        shapely.MultiLineString([np.r_[loop, loop[:1]] for loop in loops]), step
    )
    theirs = shapely.segmentize(reference.boundary, step)
    a = shapely.distance(shapely.points(shapely.get_coordinates(ours)), reference.boundary)
    b = shapely.distance(shapely.points(shapely.get_coordinates(theirs)), ours)
    return float(max(a.max(), b.max()))


def extent(*polylines: np.ndarray) -> float:
    pts = np.concatenate(polylines)
    return float(np.ptp(pts, axis=0).max())


# --- closed forms and shapely references ---------------------------------------------------


@pytest.mark.parametrize("d", [0.3, 0.05, -0.4, -0.05])
def test_circle_offsets_to_a_circle(d):
    (loop,) = offset_polylines([circle(1.0)], [True], d)
    radius = np.hypot(loop[:, 0], loop[:, 1])
    assert np.abs(radius - (1 + d)).max() < 1e-3 * 2.0
    # Between vertices too: the chords' midpoints.
    mid = (loop + np.roll(loop, -1, axis=0)) / 2
    assert np.abs(np.hypot(mid[:, 0], mid[:, 1]) - (1 + d)).max() < 1e-3 * 2.0
    assert area(loop) > 0  # an island runs counter-clockwise


def test_square_outward_matches_round_buffer_area():
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    d = 0.3
    (loop,) = offset_polylines([square], [True], d)
    exact = 4 + 4 * 2 * d + np.pi * d**2
    assert abs(area(loop) - exact) < 0.005 * exact
    reference = shapely.Polygon(square).buffer(d, quad_segs=64)
    assert abs(area(loop) - reference.area) < 0.005 * reference.area
    assert hausdorff([loop], reference) < 1e-3 * 2


def test_square_inward_keeps_sharp_corners():
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    (loop,) = offset_polylines([square], [True], -0.3)
    # The inward offset of a square is a square with sharp corners at (0.3, 0.3) etc.
    corners = np.array([[0.3, 0.3], [1.7, 0.3], [1.7, 1.7], [0.3, 1.7]])
    gap = np.hypot(*(loop[:, None] - corners[None]).transpose(2, 0, 1)).min(axis=0)
    assert gap.max() < 1e-3 * 2
    assert abs(area(loop) - 1.4**2) < 1e-3


def test_clockwise_input_gives_the_same_result():
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    (ccw,) = offset_polylines([square], [True], 0.25)
    (cw,) = offset_polylines([square[::-1]], [True], 0.25)
    assert area(ccw) > 0 and area(cw) > 0
    assert abs(area(ccw) - area(cw)) < 1e-9


@pytest.mark.parametrize("d", [0.05, -0.05])
def test_sparse_sample_store_gives_the_same_loops(monkeypatch, d):
    # Big grids keep their band of samples sorted and searched instead of in a dense table;
    # both stores must give the very same offset.
    import formgraph.kernels.offset.band as band

    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    r = 1 + 0.1 * np.sin(9 * t)
    pts = np.c_[r * np.cos(t), r * np.sin(t)]
    dense = offset_polylines([pts], [True], d)
    monkeypatch.setattr(band, "_DENSE", 0)
    monkeypatch.setattr(band, "_DENSE_MIN", 0)
    sparse = offset_polylines([pts], [True], d)
    assert len(dense) == len(sparse)
    for a, b in zip(dense, sparse, strict=True):
        np.testing.assert_array_equal(a, b)


def test_inward_offset_splits_a_dumbbell_into_two_islands():
    # Two 1 x 1 squares joined by a bar 0.2 wide.
    shape = np.array(
        [
            [0, 0],
            [1, 0],
            [1, 0.4],
            [2, 0.4],
            [2, 0],
            [3, 0],
            [3, 1],
            [2, 1],
            [2, 0.6],
            [1, 0.6],
            [1, 1],
            [0, 1],
        ],
        dtype=float,
    )
    joined = offset_polylines([shape], [True], -0.05)
    assert len(joined) == 1
    loops = offset_polylines([shape], [True], -0.15)
    assert len(loops) == 2
    assert all(area(loop) > 0 for loop in loops)
    reference = shapely.Polygon(shape).buffer(-0.15, quad_segs=64)
    assert len(reference.geoms) == 2
    assert hausdorff(loops, reference) < 1e-3 * 3


def test_overlapping_circles_follow_the_even_odd_rule():
    a, b = circle(1.0), circle(1.0, c=(1.0, 0.0))
    region = shapely.Polygon(a).symmetric_difference(shapely.Polygon(b))
    # The lens is outside; a small offset leaves it as a hole (clockwise).
    loops = offset_polylines([a, b], [True, True], 0.2)
    assert len(loops) == 2
    assert sorted(np.sign([area(loop) for loop in loops])) == [-1, 1]
    reference = region.buffer(0.2, quad_segs=64)
    assert abs(as_shape(loops).area - reference.area) < 0.005 * reference.area
    assert hausdorff(loops, reference) < 1e-3 * 2
    # The lens is 1 wide: an offset past 0.5 covers it.
    (loop,) = offset_polylines([a, b], [True, True], 0.6)
    assert area(loop) > 0
    assert abs(area(loop) - region.buffer(0.6, quad_segs=64).area) < 0.005 * area(loop)


def test_distant_circles_stay_apart():
    loops = offset_polylines([circle(1.0), circle(1.0, c=(3.0, 0.0))], [True, True], 0.3)
    assert len(loops) == 2
    assert all(area(loop) > 0 for loop in loops)
    assert sorted(round(float(loop[:, 0].mean())) for loop in loops) == [0, 3]


@pytest.mark.parametrize("d", [0.1, -0.1])
def test_concentric_circles_give_a_ring(d):
    loops = offset_polylines([circle(1.0), circle(0.5)], [True, True], d)
    assert len(loops) == 2
    outer, inner = sorted(loops, key=lambda loop: -abs(area(loop)))
    assert area(outer) > 0 > area(inner)
    assert np.allclose(np.hypot(*outer.T), 1 + d, atol=2e-3)
    assert np.allclose(np.hypot(*inner.T), 0.5 - d, atol=2e-3)


def test_open_segment_gives_a_stadium():
    segment = np.array([[0.0, 0.0], [1.0, 0.0]])
    (loop,) = offset_polylines([segment], [False], 0.2)
    assert area(loop) > 0
    assert abs(area(loop) - (2 * 0.2 * 1 + np.pi * 0.2**2)) < 1e-3
    reference = shapely.LineString(segment).buffer(0.2, quad_segs=64)
    assert hausdorff([loop], reference) < 1e-3 * 1.4
    # Every vertex is exactly at the distance.
    d, _ = point_segment(loop, np.zeros_like(loop), np.tile([1.0, 0.0], (len(loop), 1)))
    assert np.abs(d - 0.2).max() < 1e-9


def test_open_input_with_negative_distance_is_empty():
    assert offset_polylines([np.array([[0.0, 0.0], [1.0, 0.0]])], [False], -0.2) == []


def test_single_point_gives_a_circle():
    (loop,) = offset_polylines([np.array([[2.0, 3.0]])], [False], 0.5)
    assert np.abs(np.hypot(loop[:, 0] - 2, loop[:, 1] - 3) - 0.5).max() < 1e-9


def test_self_intersecting_figure_eight():
    bowtie = np.array([[0, 0], [2, 2], [2, 0], [0, 2]], dtype=float)
    lobes = shapely.make_valid(shapely.Polygon(bowtie))
    assert abs(lobes.area - 2.0) < 1e-12  # two triangles of area 1
    for d in (0.1, -0.05):
        loops = offset_polylines([bowtie], [True], d)
        reference = lobes.buffer(d, quad_segs=64)
        assert abs(as_shape(loops).area - reference.area) < 0.005 * reference.area
        assert hausdorff(loops, reference) < 1e-3 * 2
    # Outward the lobes join at the crossing; inward they part.
    assert len(offset_polylines([bowtie], [True], 0.1)) == 1
    assert len(offset_polylines([bowtie], [True], -0.05)) == 2


def test_inward_past_the_middle_is_empty():
    assert offset_polylines([circle(1.0)], [True], -1.2) == []


def test_every_vertex_is_on_the_offset(path):
    pts = circle(1.0, 300) * (1 + 0.2 * np.sin(5 * np.linspace(0, 2 * np.pi, 300)))[:, None]
    tree = SegmentTree(pts, np.roll(pts, -1, axis=0))
    for d in (0.15, -0.1):
        # GEOS drops the input's vertices within 1 % of |d| of their neighbours' chord
        # first (within half the tolerance here), so its vertices are that close.
        bound = 1e-6 if path == "marching" else koffset.buffer.GEOS_SIMPLIFY_FACTOR * abs(d)
        for loop in offset_polylines([pts], [True], d):
            assert np.abs(tree.query(loop).dist - abs(d)).max() < bound


def test_error_is_within_the_tolerance_for_a_user_cell():
    # A coarse cell does not cost accuracy: vertices are projected and chords refined.
    pts = circle(1.0, 500) * (1 + 0.1 * np.sin(9 * np.linspace(0, 2 * np.pi, 500)))[:, None]
    reference = shapely.Polygon(pts).buffer(0.1, quad_segs=64)
    for cell in (0.01, 0.04):
        loops = offset_polylines([pts], [True], 0.1, cell=cell)
        assert hausdorff(loops, reference) < 1e-3 * extent(pts)


# --- smoothing and simplification ----------------------------------------------------------


def test_smoothing_keeps_the_distance():
    pts = circle(1.0, 300) * (1 + 0.2 * np.sin(5 * np.linspace(0, 2 * np.pi, 300)))[:, None]
    tree = SegmentTree(pts, np.roll(pts, -1, axis=0))
    (loop,) = offset_polylines([pts], [True], 0.15, smooth=4)
    assert np.abs(tree.query(loop).dist - 0.15).max() < 1e-6
    (plain,) = offset_polylines([pts], [True], 0.15)

    # Smoothing evens out the spacing of the vertices.
    def spread(p):
        step = np.hypot(*(np.roll(p, -1, axis=0) - p).T)
        return step.std() / step.mean()

    assert spread(loop) < spread(plain)


def test_simplify_stays_within_its_tolerance():
    pts = circle(1.0)
    (full,) = offset_polylines([pts], [True], 0.2)
    (simple,) = offset_polylines([pts], [True], 0.2, simplify=0.01)
    assert len(simple) < len(full) / 3
    # Every dropped vertex is within the tolerance of the simplified loop.
    ring = shapely.LinearRing(simple)
    assert max(ring.distance(shapely.Point(p)) for p in full) <= 0.01 + 1e-9
    assert area(simple) > 0


# --- hypothesis: random polygons against shapely -------------------------------------------


@st.composite
def star_polygons(draw):
    n = draw(st.integers(min_value=3, max_value=24))
    radii = draw(st.lists(st.floats(0.3, 1.0), min_size=n, max_size=n))
    gaps = draw(st.lists(st.floats(0.2, 1.0), min_size=n, max_size=n))
    angles = 2 * np.pi * np.cumsum(gaps) / np.sum(gaps)
    return np.c_[np.array(radii) * np.cos(angles), np.array(radii) * np.sin(angles)]


def _seeded_star(seed: int) -> tuple[np.ndarray, float]:
    """A random star polygon and distance from ``seed``, drawn as :func:`star_polygons` draws."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 25))
    radii, gaps = rng.uniform(0.3, 1.0, n), rng.uniform(0.2, 1.0, n)
    angles = 2 * np.pi * np.cumsum(gaps) / np.sum(gaps)
    d = float(rng.uniform(-0.25, 0.3))
    return np.c_[radii * np.cos(angles), radii * np.sin(angles)], d if abs(d) > 0.02 else 0.1


def _matches_shapely(polygon: np.ndarray, d: float) -> None:
    loops = offset_polylines([polygon], [True], d)
    # Every loop is a simple ring, islands counter-clockwise and holes clockwise.
    assert all(shapely.Polygon(loop).is_valid for loop in loops)
    reference = shapely.Polygon(polygon).buffer(d, quad_segs=64)
    ours = as_shape(loops)
    assert ours.is_valid
    assert np.isclose(sum(area(loop) for loop in loops), ours.area, rtol=1e-6, atol=1e-9)
    # The symmetric difference is no more than the boundary length times the 0.1 %
    # tolerance (so a sliver at most that thin along the whole boundary).
    size = extent(polygon)
    assert ours.symmetric_difference(reference).area <= 1e-3 * size * reference.length + 1e-9


# Seeded, not drawn by hypothesis: the derandomized draw turned out to depend on what ran
# before it in the process (see docs/family-offset.md and the thin-neck case below).
@pytest.mark.parametrize("seed", range(40))
def test_random_polygons_match_shapely(seed):
    _matches_shapely(*_seeded_star(seed))


# Found by hypothesis (a 21-corner star at d = -0.17): the inward offset leaves a thin
# triangular island whose tip narrows below a cell. The grid cut the tip off as a loop of
# its own, then refinement recovered the island's true corner over it: two overlapping
# islands (the union's area off by 1.7e-6 of the sum's). The covered piece must go.
_THIN_NECK = np.array(
    [
        [9.28367933e-01, 3.71662456e-01],
        [7.23734038e-01, 6.90079011e-01],
        [1.55780630e-01, 3.41111998e-01],
        [2.35758936e-01, 9.71811568e-01],
        [-4.75819158e-02, 9.98867339e-01],
        [-1.42314838e-01, 9.89821442e-01],
        [-1.87500000e-01, 3.24759526e-01],
        [-7.86053095e-01, 6.18158986e-01],
        [-9.59492974e-01, 2.81732557e-01],
        [-9.95471923e-01, -9.50560433e-02],
        [-8.88835449e-01, -4.58226522e-01],
        [-6.54860734e-01, -7.55749574e-01],
        [-3.27067963e-01, -9.45000819e-01],
        [4.75819158e-02, -9.98867339e-01],
        [4.15415013e-01, -9.09631995e-01],
        [5.80056910e-01, -8.14575952e-01],
        [7.23734038e-01, -6.90079011e-01],
        [8.41253533e-01, -5.40640817e-01],
        [9.28367933e-01, -3.71662456e-01],
        [9.81928697e-01, -1.89251244e-01],
        [1.00000000e00, -2.44929360e-16],
    ]
)


def test_thin_neck_star_matches_shapely():
    _matches_shapely(_THIN_NECK, -0.171875)
    # Two islands, as GEOS finds: the star's body and the thin triangle, no piece of its tip.
    assert len(offset_polylines([_THIN_NECK], [True], -0.171875)) == 2


def _seeded_deep_star(seed: int) -> tuple[np.ndarray, float]:
    """A random star of 15 to 24 corners and an inward distance from ``seed`` (deep notches
    and thin spikes left between them)."""
    rng = np.random.default_rng(10_000 + seed)
    n = int(rng.integers(15, 25))
    radii, gaps = rng.uniform(0.3, 1.0, n), rng.uniform(0.2, 1.0, n)
    angles = 2 * np.pi * np.cumsum(gaps) / np.sum(gaps)
    return np.c_[radii * np.cos(angles), radii * np.sin(angles)], float(rng.uniform(-0.25, -0.1))


# Found by fuzzing 1,000 such stars: 150, 404, 425 and 707 left a spike's cut-off tip under
# the recovered one, wholly or in part (as the thin neck above); 412 kept a twist of 12
# chords in one loop.
@pytest.mark.parametrize("seed", [150, 404, 412, 425, 707])
def test_deep_stars_shrink_to_simple_loops(seed):
    _matches_shapely(*_seeded_deep_star(seed))


# A random star (found by fuzzing) whose inward offset keeps a narrow spike: a corner
# solve whose segments could walk round the polygon's sharp vertices met the far flank of
# the spike and cut it off.
SPIKY_STAR = np.array(
    [
        [0.3950631104613595, 0.17798558189271604],
        [0.23597679658863652, 0.27332259819061394],
        [0.09564953853487583, 0.29255136867851256],
        [-0.11691101407881564, 0.9545169250357848],
        [-0.2779190282513372, 0.7877899752682074],
        [-0.34751718368123397, 0.5738162387947644],
        [-0.3387914858625161, 0.41358057403190557],
        [-0.29291016526811825, 0.22000080714470535],
        [-0.37358027137669636, 0.09280620620101013],
        [-0.39345000385223095, -0.081206536364076],
        [-0.3821480813026686, -0.27003934290271125],
        [-0.5307432625424624, -0.5011466033953933],
        [-0.2316353573012384, -0.5935927823832722],
        [-0.22552084082926055, -0.9712233856102825],
        [0.1126549613362168, -0.9638272519723242],
        [0.09006644750001548, -0.3517111393741989],
        [0.3241223554725673, -0.6902259264556769],
        [0.5417953958873498, -0.7584131218391902],
        [0.6384207082182218, -0.602956613381105],
        [0.32523629417872857, -0.2426012245112854],
        [0.3436935364093114, -0.06930510026206509],
        [0.30788240785615795, -3.4886395152211657e-16],
    ]
)


def test_corners_do_not_walk_round_sharp_vertices():
    d = -0.2262821260648043
    (loop,) = offset_polylines([SPIKY_STAR], [True], d)
    reference = shapely.Polygon(SPIKY_STAR).buffer(d, quad_segs=64)
    ours = shapely.Polygon(loop)
    size = extent(SPIKY_STAR)
    assert ours.symmetric_difference(reference).area <= 1e-3 * size * reference.length


def test_smooth_runs_stop_at_sharp_vertices_and_between_polylines():
    from formgraph.kernels.offset.refine import _smooth_runs

    t = np.linspace(0, np.pi / 2, 50)
    arc = np.c_[np.cos(t), np.sin(t)]  # 49 segments turning 1.8 degrees each
    corner = np.array([[0.0, 1.0], [0.0, 2.0], [1.0, 2.0]])  # a right angle
    a = np.concatenate([arc[:-1], corner[:-1], arc[:-1] + 5])
    b = np.concatenate([arc[1:], corner[1:], arc[1:] + 5])
    run = _smooth_runs(SegmentTree(a, b))
    assert len(np.unique(run[:49])) == 1  # the arc is one run
    assert run[49] != run[48]  # the next polyline starts by the arc's end, turning 90 degrees
    assert run[50] != run[49]  # its right angle
    assert run[51] != run[50] and len(np.unique(run[51:])) == 1  # a new polyline, smooth


# --- errors ---------------------------------------------------------------------------------


def test_errors():
    square = np.array([[0, 0], [1, 0], [1, 1]], dtype=float)
    with pytest.raises(ValueError, match="at least one polyline, got none"):
        offset_polylines([], [], 0.1)
    with pytest.raises(ValueError, match="distance must be a nonzero finite number, got 0"):
        offset_polylines([square], [True], 0.0)
    with pytest.raises(ValueError, match="distance must be a nonzero finite number, got nan"):
        offset_polylines([square], [True], float("nan"))
    with pytest.raises(ValueError, match="one flag per polyline: 1 polylines, 2 flags"):
        offset_polylines([square], [True, False], 0.1)
    with pytest.raises(ValueError, match=r"polyline 0 must be an \(n, 2\) array"):
        offset_polylines([np.zeros((3, 3))], [True], 0.1)
    with pytest.raises(ValueError, match="polyline 0 has NaN or infinite coordinates"):
        offset_polylines([np.array([[0, 0], [np.nan, 1.0]])], [False], 0.1)
    with pytest.raises(ValueError, match="cell must be a positive finite number, got -1"):
        offset_polylines([square], [True], 0.1, cell=-1)
    with pytest.raises(ValueError, match="smooth must be a whole number of passes"):
        offset_polylines([square], [True], 0.1, smooth=1.5)
    with pytest.raises(ValueError, match="simplify must be a tolerance >= 0"):
        offset_polylines([square], [True], 0.1, simplify=-1)
    with pytest.raises(ValueError, match=r"cells, more than the limit of 1000; use a larger cell"):
        offset_polylines([square], [True], 0.1, cell=0.001, max_cells=1000)


def test_default_cell():
    # Second order: the chord sag h^2 / (4 R) with R >= |d| stays well below the tolerance.
    h = default_cell(2.0, 0.05)
    assert h == pytest.approx(min(0.025, 2 * np.sqrt(0.05 * 2e-3)))
    assert default_cell(0.0, 0.5) == pytest.approx(min(0.25, 2 * np.sqrt(0.5 * 1e-3)))


# --- the distance kernel --------------------------------------------------------------------


def test_segment_tree_matches_brute_force():
    rng = np.random.default_rng(3)
    a = rng.uniform(-1, 1, (300, 2))
    b = a + rng.normal(0, 0.1, (300, 2))
    b[7] = a[7]  # a zero-length segment
    p = rng.uniform(-1.5, 1.5, (500, 2))
    brute = point_segment(p[:, None], a[None], b[None])[0]
    tree = SegmentTree(a, b)
    near = tree.query(p)
    assert np.allclose(near.dist, brute.min(axis=1), rtol=0, atol=1e-12)
    assert np.allclose(brute[np.arange(500), near.segment], near.dist, atol=1e-12)
    # A band: exact inside it, certified outside.
    lo, hi = 0.1, 0.2
    band = tree.query(p, lo, hi)
    true = brute.min(axis=1)
    inside = (true >= lo) & (true <= hi)
    assert np.allclose(band.dist[inside], true[inside], atol=1e-12)
    assert band.exact[inside].all()
    assert ((band.dist < lo) == (true < lo)).all()
    assert ((band.dist > hi) == (true > hi)).all()


def test_row_parity_matches_shapely():
    rng = np.random.default_rng(5)
    star = circle(1.0, 9) * rng.uniform(0.4, 1.0, (9, 1))
    a, b = star, np.roll(star, -1, axis=0)
    origin, cell, ny, nx = np.array([-1.2, -1.2]), 0.05, 49, 49
    parity = RowParity(a, b, origin, cell, ny, nx)
    i, j = np.divmod(np.arange(ny * nx), nx)
    inside = parity.inside(i, j)
    pts = shapely.points(origin[0] + j * cell, origin[1] + i * cell)
    assert (inside == shapely.contains(shapely.Polygon(star), pts)).all()


def test_points_on_the_segments_are_at_distance_zero():
    # A grid sample exactly on an input vertex (or on a flat run of segments) has an upper
    # bound of 0 and flat capsules of radius 0: the pruning needs an absolute slack, or the
    # rounding of the axis distance drops the very node the point lies on and the distance
    # comes back as "above the band" (the cause of the offset-of-an-offset failure).
    x = np.linspace(-5.0, 85.0, 901)
    a = np.c_[x[:-1], np.full(900, -5.0)]
    b = np.c_[x[1:], np.full(900, -5.0)]
    tree = SegmentTree(a, b)
    p = np.r_[a[::7], (a[::11] + b[::11]) / 2]
    for upper in (None, np.zeros(p.shape[0])):
        near = tree.query(p, 0.0, 0.3, upper=upper)
        assert near.exact.all()
        assert np.abs(near.dist).max() <= 1e-12


# --- offsets of offsets, of our own outputs, of arbitrary polylines -------------------------


def _rounded_rectangle(w: float, h: float, r: float) -> np.ndarray:
    (loop,) = offset_polylines([np.array([[0, 0], [w, 0], [w, h], [0, h]], float)], [True], r)
    return loop


def _check_against_buffer(loops, polygon, d, closed=True, tolerance=1e-3):
    """Our loops against shapely's buffer of the very polyline we offset."""
    assert all(shapely.Polygon(loop).is_valid for loop in loops)
    geom = shapely.Polygon(polygon) if closed else shapely.LineString(polygon)
    reference = geom.buffer(d, quad_segs=64)
    ours = as_shape(loops)
    assert ours.is_valid
    size = extent(polygon)
    assert ours.symmetric_difference(reference).area <= tolerance * size * reference.length + 1e-9


@pytest.mark.parametrize("cell", [None, 0.02])
@pytest.mark.parametrize("d", [0.1, 0.5, 1.0, -0.1])
def test_kerf_of_a_rounded_plate(d, cell):
    # The nameplate: an 80 x 30 rectangle rounded by an offset of 5, then a kerf. The plate's
    # straight sides run through samples of the kerf's grid, exactly on its input vertices.
    plate = _rounded_rectangle(80.0, 30.0, 5.0)
    loops = offset_polylines([plate], [True], d, cell=cell)
    assert len(loops) == 1
    _check_against_buffer(loops, plate, d)
    # The kerf of the plate is the plate of the rectangle grown by 5 + d (to the tolerance).
    reference = shapely.box(0, 0, 80, 30).buffer(5 + d, quad_segs=64)
    assert as_shape(loops).symmetric_difference(reference).area <= 1e-3 * 90 * reference.length


def test_kerf_traces_on_the_first_grid(monkeypatch):
    # The exact distance, not the shifted grids of the fallback, is what makes it work.
    from formgraph.kernels.offset import marching

    monkeypatch.setattr(marching, "_SHIFTS", (0.0,))
    plate = _rounded_rectangle(80.0, 30.0, 5.0)
    for d in (0.1, -0.1, 0.5):
        _check_against_buffer(offset_polylines([plate], [True], d), plate, d)


_OFFSET_SETTINGS = settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck))


@_OFFSET_SETTINGS
@given(
    st.integers(1, 40),
    st.integers(1, 40),
    st.sampled_from([0.5, 1.0, 2.0, 5.0]),
    st.sampled_from([0.05, 0.1, 0.25, 0.5, 1.0, -0.05, -0.1, -0.25]),
    st.sampled_from([None, 0.01, 0.02, 0.05]),
)
def test_offsets_of_grid_aligned_offsets(w, h, r, d, cell):
    # Whole-number sizes and round distances put many samples exactly on the input and on
    # the level: the degenerate cases.
    plate = _rounded_rectangle(float(w), float(h), r)
    if cell is not None and cell >= 0.9 * abs(d):
        cell = abs(d) / 2
    loops = offset_polylines([plate], [True], d, cell=cell)
    _check_against_buffer(loops, plate, d)


@_OFFSET_SETTINGS
@given(
    star_polygons(),
    st.floats(-0.2, 0.3).filter(lambda d: abs(d) > 0.03),
    st.floats(-0.1, 0.1).filter(lambda d: abs(d) > 0.005),
    st.sampled_from([None, 0.5, 0.25]),
)
def test_offsets_of_our_own_outputs(polygon, d1, d2, cell_share):
    # Each loop of an offset, offset again (inward, outward, at kerf-like distances).
    first = offset_polylines([polygon], [True], d1)
    if not first:
        return
    cell = None if cell_share is None else cell_share * abs(d2)
    loops = offset_polylines(first, [True] * len(first), d2, cell=cell)
    reference = as_shape(first).buffer(d2, quad_segs=64)
    ours = as_shape(loops)
    assert ours.is_valid
    size = max(extent(*first), 1e-9)
    assert ours.symmetric_difference(reference).area <= 1e-3 * size * reference.length + 1e-9


@_OFFSET_SETTINGS
@given(
    st.lists(st.tuples(st.integers(-20, 20), st.integers(-20, 20)), min_size=2, max_size=30),
    st.sampled_from([0.25, 0.5, 1.0, 2.0]),
    st.sampled_from([None, 0.1, 0.2]),
)
def test_offsets_of_arbitrary_open_polylines(points, d, cell):
    # Integer vertices (repeats, spikes, self-crossings and collinear runs included): a band.
    pts = np.array(points, dtype=float) / 4
    loops = offset_polylines([pts], [False], d, cell=cell)
    if np.ptp(pts, axis=0).max() == 0:
        reference = shapely.Point(pts[0]).buffer(d, quad_segs=64)
        assert as_shape(loops).symmetric_difference(reference).area <= 1e-3 * 2 * d * 7
        return
    _check_against_buffer(loops, pts, d, closed=False)


def test_a_trace_failure_says_where_and_what_to_do(monkeypatch):
    from formgraph.kernels.offset import OffsetTraceError, contour, marching

    def broken(*args, **kwargs):
        raise contour.InconsistentField("inconsistent field samples: test", np.array([0]))

    monkeypatch.setattr(marching, "trace_crossings", broken)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    with pytest.raises(OffsetTraceError, match=r"near \(.*\).*shifted grids.*different cell"):
        offset_polylines([square], [True], 0.1)


def test_segment_tree_of_a_messy_input_matches_brute_force(monkeypatch):
    # Random points joined up: long segments criss-crossing, cut into pieces in Z-order for
    # the tree; results still name the whole segment and its parameter. Small chunks force
    # the chunked path.
    from formgraph.kernels.offset import distance

    monkeypatch.setattr(distance, "_FIRST_CHUNK", 64)
    monkeypatch.setattr(distance, "_MAX_PAIRS", 2000)
    rng = np.random.default_rng(5)
    a = rng.uniform(0, 1, (60, 2))
    b = np.roll(a, -1, axis=0)
    tree = SegmentTree(a, b)
    assert tree._n_pieces > a.shape[0]
    p = rng.uniform(-0.2, 1.2, (700, 2))
    brute, t = point_segment(p[:, None], a[None], b[None])
    near = tree.query(p)
    assert np.allclose(near.dist, brute.min(axis=1), rtol=0, atol=1e-12)
    rows = np.arange(700)
    assert np.allclose(brute[rows, near.segment], near.dist, atol=1e-12)
    foot = a[near.segment] + near.t[:, None] * (b[near.segment] - a[near.segment])
    assert np.allclose(np.hypot(*(p - foot).T), near.dist, atol=1e-12)
    band = tree.query(p, 0.01, 0.02, upper=np.full(700, np.inf))
    true = brute.min(axis=1)
    inside = (true >= 0.01) & (true <= 0.02)
    assert np.allclose(band.dist[inside], true[inside], atol=1e-12)
    assert ((band.dist < 0.01) == (true < 0.01)).all()
    assert ((band.dist > 0.02) == (true > 0.02)).all()


def test_messy_input_is_charged_against_the_budget():
    # 300 random points as one closed polyline, offset by 0.001: every sample near the
    # (very long) result tests many segments. The work is counted and refused early,
    # instead of gigabytes of (point, node) pairs.
    from formgraph.kernels.offset import WorkLimit

    pts = np.random.default_rng(0).uniform(0, 1, (300, 2))
    with pytest.raises(WorkLimit, match=r"more than 5,000,000 \(point, segment\) pairs"):
        offset_polylines([pts], [True], 0.001, max_cells=5_000_000)
    # A clean input of as many segments does the same offset in far fewer pairs.
    th = np.linspace(0, 2 * np.pi, 300, endpoint=False)
    (loop,) = offset_polylines([np.c_[np.cos(th), np.sin(th)] / 2 + 0.5], [True], 0.001)
    assert np.allclose(np.hypot(*(loop - 0.5).T).max(), 0.501, atol=1e-3)


@pytest.mark.xfail(strict=True, reason="marching path defect found exploring, not yet fixed")
def test_an_open_polyline_crossing_near_itself_at_a_coarse_cell():
    # Found by the exploring property test (seed 153): at cell 0.1 (0.4 |d|) the band of
    # this open polyline comes out 0.025 too large in area (2.3 % of it; GEOS's buffer and
    # the marching path at its default cell agree with shapely to 1.6e-4).
    pts = np.array([(0, 1), (0, -1), (3, 0), (2, 2)], dtype=float) / 4
    loops = koffset.offset_polylines([pts], [False], 0.25, cell=0.1)
    _check_against_buffer(loops, pts, 0.25, closed=False)
