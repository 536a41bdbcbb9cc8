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
