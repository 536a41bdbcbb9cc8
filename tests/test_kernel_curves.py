"""Tests of formgraph.kernels.curves against closed forms, invariants and reference libraries
(scipy.interpolate.BSpline and geomdl to evaluate the NURBS results, shapely for offsets and
arc-length interpolation)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.interpolate import BSpline

from formgraph.kernels.curves import (
    bezier_chain,
    bisector_offset,
    catmull_rom,
    catmull_rom_surface,
    polyline_length,
    resample_count,
    resample_polyline,
    subdivide_polygon,
    subdivided_count,
)

RNG = np.random.default_rng(20240601)
SPACINGS = ["uniform", "centripetal", "chordal"]


def spline(result) -> BSpline:
    cps, degree, knots, weights = result
    assert weights is None
    assert len(knots) == len(cps) + degree + 1
    assert np.all(np.diff(knots) >= 0)
    return BSpline(knots, cps, degree)


def breakpoints(knots: np.ndarray) -> np.ndarray:
    return np.unique(knots)


def processing_point(p: np.ndarray, t: float, s: float) -> np.ndarray:
    """Processing's curvePoint: the basis matrix of PGraphics.curveInit with tightness s."""
    m = np.array(
        [
            [(s - 1) / 2, (s + 3) / 2, (-3 - s) / 2, (1 - s) / 2],
            [1 - s, (-5 - s) / 2, s + 2, (s - 1) / 2],
            [(s - 1) / 2, 0, (1 - s) / 2, 0],
            [0, 1, 0, 0],
        ]
    )
    return np.array([t**3, t**2, t, 1.0]) @ m @ p


def assert_c1(result, closed: bool, rtol: float = 1e-6) -> None:
    """Position and first derivative agree from both sides of every interior breakpoint
    (and across the seam of a closed curve): once from the Bezier control points exactly,
    once numerically with scipy."""
    cps, _, knots, _ = result
    b = spline(result)
    db = b.derivative()
    t = breakpoints(knots)
    h = np.diff(t)
    # exact: 3 (b3 - b2) / h_left == 3 (b1' - b0') / h_right
    left = 3 * (cps[3:-1:3] - cps[2:-2:3]) / h[:-1, None]
    right = 3 * (cps[4::3] - cps[3:-1:3]) / h[1:, None]
    scale = max(1.0, float(np.abs(left).max(initial=0)), float(np.abs(right).max(initial=0)))
    np.testing.assert_allclose(left, right, atol=1e-9 * scale)
    eps = 1e-7 * h.min()
    for ti in t[1:-1]:
        np.testing.assert_allclose(db(ti - eps), db(ti + eps), rtol=rtol, atol=1e-5 * scale)
        np.testing.assert_allclose(b(ti - eps), b(ti + eps), atol=1e-6 * scale)
    if closed:
        np.testing.assert_allclose(b(t[0]), b(t[-1]), atol=1e-12 * scale)
        np.testing.assert_allclose(db(t[0]), db(t[-1] - 1e-12), rtol=1e-6, atol=1e-9 * scale)


def distinct_run(p: np.ndarray) -> np.ndarray:
    keep = np.ones(len(p), dtype=bool)
    keep[1:] = np.any(p[1:] != p[:-1], axis=1)
    return p[keep]


# --------------------------------------------------------------------------- Bezier


def test_bezier_chain_midpoints_and_joints():
    p = RNG.normal(size=(10, 3))
    result = bezier_chain(p)
    b = spline(result)
    assert result[1] == 3
    np.testing.assert_array_equal(result[2], [0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 3])
    for i in range(3):
        q = p[3 * i : 3 * i + 4]
        np.testing.assert_allclose(b(i + 0.5), (q[0] + 3 * q[1] + 3 * q[2] + q[3]) / 8)
        np.testing.assert_allclose(b(i), q[0], atol=1e-14)
        np.testing.assert_allclose(b(i + 1 - 1e-15), q[3], atol=1e-12)


def test_bezier_chain_2d_points_get_z0():
    cps = bezier_chain([[0, 0], [1, 2], [3, 2], [4, 0]])[0]
    assert cps.shape == (4, 3) and np.all(cps[:, 2] == 0)


@pytest.mark.parametrize("n", [1, 2, 3, 5, 6, 8])
def test_bezier_chain_bad_count(n):
    with pytest.raises(ValueError, match=rf"3k\+1 points .*got {n}$"):
        bezier_chain(np.zeros((n, 3)))


def test_bad_point_arrays():
    with pytest.raises(ValueError, match=r"finite, but point 1 is \[nan"):
        bezier_chain([[0, 0, 0], [np.nan, 0, 0], [1, 1, 1], [2, 2, 2]])
    with pytest.raises(ValueError, match=r"\(n, 3\) or \(n, 2\) array .*got shape \(4,\)"):
        catmull_rom([1, 2, 3, 4])
    with pytest.raises(ValueError, match=r"\(n, 3\) array of coordinates"):
        catmull_rom([[1, 2], [3]])


# --------------------------------------------------------------------------- Catmull-Rom


def test_catmull_rom_uniform_midpoint_closed_form():
    p = RNG.normal(size=(7, 3))
    b = spline(catmull_rom(p))
    for i in range(4):  # segment p[i+1] -> p[i+2], parameter i .. i+1
        q = p[i : i + 4]
        np.testing.assert_allclose(b(i + 0.5), (-q[0] + 9 * q[1] + 9 * q[2] - q[3]) / 16)


@pytest.mark.parametrize("tension", [-0.5, 0.0, 0.3, 1.0])
def test_catmull_rom_tension_is_processing_curve_tightness(tension):
    p = RNG.normal(size=(6, 3))
    b = spline(catmull_rom(p, tension=tension))
    for i in range(3):
        for t in (0.0, 0.25, 0.5, 0.9):
            np.testing.assert_allclose(
                b(i + t), processing_point(p[i : i + 4], t, tension), atol=1e-12
            )


def test_catmull_rom_tension_one_is_the_polyline():
    p = RNG.normal(size=(5, 3))
    b = spline(catmull_rom(p, ends="clamped", tension=1.0))
    x = b(np.linspace(0, 4, 41))
    # every sample lies on the chord of its span
    for i in range(4):
        seg = x[10 * i : 10 * i + 11]
        d = p[i + 1] - p[i]
        off = np.cross(seg - p[i], d)
        np.testing.assert_allclose(off, 0, atol=1e-12)


@pytest.mark.parametrize("spacing", SPACINGS)
@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("ends", ["processing", "clamped"])
def test_catmull_rom_c1_and_through_points(spacing, closed, ends):
    p = RNG.normal(size=(9, 3))
    result = catmull_rom(p, closed=closed, spacing=spacing, ends=ends)
    b = spline(result)
    t = breakpoints(result[2])
    through = p if (closed or ends == "clamped") else p[1:-1]
    if closed:
        through = np.concatenate([p, p[:1]])
    np.testing.assert_allclose(b(t[:-1]), through[:-1], atol=1e-12)
    np.testing.assert_allclose(b(t[-1]), through[-1], atol=1e-12)
    assert_c1(result, closed)


@pytest.mark.parametrize("spacing,alpha", [("uniform", 0.0), ("centripetal", 0.5), ("chordal", 1)])
def test_catmull_rom_knot_intervals(spacing, alpha):
    p = RNG.normal(size=(6, 3))
    knots = catmull_rom(p, spacing=spacing, ends="clamped")[2]
    expected = np.linalg.norm(np.diff(p, axis=0), axis=1) ** alpha
    np.testing.assert_allclose(np.diff(breakpoints(knots)), expected)


def test_catmull_rom_closed_seam_and_last_point_repeat():
    p = RNG.normal(size=(5, 3))
    a = catmull_rom(p, closed=True, spacing="centripetal")
    b = catmull_rom(np.concatenate([p, p[:1]]), closed=True, spacing="centripetal")
    np.testing.assert_array_equal(a[0], b[0])
    assert np.array_equal(a[0][0], a[0][-1])
    assert len(a[0]) == 3 * 5 + 1


def test_catmull_rom_clamped_end_tangent_along_first_chord():
    p = RNG.normal(size=(5, 3))
    cps = catmull_rom(p, ends="clamped", spacing="chordal")[0]
    np.testing.assert_allclose(cps[1], p[0] + (p[1] - p[0]) / 3)
    np.testing.assert_allclose(cps[-2], p[-1] - (p[-1] - p[-2]) / 3)


def test_centripetal_has_no_loop_where_uniform_does():
    p = np.array([[3.0, -2.0], [0.0, -2.0], [0.5, -1.5], [2.0, 2.0]])

    def is_simple(spacing):
        result = catmull_rom(p, spacing=spacing)
        t = np.linspace(result[2][0], result[2][-1], 400)
        return shapely.LineString(spline(result)(t)[:, :2]).is_simple

    assert not is_simple("uniform")
    assert is_simple("centripetal")


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, (4, 2), elements=st.floats(-10, 10, allow_subnormal=False)))
def test_centripetal_segment_never_self_intersects(p):
    d = np.linalg.norm(np.diff(p, axis=0), axis=1)
    assume(d.min() > 1e-2)
    # three nearly collinear points make a segment that retraces a line; skip those
    u = np.diff(p, axis=0) / d[:, None]
    assume(np.all(np.abs(u[:-1, 0] * u[1:, 1] - u[:-1, 1] * u[1:, 0]) > 1e-3))
    result = catmull_rom(p, spacing="centripetal")
    t = np.linspace(result[2][0], result[2][-1], 300)
    assert shapely.LineString(spline(result)(t)[:, :2]).is_simple


def test_repeated_points_are_dropped_not_nan():
    p = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 1, 0], [2, 1, 0], [3, 0, 0]], float)
    for spacing in SPACINGS:
        for ends in ("processing", "clamped"):
            result = catmull_rom(p, spacing=spacing, ends=ends)
            assert np.isfinite(result[0]).all()
            assert_c1(result, closed=False)
        result = catmull_rom(p, closed=True, spacing=spacing)
        assert np.isfinite(result[0]).all() and len(result[0]) == 3 * 4 + 1


def test_processing_phantom_on_top_of_its_neighbour():
    # Processing's tangent at the start is (p2 - p0) / 2 = (p2 - p1) / 2 here, whatever
    # the spacing: the zero-length phantom span takes its neighbour's interval.
    p = np.array([[0, 0, 0], [0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 0]], float)
    for spacing in SPACINGS:
        cps, _, knots, _ = catmull_rom(p, spacing=spacing)
        assert np.isfinite(cps).all()
        np.testing.assert_allclose(cps[1], p[1] + (p[2] - p[1]) / 6)
        np.testing.assert_allclose(cps[-2], p[-2] - (p[-2] - p[-3]) / 6)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(points=[[0, 0], [1, 0], [2, 0]]), r"ends='processing' needs at least 4 .*got 3"),
        (dict(points=[[0, 0], [1, 0], [1, 0], [2, 0]]), r"at least 2 distinct points .*got 1"),
        (dict(points=[[0, 0], [0, 0]], ends="clamped"), r"at least 2 distinct points"),
        (
            dict(points=[[0, 0], [1, 0], [1, 0], [0, 0]], closed=True),
            r"closed .* at least 3 distinct points, got 2 \(4 before dropping repeats\)",
        ),
        (dict(points=[[0, 0], [1, 0]], spacing="arc"), r"spacing must be one of \['uniform'"),
        (dict(points=[[0, 0], [1, 0]], ends="free"), r"ends must be one of \['processing'"),
        (dict(points=[[0, 0], [1, 0]], tension=np.inf), r"tension must be a finite number"),
    ],
)
def test_catmull_rom_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        catmull_rom(**kwargs)


@settings(max_examples=80, deadline=None)
@given(
    pts=arrays(np.float64, st.tuples(st.integers(2, 12), st.just(3)), elements=st.integers(-2, 2)),
    closed=st.booleans(),
    spacing=st.sampled_from(SPACINGS),
    ends=st.sampled_from(["processing", "clamped"]),
    tension=st.sampled_from([0.0, 0.5, -1.0]),
)
def test_catmull_rom_random_points(pts, closed, spacing, ends, tension):
    """Small integer coordinates make repeats common: never NaN, and every distinct point
    the curve must pass through is passed through."""
    try:
        result = catmull_rom(pts, closed=closed, tension=tension, spacing=spacing, ends=ends)
    except ValueError as exc:
        assert "at least" in str(exc)
        return
    cps, _, knots, _ = result
    assert np.isfinite(cps).all() and np.isfinite(knots).all()
    b = spline(result)
    t = breakpoints(knots)
    if closed:
        through = distinct_run(pts)
        while len(through) > 1 and np.array_equal(through[0], through[-1]):
            through = through[:-1]
        through = np.concatenate([through, through[:1]])
    elif ends == "processing":
        through = distinct_run(pts[1:-1])
    else:
        through = distinct_run(pts)
    assert len(t) == len(through)
    np.testing.assert_allclose(b(t[:-1]), through[:-1], atol=1e-9)
    np.testing.assert_allclose(cps[-1], through[-1])
    assert_c1(result, closed)


# --------------------------------------------------------------------------- surface


@pytest.mark.parametrize("closed_u,closed_v", [(False, False), (True, False), (True, True)])
def test_bicubic_surface_through_every_point_geomdl(closed_u, closed_v):
    from geomdl import BSpline as GBSpline

    grid = RNG.normal(size=(4, 5, 3))
    cps, du, dv, ku, kv, w = catmull_rom_surface(grid, closed_u, closed_v)
    assert (du, dv, w) == (3, 3, None)
    mu, mv = cps.shape[:2]
    assert mu == (3 * 4 + 1 if closed_u else 3 * 3 + 1)
    assert mv == (3 * 5 + 1 if closed_v else 3 * 4 + 1)
    surf = GBSpline.Surface()
    surf.degree_u, surf.degree_v = 3, 3
    surf.ctrlpts_size_u, surf.ctrlpts_size_v = mu, mv
    surf.ctrlpts = cps.reshape(-1, 3).tolist()
    surf.knotvector_u = (ku / ku[-1]).tolist()
    surf.knotvector_v = (kv / kv[-1]).tolist()
    bu, bv = breakpoints(ku) / ku[-1], breakpoints(kv) / kv[-1]
    params = [(u, v) for u in bu for v in bv]
    got = np.array(surf.evaluate_list(params)).reshape(len(bu), len(bv), 3)
    expect = grid
    if closed_u:
        expect = np.concatenate([expect, expect[:1]], axis=0)
    if closed_v:
        expect = np.concatenate([expect, expect[:, :1]], axis=1)
    np.testing.assert_allclose(got, expect, atol=1e-12)


@pytest.mark.parametrize("closed_u,closed_v", [(False, False), (False, True), (True, True)])
def test_bicubic_isocurves_are_catmull_rom_curves(closed_u, closed_v):
    """Tensor product: the control rows through grid columns are the curve conversions, and
    so is every control column (the conversion is linear)."""
    grid = RNG.normal(size=(5, 4, 3))
    cps = catmull_rom_surface(grid, closed_u, closed_v, tension=0.2)[0]
    for j in range(4):
        curve = catmull_rom(grid[:, j], closed=closed_u, ends="clamped", tension=0.2)[0]
        np.testing.assert_allclose(cps[:, 3 * j], curve, atol=1e-12)
    for i in range(len(cps)):
        row = catmull_rom(cps[i, ::3][: 4 if closed_v else None], closed=closed_v,
                          ends="clamped", tension=0.2)[0]  # fmt: skip
        np.testing.assert_allclose(cps[i], row, atol=1e-12)


def test_bicubic_surface_errors():
    with pytest.raises(ValueError, match=r"at least 3 points in closed direction u, got 2 x 4"):
        catmull_rom_surface(np.zeros((2, 4, 3)), closed_u=True)
    with pytest.raises(ValueError, match=r"\(nu, nv, 3\) grid of points, got shape \(4, 3\)"):
        catmull_rom_surface(np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"rows of equally many points"):
        catmull_rom_surface([[[0, 0, 0], [1, 0, 0]], [[0, 1, 0]]])
    g = np.zeros((3, 3, 3))
    g[1, 2, 0] = np.inf
    with pytest.raises(ValueError, match=r"row 1, point 2 is \[inf"):
        catmull_rom_surface(g)


# --------------------------------------------------------------------------- subdivision


def test_subdivide_one_round_closed_form():
    p = RNG.normal(size=(5, 3))
    out = subdivide_polygon(p, closed=True, iterations=1)
    prv, nxt = np.roll(p, 1, 0), np.roll(p, -1, 0)
    np.testing.assert_allclose(out[0::2], (prv + 6 * p + nxt) / 8)
    np.testing.assert_allclose(out[1::2], (p + nxt) / 2)
    out = subdivide_polygon(p, closed=False, iterations=1)
    np.testing.assert_allclose(out[2:-1:2], (p[:-2] + 6 * p[1:-1] + p[2:]) / 8)
    np.testing.assert_allclose(out[1::2], (p[:-1] + p[1:]) / 2)
    np.testing.assert_array_equal(out[[0, -1]], p[[0, -1]])


def test_subdivide_closed_converges_to_uniform_cubic_bspline():
    p = RNG.normal(size=(6, 3))
    k = 10
    out = subdivide_polygon(p, closed=True, iterations=k)
    prv, nxt, nxt2 = np.roll(p, 1, 0), np.roll(p, -1, 0), np.roll(p, -2, 0)
    vertex_limit = (prv + 4 * p + nxt) / 6
    edge_limit = (prv + 23 * p + 23 * nxt + nxt2) / 48  # B-spline at a span's middle
    step = 2**k
    np.testing.assert_allclose(out[::step], vertex_limit, atol=1e-5)
    np.testing.assert_allclose(out[step // 2 :: step], edge_limit, atol=1e-5)
    # and against scipy's periodic uniform cubic B-spline on the same control polygon
    ext = np.concatenate([p[-1:], p, p[:2]])
    bs = BSpline(np.arange(len(ext) + 4, dtype=float), ext, 3)
    t = 3 + np.arange(len(out)) / step
    np.testing.assert_allclose(out, bs(t), atol=1e-5)


def test_subdivide_open_keeps_ends_and_limit_next_to_end():
    p = RNG.normal(size=(5, 3))
    out = subdivide_polygon(p, closed=False, iterations=10)
    np.testing.assert_array_equal(out[[0, -1]], p[[0, -1]])
    np.testing.assert_allclose(out[2**10], (p[0] + 4 * p[1] + p[2]) / 6, atol=1e-5)


@pytest.mark.parametrize(
    "closed,n,k", [(False, 2, 0), (False, 2, 3), (False, 7, 3), (True, 3, 0), (True, 3, 1),
                   (True, 10, 5)]
)  # fmt: skip
def test_subdivided_count(closed, n, k):
    out = subdivide_polygon(RNG.normal(size=(n, 3)), closed=closed, iterations=k)
    assert len(out) == subdivided_count(n, closed, k)
    assert subdivided_count(10_000, True, 60) == 10_000 * 2**60


def test_subdivide_closed_drops_repeated_first_point_and_errors():
    p = RNG.normal(size=(4, 3))
    a = subdivide_polygon(p, closed=True, iterations=2)
    b = subdivide_polygon(np.concatenate([p, p[:1]]), closed=True, iterations=2)
    np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="closed polygon needs at least 3 points, got 2"):
        subdivide_polygon(p[:2], closed=True)
    with pytest.raises(ValueError, match="iterations must be >= 0, got -1"):
        subdivide_polygon(p, iterations=-1)


# --------------------------------------------------------------------------- resampling


@pytest.mark.parametrize("closed", [False, True])
def test_resample_matches_shapely_interpolation(closed):
    p = RNG.normal(size=(12, 2))
    out = resample_polyline(p, count=40, closed=closed)
    line = shapely.LinearRing(p) if closed else shapely.LineString(p)
    total = line.length
    s = np.arange(40) * total / 40 if closed else np.linspace(0, total, 40)
    ref = shapely.get_coordinates(shapely.line_interpolate_point(line, s))
    np.testing.assert_allclose(out[:, :2], ref, atol=1e-12)
    assert np.isclose(polyline_length(p, closed), total)


def test_resample_spacing_rounds_to_divide_length():
    p = np.array([[0, 0, 0], [10, 0, 0]], float)
    out = resample_polyline(p, spacing=3.0)  # 10 / 3 -> 3 segments of 10/3
    np.testing.assert_allclose(out[:, 0], [0, 10 / 3, 20 / 3, 10])
    assert resample_count(10.0, 3.0) == 4
    assert resample_count(10.0, 100.0, closed=True) == 3
    with pytest.raises(ValueError, match=r"more than 2\^53 points"):
        resample_count(10.0, 1e-300)
    with pytest.raises(ValueError, match="spacing must be a positive number, got -1"):
        resample_count(10.0, -1.0)


def test_resample_with_repeats_and_errors():
    p = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [1, 1, 0]], float)
    out = resample_polyline(p, count=5)
    np.testing.assert_allclose(out[:, :2], [[0, 0], [0.5, 0], [1, 0], [1, 0.5], [1, 1]])
    with pytest.raises(ValueError, match="exactly one of count and spacing"):
        resample_polyline(p)
    with pytest.raises(ValueError, match="exactly one of count and spacing"):
        resample_polyline(p, count=3, spacing=1.0)
    with pytest.raises(ValueError, match="zero length"):
        resample_polyline(np.zeros((3, 3)), count=3)
    with pytest.raises(ValueError, match="closed polyline needs count >= 3, got 2"):
        resample_polyline(p, count=2, closed=True)


# --------------------------------------------------------------------------- offset


def convex_polygon(n: int) -> np.ndarray:
    """A random convex polygon, counter-clockwise."""
    hull = shapely.MultiPoint(RNG.normal(size=(n, 2))).convex_hull
    ring = shapely.get_coordinates(hull.exterior)[:-1]
    return ring if shapely.LinearRing(ring).is_ccw else ring[::-1]


def edge_offsets(p: np.ndarray, out: np.ndarray, source: np.ndarray, closed: bool) -> np.ndarray:
    """Signed left distance of the two ends of each offset edge from its original edge."""
    n = len(p)
    m = n if closed else n - 1
    last = np.searchsorted(source, np.arange(n), side="right") - 1  # last output of vertex i
    firsts = np.searchsorted(source, np.arange(n), side="left")
    a, b = p[np.arange(m)], p[(np.arange(m) + 1) % n]
    e = (b - a)[:, :2] / np.linalg.norm((b - a)[:, :2], axis=1)[:, None]
    dist = []
    for pts in (out[last[:m]], out[firsts[(np.arange(m) + 1) % n]]):
        v = (pts - a)[:, :2]
        dist.append(e[:, 0] * v[:, 1] - e[:, 1] * v[:, 0])
    return np.stack(dist, axis=1)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("distance", [0.3, -0.05])
def test_offset_edges_at_exactly_distance(closed, distance):
    p = convex_polygon(12)
    p = np.column_stack([p, RNG.normal(size=len(p))])  # z is carried
    out, source = bisector_offset(p, closed, distance, return_source=True)
    np.testing.assert_array_equal(out[:, 2], p[source, 2])
    d = edge_offsets(p, out, source, closed)
    side = -distance if closed else distance  # ccw: growing is to the right
    np.testing.assert_allclose(d, side, atol=1e-12)


@pytest.mark.parametrize("limit", [1.0, 1.3, 4.0])
def test_offset_grows_closed_convex_like_shapely_buffer(limit):
    p = convex_polygon(9)
    for pts in (p, p[::-1]):  # either orientation grows
        out = bisector_offset(pts, True, 0.2, miter_limit=limit)
        ref = shapely.Polygon(p).buffer(0.2, join_style="mitre", mitre_limit=limit).exterior
        ours = shapely.LinearRing(out[:, :2])
        assert shapely.hausdorff_distance(ours, ref) < 1e-9
        assert shapely.Polygon(out[:, :2]).area > shapely.Polygon(p).area


def test_offset_shrinks_closed_convex_like_shapely_offset_curve():
    p = np.array([[0, 0], [4, 0], [5, 2], [3, 4], [0, 3]], float)
    for pts in (p, p[::-1]):
        out = bisector_offset(pts, True, -0.3)
        ref = shapely.offset_curve(shapely.LineString(np.vstack([p, p[:1]])), 0.3,
                                   join_style="mitre")  # fmt: skip
        assert shapely.hausdorff_distance(shapely.LinearRing(out[:, :2]), ref) < 1e-9


@pytest.mark.parametrize("distance", [0.1, -0.1])
@pytest.mark.parametrize("limit", [1.5, 5.0])
def test_offset_open_like_shapely_offset_curve(distance, limit):
    p = np.array([[0, 0], [2, 0], [3, 1], [3.2, 3], [1, 2.5], [0.8, 0.9]], float)
    out = bisector_offset(p, False, distance, miter_limit=limit)
    ref = shapely.offset_curve(
        shapely.LineString(p), distance, join_style="mitre", mitre_limit=limit
    )
    np.testing.assert_allclose(out[:, :2], shapely.get_coordinates(ref), atol=1e-12)


def test_offset_sharp_corner_is_clipped_at_miter_limit():
    p = np.array([[0, 0], [10, 0], [0, 1]], float)
    out, source = bisector_offset(p, False, -1.0, miter_limit=2.0, return_source=True)
    assert source.tolist() == [0, 1, 1, 2]
    bevel_mid = out[1:3, :2].mean(axis=0)
    assert np.isclose(np.linalg.norm(bevel_mid - p[1, :2]), 2.0)
    # the other side of the same corner is concave: the exact intersection point
    out = bisector_offset(p, False, 0.01, miter_limit=2.0)
    assert len(out) == 3


def test_offset_collinear_runs_and_reversal():
    p = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 2], [3, 0]], float)
    out = bisector_offset(p, False, 0.5, miter_limit=2.0)
    assert np.isfinite(out).all()
    np.testing.assert_allclose(out[:3, :2], [[0, 0.5], [1, 0.5], [2, 0.5]])
    # the 180-degree turn at (3, 2) is capped at 2 * 0.5 beyond the tip
    tip = out[np.isclose(out[:, 1], 3.0)]
    assert len(tip) == 2


def test_offset_open_left_of_travel_and_repeats_dropped():
    p = np.array([[0, 0], [1, 0], [1, 0], [2, 0]], float)
    out = bisector_offset(p, False, 0.25)
    np.testing.assert_allclose(out[:, :2], [[0, 0.25], [1, 0.25], [2, 0.25]])
    out = bisector_offset(p[::-1], False, 0.25)
    np.testing.assert_allclose(out[:, 1], -0.25)


@settings(max_examples=40, deadline=None)
@given(
    n=st.integers(3, 30),
    distance=st.floats(-0.5, 0.5, allow_subnormal=False),
    closed=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
)
def test_offset_random_polylines(n, distance, closed, seed):
    p = np.random.default_rng(seed).normal(size=(n, 2))
    try:
        out, source = bisector_offset(p, closed, distance, return_source=True)
    except ValueError as exc:
        assert "zero signed area" in str(exc)
        return
    assert np.isfinite(out).all()
    d = edge_offsets(np.column_stack([p, np.zeros(n)]), out, source, closed)
    if closed:
        # the signed area decides (shapely's is_ccw looks at one vertex, which differs on
        # self-intersecting rings)
        area2 = np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(np.roll(p[:, 0], -1), p[:, 1])
        sign = np.sign(area2)
        expected = -distance * sign
    else:
        expected = distance
    scale = 1 + np.abs(out).max()
    np.testing.assert_allclose(d, expected, atol=1e-9 * scale)


def test_offset_errors():
    with pytest.raises(ValueError, match="zero signed area has no outside"):
        bisector_offset([[0, 0], [1, 0], [2, 0]], True, 1.0)
    with pytest.raises(ValueError, match="miter_limit must be a number >= 1, got 0.5"):
        bisector_offset([[0, 0], [1, 0]], False, 1.0, miter_limit=0.5)
    with pytest.raises(ValueError, match=r"open polyline needs at least 2 distinct points"):
        bisector_offset([[0, 0, 0], [0, 0, 1]], False, 1.0)


def test_results_never_alias_a_read_only_input():
    p = RNG.normal(size=(7, 3))
    p.flags.writeable = False
    outs = [
        bezier_chain(p)[0],
        catmull_rom(p)[0],
        catmull_rom(p, closed=True)[0],
        subdivide_polygon(p, iterations=0),
        subdivide_polygon(p, closed=True, iterations=2),
        resample_polyline(p, count=5),
        bisector_offset(p, False, 0.0),
        bisector_offset(p, True, 0.1),
        catmull_rom_surface(p.reshape(1, 7, 3).repeat(2, axis=0))[0],
    ]
    for out in outs:
        assert out.flags.writeable and not np.shares_memory(out, p)
