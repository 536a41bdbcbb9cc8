"""The cutting nodes (nodes/curves/regions.py): rectangles, polygons, region booleans, text.

References are closed forms (areas of rounded rectangles, circle lenses, polygons), shapely
on the same polylines, and an even-odd point count of our own on a grid.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.geometry import NurbsCurve
from formgraph.kernels import nurbs
from formgraph.kernels.curves import regions, sampling


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n")


def circle(r: float, cx: float = 0.0, cy: float = 0.0) -> NurbsCurve:
    return NurbsCurve(*nurbs.circle(r, (cx, cy, 0.0)))


def square(side: float, cx: float = 0.0, cy: float = 0.0, ccw: bool = True) -> NurbsCurve:
    h = side / 2
    p = [[cx - h, cy - h], [cx + h, cy - h], [cx + h, cy + h], [cx - h, cy + h]]
    return NurbsCurve.polyline(p if ccw else p[::-1], closed=True)


def ring(c: NurbsCurve, n: int = 20000) -> np.ndarray:
    """A dense sampling of a closed curve in XY, without the closing point."""
    return np.asarray(c.evaluate(np.linspace(*c.domain, n + 1)))[:-1, :2]


def signed_area(c: NurbsCurve) -> float:
    """Shoelace area of a closed curve (its vertices if a polyline, else densely sampled)."""
    p = np.asarray(c.control_points)[:-1, :2] if c.degree == 1 else ring(c)
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def region_area(curves) -> float:
    """The area of outlines read as outer CCW / holes CW: the sum of signed areas."""
    return sum(signed_area(c) for c in curves)


def lens(r: float, d: float) -> float:
    """Area of the overlap of two circles of radius r whose centres are d apart."""
    return 2 * r * r * math.acos(d / (2 * r)) - 0.5 * d * math.sqrt(4 * r * r - d * d)


# --------------------------------------------------------------------------- rectangle


@pytest.mark.parametrize("w,h,r", [(80, 30, 5), (10, 4, 2), (6, 6, 3), (7, 3, 0.25)])
def test_rounded_rectangle_area_is_the_closed_form(w, h, r):
    c = run("curves.rectangle", size=[w, h], radius=r)
    assert isinstance(c, NurbsCurve) and c.closed and c.degree == 2 and c.rational
    m = run("curves.measure", curve=c)
    assert m.area == pytest.approx(w * h - (4 - math.pi) * r * r, rel=1e-12)
    perimeter = 2 * (w + h) - 8 * r + 2 * math.pi * r
    assert m.length == pytest.approx(perimeter, rel=1e-9)
    assert signed_area(c) > 0  # counter-clockwise


def test_rounded_corners_lie_exactly_on_their_arcs():
    w, h, r = 80.0, 30.0, 5.0
    c = run("curves.rectangle", size=[w, h], radius=r, center=[3, -2])
    p = np.asarray(c.evaluate(np.linspace(*c.domain, 4001)))[:, :2] - [3, -2]
    centre = np.sign(p) * [w / 2 - r, h / 2 - r]
    corner = (np.abs(p[:, 0]) > w / 2 - r) & (np.abs(p[:, 1]) > h / 2 - r)
    assert corner.sum() > 100
    dist = np.linalg.norm(p[corner] - centre[corner], axis=1)
    np.testing.assert_allclose(dist, r, atol=1e-12)
    side = ~corner
    on_edge = np.isclose(np.abs(p[side, 0]), w / 2, atol=1e-12) | np.isclose(
        np.abs(p[side, 1]), h / 2, atol=1e-12
    )
    assert on_edge.all()


def test_sharp_rectangle_is_a_polygon_and_a_full_radius_square_a_circle():
    c = run("curves.rectangle", size=[4, 2])
    assert c.degree == 1 and len(c.control_points) == 5 and signed_area(c) == pytest.approx(8)
    disc = run("curves.rectangle", size=[6, 6], radius=3)
    assert len(disc.control_points) == 9  # four arcs, no sides
    pts = disc.evaluate(np.linspace(0, disc.domain[1], 999))
    np.testing.assert_allclose(np.linalg.norm(pts[:, :2], axis=1), 3, atol=1e-12)


@pytest.mark.parametrize(
    "inputs,port,match",
    [
        ({"size": [4, 2], "radius": 1.5}, "radius", r"between 0 and half the shorter side \(1\)"),
        ({"size": [4, -2]}, "size", r"both positive"),
        ({"size": [4, 2, 1]}, "size", r"\[width, height\]"),
    ],
)
def test_rectangle_bad_input_names_the_port(inputs, port, match):
    with pytest.raises(fg.NodeError, match=rf"input '{port}'.*{match}"):
        run("curves.rectangle", **inputs)


def test_regular_polygon_area_and_corners():
    c = run("curves.polygon", sides=7, radius=2.5, center=[1, 1], angle=90)
    cp = np.asarray(c.control_points)[:-1, :2]
    assert len(cp) == 7 and c.closed
    np.testing.assert_allclose(np.linalg.norm(cp - [1, 1], axis=1), 2.5, atol=1e-12)
    np.testing.assert_allclose(cp[0], [1, 3.5], atol=1e-12)
    assert signed_area(c) == pytest.approx(3.5 * 2.5**2 * math.sin(2 * math.pi / 7))


# --------------------------------------------------------------------------- sampling


@pytest.mark.parametrize("tol", [1e-2, 1e-4, 1e-6])
def test_sampling_of_a_circle_is_on_it_and_within_the_tolerance(tol):
    r = 3.0
    p = sampling.sample_nurbs(*nurbs.circle(r), tol, closed=True)
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), r, atol=1e-12)
    ang = np.sort(np.arctan2(p[:, 1], p[:, 0]))
    step = np.diff(np.append(ang, ang[0] + 2 * np.pi)).max()
    sagitta = r * (1 - math.cos(step / 2))
    assert sagitta <= tol
    # not much finer than needed: the uniform step for this tolerance, a few times over
    needed = 2 * math.pi / (2 * math.acos(1 - tol / r))
    assert len(p) < 3 * needed + 16


def test_sampling_of_a_cubic_keeps_every_chord_within_the_tolerance():
    rng = np.random.default_rng(3)
    cp = np.c_[rng.normal(size=(9, 2)) * 5, np.zeros(9)]
    knots = nurbs.clamped_uniform_knots(9, 3)
    tol = 1e-4
    p = sampling.sample_nurbs(cp, 3, knots, None, tol, closed=False)
    dense = NurbsCurve(cp, 3, knots).evaluate(np.linspace(0, 1, 200001))[:, :2]
    # each dense point is within tol of the polyline through the samples
    line = shapely.LineString(p)
    dist = shapely.distance(shapely.points(dense[::20]), line)
    assert dist.max() <= tol * 1.0001


# --------------------------------------------------------------------------- booleans


@pytest.mark.parametrize("d", [0.3, 1.0, 1.7])
def test_two_circles_give_the_lens_closed_forms(d):
    r = 1.0
    a, b = circle(r), circle(r, d)
    tol = 1e-6
    area = {
        "intersection": lens(r, d),
        "union": 2 * math.pi * r * r - lens(r, d),
        "difference": math.pi * r * r - lens(r, d),
        "xor": 2 * math.pi * r * r - 2 * lens(r, d),
    }
    for op, expected in area.items():
        out = run("curves.boolean", a=[a], b=[b], operation=op, tolerance=tol)
        assert all(c.closed for c in out)
        # every chord cuts at most tol off the boundary: the area is short by < perimeter * tol
        assert region_area(out) == pytest.approx(expected, abs=4 * math.pi * r * tol)
        assert region_area(out) <= expected + 1e-12


def test_union_node_merges_overlapping_circles_the_offset_would_xor():
    out = run("curves.union", curves=[circle(1.0), circle(1.0, 1.0)], tolerance=1e-6)
    assert len(out) == 1 and signed_area(out[0]) > 0
    assert region_area(out) == pytest.approx(2 * math.pi - lens(1, 1), abs=1e-5)
    xor = run("curves.boolean", a=[circle(1.0), circle(1.0, 1.0)], b=[], tolerance=1e-6)
    assert region_area(xor) == pytest.approx(2 * math.pi - 2 * lens(1, 1), abs=1e-5)


def test_holes_are_clockwise_and_untouched_curves_stay_exact():
    plate = run("curves.rectangle", size=[80, 30], radius=5)
    holes = [circle(2, -30), circle(2, 0), circle(2, 30)]
    out = run("curves.boolean", a=[plate], b=holes, operation="difference")
    assert len(out) == 4
    areas = [signed_area(c) for c in out]
    assert sum(a > 0 for a in areas) == 1 and sum(a < 0 for a in areas) == 3
    # every outline came through whole: each is its input curve, exact (rational quadratic)
    assert all(isinstance(c, NurbsCurve) and c.rational and c.degree == 2 for c in out)
    outer = out[int(np.argmax(areas))]
    np.testing.assert_array_equal(outer.control_points, plate.control_points)
    for c in out:
        if signed_area(c) < 0:
            centre = np.asarray(c.control_points)[:-1, :2].mean(axis=0)
            pts = c.evaluate(np.linspace(*c.domain, 101))[:, :2]
            np.testing.assert_allclose(np.linalg.norm(pts - centre, axis=1), 2, atol=1e-12)
    expected = 80 * 30 - (4 - math.pi) * 25 - 3 * math.pi * 4
    assert region_area(out) == pytest.approx(expected, rel=1e-6)


def test_outlines_of_many_rings_are_chord_length_polylines_in_the_right_direction():
    # two plates with two holes each (given either way round): six rings, two parts
    a = [square(10), square(10, 20, ccw=False)]
    b = [square(2, -2), square(2, 2, ccw=False), square(2, 18), square(2, 22)]
    out = run("curves.boolean", a=a, b=b, operation="difference")
    assert len(out) == 6
    areas = np.array([signed_area(c) for c in out])
    assert (areas > 0).sum() == 2 and (areas < 0).sum() == 4  # shells CCW, holes CW
    assert areas.sum() == pytest.approx(2 * (100 - 8))
    for c in out:
        cp = np.asarray(c.control_points)
        assert c.degree == 1 and np.array_equal(cp[0], cp[-1]) and not cp[:, 2].any()
        chord = np.r_[0, np.cumsum(np.linalg.norm(np.diff(cp, axis=0), axis=1))]
        np.testing.assert_allclose(c.knots, np.r_[0, chord, chord[-1]], atol=1e-12)
        np.testing.assert_allclose(c.evaluate(np.asarray(c.knots)[1:-1]), cp, atol=1e-12)
    # against shapely's area of the same region
    ref = shapely.difference(
        regions.even_odd_region([np.asarray(c.control_points)[:, :2] for c in a]),
        regions.even_odd_region([np.asarray(c.control_points)[:, :2] for c in b]),
    )
    assert areas.sum() == pytest.approx(ref.area, rel=1e-12)


def test_a_list_is_one_region_by_the_even_odd_rule():
    # a square inside a square (either direction) is a hole; two overlapping ones are xor
    annulus = run("curves.boolean", a=[square(4), square(2)], b=[])
    assert region_area(annulus) == pytest.approx(12)
    annulus2 = run("curves.boolean", a=[square(4), square(2, ccw=False)], b=[])
    assert region_area(annulus2) == pytest.approx(12)
    island = run("curves.boolean", a=[square(6), square(4), square(2)], b=[])
    assert region_area(island) == pytest.approx(36 - 16 + 4)
    xor = run("curves.boolean", a=[square(2), square(2, 1, 1)], b=[])
    assert region_area(xor) == pytest.approx(8 - 2)
    assert [signed_area(c) > 0 for c in island].count(False) == 1


def even_odd_inside(polys: list[np.ndarray], q: np.ndarray) -> np.ndarray:
    """Whether each point q is inside the rings by the even-odd rule (crossing parity)."""
    inside = np.zeros(len(q), dtype=bool)
    for p in polys:  # a few rings
        a, b = p, np.roll(p, -1, axis=0)
        y = q[:, 1:2]
        cross = (a[:, 1] > y) != (b[:, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xs = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
        inside ^= (np.sum(cross & (q[:, :1] < xs), axis=1) % 2).astype(bool)
    return inside


def test_self_intersecting_rings_follow_the_even_odd_rule():
    a = np.pi / 2 + np.arange(5) * 4 * np.pi / 5
    star = np.c_[np.cos(a), np.sin(a)]
    out = run("curves.boolean", a=[NurbsCurve.polyline(star, closed=True)], b=[])
    g = np.stack(np.meshgrid(np.linspace(-1, 1, 301), np.linspace(-1, 1, 301)), -1).reshape(-1, 2)
    ours = shapely.contains_xy(regions.even_odd_region([star]), g[:, 0], g[:, 1])
    np.testing.assert_array_equal(ours, even_odd_inside([star], g))
    # the five points without the centre pentagon: area of the star minus its pentagon
    r_in = math.cos(2 * math.pi / 5) / math.cos(math.pi / 5)
    pentagon = 2.5 * r_in**2 * math.sin(2 * math.pi / 5)
    star_area = 5 * 0.5 * math.sin(math.pi / 5) * r_in * 2  # ten triangles centre-tip-notch
    assert region_area(out) == pytest.approx(star_area - pentagon, rel=1e-9)


def random_polygon(draw, cx: float, cy: float) -> np.ndarray:
    n = draw(st.integers(3, 24))
    ang = np.sort(draw(st.lists(st.floats(0, 2 * np.pi - 1e-3), min_size=n, max_size=n)))
    ang = np.unique(np.round(ang, 3))
    if len(ang) < 3:
        ang = np.array([0.0, 2.0, 4.0])
    rad = draw(st.lists(st.floats(0.3, 2.0), min_size=len(ang), max_size=len(ang)))
    return np.c_[cx + np.array(rad) * np.cos(ang), cy + np.array(rad) * np.sin(ang)]


@st.composite
def polygon_pairs(draw):
    a = random_polygon(draw, 0.0, 0.0)
    b = random_polygon(draw, draw(st.floats(-2, 2)), draw(st.floats(-2, 2)))
    return a, b


@settings(max_examples=60, deadline=None)
@given(polygon_pairs(), st.sampled_from(["union", "difference", "intersection", "xor"]))
def test_booleans_of_random_polygons_agree_with_shapely(pair, op):
    a, b = pair
    ca, cb = NurbsCurve.polyline(a, closed=True), NurbsCurve.polyline(b, closed=True)
    out = run("curves.boolean", a=[ca], b=[cb], operation=op)
    pa, pb = shapely.Polygon(a), shapely.Polygon(b)
    assume(pa.is_valid and pb.is_valid)  # the reference needs valid polygons (ours need not)
    ref = {
        "union": pa.union(pb),
        "difference": pa.difference(pb),
        "intersection": pa.intersection(pb),
        "xor": pa.symmetric_difference(pb),
    }[op]
    assert all(c.closed and c.degree == 1 for c in out)
    assert region_area(out) == pytest.approx(ref.area, rel=1e-9, abs=1e-12)
    # the outlines rebuild the same region: outer CCW, holes CW
    ours = regions.even_odd_region([np.asarray(c.control_points)[:-1, :2] for c in out])
    assert ours.symmetric_difference(ref).area <= 1e-9 * max(ref.area, 1.0)
    holes = shapely.get_num_interior_rings(shapely.get_parts(ref)).sum()
    assert sum(signed_area(c) < 0 for c in out) == holes


def test_open_curves_and_empty_input_are_refused():
    open_curve = NurbsCurve.polyline([[0, 0], [1, 0], [1, 1]])
    with pytest.raises(fg.NodeError, match=r"input 'b'.*curve 0 is open"):
        run("curves.boolean", a=[square(1)], b=[open_curve])
    with pytest.raises(fg.NodeError, match=r"input 'a'.*got none"):
        run("curves.boolean", a=[], b=[])
    with pytest.raises(fg.NodeError, match=r"input 'tolerance'.*below 1e-12"):
        run("curves.union", curves=[square(1)], tolerance=1e-15)


def test_an_empty_result_warns():
    g = fg.Graph()
    g.add("n", "curves.boolean", a=[square(1)], b=[square(2)], operation="difference")
    with pytest.warns(fg.FormgraphWarning, match="leave no area"):
        assert g.evaluate("n") == []


def test_nameplate_graph_cuts_to_size_on_layers(tmp_path):
    import xml.etree.ElementTree as ET
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    g = fg.load(root / "graphs" / "nameplate.yaml", out_dir=tmp_path)
    cut = g.evaluate("cut")
    assert len(cut) == 4 and all(c.closed for c in cut)
    boxes = sorted(np.ptp(np.asarray(c.control_points)[:, :2], axis=0).tolist() for c in cut)
    # half the kerf (0.05) outside the 80 x 30 plate, inside the three holes of radius 1.6
    np.testing.assert_allclose(boxes[-1], [80.1, 30.1], atol=2e-3)
    np.testing.assert_allclose(boxes[:3], [[3.1, 3.1]] * 3, atol=2e-3)
    assert sum(signed_area(c) < 0 for c in cut) == 3
    svg = ET.parse(g.evaluate("svg")).getroot()
    ns = "{http://www.w3.org/2000/svg}"
    groups = {e.get("id"): e for e in svg.iter(f"{ns}g") if e.get("id")}
    assert groups["cut"].get("stroke") == "#ff0000" and len(groups["cut"]) == 4
    assert groups["engrave"].get("stroke") == "#0000ff" and len(groups["engrave"]) == 14


@st.composite
def ring_sets(draw):
    """Polygons around random centres: some nested, some overlapping, some apart."""
    k = draw(st.integers(1, 6))
    rings = []
    for _ in range(k):
        cx, cy = draw(st.floats(-3, 3)), draw(st.floats(-3, 3))
        r = draw(st.floats(0.3, 3))
        n = draw(st.integers(3, 12))
        a = np.linspace(0, 2 * np.pi, n, endpoint=False) + draw(st.floats(0, 1))
        rings.append(np.c_[cx + r * np.cos(a), cy + r * np.sin(a)])
    return rings


@settings(max_examples=40, deadline=None)
@given(ring_sets())
def test_even_odd_regions_match_a_crossing_count(rings):
    region = regions.even_odd_region(rings)
    g = np.random.default_rng(0).uniform(-6.5, 6.5, size=(4000, 2))
    ours = shapely.contains_xy(region, g[:, 0], g[:, 1])
    ref = even_odd_inside(rings, g)
    # points within a hair of a ring may go either way; everything else must agree
    lines = shapely.MultiLineString([np.r_[r, r[:1]] for r in rings])
    near = shapely.distance(shapely.points(g), lines) < 1e-9
    assert np.array_equal(ours[~near], ref[~near])
    # the fast path (rings that neither cross nor touch) and the xor tree agree
    polys = [shapely.Polygon(r) for r in rings]  # regular polygons: each valid alone
    xor = regions._xor_tree(np.array(polys, dtype=object))
    assert region.symmetric_difference(xor).area <= 1e-9 * max(xor.area, 1.0)


# --------------------------------------------------------------------------- divide


def test_divide_a_circle_into_equal_arcs_with_tangents_and_parameters():
    c = circle(2.0, 1.0, -1.0)
    pts = run("curves.divide", curve=c, count=8)
    assert isinstance(pts, fg.Points) and len(pts) == 8
    xy = pts.xyz[:, :2] - [1.0, -1.0]
    np.testing.assert_allclose(np.linalg.norm(xy, axis=1), 2.0, atol=1e-12)
    chords = np.linalg.norm(np.roll(xy, -1, axis=0) - xy, axis=1)
    np.testing.assert_allclose(chords, 4 * math.sin(math.pi / 8), rtol=1e-9)
    tangent = pts.point_data["tangent"]
    np.testing.assert_allclose(np.linalg.norm(tangent, axis=1), 1.0, atol=1e-12)
    # counter-clockwise: the tangent is the radius turned a quarter to the left
    np.testing.assert_allclose(tangent[:, :2], np.c_[-xy[:, 1], xy[:, 0]] / 2, atol=1e-9)
    t = pts.point_data["t"]
    assert np.all(np.diff(t) > 0) and t[0] == pytest.approx(c.domain[0])
    np.testing.assert_allclose(c.evaluate(t), pts.xyz, atol=1e-12)


def test_divide_an_open_cubic_at_equal_arc_length():
    rng = np.random.default_rng(5)
    cp = np.c_[rng.normal(size=(6, 2)) * 3, np.zeros(6)]
    c = NurbsCurve(cp, 3, nurbs.clamped_uniform_knots(6, 3))
    pts = run("curves.divide", curve=c, count=11)
    t = pts.point_data["t"]
    dense = np.linspace(*c.domain, 200001)
    p = c.evaluate(dense)
    cum = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    s = np.interp(t, dense, cum)
    np.testing.assert_allclose(np.diff(s), cum[-1] / 10, rtol=1e-6)
    np.testing.assert_allclose(pts.xyz[[0, -1]], cp[[0, -1]], atol=1e-12)


def test_divide_by_spacing_rounds_to_divide_the_length():
    line = NurbsCurve.polyline([[0, 0], [6, 0], [6, 4]])
    pts = run("curves.divide", curve=line, spacing=2.4)  # 10 / 2.4 -> 4 pieces of 2.5
    np.testing.assert_allclose(
        pts.xyz[:, :2], [[0, 0], [2.5, 0], [5, 0], [6, 1.5], [6, 4]], atol=1e-12
    )
    np.testing.assert_allclose(pts.point_data["tangent"][1], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pts.point_data["tangent"][3], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(line.evaluate(pts.point_data["t"]), pts.xyz, atol=1e-12)
    # knots that are not the chord lengths: t still gives the same points back
    uneven = NurbsCurve(line.control_points, 1, [0, 0, 0.3, 1, 1])
    again = run("curves.divide", curve=uneven, spacing=2.4)
    np.testing.assert_allclose(again.xyz, pts.xyz, atol=1e-12)
    np.testing.assert_allclose(uneven.evaluate(again.point_data["t"]), again.xyz, atol=1e-12)


def test_divide_needs_one_of_count_and_spacing():
    with pytest.raises(fg.NodeError, match=r"input 'count'.*exactly one"):
        run("curves.divide", curve=circle(1.0))
    with pytest.raises(fg.NodeError, match=r"input 'count'.*count >= 3"):
        run("curves.divide", curve=circle(1.0), count=2)


def _helix() -> fg.ParametricCurve:
    g = fg.Graph()
    g.add("p", "curves.parametric", x="=2*cos(t)", y="=sin(3*t)", z="=0.2*t", t=[0, 6])
    return g.evaluate("p")


@pytest.mark.parametrize(
    "make",
    [
        lambda: circle(2.0, 1.0, -1.0),
        lambda: NurbsCurve(
            np.c_[np.random.default_rng(2).normal(size=(7, 2)), np.zeros(7)],
            3,
            nurbs.clamped_uniform_knots(7, 3),
        ),
        lambda: NurbsCurve.polyline([[0, 0], [6, 0], [6, 4], [1, 5]]),
        lambda: NurbsCurve.polyline([[0, 0], [6, 0], [6, 4], [1, 5]], closed=True),
        _helix,
    ],
    ids=["circle", "cubic", "polyline", "closed-polyline", "parametric"],
)
@pytest.mark.parametrize("how", [{"count": 13}, {"spacing": 0.7}])
def test_divide_and_resample_place_the_same_points(make, how):
    """Their contract is the same division: ``curves.divide`` gives the points,
    ``curves.resample`` the polyline through them (closed: the first point again last)."""
    curve = make()
    points = run("curves.divide", curve=curve, **how).xyz
    poly = np.asarray(run("curves.resample", curve=curve, **how).control_points)
    if curve.closed:
        np.testing.assert_allclose(poly[-1], poly[0], atol=0)
        poly = poly[:-1]
    assert poly.shape == points.shape
    exact = not (isinstance(curve, NurbsCurve) and curve.degree == 1)  # one kernel
    np.testing.assert_allclose(poly, points, rtol=0, atol=0 if exact else 1e-12)


def test_batch_sampling_is_the_sampling_of_each_curve():
    glyphs = run("curves.text", text="Sg", size=7)
    rect = run("curves.rectangle", size=[5, 3], radius=1, center=[9, 0])
    curves = [circle(1.5, -3, 0), rect, *glyphs]
    for degree in (2,):  # DejaVu's quadratics, the circle's and the rectangle's arcs
        batch = [
            (c.control_points, c.degree, c.knots, c.weights if c.rational else None)
            for c in curves
            if c.degree == degree
        ]
        together = sampling.sample_closed_batch(batch, 1e-4)
        for args, got in zip(batch, together, strict=True):
            alone = sampling.sample_nurbs(*args, 1e-4, closed=True)
            assert got.shape == alone.shape  # the same samples, up to the parameter's rounding
            np.testing.assert_allclose(got, alone, rtol=0, atol=1e-12)


def test_a_hundred_rings_take_the_indexed_path_and_agree_with_shapely():
    # more rings than are made one by one (regions._FEW): one indexed creation call
    t = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    unit = np.c_[np.cos(t), np.sin(t)]
    rings = [0.6 * unit + [i, j] for i in range(10) for j in range(10)]  # neighbours overlap
    assert len(rings) > regions._FEW
    ref = shapely.union_all([shapely.Polygon(r) for r in rings])
    ours = run("curves.union", curves=[NurbsCurve.polyline(r, closed=True) for r in rings])
    assert region_area(ours) == pytest.approx(ref.area, rel=1e-12)
    # read as one list by the even-odd rule, the 180 lenses drop out (xor)
    xor = regions.even_odd_region(rings)
    expected = (
        ref.area
        - (2 * 9 * 10)
        * shapely.intersection(shapely.Polygon(rings[0]), shapely.Polygon(rings[1])).area
    )
    assert xor.area == pytest.approx(expected, rel=1e-9)


# --------------------------------------------------------------------------- exact arcs


def _on_circles(c: NurbsCurve, circles: list[tuple[float, float, float]], n: int = 4001):
    """Per point of c, its distance from the nearest of the circles (cx, cy, r)."""
    p = np.asarray(c.evaluate(np.linspace(*c.domain, n)))[:, :2]
    return np.min([np.abs(np.hypot(*(p - [x, y]).T) - r) for x, y, r in circles], axis=0)


def test_the_union_of_two_circles_is_two_exact_arcs_of_them():
    out = run("curves.union", curves=[circle(1.0), circle(1.0, 1.0)])
    assert len(out) == 1
    c = out[0]
    assert c.degree == 2 and c.rational and c.closed and signed_area(c) > 0
    assert _on_circles(c, [(0, 0, 1), (1, 0, 1)]).max() < 1e-12
    # the two crossings (1/2, +-sqrt(3)/2) are corners of the outline, exactly
    cp = np.asarray(c.control_points)[:, :2]
    for y in (math.sqrt(3) / 2, -math.sqrt(3) / 2):
        assert np.min(np.hypot(cp[:, 0] - 0.5, cp[:, 1] - y)) < 1e-14
    assert region_area(out) == pytest.approx(2 * math.pi - lens(1, 1), abs=1e-6)


@pytest.mark.parametrize("seed", range(6))
def test_cut_arcs_of_random_circles_stay_on_their_circles(seed):
    rng = np.random.default_rng(seed)
    circles = [(*rng.uniform(-2, 2, 2), rng.uniform(0.5, 1.5)) for _ in range(4)]
    curves = [circle(r, x, y) for x, y, r in circles]
    union = run("curves.union", curves=curves)
    ref = shapely.union_all([shapely.Point(x, y).buffer(r, 4096) for x, y, r in circles])
    assert region_area(union) == pytest.approx(ref.area, rel=1e-5)
    diff = run("curves.boolean", a=curves[:1], b=curves[1:], operation="difference")
    for c in [*union, *diff]:
        assert c.closed and _on_circles(c, circles).max() < 1e-9


def test_an_arc_meeting_a_polyline_ends_on_the_polyline():
    # a disc cut by a square: arcs of the circle, then the square's sides, joined exactly
    out = run("curves.boolean", a=[circle(1.0)], b=[square(1.2, 0.8, 0.8)], operation="difference")
    (c,) = out
    p = np.asarray(c.evaluate(np.linspace(*c.domain, 8001)))[:, :2]
    on_circle = np.abs(np.hypot(*p.T) - 1) < 1e-12
    on_side = (np.abs(p[:, 0] - 0.2) < 1e-12) | (np.abs(p[:, 1] - 0.2) < 1e-12)
    assert (on_circle | on_side).all() and on_circle.sum() > 5000
    expected = (
        math.pi
        - shapely.Point(0, 0).buffer(1, 8192).intersection(shapely.box(0.2, 0.2, 1.4, 1.4)).area
    )
    assert region_area(out) == pytest.approx(expected, rel=1e-6)


def test_text_cut_by_a_bar_keeps_its_quadratic_arcs_and_the_area():
    g = fg.Graph()
    g.add("t", "curves.text", text="AOB8&", size=10)
    g.add("r", "curves.rectangle", size=[30, 4], radius=1.5, center=[15, 3.5, 0])
    g.add("d", "curves.boolean", a="@t", b=["@r"], operation="difference")
    out = g.evaluate("d")
    assert all(c.closed and c.degree == 2 for c in out)
    # the reference: shapely on dense samples of the same exact curves (even-odd glyphs)
    glyphs = regions.even_odd_region([ring(c, 20000) for c in g.evaluate("t")])
    ref = shapely.difference(glyphs, shapely.Polygon(ring(g.evaluate("r"), 40000)))
    assert region_area(out) == pytest.approx(ref.area, rel=1e-6)
