"""curves.voronoi and curves.delaunay (nodes/curves/voronoi.py, kernels/curves/voronoi.py):
cells tile the region and hold their points, against a k-d tree's nearest site; Delaunay
against GEOS's and the empty-circumcircle property."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

import formgraph as fg
from formgraph.geometry import NurbsCurve, Points


def run(node_type: str, points: Points, **inputs):
    g = fg.Graph()
    g.add_param("p_", type="Points")
    g.add("v", node_type, points="=p_", **inputs)
    return g.evaluate("v", p_=points)


def polygon(c: NurbsCurve) -> shapely.Polygon:
    return shapely.Polygon(np.asarray(c.control_points)[:, :2])


def seeds(n: int, seed: int = 0, lo=0.0, hi=10.0) -> Points:
    return Points(np.random.default_rng(seed).uniform(lo, hi, (n, 2)))


def square(lo: float, hi: float) -> NurbsCurve:
    return NurbsCurve.polyline([[lo, lo], [hi, lo], [hi, hi], [lo, hi]], closed=True)


def check_cells(cells, xy, region: shapely.Geometry) -> None:
    assert len(cells) == len(xy)
    polys = [polygon(c) for c in cells]
    # one closed counter-clockwise curve per point, holding it
    assert all(c.closed and c.degree == 1 for c in cells)
    assert all(p.exterior.is_ccw and p.is_valid for p in polys)
    assert all(p.covers(shapely.Point(q)) for p, q in zip(polys, xy, strict=True))
    # the cells tile the region: areas add up to it and their union is it
    areas = np.array([p.area for p in polys])
    assert abs(areas.sum() - region.area) < 1e-9 * region.area
    assert shapely.union_all(polys).symmetric_difference(region).area < 1e-9 * region.area
    # each cell is the part nearest its own point: its corners are no nearer another point
    tree = cKDTree(xy)
    for i, p in enumerate(polys):
        corners = np.asarray(p.exterior.coords)
        d, _ = tree.query(corners)
        np.testing.assert_allclose(np.linalg.norm(corners - xy[i], axis=1), d, atol=1e-9)


def test_cells_tile_the_default_box_and_are_nearest_their_points():
    p = seeds(300, 1)
    cells = run("curves.voronoi", p)
    xy = p.xyz[:, :2]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    grow = 0.05 * (hi - lo).max()
    check_cells(cells, xy, shapely.box(*(lo - grow), *(hi + grow)))
    assert all(np.all(np.asarray(c.control_points)[:, 2] == 0) for c in cells)


def test_cells_tile_a_given_region_in_the_points_order():
    p = Points(np.random.default_rng(2).uniform(1, 9, (120, 3)))  # z is ignored
    cells = run("curves.voronoi", p, region=square(0, 10))
    check_cells(cells, p.xyz[:, :2], shapely.box(0, 0, 10, 10))


def test_a_region_with_a_hole_holes_a_cell_which_keeps_its_outline_with_a_warning():
    region = [square(0, 10), square(4, 6)]  # even-odd: a square with a square hole
    xy = np.array([[5.0, 2.0], [0.5, 9.8], [9.5, 9.8]])  # the first one's cell holds the hole
    with pytest.warns(fg.FormgraphWarning, match=r"cuts 1 cells into pieces or holes them"):
        cells = run("curves.voronoi", Points(xy), region=region)
    polys = [polygon(c) for c in cells]
    assert all(
        p.covers(shapely.Point(q)) and p.exterior.is_ccw for p, q in zip(polys, xy, strict=True)
    )
    holed = shapely.box(0, 0, 10, 10).difference(shapely.box(4, 4, 6, 6))
    assert abs(sum(p.area for p in polys) - (holed.area + 4.0)) < 1e-9  # the hole counted once
    assert (
        shapely.union_all(polys)
        .difference(shapely.box(4, 4, 6, 6))
        .symmetric_difference(holed)
        .area
        < 1e-9
    )


def test_voronoi_refuses_one_point_coincident_points_and_points_outside():
    with pytest.raises(fg.NodeError, match="needs at least 2 points, got 1"):
        run("curves.voronoi", Points([[0, 0]]))
    with pytest.raises(fg.NodeError, match=r"points 1 and 3 coincide at \(2, 5\) in XY"):
        run("curves.voronoi", Points([[0, 0, 0], [2, 5, 0], [1, 1, 0], [2, 5, 7]]))
    with pytest.raises(fg.NodeError, match=r"point 2 at \(12, 3\) lies outside the region"):
        run("curves.voronoi", Points([[1, 1], [2, 2], [12, 3]]), region=square(0, 10))


def test_delaunay_is_geos_triangulation_with_empty_circumcircles():
    p = seeds(400, 5)
    rng = np.random.default_rng(6)
    p = Points(np.column_stack([p.xyz[:, :2], rng.normal(size=400)]), {"h": np.arange(400.0)})
    m = run("curves.delaunay", p)
    tri = np.asarray(m.face_indices).reshape(-1, 3)
    np.testing.assert_array_equal(m.vertices, p.xyz)  # z kept
    np.testing.assert_array_equal(m.point_data["h"], np.arange(400.0))
    xy = p.xyz[:, :2]
    a, b, c = xy[tri[:, 0]], xy[tri[:, 1]], xy[tri[:, 2]]
    turn = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert np.all(turn > 0)
    # the same triangles as GEOS's
    theirs = shapely.get_parts(shapely.delaunay_triangles(shapely.multipoints(xy)))
    index = {tuple(q): i for i, q in enumerate(xy.tolist())}
    geos = {
        tuple(sorted(index[tuple(q)] for q in np.asarray(t.exterior.coords)[:3].tolist()))
        for t in theirs
    }
    assert {tuple(sorted(t)) for t in tri.tolist()} == geos
    # no point strictly inside a circumcircle
    d = a - c
    e = b - c
    den = 2 * (d[:, 0] * e[:, 1] - d[:, 1] * e[:, 0])
    dd, ee = (d**2).sum(1), (e**2).sum(1)
    centre = (
        c
        + np.column_stack([e[:, 1] * dd - d[:, 1] * ee, d[:, 0] * ee - e[:, 0] * dd]) / den[:, None]
    )
    radius = np.linalg.norm(a - centre, axis=1)
    nearest, _ = cKDTree(xy).query(centre)
    assert np.all(nearest >= radius * (1 - 1e-9))


def test_delaunay_refuses_points_on_one_line():
    with pytest.raises(fg.NodeError, match="the points all lie on one line"):
        run("curves.delaunay", Points([[0, 0], [1, 1], [2, 2], [3, 3]]))
    with pytest.raises(fg.NodeError, match="needs at least 3 points, got 2"):
        run("curves.delaunay", Points([[0, 0], [1, 1]]))
