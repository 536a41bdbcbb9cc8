"""The CNC kernels: exact offsets of arc chains against closed forms, pass depths, pocket
levels against shapely's buffer, and what a tool cannot reach."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import formgraph as fg
from formgraph.kernels.cam import arcs, paths


def _curve(kind, **kw):
    g = fg.Graph()
    g.add("c", kind, **kw)
    return g.evaluate("c")


@pytest.mark.parametrize("d", [-3.0, 2.5])
def test_offset_of_a_circle_is_the_circle_of_radius_r_plus_d(d):
    c = _curve("nurbs.circle", radius=8, center=[3, -2, 0])
    cp = arcs.offset_chain(c.control_points, c.knots, c.weights, d)
    off = fg.NurbsCurve(cp, 2, c.knots, c.weights)
    p = np.asarray(off.evaluate(np.linspace(c.knots[0], c.knots[-1], 97)))
    # a counter-clockwise circle: right of travel is outward
    assert np.linalg.norm(p[:, :2] - [3, -2], axis=1) == pytest.approx(8 + d, abs=1e-12)


def test_offset_of_a_rounded_rectangle_matches_shapely_buffer():
    c = _curve("curves.rectangle", size=[80, 50], radius=6)
    cp = arcs.offset_chain(c.control_points, c.knots, c.weights, 3.0)
    off = fg.NurbsCurve(cp, 2, c.knots, c.weights)
    ours = shapely.Polygon(np.asarray(off.sample(2000))[:-1, :2])
    ref = shapely.buffer(shapely.box(-34, -19, 34, 19), 9.0, quad_segs=256)
    assert shapely.hausdorff_distance(ours.exterior, ref.exterior) < 1e-3


def test_a_chain_with_a_corner_or_a_vanishing_arc_has_no_exact_offset():
    c = _curve("curves.rectangle", size=[80, 50], radius=6)
    assert arcs.offset_chain(c.control_points, c.knots, c.weights, -7.0) is None
    sharp = _curve("curves.rectangle", size=[80, 50], radius=0)  # degree 1: no chain
    assert (
        arcs.offset_chain(
            sharp.control_points,
            [0.0] * (len(sharp.control_points) + 3),
            np.ones(len(sharp.control_points)),
            1.0,
        )
        is None
    )


def test_depths_step_down_to_exactly_the_depth():
    assert paths.depths(5, 2).tolist() == [-2, -4, -5]
    assert paths.depths(6, 2).tolist() == [-2, -4, -6]
    assert paths.depths(3, None).tolist() == [-3]
    with pytest.raises(ValueError, match="depth must be positive"):
        paths.depths(-1, None)
    with pytest.raises(ValueError, match="step down must be positive"):
        paths.depths(1, 0)


def _wiggly(n=1000):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 50 + 8 * np.sin(7 * t)
    return np.c_[r * np.cos(t), r * np.sin(t)]


@pytest.mark.parametrize("stepover", [0.4, 0.9])
def test_pocket_levels_are_the_region_shrunk_and_leave_nothing_standing(stepover):
    ring = _wiggly()
    island = np.c_[10 * np.cos(np.linspace(0, 6.28, 60)), 10 * np.sin(np.linspace(0, 6.28, 60))]
    r, step = 3.0, stepover * 6.0
    levels = paths.pocket_levels([ring, island], r, step, 0.01)
    region = shapely.Polygon(ring, [island])
    ref = shapely.buffer(region, -r, quad_segs=64)
    ours = shapely.Polygon()
    for lp in levels[0]:  # the wall pass: the even-odd region of its loops
        ours = shapely.symmetric_difference(ours, shapely.Polygon(lp))
    assert shapely.symmetric_difference(ours, ref).area < 0.01 * ref.boundary.length
    # coverage by sampling: every point the tool can reach lies within r of a pass
    rng = np.random.default_rng(0)
    opening = shapely.buffer(ref, r, quad_segs=64)
    pts = rng.uniform(-60, 60, (20000, 2))
    inside = shapely.contains_xy(shapely.buffer(opening, -1e-3), pts[:, 0], pts[:, 1])
    loops = shapely.MultiLineString([np.r_[lp, lp[:1]] for lv in levels for lp in lv])
    d = shapely.distance(shapely.points(pts[inside]), loops)
    assert d.max() <= r + 1e-6
    # and no pass comes closer than r to the wall
    all_pts = np.concatenate([lp for lv in levels for lp in lv])
    wall_d = shapely.distance(shapely.points(all_pts), region.boundary)
    assert wall_d.min() >= r - 0.02


def test_a_slot_narrower_than_the_tool_is_found():
    sq = shapely.box(0, 0, 40, 40)
    slot = shapely.box(40, 18, 70, 22)
    ring = shapely.get_coordinates(shapely.union(sq, slot).exterior)[:-1]
    levels = paths.pocket_levels([ring], 3.0, 2.4, 0.01)
    left = paths.leftovers([ring], levels, 3.0)
    assert len(left) == 1
    x, y, area, width = left[0]
    assert 40 < x < 70 and y == pytest.approx(20)
    assert area > 100 and width == pytest.approx(4, abs=0.05)
    # a square pocket keeps only its corners' fillets: nothing to report
    square = shapely.get_coordinates(sq.exterior)[:-1]
    assert paths.leftovers([square], paths.pocket_levels([square], 3.0, 2.4, 0.01), 3.0) == []


def _arcs_of(cp, w):
    """Centres and radii of a Bezier-form chain's circular pieces (middle weight < 1)."""
    p0, p1, p2 = cp[0:-1:2, :2], cp[1::2, :2], cp[2::2, :2]
    arc = w[1::2] < 1 - 1e-12
    tm = 0.5 * (p0 + p2) - p1
    t2 = np.sum((p0 - p1) ** 2, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        centre = p1 + tm * (t2 / np.sum(tm * tm, axis=1))[:, None]
    return centre[arc], np.linalg.norm(p0 - centre, axis=1)[arc]


def _ring(cp, knots, w):
    """The chain sampled 256 times a piece, every joint among the samples."""
    curve = fg.NurbsCurve(cp, 2, knots, w)
    t = np.linspace(knots[0], knots[-1], 256 * (len(cp) - 1) // 2 + 1)
    return shapely.LinearRing(np.asarray(curve.evaluate(t))[:-1, :2])


def test_offset_of_a_rectangle_rounds_its_corners_with_arcs_of_the_distance():
    corners = np.array([[0, 0], [40, 0], [40, 30], [0, 30]], dtype=float)
    cp, knots, w = arcs.polygon_chain(corners)
    got = arcs.offset_loop(cp, knots, w, 3.0)
    assert got is not None
    out, k2, w2 = got
    centre, radius = _arcs_of(out, w2)
    # four quarter arcs of radius 3, one about each corner, and four straight sides
    assert radius == pytest.approx([3.0] * 4, abs=1e-12)
    assert sorted(map(tuple, np.round(centre, 9))) == sorted(map(tuple, corners))
    ours = shapely.Polygon(_ring(out, k2, w2))
    ref = shapely.buffer(shapely.Polygon(corners), 3.0, quad_segs=512)
    assert shapely.hausdorff_distance(ours.exterior, ref.exterior) < 1e-4
    assert ours.area == pytest.approx(40 * 30 + 2 * 3 * 70 + np.pi * 9, rel=1e-6)


def test_inward_offset_of_an_l_rounds_only_its_inside_corner():
    ell = np.array([[0, 0], [40, 0], [40, 10], [10, 10], [10, 30], [0, 30]], dtype=float)
    cp, knots, w = arcs.polygon_chain(ell)
    out, k2, w2 = arcs.offset_loop(cp, knots, w, -2.0)
    centre, radius = _arcs_of(out, w2)
    assert radius == pytest.approx([2.0], abs=1e-12)
    assert centre[0] == pytest.approx([10, 10], abs=1e-12)  # the reflex corner
    ours = shapely.Polygon(_ring(out, k2, w2))
    ref = shapely.buffer(shapely.Polygon(ell), -2.0, quad_segs=512)
    assert shapely.hausdorff_distance(ours.exterior, ref.exterior) < 1e-4


def test_offset_of_a_half_disc_joins_and_cuts_arcs_and_lines_in_closed_form():
    # a half disc: two quarter arcs and the diameter, meeting at two right-angled corners
    q = np.sqrt(0.5)
    cp = np.array([[10, 0], [10, 10], [0, 10], [-10, 10], [-10, 0], [0, 0], [10, 0]], dtype=float)
    knots = np.array([0, 0, 0, 1, 1, 2, 2, 3, 3, 3], dtype=float)
    w = np.array([1, q, 1, q, 1, 1, 1])
    for d in (2.0, -2.0):  # outward: two join arcs; inward: each arc cut by the line
        got = arcs.offset_loop(np.c_[cp, np.zeros(7)], knots, w, d)
        assert got is not None
        ours = shapely.Polygon(_ring(*got))
        centre, radius = _arcs_of(got[0], got[2])
        if d > 0:
            # the diameter's ends are the centres of the joins; Steiner's formula for a
            # convex set grown by d: area + perimeter d + pi d^2
            assert sorted(np.round(radius, 9)) == [2, 2, 12, 12]
            steiner = 50 * np.pi + (10 * np.pi + 20) * d + np.pi * d * d
            assert ours.area == pytest.approx(steiner, rel=1e-5)
        else:
            # the disc of radius 8 above y = 2: the arcs end at x = +-sqrt(60)
            assert np.round(radius, 9).tolist() == [8, 8]
            assert np.abs(got[0][:, 0]).max() == pytest.approx(np.sqrt(60), abs=1e-12)
            segment = 64 * np.arccos(0.25) - 2 * np.sqrt(60)
            assert ours.area == pytest.approx(segment, rel=1e-5)


def test_a_notch_the_offset_closes_keeps_the_offset_kernels_polylines():
    notch = np.array(
        [[0, 0], [40, 0], [40, 20], [21, 20], [21, 5], [19, 5], [19, 20], [0, 20]], dtype=float
    )
    g = fg.Graph()
    g.add("c", "curves.polyline", points=np.c_[notch, np.zeros(8)].tolist(), closed=True)
    # outward by 3 the 2 mm slot closes: the raw offset crosses itself, the offset kernel's
    # loop is what the tool runs on
    g.add("p", "cam.profile", curves=["@c"], tool_diameter=6)
    (path,) = g.evaluate("p")
    assert path.degree == 1
    ref = shapely.buffer(shapely.Polygon(notch), 3.0, quad_segs=64).exterior
    ours = shapely.LinearRing(np.asarray(path.control_points)[:-1, :2])
    assert shapely.hausdorff_distance(ours, ref) < 0.01


def test_tabs_lift_a_pass_straight_up_over_and_down_at_even_spacing():
    square = np.array([[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]], dtype=float)
    spans = paths.tab_spans(40.0, 2, 4.0)
    assert spans.tolist() == [[8, 12], [28, 32]]  # centred at 10 and 30
    got = paths.over_tabs(square, spans, -5.0, -3.0)
    expected = [
        [0, 0, -5], [8, 0, -5], [8, 0, -3], [10, 0, -3], [10, 2, -3], [10, 2, -5],
        [10, 10, -5], [2, 10, -5], [2, 10, -3], [0, 10, -3], [0, 8, -3], [0, 8, -5],
        [0, 0, -5],
    ]  # fmt: skip
    assert got.tolist() == expected
    with pytest.raises(ValueError, match="3 tabs of 14 .* do not fit on a loop of length 40"):
        paths.tab_spans(40.0, 3, 14.0)
