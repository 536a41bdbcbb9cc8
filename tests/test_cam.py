"""``cam.profile`` and ``cam.pocket``: tool paths at the right distance from the outline
(shapely), at the pass depths, exact where the outline is, and the warnings and errors."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import formgraph as fg


def _graph():
    g = fg.Graph()
    g.add("plate", "curves.rectangle", size=[80, 50], radius=6)
    g.add("hole", "nurbs.circle", radius=8, center=[20, 0, 0])
    g.add("star", "curves.polygon", sides=5, radius=9, center=[-20, 0, 0])
    return g


@pytest.mark.parametrize(("side", "sign"), [("outside", 1), ("inside", -1)])
def test_profile_runs_a_tool_radius_from_the_outline(side, sign):
    g = _graph()
    g.add(
        "p",
        "cam.profile",
        curves=["@plate", "@hole", "@star"],
        tool_diameter=6,
        side=side,
        depth=6,
        step_down=2.5,
    )
    paths = g.evaluate("p")
    region = shapely.difference(
        shapely.Polygon(np.asarray(g.evaluate("plate").sample(4000))[:-1, :2]),
        shapely.union(
            shapely.Polygon(np.asarray(g.evaluate("hole").sample(4000))[:-1, :2]),
            shapely.Polygon(np.asarray(g.evaluate("star").control_points)[:-1, :2]),
        ),
    )
    depths = sorted({round(float(np.asarray(c.control_points)[0, 2]), 9) for c in paths})
    assert depths == [-6.0, -5.0, -2.5]
    for c in paths:
        p = np.asarray(c.sample(500))
        assert p[:, 2] == pytest.approx(p[0, 2], abs=1e-12)
        d = shapely.distance(shapely.points(p[:, :2]), region.boundary)
        inside = shapely.contains_xy(region, p[:, 0], p[:, 1])
        assert np.all(inside == (sign < 0))
        # every path is exact: at the tool's radius up to the outline's own sampling
        assert d.min() >= 3 - 1e-4
        assert np.median(d) == pytest.approx(3, abs=1e-4)
    # the circle's, the rounded rectangle's and the star's paths are exact: the star (a
    # polygon, a hole) grows with arcs of the tool's radius about its corners when the
    # region shrinks, and shrinks to a pentagon of five sharp corners when it grows
    exact = [c for c in paths if c.degree == 2 and c.rational]
    assert len(exact) == (3 if sign < 0 else 2) * 3
    pentagons = [c for c in paths if c.degree == 1 and len(c.control_points) == 6]
    assert len(pentagons) == (0 if sign < 0 else 3)


def test_profile_cuts_holes_before_the_outer_loop_and_on_stays_on_the_curves():
    g = _graph()
    g.add("p", "cam.profile", curves=["@plate", "@hole"], tool_diameter=6, depth=1)
    first, last = g.evaluate("p")
    assert first.degree == 2 and np.asarray(first.control_points)[:, 0].max() < 40
    assert np.asarray(last.control_points)[:, 0].max() > 42  # the plate, grown by 3
    g.add("on", "cam.profile", curves=["@hole"], tool_diameter=0.2, side="on", depth=0.5)
    (c,) = g.evaluate("on")
    hole = g.evaluate("hole")
    assert np.allclose(np.asarray(c.control_points)[:, :2], np.asarray(hole.control_points)[:, :2])
    assert np.allclose(np.asarray(c.control_points)[:, 2], -0.5)


def test_pocket_covers_the_region_and_never_cuts_the_wall():
    g = _graph()
    g.add("p", "cam.pocket", curves=["@plate", "@hole"], tool_diameter=6, stepover=0.5, depth=2)
    paths = g.evaluate("p")
    assert not g.stats["p"].warnings
    region = shapely.difference(
        shapely.Polygon(np.asarray(g.evaluate("plate").sample(4000))[:-1, :2]),
        shapely.Polygon(np.asarray(g.evaluate("hole").sample(4000))[:-1, :2]),
    )
    pts = np.concatenate([np.asarray(c.sample(800))[:, :2] for c in paths])
    assert shapely.distance(shapely.points(pts), region.boundary).min() >= 3 - 2e-3
    assert shapely.contains_xy(region, pts[:, 0], pts[:, 1]).all()
    reach = shapely.buffer(shapely.buffer(region, -3, quad_segs=64), 3, quad_segs=64)
    rng = np.random.default_rng(1)
    sample = rng.uniform([-40, -25], [40, 25], (4000, 2))
    inside = shapely.contains_xy(shapely.buffer(reach, -0.01), sample[:, 0], sample[:, 1])
    lines = shapely.linestrings([np.asarray(c.sample(400))[:, :2] for c in paths])
    tree = shapely.STRtree(lines)
    _, d = tree.query_nearest(
        shapely.points(sample[inside]), return_distance=True, all_matches=False
    )
    assert d.max() <= 3 + 1e-6
    assert all(np.asarray(c.control_points)[:, 2].max() >= -2 for c in paths)


def test_pocket_warns_where_the_tool_cannot_go():
    g = fg.Graph()
    g.add(
        "pts",
        "points.list",
        points=[[0, 0], [40, 0], [40, 18], [70, 18], [70, 22], [40, 22], [40, 40], [0, 40]],
    )
    g.add("outline", "curves.polyline", points="@pts", closed=True)
    g.add("p", "cam.pocket", curves=["@outline"], tool_diameter=6, depth=1)
    assert g.evaluate("p")
    (warning,) = g.stats["p"].warnings
    assert "wider than the pocket's narrowest gaps" in warning and "around (5" in warning
    g.add("tiny", "cam.pocket", curves=["@outline"], tool_diameter=45, depth=1)
    assert g.evaluate("tiny") == []
    assert "fits nowhere" in g.stats["tiny"].warnings[0]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"tool_diameter": 0}, r"tool_diameter.*diameter must be positive"),
        ({"tool_diameter": 3, "depth": -2}, r"depth.*must be positive"),
        ({"tool_diameter": 3, "step_down": 0}, r"step_down.*must be positive"),
    ],
)
def test_bad_tools_and_depths_are_located_errors(kwargs, message):
    g = _graph()
    g.add("p", "cam.profile", curves=["@plate"], **kwargs)
    with pytest.raises(fg.FormgraphError, match=message):
        g.evaluate("p")


def test_tabs_hold_the_part_and_leave_the_holes_exact():
    g = _graph()
    g.add(
        "p", "cam.profile", curves=["@plate", "@hole"], tool_diameter=6, depth=6, step_down=2,
        tabs=3, tab_height=1,
    )  # fmt: skip
    paths = g.evaluate("p")
    hole, plate = paths[:3], paths[3:]  # holes first, each loop through its depths
    assert all(c.degree == 2 and c.rational for c in hole)
    assert all(c.degree == 2 and c.rational for c in plate[:2])  # -2, -4: above -5
    z = np.asarray(plate[2].control_points)[:, 2]
    assert set(np.round(z, 9)) == {-6.0, -5.0}  # the last pass, lifted to the tabs' top
    assert np.sum(np.diff(z) > 0) == 3  # three tabs, each climbed once
