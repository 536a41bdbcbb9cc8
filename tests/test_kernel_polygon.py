"""Ear clipping of one polygon (kernels/mesh/polygon.py) against shapely: the triangles
tile the polygon exactly (areas add up, each lies inside, none is flipped)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from formgraph.kernels.mesh import WorkLimitError, meshops, triangulate_polygon


def star(k: int, inner: float = 0.4) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    r = np.where(np.arange(k) % 2 == 0, 1.0, inner)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def signed_areas(xy: np.ndarray, tris: np.ndarray) -> np.ndarray:
    a, b, c = xy[tris[:, 0]], xy[tris[:, 1]], xy[tris[:, 2]]
    return 0.5 * (
        (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    )


def assert_tiles(xy: np.ndarray, tris: np.ndarray) -> None:
    shapely = pytest.importorskip("shapely")
    poly = shapely.Polygon(xy)
    assert poly.is_valid
    k = len(xy)
    assert tris.shape == (k - 2, 3)
    assert np.array_equal(np.sort(np.unique(tris)), np.arange(k))  # every corner used
    area = signed_areas(xy, tris)
    sign = 1.0 if poly.exterior.is_ccw else -1.0
    assert np.all(sign * area > 0)  # same winding as the loop, no flipped triangle
    assert abs(np.abs(area).sum() - poly.area) <= 1e-9 * poly.area
    centroids = xy[tris].mean(axis=1)
    assert np.all(shapely.contains_xy(poly.buffer(1e-9 * np.sqrt(poly.area)), *centroids.T))


@pytest.mark.parametrize("k", [4, 6, 40, 1200])
def test_stars_are_tiled(k):
    xy = star(k)
    assert_tiles(xy, triangulate_polygon(xy))


def test_a_clockwise_loop_gets_clockwise_triangles():
    xy = star(30)[::-1]
    tris = triangulate_polygon(xy)
    assert_tiles(xy, tris)
    assert np.all(signed_areas(xy, tris) < 0)


def test_a_comb_with_deep_teeth_is_tiled():
    n = 200
    x = np.linspace(0, 1, n)
    top = np.column_stack([x[::-1], 1 + 3 * (np.arange(n) % 2)])
    xy = np.concatenate([np.column_stack([x, np.zeros(n)]), top])
    assert_tiles(xy, triangulate_polygon(xy))


@settings(max_examples=40, deadline=None)
@given(k=st.integers(3, 300), seed=st.integers(0, 10_000))
def test_random_star_shaped_polygons_are_tiled(k, seed):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * np.pi, k))
    t += np.arange(k) * 1e-6  # distinct angles
    r = rng.uniform(0.1, 1.0, k)
    xy = np.column_stack([r * np.cos(t), r * np.sin(t)])
    shapely = pytest.importorskip("shapely")
    if not shapely.Polygon(xy).is_valid:
        return  # (nearly coincident angles can touch)
    assert_tiles(xy, triangulate_polygon(xy))


def test_a_loop_in_space_is_triangulated_in_its_plane_and_keeps_its_normal():
    xy = star(50)
    rot = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    pts = np.column_stack([xy, np.zeros(len(xy))]) @ rot.T + [3, -2, 5]
    tris = triangulate_polygon(pts)
    assert_tiles(xy, tris)
    normal = np.cross(pts[tris[:, 1]] - pts[tris[:, 0]], pts[tris[:, 2]] - pts[tris[:, 0]])
    newell = np.cross(pts, np.roll(pts, -1, axis=0)).sum(axis=0)
    assert np.all(normal @ newell > 0)


def test_the_work_is_refused_past_the_limit():
    with pytest.raises(WorkLimitError, match="triangle-corner tests"):
        triangulate_polygon(star(2000), max_tests=1000)


def test_agrees_with_mapbox_earcut_on_the_count_and_area():
    earcut = pytest.importorskip("mapbox_earcut")
    xy = star(600, inner=0.2)
    ref = earcut.triangulate_float64(xy, np.array([len(xy)], dtype=np.uint32)).reshape(-1, 3)
    ours = triangulate_polygon(xy)
    assert len(ours) == len(ref)
    assert np.abs(signed_areas(xy, ours)).sum() == pytest.approx(
        np.abs(signed_areas(xy, ref)).sum(), rel=1e-12
    )


def test_mesh_triangulate_clips_a_large_concave_face():
    xy = star(1200)
    v = np.column_stack([xy, np.zeros(len(xy))])
    _, fi, fo = meshops.triangulate(v, np.arange(len(xy)), np.array([0, len(xy)]))
    tris = fi.reshape(-1, 3)
    assert_tiles(xy, tris)


def test_large_faces_alone_and_batched_are_triangulated_alike():
    # up to 8 large faces of one size take the one-plane path, more the batched test:
    # a convex face is a fan from its first corner either way, a concave one is clipped
    k = 40
    a = 2 * np.pi * np.arange(k) / k
    convex = np.column_stack([np.cos(a), np.sin(a)])
    concave = star(k)
    tilt = np.array([[1.0, 0, 0], [0, 0.6, 0.8]])  # a plane in space
    for loop in (convex, concave):
        v = np.tile(loop @ tilt, (9, 1))
        fi = np.arange(9 * k)
        alone = meshops.triangulate(v[:k], fi[:k], np.array([0, k]))[1].reshape(-1, 3)
        batched = meshops.triangulate(v, fi, np.arange(0, 9 * k + 1, k))[1].reshape(-1, 3)
        assert np.array_equal(alone, batched[: k - 2])
        assert_tiles(loop, alone)
    fan = meshops.triangulate(convex @ tilt, np.arange(k), np.array([0, k]))[1].reshape(-1, 3)
    assert (fan[:, 0] == 0).all() and np.array_equal(fan[:, 1], np.arange(1, k - 1))


def test_bad_polygons_are_refused():
    with pytest.raises(ValueError, match="at least 3 corners"):
        triangulate_polygon(np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"\(k, 2\) or \(k, 3\)"):
        triangulate_polygon(np.zeros((5, 4)))
    with pytest.raises(ValueError, match="finite"):
        triangulate_polygon([[0, 0], [1, 0], [np.nan, 1]])


@settings(max_examples=60, deadline=None)
@given(
    k=st.integers(3, 80),
    seed=st.integers(0, 10_000),
    dup=st.booleans(),
)
def test_any_loop_gets_k_minus_2_triangles_of_its_corners(k, seed, dup):
    """Self-intersecting, repeated and collinear corners: no crash, no endless loop."""
    rng = np.random.default_rng(seed)
    xy = rng.integers(-3, 4, size=(k, 2)).astype(float)  # many collinear and equal points
    if dup:
        xy[k // 2] = xy[0]
    tris = triangulate_polygon(xy)
    assert tris.shape == (k - 2, 3)
    assert tris.min() >= 0 and tris.max() < k
    assert np.all(
        (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
    )


def test_a_loop_of_no_area_is_fanned_without_error():
    xy = np.column_stack([np.arange(6.0), np.zeros(6)])
    assert triangulate_polygon(xy).shape == (4, 3)
    assert triangulate_polygon(np.zeros((5, 3))).shape == (3, 3)


def test_earcut_answers_are_checked_before_they_are_used(monkeypatch):
    # A wrong answer from the library (here: triangles dropped, then one flipped) is not
    # used: the rounds of our own clipper tile the polygon instead.
    import mapbox_earcut

    from formgraph.kernels.mesh import polygon

    xy = star(300)
    good = mapbox_earcut.triangulate_float64(xy, np.array([300], dtype=np.uint32))
    for bad in (good[:-3], np.r_[good[:-3], good[-3:][::-1]]):
        monkeypatch.setattr(mapbox_earcut, "triangulate_float64", lambda *a, b=bad: b)
        assert polygon._earcut(polygon.polygon_plane(xy)) is None
        assert_tiles(xy, triangulate_polygon(xy))


def test_a_self_crossing_loop_falls_back_to_the_rounds():
    # A bow tie of many corners: earcut drops triangles there; the rounds still give k - 2.
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    xy = np.column_stack([np.sin(t), np.sin(t) * np.cos(t)])
    tris = triangulate_polygon(xy)
    assert tris.shape == (398, 3)
    assert np.array_equal(np.unique(tris), np.arange(400))


def _star_with_holes(seed: int, k: int, holes: int) -> tuple[np.ndarray, np.ndarray]:
    """An outer star (counter-clockwise, radii 0.6-1) and up to 3 star holes (clockwise,
    radii 0.05-0.15) around points 0.35 from the centre, 0.6 apart: rings that never
    touch."""
    rng = np.random.default_rng(seed)

    def ring(m: int, lo: float, hi: float) -> np.ndarray:
        # angles spread evenly, each moved by up to 0.4 of its share: no gap of pi or
        # more, so the ring winds once about its centre, counter-clockwise
        t = 2 * np.pi * (np.arange(m) + rng.uniform(0, 0.4, m)) / m
        r = rng.uniform(lo, hi, m)
        return np.column_stack([r * np.cos(t), r * np.sin(t)])

    rings = [ring(k, 0.6, 1.0)]
    for j in range(holes):
        a = 2 * np.pi * j / 3
        rings.append(
            ring(int(rng.integers(3, 12)), 0.05, 0.15)[::-1]
            + 0.35 * np.array([np.cos(a), np.sin(a)])
        )
    return np.concatenate(rings), np.cumsum([len(r) for r in rings]).astype(np.uint32)


def assert_tiles_region(xy: np.ndarray, ends: np.ndarray, tris: np.ndarray) -> None:
    """shapely's word: the triangles' areas add up to the region's, each lies inside it,
    and together they cover it (their union's area is the region's: no overlap, no gap)."""
    shapely = pytest.importorskip("shapely")
    rings = np.split(xy, ends[:-1].astype(np.int64))
    region = shapely.Polygon(rings[0], rings[1:])
    assert region.is_valid
    area = signed_areas(xy, tris)
    assert np.all(area > 0)
    assert abs(area.sum() - region.area) <= 1e-9 * region.area
    pieces = shapely.polygons(xy[tris])
    assert np.all(shapely.covers(region.buffer(1e-9), pieces))
    assert shapely.union_all(pieces).area == pytest.approx(region.area, rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), k=st.integers(3, 200), holes=st.integers(0, 3))
def test_earcut_on_stars_with_holes_is_accepted_and_tiles(seed, k, holes):
    earcut = pytest.importorskip("mapbox_earcut")
    from formgraph.kernels.mesh.polygon import tiling

    xy, ends = _star_with_holes(seed, k, holes if k >= 8 else 0)  # (a few corners: thin)
    tris = tiling(xy, ends, earcut.triangulate_float64(xy, ends))
    assert tris is not None
    assert_tiles_region(xy, ends, tris)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    holes=st.integers(0, 2),
    how=st.sampled_from(["move", "swap", "repeat", "reverse"]),
)
def test_tiling_accepts_only_what_tiles(seed, holes, how):
    """earcut's answer spoiled (a corner moved to another, two triangles sharing a corner
    swapped, a triangle repeated over another, one turned over): refused, or, where the
    change happens to give a tiling still, shapely agrees that it tiles."""
    earcut = pytest.importorskip("mapbox_earcut")
    from formgraph.kernels.mesh.polygon import tiling

    xy, ends = _star_with_holes(seed, 12, holes)
    tris = tiling(xy, ends, earcut.triangulate_float64(xy, ends)).copy()
    rng = np.random.default_rng(seed)
    t, c = rng.integers(len(tris)), rng.integers(3)
    if how == "move":
        tris[t, c] = (tris[t, c] + 1 + rng.integers(len(xy) - 1)) % len(xy)
    elif how == "swap":
        tris[t, [c, (c + 1) % 3]] = tris[t, [(c + 1) % 3, c]]
    elif how == "repeat":
        tris[(t + 1) % len(tris)] = tris[t]
    else:
        tris = tris[:, ::-1] if rng.integers(2) else np.r_[tris[:t], tris[t:][:, ::-1]]
    got = tiling(xy, ends, tris)
    if got is not None:
        assert_tiles_region(xy, ends, got)
    if how in ("swap", "repeat"):
        assert got is None


def test_an_overlap_over_a_gap_of_the_same_area_is_refused(monkeypatch):
    # two triangles of a square on the same edge: k - 2 of them, neither flipped, their
    # areas adding up to the square's (what the check counted before), yet they overlap
    # and leave a gap; the edge 0 -> 1 runs twice, which the pairing refuses
    import mapbox_earcut

    from formgraph.kernels.mesh import polygon

    xy = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    bad = np.array([0, 1, 2, 0, 1, 3], dtype=np.uint32)
    assert np.abs(signed_areas(xy, bad.reshape(-1, 3))).sum() == 1.0
    assert polygon.tiling(xy, np.array([4]), bad) is None
    monkeypatch.setattr(mapbox_earcut, "triangulate_float64", lambda *a: bad)
    assert_tiles(xy, triangulate_polygon(xy))


def test_tiling_refuses_indices_outside_the_rings():
    from formgraph.kernels.mesh.polygon import tiling

    xy = star(6)
    ends = np.array([6])
    assert tiling(xy, ends, np.array([0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 9])) is None
    assert tiling(xy, ends, np.array([0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, -1])) is None
    assert tiling(xy, ends, np.array([0, 1, 2])) is None  # too few


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), k=st.integers(3, 60), flat=st.booleans())
def test_the_plane_of_a_loop_keeps_its_lengths_and_runs_counter_clockwise(seed, k, flat):
    """polygon_plane of a planar loop placed anywhere in space: an isometry (every
    distance between corners kept) onto a counter-clockwise loop, the Newell normal (by
    np.cross, the reference) pointing at the viewer."""
    from formgraph.kernels.mesh.polygon import polygon_plane

    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * np.pi, k)) + np.arange(k) * 1e-6
    r = rng.uniform(0.2, 1.0, k)
    xy = np.column_stack([r * np.cos(t), r * np.sin(t)])
    rot = np.eye(3) if flat else np.linalg.qr(rng.normal(size=(3, 3)))[0]
    pts = np.column_stack([xy, np.zeros(k)]) @ rot.T + rng.uniform(-5, 5, 3)
    plane = polygon_plane(pts)
    d3 = np.linalg.norm(pts[:, None] - pts[None], axis=-1)
    d2 = np.linalg.norm(plane[:, None] - plane[None], axis=-1)
    assert np.allclose(d2, d3, atol=1e-12 * 10)
    shoelace = np.sum(
        plane[:, 0] * np.roll(plane[:, 1], -1) - np.roll(plane[:, 0], -1) * plane[:, 1]
    )
    assert shoelace > 0
    newell = np.cross(pts, np.roll(pts, -1, axis=0)).sum(axis=0)
    assert np.linalg.norm(newell) == pytest.approx(shoelace, rel=1e-9)
