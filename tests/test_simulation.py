"""The nodes made to step (nodes/curves/grow.py, nodes/mesh/relax.py) in graphs: curves.grow
lengthens a curve and keeps it simple (shapely) and inside its bounds; mesh.relax brings a
net to rest with its anchors unmoved, symmetric, and inflates a closed mesh;
bad inputs are located."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import formgraph as fg

GROW = """\
formgraph: 1
params:
  steps: {default: 30, min: 0, max: 300}
nodes:
  circle: {type: nurbs.circle, radius: 3}
  seed: {type: curves.resample, curve: "@circle", count: 20}
  fence: {type: nurbs.circle, radius: 8}
  grown:
    type: curves.grow
    simulate: {state: curve, from: "@seed", steps: "=steps"}
    curve: "=curve"
  m: {type: curves.measure, curve: "@grown"}
"""


def ring_of(curve) -> shapely.LinearRing:
    p = np.asarray(curve.control_points)
    return shapely.LinearRing(p[:-1, :2])


def test_a_few_dozen_steps_lengthen_the_curve_and_keep_it_simple():
    g = fg.Graph.from_text(GROW)
    start = 2 * np.pi * 3
    assert g.evaluate("m").length > 3 * start
    lengths = []
    for steps in (5, 10, 20, 30):
        c = g.evaluate("grown", steps=steps)
        assert ring_of(c).is_simple and c.closed
        assert np.ptp(np.asarray(c.control_points)[:, 2]) == 0.0  # stays in its plane
        lengths.append(g.evaluate("m", steps=steps).length)
    assert lengths == sorted(lengths)


def test_growth_stays_inside_its_bounds_and_reaches_them():
    g = fg.Graph.from_text(GROW.replace('curve: "=curve"', 'curve: "=curve"\n    bounds: "@fence"'))
    c = g.evaluate("grown", steps=120)
    inside = shapely.Polygon(shapely.Point(0, 0).buffer(8, 256).exterior)
    assert inside.contains(ring_of(c)) and ring_of(c).is_simple
    assert np.linalg.norm(np.asarray(c.control_points)[:, :2], axis=1).max() > 6.5


def test_an_open_curve_and_a_curve_that_is_not_a_polyline_grow():
    g = fg.Graph()
    g.add("pts", "points.list", points=[[0, 0, 2], [4, 0, 2], [8, 0, 2]])
    g.add("line", "curves.polyline", points="@pts")
    g.add(
        "grown",
        "curves.grow",
        curve="=curve",
        simulate={"state": "curve", "from": "@line", "steps": 25},
    )
    c = g.evaluate("grown")
    assert not c.closed and shapely.LineString(np.asarray(c.control_points)[:, :2]).is_simple
    assert np.asarray(c.control_points)[:, 2].tolist() == [2.0] * len(c.control_points)
    g.add("circle", "nurbs.circle", radius=2)  # rational, degree 2: sampled about split/2 apart
    g.add("round", "curves.grow", simulate={"state": "curve", "from": "@circle", "steps": 3})
    assert ring_of(g.evaluate("round")).is_simple


def test_a_crossing_seed_and_a_tilted_curve_are_located():
    g = fg.Graph()
    g.add("pts", "points.list", points=[[0, 0, 0], [2, 2, 0], [2, 0, 0], [0, 2, 0]])
    g.add("eight", "curves.polyline", points="@pts", closed=True)
    g.add("grown", "curves.grow", simulate={"state": "curve", "from": "@eight", "steps": 3})
    with pytest.raises(fg.NodeError, match=r"input 'curve'.*step 1: the curve crosses itself"):
        g.evaluate("grown")
    g.set_input("pts", "points", [[0, 0, 0], [2, 0, 1], [2, 2, 0]])
    with pytest.raises(fg.NodeError, match="must lie in a plane z = constant"):
        g.evaluate("grown")


RELAX = """\
formgraph: 1
params:
  steps: {default: 300, min: 0, max: 3000}
nodes:
  net: {type: mesh.plane, size: [6, 6], divisions: [8, 8], center: [0.1, 0.2, 0.3]}
  hang:
    type: mesh.relax
    simulate: {state: mesh, from: "@net", steps: "=steps"}
    reference: "@net"
    anchors: [0, 8, 72, 80]
    load: [0, 0, -0.02]
"""


def test_a_few_hundred_steps_bring_a_small_net_to_rest_with_anchors_fixed():
    g = fg.Graph.from_text(RELAX)
    net = g.evaluate("net")
    hung = g.evaluate("hang")
    after = g.evaluate("hang", steps=301)
    assert np.abs(after.vertices - hung.vertices).max() < 1e-6
    corners = [0, 8, 72, 80]
    assert hung.vertices[corners].tobytes() == net.vertices[corners].tobytes()
    z = (hung.vertices[:, 2] - 0.3).reshape(9, 9)
    assert z.min() < -1.0
    for image in (z[::-1], z[:, ::-1], z.T):
        np.testing.assert_allclose(image, z, atol=1e-7)
    assert hung.face_indices.tobytes() == net.face_indices.tobytes()


def test_a_held_boundary_gives_a_pillow_and_pressure_inflates_a_sphere():
    g = fg.Graph.from_text(RELAX.replace("anchors: [0, 8, 72, 80]", "anchor_boundary: true"))
    hung = g.evaluate("hang")
    edge = np.abs(hung.vertices[:, :2] - [0.1, 0.2]).max(axis=1) > 3 - 1e-9
    assert np.array_equal(hung.vertices[edge], g.evaluate("net").vertices[edge])
    assert hung.vertices[~edge, 2].max() < 0.3
    g = fg.Graph()
    g.add("ball", "mesh.sphere", radius=1)
    g.add(
        "blown",
        "mesh.relax",
        simulate={"state": "mesh", "from": "@ball", "steps": 40},
        reference="@ball",
        pressure=1.0,
    )
    ball, blown = g.evaluate("ball"), g.evaluate("blown")
    assert blown.volume > 1.1 * ball.volume and blown.is_watertight


def test_relax_problems_are_located():
    g = fg.Graph.from_text(RELAX.replace("anchors: [0, 8, 72, 80]", "anchors: [0, 99]"))
    with pytest.raises(fg.NodeError, match=r"input 'anchors'.*anchor 99 is not a vertex"):
        g.evaluate("hang")
    g = fg.Graph.from_text(RELAX + "  other: {type: mesh.box}\n")
    g.set_input("hang", "reference", "@other")
    with pytest.raises(fg.NodeError, match="reference must have the mesh's faces"):
        g.evaluate("hang")


def test_momentum_carries_the_velocities_so_the_steps_are_one_motion():
    g = fg.Graph.from_text(RELAX)
    hung = g.evaluate("hang", steps=60)
    velocity = hung.point_data["relax_velocity"]
    assert velocity.shape == (81, 3) and not velocity[[0, 8, 72, 80]].any()
    # the same 600 iterations as one motion: at rest; from rest every step: still falling
    moving = np.abs(g.evaluate("hang", steps=61).vertices - hung.vertices).max()
    g.set_input("hang", "momentum", False)
    slow = g.evaluate("hang", steps=60)
    assert "relax_velocity" not in slow.point_data
    assert np.abs(g.evaluate("hang", steps=61).vertices - slow.vertices).max() > 100 * moving


def test_steps_from_the_disk_cache_go_on_exactly_as_a_cold_run(tmp_path):
    # the velocities ride in the cached mesh: a resumed motion is the same motion
    g = fg.Graph.from_text(RELAX, cache_dir=tmp_path)
    g.evaluate("hang", steps=40)
    resumed = fg.Graph.from_text(RELAX, cache_dir=tmp_path)
    out = resumed.evaluate("hang", steps=45)
    assert resumed.stats["hang"].computed_items == 5
    cold = fg.Graph.from_text(RELAX).evaluate("hang", steps=45)
    assert out.vertices.tobytes() == cold.vertices.tobytes()
