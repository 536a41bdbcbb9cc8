"""The offset.marching_squares node, run through graphs (against shapely's buffers).

Every test runs on the node's default path (GEOS's buffer where it can promise the
tolerance) and again with that path declined, so the distance field and marching squares
do the same offsets.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import formgraph as fg
from formgraph.kernels.offset import buffer as kbuffer

SQUARE = [[0, 0], [4, 0], [4, 4], [0, 4]]


@pytest.fixture(autouse=True, params=["default", "marching"])
def path(request, monkeypatch):
    """The node's default path, then the marching path alone (the GEOS path declined)."""
    if request.param == "marching":

        def declined(*args, **kwargs):
            raise kbuffer.BufferDeclined("declined by the test")

        monkeypatch.setattr(kbuffer, "buffer_polylines", declined)
    return request.param


def area(curve) -> float:
    p = np.asarray(curve.control_points)[:-1]
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


def offset(*curve_nodes, **inputs):
    """A graph: each (type, inputs) curve node, all wired into one offset node."""
    g = fg.Graph()
    wires = []
    for k, (node_type, node_inputs) in enumerate(curve_nodes):
        g.add(f"c{k}", node_type, **node_inputs)
        wires.append(f"@c{k}")
    g.add("off", "offset.marching_squares", curves=wires, **inputs)
    return g, g.evaluate("off")


def polyline(points, closed=True):
    return ("curves.polyline", {"points": points, "closed": closed})


def test_square_grows_to_the_round_buffer():
    _, (loop,) = offset(polyline(SQUARE), distance=0.5)
    assert isinstance(loop, fg.NurbsCurve) and loop.degree == 1 and loop.closed
    assert np.all(np.asarray(loop.control_points)[:, 2] == 0)
    exact = 16 + 4 * 4 * 0.5 + np.pi * 0.25
    assert area(loop) == pytest.approx(exact, rel=1e-3)
    assert area(loop) > 0  # counter-clockwise


def test_polylines_are_taken_at_their_vertices():
    # A square shrunk keeps exact sharp corners at (d, d) etc.
    _, (loop,) = offset(polyline(SQUARE), distance=-1.0)
    pts = np.asarray(loop.control_points)[:, :2]
    for corner in ([1, 1], [3, 1], [3, 3], [1, 3]):
        assert np.hypot(*(pts - corner).T).min() < 1e-9


def test_curved_input_is_sampled_finely_enough():
    g = fg.Graph()
    g.add("circle", "nurbs.circle", radius=2.0)
    g.add("off", "offset.marching_squares", curves=["@circle"], distance=0.5)
    (loop,) = g.evaluate("off")
    p = np.asarray(loop.control_points)
    mid = (p[:-1] + p[1:]) / 2
    # The exact circle grows to radius 2.5: vertices and chords within 0.1 % of the extent.
    assert np.abs(np.hypot(p[:, 0], p[:, 1]) - 2.5).max() < 4e-3
    assert np.abs(np.hypot(mid[:, 0], mid[:, 1]) - 2.5).max() < 4e-3


def test_letter_with_holes_makes_concentric_paths():
    outer = [[0, 0], [6, 0], [6, 8], [0, 8]]
    hole = [[2, 2], [4, 2], [4, 6], [2, 6]]
    g, loops = offset(polyline(outer), polyline(hole), distance=-0.5)
    assert len(loops) == 2
    outer_loop, inner_loop = sorted(loops, key=lambda c: -abs(area(c)))
    assert area(outer_loop) > 0 > area(inner_loop)
    ref = shapely.Polygon(outer, [hole]).buffer(-0.5, join_style="round", quad_segs=64)
    ours = shapely.Polygon(
        np.asarray(outer_loop.control_points)[:, :2], [np.asarray(inner_loop.control_points)[:, :2]]
    )
    assert ours.symmetric_difference(ref).area < 1e-3 * ref.length * 8


def test_open_curve_gives_a_band_and_z_is_dropped():
    g = fg.Graph()
    g.add("pts", "points.list", points=[[0, 0, 5], [3, 0, 5]])
    g.add("line", "curves.polyline", points="@pts")
    g.add("off", "offset.marching_squares", curves="@line", distance=0.5)
    (loop,) = g.evaluate("off")
    assert area(loop) == pytest.approx(2 * 0.5 * 3 + np.pi * 0.25, rel=1e-3)
    assert np.all(np.asarray(loop.control_points)[:, 2] == 0)


def test_smooth_and_simplify_ports():
    _, (plain,) = offset(polyline(SQUARE), distance=0.5)
    _, (simple,) = offset(polyline(SQUARE), distance=0.5, simplify=0.05)
    _, (smooth,) = offset(polyline(SQUARE), distance=0.5, smooth=3)
    assert len(simple.control_points) < len(plain.control_points)
    assert area(simple) == pytest.approx(area(plain), rel=0.02)
    assert area(smooth) == pytest.approx(area(plain), rel=1e-3)


def test_empty_result_warns():
    g, loops = offset(polyline(SQUARE), distance=-3.0)
    assert loops == []
    assert any("empty" in w for w in g.stats["off"].warnings)


def test_cached_and_recomputed_on_change():
    g, _ = offset(polyline(SQUARE), distance=0.5)
    g.evaluate("off")
    assert g.stats["off"].status == "cached"


def test_errors_name_the_input():
    with pytest.raises(fg.NodeError, match=r"input 'distance'.*nonzero, got 0"):
        offset(polyline(SQUARE), distance=0.0)
    with pytest.raises(fg.NodeError, match=r"input 'curves'.*at least one curve"):
        g = fg.Graph()
        g.add("off", "offset.marching_squares", curves=[], distance=1.0)
        g.evaluate("off")
    with pytest.raises(fg.GraphError, match=r"offset grid cells, over the budget"):
        g = fg.Graph(budget=10_000)
        g.add("c", "curves.polyline", points=SQUARE, closed=True)
        g.add("off", "offset.marching_squares", curves=["@c"], distance=0.5, cell=0.001)
        g.evaluate("off")


@pytest.mark.parametrize("kerf", [0.1, -0.1, 0.5])
def test_offset_of_an_offset_node(kerf):
    # The nameplate's chain: a rounded plate (an offset), then a kerf (an offset of it).
    g = fg.Graph()
    g.add("plate", "curves.polyline", points=[[0, 0], [80, 0], [80, 30], [0, 30]], closed=True)
    g.add("round", "offset.marching_squares", curves=["@plate"], distance=5)
    g.add("kerf", "offset.marching_squares", curves=["@round"], distance=kerf)
    (loop,) = g.evaluate("kerf")
    reference = shapely.box(0, 0, 80, 30).buffer(5 + kerf, quad_segs=64)
    ours = shapely.Polygon(np.asarray(loop.control_points)[:-1, :2])
    assert ours.symmetric_difference(reference).area <= 1e-3 * 90 * reference.length
