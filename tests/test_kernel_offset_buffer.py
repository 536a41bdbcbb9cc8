"""The GEOS path of the offset (`buffer_polylines`) against the marching path and closed forms.

The two paths share nothing but the input: one buffers the even-odd region in GEOS, the
other traces the level set of an exact distance field. Where both promise 0.1 % of the
extent, their results must agree to that (Hausdorff), on random stars, self-intersecting
loops, nested loops, open polylines and offsets of offsets, inward and outward.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from formgraph.kernels.offset import (
    BufferDeclined,
    buffer_polylines,
    offset_loops,
    offset_polylines,
    quad_segs,
)
from formgraph.kernels.offset import buffer as kbuffer
from formgraph.kernels.offset.distance import SegmentTree

# Derandomized again: explored, test_offsets_of_offsets_agree found a marching-path defect
# (test_a_star_shrunk_twice_by_a_tenth, a strict xfail) in the fourth of seven full runs,
# and hypothesis's example database then replayed it in every later run. Explore again
# once that defect and test_a_tiny_offset_offset_again_past_five_percent_of_its_extent
# are fixed (issue #33, item 14).
_SETTINGS = settings(
    max_examples=20, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck)
)


def area(loop: np.ndarray) -> float:
    x, y = loop[:, 0], loop[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def extent(polylines) -> float:
    pts = np.concatenate(polylines)
    return float(np.ptp(pts, axis=0).max())


def _edges(lines: list[np.ndarray]) -> shapely.STRtree:
    """A tree of the lines' segments (each line's points in order)."""
    segs = np.concatenate([np.stack([p[:-1], p[1:]], axis=1) for p in lines if len(p) > 1])
    return shapely.STRtree(shapely.linestrings(segs))


def _far(points: np.ndarray, tree: shapely.STRtree) -> np.ndarray:
    """Each point's distance to the nearest segment in the tree."""
    _, dist = tree.query_nearest(shapely.points(points), return_distance=True, all_matches=False)
    return dist


def _samples(lines: list[np.ndarray], step: float) -> np.ndarray:
    return shapely.get_coordinates(shapely.segmentize(shapely.MultiLineString(lines), step))


def hausdorff(a: list[np.ndarray], b: list[np.ndarray], step: float) -> float:
    """Hausdorff distance between two sets of closed loops, their chords sampled at ``step``."""
    if not a or not b:
        return 0.0 if not a and not b else np.inf
    la, lb = [np.r_[lp, lp[:1]] for lp in a], [np.r_[lp, lp[:1]] for lp in b]
    da = _far(_samples(la, step), _edges(lb))
    db = _far(_samples(lb, step), _edges(la))
    return float(max(da.max(), db.max()))


def level_error(loops: list[np.ndarray], polylines, closed, d, step: float) -> float:
    """How far the loops' points (chords sampled at ``step``) are from the level set: the
    largest ``| distance to the input - |d| |``."""
    if not loops:
        return 0.0
    lines = [np.r_[p, p[:1]] if c else p for p, c in zip(polylines, closed, strict=True)]
    lines = [np.r_[p, p] if len(p) == 1 else p for p in lines]
    dist = _far(_samples([np.r_[lp, lp[:1]] for lp in loops], step), _edges(lines))
    return float(np.abs(dist - abs(d)).max())


def reference(polylines, closed, d) -> list[np.ndarray]:
    """The offset as a set, built here from its definition with shapely at 64 chords a
    quarter circle: the even-odd region (the faces of the noded rings whose points the rings
    cross an odd number of times, to the right), with the band of half-width ``|d|`` around
    all the input's linework added (``d > 0``) or taken away; the band alone for open input.
    """
    lines = [np.r_[p, p[:1]] if c else p for p, c in zip(polylines, closed, strict=True)]
    lines = [np.r_[p, p] if len(p) == 1 else p for p in lines]
    band = shapely.MultiLineString(lines).buffer(abs(d), quad_segs=64)
    region = shapely.Polygon()
    rings = [p for p, c in zip(polylines, closed, strict=True) if c]
    if rings:
        # The faces of the noded linework inside by the crossing number of a point in each.
        faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(shapely.node(
            shapely.MultiLineString([np.r_[p, p[:1]] for p in rings])))))  # fmt: skip
        inner = shapely.get_coordinates(shapely.point_on_surface(faces))
        a = np.concatenate(rings)
        b = np.concatenate([np.roll(p, -1, axis=0) for p in rings])
        x, y = inner[:, :1], inner[:, 1:]
        spans = (a[:, 1] > y) != (b[:, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            cut = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
        odd = (spans & (cut > x)).sum(axis=1) % 2 == 1
        region = shapely.union_all(faces[odd]) if odd.any() else region
    shape = region.union(band) if d > 0 else region.difference(band)
    rings = [shapely.get_coordinates(r)[:-1] for r in shapely.get_rings(shapely.get_parts(shape))]
    return [r for r in rings if len(r) >= 3]


def region(loops: list[np.ndarray]) -> shapely.Geometry:
    """The even-odd region of closed loops."""
    shape = shapely.Polygon()
    for lp in loops:
        shape = shape.symmetric_difference(shapely.Polygon(lp))
    return shape


def _at_a_saddle(fast, exact, polylines, closed, d, tol) -> None:
    """Where the GEOS offset is farther than the tolerance from the exact one, its region
    must lie between the exact offsets at ``|d| - tol`` and ``|d| + tol``.

    Near a saddle of the distance to the input (two holes about to part, two islands about
    to meet) the offset's shape is not continuous in the distance: a level error far below
    the tolerance joins two holes by a channel as long as the square root of it times the
    radius (GEOS's chords lie inside their arcs, up to a tenth of the tolerance nearer the
    input: nested stars, d 0.05, a 4.6e-3 channel from a 7.7e-5 deficit, tolerance
    1.5e-3; hypothesis found it). No level-accurate method escapes that, so the promise there
    is the level's: the loops are on the level set within the tolerance (checked by
    `agree`), and the region they bound is sandwiched between the offsets a tolerance
    nearer and farther."""
    ours = region(fast)
    slack = 1e-9 * extent(polylines) ** 2  # the references' own rounding
    step = tol if d > 0 else -tol
    nearer, farther = reference(polylines, closed, d - step), reference(polylines, closed, d + step)
    small, big = (nearer, farther) if d > 0 else (farther, nearer)
    assert region(small).difference(ours).area <= slack
    assert ours.difference(region(big)).area <= slack


def agree(polylines, closed, d) -> list[np.ndarray]:
    """Both paths' offsets within the 0.1 % tolerance of each other, and the GEOS one on
    the level set (every point of it at ``|d|`` from the input, to the tolerance); the GEOS
    loops.

    Where the two differ by more, the GEOS path must be within the tolerance of the offset
    built from its definition (`reference`); the marching path may be off it (a known defect
    on collinear runs that double back: its corner recovery misses where a doubled segment's
    band meets the next edge's offset)."""
    size = extent(polylines)
    scale = size if size > 0 else 2 * abs(d)
    tol = 1e-3 * scale
    try:
        fast = buffer_polylines(polylines, closed, d)
    except BufferDeclined as exc:
        # Above |d| = 5 % of the extent GEOS's dropping of vertices within 1 % of |d| of
        # their neighbours' chord could move the result by more than half the tolerance,
        # and the GEOS path declines where a vertex is that shallow (an offset's own arcs,
        # offset again by 0.1 of a 1.8 extent: hypothesis found it). That is the promise
        # working, not a disagreement: the offset is then the marching path's, which must
        # be within the tolerance of the definition.
        assert "within 1 % of the distance" in str(exc), str(exc)
        assert kbuffer.GEOS_SIMPLIFY_FACTOR * abs(d) > kbuffer.SIMPLIFY_SHARE * tol
        result = offset_loops(polylines, closed, d)
        assert result.path == "marching" and result.declined == str(exc)
        assert hausdorff(result.loops, reference(polylines, closed, d), tol) <= tol
        return result.loops
    slow = offset_polylines(polylines, closed, d)
    assert all(shapely.Polygon(lp).is_valid for lp in fast)
    assert level_error(fast, polylines, closed, d, tol) <= tol
    if hausdorff(fast, slow, tol) > tol:
        exact = reference(polylines, closed, d)
        # Both may be within the tolerance of it and still 2 tolerances apart (nested stars
        # shrunk 0.3, d 0.05: 1.2e-3 and 1.6e-4 from it, tolerance 1.3e-3): only the GEOS
        # path is held to it here; the marching path's own accuracy is tested elsewhere.
        if hausdorff(fast, exact, tol) > tol:
            _at_a_saddle(fast, exact, polylines, closed, d, tol)
        return fast
    # The same islands and holes: orientation by orientation, the same total area.
    for sign in (1, -1):
        a = sum(area(lp) for lp in fast if np.sign(area(lp)) == sign)
        b = sum(area(lp) for lp in slow if np.sign(area(lp)) == sign)
        assert a == pytest.approx(b, abs=2e-3 * scale * max(1.0, scale))
    return fast


# --- closed forms ---------------------------------------------------------------------------


@pytest.mark.parametrize("r", [0.05, 0.3, 2.0])
def test_square_grows_by_chords_of_exact_arcs(r):
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    (loop,) = buffer_polylines([square], [True], r)
    q = quad_segs(r, 1e-3 * 2)
    # Straight sides exact; each corner q chords inscribed in the quarter circle.
    exact = 4 + 4 * 2 * r + 4 * q * 0.5 * r**2 * np.sin(np.pi / (2 * q))
    assert area(loop) == pytest.approx(exact, rel=1e-12)
    inner = np.clip(loop, 0, 2)
    assert np.allclose(np.hypot(*(loop - inner).T), r, rtol=1e-12)
    assert area(loop) > 0  # an island, counter-clockwise


def test_square_shrinks_to_an_exact_square():
    square = np.array([[0, 0], [2, 0], [0 + 2, 2], [0, 2]], dtype=float)
    (loop,) = buffer_polylines([square[::-1]], [True], -0.3)  # clockwise input
    assert area(loop) == pytest.approx(1.4**2, rel=1e-12)
    assert sorted(map(tuple, np.round(loop, 12))) == [
        (0.3, 0.3),
        (0.3, 1.7),
        (1.7, 0.3),
        (1.7, 1.7),
    ]


@pytest.mark.parametrize(("d", "tol"), [(0.05, 2e-3), (1.0, 2e-3), (10.0, 2e-3), (1.0, 1e-7)])
def test_quad_segs_keeps_the_sagitta_under_the_tolerance(d, tol):
    q = quad_segs(d, tol)
    sagitta = d * (1 - np.cos(np.pi / (4 * q)))
    assert sagitta <= kbuffer.ARC_SHARE * tol
    assert q >= 8  # never coarser than GEOS's default
    if q > 8:  # and no finer than it must be
        assert d * (1 - np.cos(np.pi / (4 * (q - 1)))) > kbuffer.ARC_SHARE * tol


def test_circle_offsets_within_the_tolerance_between_vertices():
    t = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    circle = np.c_[np.cos(t), np.sin(t)]
    for d in (0.05, -0.05, 0.1, -0.1):
        (loop,) = buffer_polylines([circle], [True], d)
        mid = (loop + np.roll(loop, -1, axis=0)) / 2
        for p in (loop, mid):
            assert np.abs(np.hypot(*p.T) - (1 + d)).max() < 1e-3 * 2


def test_open_segment_and_point_give_a_stadium_and_a_disc():
    (loop,) = buffer_polylines([np.array([[0.0, 0.0], [1.0, 0.0]])], [False], 0.2)
    q = quad_segs(0.2, 1e-3 * 1.0)
    caps = 4 * q * 0.5 * 0.2**2 * np.sin(np.pi / (2 * q))  # two half circles of 2 q chords
    assert area(loop) == pytest.approx(0.4 + caps, rel=1e-12)
    (disc,) = buffer_polylines([np.array([[2.0, 3.0]])], [False], 0.5)
    assert np.allclose(np.hypot(disc[:, 0] - 2, disc[:, 1] - 3), 0.5, atol=1e-12)
    assert buffer_polylines([np.array([[0.0, 0.0], [1.0, 0.0]])], [False], -0.2) == []


# --- the marching path's semantics, case by case ---------------------------------------------


def test_nested_rings_make_holes_and_islands_in_holes():
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    ring = np.c_[np.cos(t), np.sin(t)]
    loops = agree([ring * 2, ring * 1.2, ring * 0.5], [True] * 3, -0.1)
    signs = sorted(np.sign([area(lp) for lp in loops]))
    assert signs == [-1, 1, 1]  # the annulus's outside and hole, the island in the hole


def test_squares_sharing_an_edge_part_inward_as_the_field_does():
    # By the even-odd rule the shared edge cancels (one rectangle), but the offset is at a
    # distance from the curves, the shared edge too: inward, two squares.
    left = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    right = left + [1, 0]
    assert len(agree([left, right], [True, True], -0.1)) == 2
    assert len(agree([left, right], [True, True], 0.1)) == 1


def test_a_spike_out_and_back_and_a_two_point_ring_count_as_linework():
    spiked = np.array([[0, 0], [1, 0], [1, 0.5], [2, 0.5], [1, 0.5], [1, 1], [0, 1]], float)
    (loop,) = agree([spiked], [True], 0.1)
    assert loop[:, 0].max() == pytest.approx(2.1, abs=1e-9)  # the spike's capsule
    (band,) = agree([np.array([[0.0, 0.0], [1.0, 0.0]])], [True], 0.1)
    assert area(band) == pytest.approx(0.2 + np.pi * 0.01, rel=1e-2)
    assert buffer_polylines([np.array([[0.0, 0.0], [1.0, 0.0]])], [True], -0.1) == []


def test_a_self_intersecting_figure_eight_keeps_its_lobes():
    bowtie = np.array([[0, 0], [2, 2], [2, 0], [0, 2]], dtype=float)
    assert len(agree([bowtie], [True], 0.1)) == 1
    assert len(agree([bowtie], [True], -0.05)) == 2


def test_an_offset_past_the_middle_is_empty():
    t = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    assert buffer_polylines([np.c_[np.cos(t), np.sin(t)]], [True], -1.2) == []


# --- where the GEOS path declines ----------------------------------------------------------


def test_large_distances_over_shallow_vertices_go_to_the_marching_path():
    # GEOS drops a concave vertex within 1 % of |d| of its neighbours' chord and of the
    # vertex before it, before it offsets: here a small step at the start of a 10-long
    # edge, which tilts the whole edge and so its offset by 10 (GEOS alone: 7 times the
    # 0.1 % tolerance off).
    square = np.array([(10, 10), (0, 10), (0, 0), (0.05, 0.08), (10, 0)], dtype=float)
    raw = shapely.Polygon(square).buffer(10.0, quad_segs=64)
    assert (
        level_error([shapely.get_coordinates(raw.exterior)[:-1]], [square], [True], 10, 0.01) > 0.05
    )
    with pytest.raises(BufferDeclined, match="within 1 % of the distance"):
        buffer_polylines([square], [True], 10.0)
    result = offset_loops([square], [True], 10.0)
    assert result.path == "marching" and "1 %" in result.declined
    assert level_error(result.loops, [square], [True], 10, 0.01) < 1e-3 * 10
    # Within 5 % of the extent GEOS's step stays within half the tolerance: no check.
    assert offset_loops([square], [True], 0.5).path == "geos"
    # Without such vertices the GEOS path holds at any distance.
    t = np.linspace(0, 2 * np.pi, 6, endpoint=False)
    hexagon = np.c_[np.cos(t), np.sin(t)]
    assert offset_loops([hexagon], [True], -0.5).path == "geos"
    assert offset_loops([hexagon], [True], 20.0).path == "geos"


def test_a_tangle_is_declined_before_geos_repairs_it():
    pts = np.random.default_rng(0).uniform(0, 1, (300, 2))  # about 12,000 self-crossings
    with pytest.raises(BufferDeclined, match=r"cross themselves about [\d,]+ times"):
        buffer_polylines([pts], [True], 0.01)
    big = np.random.default_rng(1).uniform(0, 1, (5000, 2))  # estimated from a sample
    with pytest.raises(BufferDeclined, match="cross themselves"):
        buffer_polylines([big], [False], 0.01)


def test_the_raw_offset_curve_is_bounded():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    with pytest.raises(BufferDeclined, match="vertices, over the limit of 100"):
        buffer_polylines([square], [True], 0.5, max_vertices=100)


def test_the_path_taken():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    line = np.array([[3.0, 0.0], [4.0, 1.0]])
    assert offset_loops([square], [True], 0.1).path == "geos"
    assert offset_loops([line], [False], 0.1).path == "geos"
    assert offset_loops([square], [True], 0.1, cell=0.02).path == "marching"
    assert offset_loops([square], [True], 0.1, smooth=2).path == "marching"
    assert offset_loops([square, line], [True, False], 0.1).path == "marching"


def test_a_geos_failure_falls_back(monkeypatch):
    def broken(*args, **kwargs):
        raise shapely.errors.GEOSException("TopologyException: test")

    monkeypatch.setattr(kbuffer.shapely, "buffer", broken)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    with pytest.raises(BufferDeclined, match="GEOS failed: TopologyException"):
        buffer_polylines([square], [True], 0.1)
    monkeypatch.undo()
    assert offset_loops([square], [True], 0.1).path == "geos"


def test_errors_are_the_marching_paths():
    square = np.array([[0, 0], [1, 0], [1, 1]], dtype=float)
    with pytest.raises(ValueError, match="at least one polyline, got none"):
        offset_loops([], [], 0.1)
    with pytest.raises(ValueError, match="distance must be a nonzero finite number, got 0"):
        offset_loops([square], [True], 0.0)
    with pytest.raises(ValueError, match="polyline 0 has NaN or infinite coordinates"):
        offset_loops([np.array([[0, 0], [np.nan, 1.0]])], [False], 0.1)
    with pytest.raises(ValueError, match="simplify must be a tolerance >= 0"):
        offset_loops([square], [True], 0.1, simplify=-1)
    with pytest.raises(ValueError, match="all closed or all open"):
        buffer_polylines([square, square], [True, False], 0.1)


def test_simplify_on_the_geos_path():
    t = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    circle = np.c_[np.cos(t), np.sin(t)]
    (full,) = offset_loops([circle], [True], 0.05).loops
    result = offset_loops([circle], [True], 0.05, simplify=0.01)
    (simple,) = result.loops
    assert result.path == "geos" and len(simple) < len(full) / 3
    ring = shapely.LinearRing(simple)
    assert shapely.distance(shapely.points(full), ring).max() <= 0.01 + 1e-9


# --- the paths against each other: hypothesis ------------------------------------------------


@st.composite
def stars(draw, deep: bool = False):
    n = draw(st.integers(15, 24) if deep else st.integers(3, 24))
    radii = draw(st.lists(st.floats(0.3, 1.0), min_size=n, max_size=n))
    gaps = draw(st.lists(st.floats(0.2, 1.0), min_size=n, max_size=n))
    angles = 2 * np.pi * np.cumsum(gaps) / np.sum(gaps)
    return np.c_[np.array(radii) * np.cos(angles), np.array(radii) * np.sin(angles)]


@_SETTINGS
@given(stars(), st.sampled_from([0.05, 0.1, 0.3, -0.03, -0.1, -0.2, -1.5]))
def test_random_stars_agree(star, d):
    loops = agree([star], [True], d)
    if d == -1.5:  # past every star's inradius
        assert loops == []


@_SETTINGS
@given(
    st.lists(
        st.tuples(st.integers(-8, 8), st.integers(-8, 8)), min_size=4, max_size=9, unique=True
    ),
    st.sampled_from([0.05, 0.2, -0.05, -0.2]),
)
# Found exploring: spikes out and back (GEOS's buffer of a closed line lost the join at the
# tip), and a ring running back over a stretch of itself (the region's repair kept a face
# the ring crosses twice).
@example([(0, 0), (0, -1), (2, 0), (-1, 0)], 0.2)
@example([(0, 0), (-2, 0), (0, -2), (-3, 1), (-1, 0), (2, -1)], 0.05)
@example([(0, 0), (0, -1), (2, 0), (-1, 0), (1, 0), (0, -2)], 0.05)
def test_self_intersecting_loops_agree(points, d):
    # Integer vertices joined in the order drawn: crossings, collinear runs, lobes.
    pts = np.array(points, dtype=float) / 4
    u, v = pts[1] - pts[0], pts[2:] - pts[0]
    if np.abs(u[0] * v[:, 1] - u[1] * v[:, 0]).max() == 0:
        return  # all on one line: no region, nothing to compare but a band
    agree([pts], [True], d)


def test_a_join_meeting_an_edge_at_a_shallow_angle_keeps_its_corner():
    # A hole shrunk to a sliver by d = 0.05: its corner where the round join about the
    # star's reflex corner meets another edge's offset at about 20 degrees was 1.13
    # tolerances off with joins chorded to 0.4 of the tolerance (hypothesis found it).
    outer = np.array(
        [
            [0.106224592, 0.326925677],
            [-0.351940964, 0.169485836],
            [-0.497987147, 0.0448196545],
            [-0.48198143, -0.133018423],
            [0.134233266, -0.990949762],
            [0.936234871, -0.351374824],
            [1.0, 0.0],
        ]
    )
    inner = np.array(
        [
            [0.723734038, 0.690079011],
            [0.0148693487, 0.312146043],
            [-0.327067963, 0.945000819],
            [-0.654860734, 0.755749574],
            [-0.888835449, 0.458226522],
            [-0.959492974, -0.281732557],
            [-0.786053095, -0.618158986],
            [-0.142314838, -0.989821442],
            [0.235758936, -0.971811568],
            [0.723734038, -0.690079011],
            [1.0, 0.0],
        ]
    )
    free = shapely.Polygon(outer).exterior.distance(shapely.Point(0.0, 0.0))
    polylines = [outer, inner * 0.3 * free]
    tol = 1e-3 * extent(polylines)
    fast = buffer_polylines(polylines, [True, True], 0.05)
    assert hausdorff(fast, reference(polylines, [True, True], 0.05), tol) <= tol
    agree(polylines, [True, True], 0.05)


# The hole shrinks to two holes joined at a saddle of the distance: GEOS's leaves them one
# (see _at_a_saddle; found exploring).
_SADDLE_OUTER = np.array(
    [
        [0.368369401, 0.51354611],
        [-0.173404299, 0.512423358],
        [-0.587426035, -0.120150659],
        [0.114583141, -0.780443142],
        [0.909205077, -0.38863729],
        [0.769834591, -1.88555094e-16],
    ]
)
_SADDLE_INNER = np.array(
    [
        [0.824318719, 0.566126002],
        [0.452171907, 0.891930808],
        [0.142314838, 0.989821442],
        [-0.151723843, 0.332228873],
        [-0.800541241, 0.599277667],
        [-0.991221535, 0.132211455],
        [-0.94388333, -0.330279062],
        [-0.728409796, -0.685141715],
        [-0.433883739, -0.900968868],
        [0.142314838, -0.989821442],
        [0.714282345, -0.699857651],
        [0.891930808, -0.452171907],
        [0.986712473, -0.162476136],
        [0.3, -7.34788079e-17],
    ]
)


@_SETTINGS
@given(stars(), stars(), st.floats(0.3, 0.8), st.sampled_from([0.05, -0.03, -0.08]))
@example(_SADDLE_OUTER, _SADDLE_INNER, 0.4184000365097209, 0.05)
def test_nested_stars_agree(outer, inner, shrink, d):
    # A star with a star-shaped hole inside the circle the outer star's edges leave free
    # (an edge between far-apart corners passes close to the centre: the rings would cross).
    free = shapely.Polygon(outer).exterior.distance(shapely.Point(0.0, 0.0))
    if free < 0.05:
        return
    agree([outer, inner * shrink * free], [True, True], d)


@_SETTINGS
@given(
    st.lists(st.tuples(st.integers(-20, 20), st.integers(-20, 20)), min_size=2, max_size=20),
    st.sampled_from([0.25, 0.5, 1.0]),
)
def test_open_polylines_agree(points, d):
    agree([np.array(points, dtype=float) / 4], [False], d)


# A first offset whose short steps at its joins leave vertices within 1 % of d2 of their
# neighbours' chord, d2 over 5 % of its extent: the GEOS path declines (found exploring).
_SHALLOW_KERF = np.array(
    [
        [0.767594976, 0.640935217],
        [0.503134772, 0.864207962],
        [0.178404095, 0.983957306],
        [-0.33577015, 0.941943951],
        [-0.701318358, 0.712848203],
        [-0.936343958, 0.351084024],
        [-0.997106253, -0.0760205267],
        [-0.87229675, -0.48897687],
        [-0.774516813, -0.632553323],
        [-0.653365743, -0.757042407],
        [-0.435981283, -0.899955733],
        [-0.304878678, -0.952391197],
        [0.0892020473, -0.491978653],
        [0.299841788, -0.250365319],
        [1.0, -2.4492936e-16],
    ]
)


@_SETTINGS
@given(
    stars(),
    st.sampled_from([0.2, 0.05, -0.1]),
    st.sampled_from([0.1, -0.1, 0.02, -0.02]),
)
@example(_SHALLOW_KERF, -0.1, 0.1)
def test_offsets_of_offsets_agree(star, d1, d2):
    # The nameplate's kerf: an offset's own (dense) output, offset again.
    first = buffer_polylines([star], [True], d1)
    if first:
        agree(first, [True] * len(first), d2)


# --- the stars the marching path still fails ------------------------------------------------


def _deep_star(seed: int) -> tuple[np.ndarray, float]:
    rng = np.random.default_rng(10_000 + seed)
    n = int(rng.integers(15, 25))
    radii, gaps = rng.uniform(0.3, 1.0, n), rng.uniform(0.2, 1.0, n)
    angles = 2 * np.pi * np.cumsum(gaps) / np.sum(gaps)
    return np.c_[radii * np.cos(angles), radii * np.sin(angles)], float(rng.uniform(-0.25, -0.1))


# The five the marching path once failed (fixed there), and the three of the next thousand
# it still fails (pieces of a neck thinner than a cell overlapping the loop next to them).
@pytest.mark.parametrize("seed", [150, 404, 412, 425, 707, 1736, 1755, 1779])
def test_deep_stars_shrink_to_simple_loops(seed):
    star, d = _deep_star(seed)
    loops = offset_loops([star], [True], d)
    assert loops.path == "geos"
    ours = shapely.Polygon()
    for lp in loops.loops:
        assert shapely.Polygon(lp).is_valid
        ours = ours.symmetric_difference(shapely.Polygon(lp))
    reference = shapely.Polygon(star).buffer(d, quad_segs=64)
    assert ours.is_valid
    assert ours.symmetric_difference(reference).area <= 1e-3 * extent([star]) * reference.length


def test_every_vertex_is_within_the_simplification_of_the_offset():
    star, _ = _deep_star(3)
    tree = SegmentTree(star, np.roll(star, -1, axis=0))
    for d in (0.04, -0.04):
        for loop in buffer_polylines([star], [True], d):
            assert np.abs(tree.query(loop).dist - abs(d)).max() <= 0.01 * abs(d)


def test_a_ring_of_one_point_goes_to_the_marching_path_as_a_disc():
    # A closed polyline of one point repeated bounds no area: the region refused it
    # (NoArea, a ValueError that escaped the path choice); its offset is the disc.
    result = offset_loops([np.full((4, 2), 2.0)], [True], 0.5)
    assert result.path == "marching" and "fewer than 3 distinct points" in result.declined
    (loop,) = result.loops
    assert np.abs(np.hypot(*(loop - 2.0).T) - 0.5).max() <= 1e-3


def test_a_spike_out_and_back_keeps_the_round_join_at_its_tip():
    # GEOS buffers a closed line as a ring and lost the join at the spike's tip (-0.25, 0):
    # the band stopped at x = -0.25 instead of reaching -0.45.
    ring = np.array([(0, 0), (0, -1), (2, 0), (-1, 0)], dtype=float) / 4
    (loop,) = buffer_polylines([ring], [True], 0.2)
    assert loop[:, 0].min() == pytest.approx(-0.45, abs=1e-3)


@pytest.mark.xfail(strict=True, reason="marching path accuracy on a tiny input, found exploring")
def test_a_tiny_offset_offset_again_past_five_percent_of_its_extent():
    # Found by the exploring property test (seed 105): a thin triangle shrunk by 0.1 to
    # one of extent 2e-3, grown by 0.1 again: the GEOS path declines (50 times the
    # extent) and the marching path is 7.6e-6 from the definition, tolerance 2e-6.
    star = np.array([[-0.478726281, -0.230320885], [0.0667013338, -0.292490909], [0.30078125, 0.0]])
    first = buffer_polylines([star], [True], -0.1)
    agree(first, [True] * len(first), 0.1)


# Found by the exploring property test in a full run (test_offsets_of_offsets_agree): a
# 20-point star shrunk by 0.1, its dense output shrunk by 0.1 again. The GEOS path declines
# (vertices within 1 % of the distance of their neighbours' chord) and the marching path
# stands 0.0060 from the definition, tolerance 0.0017 (0.0035 from the example as printed,
# to nine digits).
_SHRUNK_TWICE = np.array(
    [
        [0.955520265, 0.294925454],
        [0.712050862, 0.702127887],
        [0.419742702, 0.907643137],
        [0.250827823, 0.968031716],
        [0.0887607308, 0.996052977],
        [-0.0906242984, 0.995885152],
        [-0.267093127, 0.963670723],
        [-0.461725562, 0.887022833],
        [-0.702793742, 0.711393671],
        [-0.925924777, 0.377707965],
        [-0.996135581, 0.08782883],
        [-0.497899966, -0.0457779818],
        [-0.924504831, -0.381170325],
        [-0.73147421, -0.681869108],
        [-0.125579855, -0.353347846],
        [-0.161145252, -0.986930701],
        [-0.0420875258, -0.999113928],
        [0.0612882779, -0.306431064],
        [0.364677401, -0.931133929],
        [0.376395004, -0.32913037],
        [0.97145623, -0.237218872],
        [0.5, -1.2246468e-16],
    ]
)


@pytest.mark.xfail(strict=True, reason="marching path accuracy on an offset's own output")
def test_a_star_shrunk_twice_by_a_tenth():
    first = buffer_polylines([_SHRUNK_TWICE], [True], -0.1)
    agree(first, [True] * len(first), -0.1)
