"""kernels.curves.regions: rings into regions (the even-odd rule, the simplicity shortcut) and
the result's rings back out (orientation, repeats, step lengths), against shapely."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

from formgraph.kernels.curves import regions


def oriented_reference(region: shapely.Geometry) -> tuple[np.ndarray, np.ndarray]:
    """Every ring of the region's polygons, shells CCW and holes CW (GEOS's own
    orient_polygons, independent of ours), points and offsets."""
    parts = shapely.get_parts(region)
    parts = parts[shapely.get_type_id(parts) == 3]
    rings = shapely.get_rings(shapely.orient_polygons(parts, exterior_cw=False))
    sizes = shapely.get_num_coordinates(rings)
    return shapely.get_coordinates(rings), np.concatenate([[0], np.cumsum(sizes)])


def square(x: float, y: float, s: float) -> np.ndarray:
    return np.array([[x, y], [x + s, y], [x + s, y + s], [x, y + s]], dtype=float)


@st.composite
def random_regions(draw):
    """Unions of random star polygons: holes, several parts, any orientation GEOS gives."""
    n = draw(st.integers(1, 4))
    polys = []
    for _ in range(n):
        k = draw(st.integers(3, 12))
        cx, cy = draw(st.floats(-3, 3)), draw(st.floats(-3, 3))
        r = np.array(draw(st.lists(st.floats(0.2, 2), min_size=k, max_size=k)))
        t = np.sort(np.array(draw(st.lists(st.floats(0, 6.2), min_size=k, max_size=k))))
        t += np.arange(k) * 1e-3  # distinct angles
        polys.append(shapely.Polygon(np.c_[cx + r * np.cos(t), cy + r * np.sin(t)]).buffer(0))
    return shapely.union_all(polys)


@settings(max_examples=60, deadline=None)
@given(random_regions(), st.booleans())
def test_rings_come_out_as_geos_orients_them(region, with_z):
    coords, offsets, hole, step = regions.rings_of(region, with_z=with_z, steps=True)
    ref, ref_offsets = oriented_reference(region)
    np.testing.assert_array_equal(offsets, ref_offsets)
    np.testing.assert_array_equal(coords[:, :2], ref)
    assert coords.shape[1] == (3 if with_z else 2)
    if with_z:
        assert not coords[:, 2].any()
    ccw = [
        shapely.is_ccw(shapely.linearrings(coords[a:b, :2]))
        for a, b in zip(offsets[:-1], offsets[1:], strict=True)
    ]
    np.testing.assert_array_equal(ccw, ~hole)
    inside = np.ones(len(coords) - 1, dtype=bool)
    inside[offsets[1:-1] - 1] = False  # the jumps between rings
    length = np.hypot(*np.diff(coords[:, :2], axis=0).T)
    np.testing.assert_allclose(step[inside], length[inside], rtol=1e-15)


def test_many_rings_take_the_gather_and_agree_with_the_few():
    # 100 squares with a hole each: 200 rings, past the slice-per-ring path
    parts = [
        shapely.Polygon(square(3 * i, 0, 2), [square(3 * i + 0.5, 0.5, 1)[::-1]])
        for i in range(100)
    ]
    region = shapely.MultiPolygon(parts)
    coords, offsets, hole, step = regions.rings_of(region, with_z=True, steps=True)
    ref, ref_offsets = oriented_reference(region)
    np.testing.assert_array_equal(offsets, ref_offsets)
    np.testing.assert_array_equal(coords[:, :2], ref)
    assert hole.tolist() == [False, True] * 100
    few = [regions.rings_of(p, steps=True) for p in parts[:3]]
    n = few[0][1][-1]
    for k, (c, _, _, s) in enumerate(few):  # the same rings, one polygon at a time
        np.testing.assert_array_equal(coords[k * n : (k + 1) * n, :2], c)
        np.testing.assert_array_equal(step[k * n : (k + 1) * n - 1], s)


def test_repeated_points_are_dropped_and_no_step_is_zero():
    ring = np.array([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1], [0, 1], [0, 0]], dtype=float)
    coords, offsets, hole, step = regions.rings_of(shapely.Polygon(ring), steps=True)
    assert offsets.tolist() == [0, 5] and not hole[0]
    assert (step > 0).all() and np.isclose(step.sum(), 4.0)
    assert shapely.is_ccw(shapely.linearrings(coords))


def test_a_tiny_ring_far_away_keeps_its_orientation():
    far = square(1e7, -1e7, 1e-5)  # its area, 1e-10, far below the coordinates' squares
    region = shapely.MultiPolygon([shapely.Polygon(far[::-1]), shapely.Polygon(square(0, 0, 1))])
    coords, offsets, hole = regions.rings_of(region)
    for a, b in zip(offsets[:-1], offsets[1:], strict=True):
        assert shapely.is_ccw(shapely.linearrings(coords[a:b]))


def test_steps_below_the_square_root_of_the_smallest_double_are_not_zero():
    ring = square(0, 0, 1e-160)  # dx * dx underflows to 0
    *_, step = regions.rings_of(shapely.Polygon(ring), steps=True)
    np.testing.assert_allclose(step, 1e-160, rtol=1e-15)


def test_an_empty_or_lineal_region_has_no_rings():
    for region in (shapely.Polygon(), shapely.LineString([(0, 0), (1, 1)])):
        coords, offsets, hole, step = regions.rings_of(region, with_z=True, steps=True)
        assert coords.shape == (0, 3) and offsets.tolist() == [0]
        assert len(hole) == 0 and len(step) == 0


@st.composite
def random_rings(draw):
    """Rings of few random lattice points: often self-crossing, touching, collinear."""
    k = draw(st.integers(3, 9))
    pts = draw(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4)), min_size=k, max_size=k))
    return np.array(pts, dtype=float)


def even_odd_faces(ring: np.ndarray) -> shapely.Geometry:
    """The even-odd region of a ring from its definition: the faces of its noded linework
    whose inner point the ring's edges cross an odd number of times (a ray to +x)."""
    noded = shapely.node(shapely.LineString(np.r_[ring, ring[:1]]))
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
    if len(faces) == 0:
        return shapely.Polygon()
    inner = shapely.get_coordinates(shapely.point_on_surface(faces))
    a, b = ring, np.roll(ring, -1, axis=0)
    x, y = inner[:, :1], inner[:, 1:]
    spans = (a[:, 1] > y) != (b[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        cut = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    odd = (spans & (cut > x)).sum(axis=1) % 2 == 1
    return shapely.union_all(faces[odd]) if odd.any() else shapely.Polygon()


@settings(max_examples=150, deadline=None)
@example(np.array([(0, 0), (0, -1), (2, 0), (-1, 0), (1, 0), (0, -2)], dtype=float))
@given(random_rings())
def test_each_ring_is_its_even_odd_region(ring):
    # Against the definition, not GEOS's linework repair: that one takes the faces of the
    # noded ring alternately, wrong where the ring runs back over a stretch of itself (the
    # example: a triangle the ring crosses twice came out inside); elsewhere the two agree.
    poly = shapely.Polygon(ring)
    if regions.distinct_steps(np.r_[ring, ring[:1]]) < 3:
        with pytest.raises(regions.NoArea):
            regions.each_region([ring])
        return
    ours = regions.each_region([ring])
    assert shapely.is_valid(ours)
    assert shapely.symmetric_difference(ours, even_odd_faces(ring)).area <= 1e-12
    if not regions._runs_over_itself(shapely.linearrings(np.r_[ring, ring[:1]])):
        ref = shapely.make_valid(poly, method="linework")
        assert shapely.symmetric_difference(ours, ref).area <= 1e-12


def test_a_simple_ring_is_taken_as_it_is():
    t = np.linspace(0, 2 * np.pi, 500, endpoint=False)
    ring = np.c_[np.cos(t), np.sin(t), np.full(500, 3.0)]  # z is dropped
    (poly,) = regions._even_odd_each(*regions._linearrings([ring]))
    np.testing.assert_array_equal(shapely.get_coordinates(poly), np.r_[ring, ring[:1]][:, :2])


@pytest.mark.parametrize(
    "ring",
    [
        [[1, 1]] * 6,  # one point: GEOS calls it simple
        [[0, 0], [1, 1], [1, 1], [0, 0]],  # two points: there and back
        [[2, 2], [2, 2], [2, 2]],
    ],
)
def test_rings_of_fewer_than_three_points_bound_no_area(ring):
    good = square(5, 5, 1)
    for make, rings in (
        (regions.each_region, [good, np.array(ring, float)]),
        (regions.even_odd_region, [good, np.array(ring, float)]),
        (regions.even_odd_region, [np.array(ring, float)]),
    ):
        with pytest.raises(regions.NoArea) as exc:
            make(rings)
        assert exc.value.ring == len(rings) - 1


def test_planar_points_are_contiguous_xy():
    p = np.arange(30.0).reshape(10, 3)
    xy = regions.planar(p)
    assert xy.flags.c_contiguous and xy.shape == (10, 2)
    np.testing.assert_array_equal(xy, p[:, :2])
    assert regions.planar(xy) is xy
    assert regions.distinct_steps(np.array([[0, 0], [0, 0], [1, 0], [1, 0], [0, 0.0]])) == 2


def star_ring(t: np.ndarray, r: np.ndarray, centre=(0.0, 0.0)) -> np.ndarray:
    ring = np.c_[centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)]
    return np.ascontiguousarray(np.r_[ring, ring[:1]])


def star_shaped(ring: np.ndarray) -> bool:
    return regions._star_shaped(ring, shapely.bounds(shapely.linearrings(ring)))


@settings(max_examples=150, deadline=None)
@given(
    st.integers(4, 60),
    st.integers(0, 2**32 - 1),
    st.sampled_from(["sorted", "shuffled", "jittered"]),
    st.booleans(),
)
def test_a_ring_shown_star_shaped_is_simple(k, seed, order, clockwise):
    # sound: whatever the ring, "star-shaped" is never said of a ring GEOS finds not simple
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * np.pi, k))
    if order == "shuffled":
        rng.shuffle(t)
    elif order == "jittered":  # mostly turning one way, a few steps back
        t = t + rng.normal(0, 0.3, k) * (rng.random(k) < 0.2)
    r = rng.uniform(rng.uniform(0.05, 1.9), 2.0, k)  # from wild to nearly round
    ring = star_ring(t[::-1] if clockwise else t, r, centre=tuple(rng.uniform(-1e3, 1e3, 2)))
    if star_shaped(ring):
        assert shapely.is_simple(shapely.linearrings(ring))


def test_long_star_shaped_rings_are_shown_so_both_ways_round():
    t = np.linspace(0, 2 * np.pi, 5000, endpoint=False)
    blob = star_ring(t, 1 + 0.3 * np.sin(9 * t), centre=(1e6, -2e6))
    assert star_shaped(blob) and star_shaped(blob[::-1].copy())
    simple = regions._simple(
        np.array([shapely.linearrings(blob)]),
        [blob],
        shapely.bounds(shapely.linearrings(blob))[None],
    )
    assert simple.tolist() == [True]


def test_rings_that_wind_twice_or_turn_back_are_not_shown_star_shaped():
    t = np.linspace(0, 4 * np.pi, 5, endpoint=False)  # a pentagram: every edge turns left
    pentagram = star_ring(t, np.ones(5))
    assert not star_shaped(pentagram)
    t = np.linspace(0, 2 * np.pi, 3000, endpoint=False)
    back = star_ring(t + 0.5 * np.sin(3 * t), np.ones(3000))  # angle not monotone: loops
    assert not star_shaped(back)
    # both refused rings are told apart by GEOS instead, and read by the even-odd rule
    for ring in (pentagram, back):
        ours = regions.each_region([ring])
        ref = shapely.make_valid(shapely.Polygon(ring), method="linework")
        assert shapely.symmetric_difference(ours, ref).area <= 1e-9 * ref.area
