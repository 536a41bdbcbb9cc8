"""The viewer's shading and layouts, off screen: back faces in their own colour, smooth
shading with feature edges, face edges on coarse meshes only, framing, the scale bar, and
several nodes overlaid or side by side."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.geometry import Mesh, Points
from formgraph.kernels.mesh import meshops

pv = pytest.importorskip("pyvista")
pv.OFF_SCREEN = True

from test_viewer import (  # noqa: E402
    SIZE,
    assert_not_blank,
    box_mesh,
    circle_curve,
    picture,
    ring_graph,
)

from formgraph import viewer  # noqa: E402
from formgraph.viewer.scene import view_axis  # noqa: E402
from formgraph.viewer.style import BACK_FACE, PALETTE  # noqa: E402


@pytest.fixture
def plotter():
    p = pv.Plotter(off_screen=True, window_size=list(SIZE))
    yield p
    p.close()


# ----------------------------------------------------------------- shading, layouts


def hue_share(path: Path, colors: list[str], rows: slice = slice(None)) -> np.ndarray:
    """The share of the picture's saturated pixels nearest in hue to each of ``colors``
    (shading changes a colour's brightness, not its hue)."""
    import colorsys

    img = picture(path)[rows]
    rgb = img.reshape(-1, 3)
    sat = rgb.max(axis=1) - rgb.min(axis=1)
    rgb = rgb[sat > 0.25]
    if not len(rgb):
        return np.zeros(len(colors))
    hsv = np.array([colorsys.rgb_to_hsv(*p) for p in rgb[:: max(1, len(rgb) // 4000)]])
    refs = np.array([colorsys.rgb_to_hsv(*pv.Color(c).float_rgb)[0] for c in colors])
    d = np.abs(hsv[:, :1] - refs[None, :])
    nearest = np.minimum(d, 1 - d).argmin(axis=1)
    return np.bincount(nearest, minlength=len(colors)) / len(nearest)


def flipped(mesh: Mesh) -> Mesh:
    return Mesh(mesh.vertices, [f[::-1] for f in mesh.faces])


def two_boxes_graph() -> fg.Graph:
    g = fg.Graph()
    g.add("a", "mesh.box", size=[1, 1, 1])
    g.add("b", "mesh.box", size=[1, 1, 1], center=[3, 0, 0])
    g.add("c", "mesh.box", size=[0.5, 2, 1], center=[0, 3, 0])
    return g


def test_a_flipped_mesh_shows_the_back_face_colour(tmp_path):
    good = viewer.screenshot(box_mesh(), tmp_path / "good.png", size=SIZE)
    bad = viewer.screenshot(flipped(box_mesh()), tmp_path / "bad.png", size=SIZE)
    colours = [PALETTE[0], BACK_FACE]
    rows = slice(int(0.15 * SIZE[1]), None)  # below the legend
    front, back = hue_share(good, colours, rows)
    assert front > 0.95 and back < 0.05
    front, back = hue_share(bad, colours, rows)
    assert back > 0.95 and front < 0.05, "an inward-facing box must not look like a good one"


def test_meshes_are_smooth_shaded_with_feature_edges_kept(plotter):
    from formgraph.kernels.mesh import subdivision

    scene = viewer.Scene(plotter)
    smooth = Mesh(*subdivision.catmull_clark(*meshops.box([1.0, 1.0, 1.0]), levels=3))
    scene.update([("box", box_mesh()), ("smooth", smooth)])
    box, blob = scene.layers["box"].parts["meshes"], scene.layers["smooth"].parts["meshes"]
    assert box.actor.GetProperty().GetInterpolationAsString() == "Phong"
    assert box.data.point_data.active_normals is not None
    assert box.data.n_points == 24  # each corner split three ways: the box stays a box
    assert blob.data.n_points == smooth.n_vertices  # nothing sharp: nothing split
    assert scene.layers["box"].parts["features"].data.n_lines == 12  # the box's edges
    assert "features" not in scene.layers["smooth"].parts
    # the faces are never reordered (that would hide a wrong orientation)
    assert box.actor.GetBackfaceProperty() is not None


def test_face_edges_on_coarse_meshes_only_or_when_asked(plotter):
    from formgraph.kernels.mesh import subdivision

    fine = Mesh(*subdivision.catmull_clark(*meshops.box([1.0, 1.0, 1.0]), levels=4))
    assert fine.n_faces > 1000
    scene = viewer.Scene(plotter)
    scene.update([("coarse", box_mesh()), ("fine", fine)])

    def edges(label):
        return bool(scene.layers[label].parts["meshes"].actor.GetProperty().GetEdgeVisibility())

    assert edges("coarse") and not edges("fine")
    assert scene.toggle_edges() is True and edges("fine") and edges("coarse")
    assert scene.toggle_edges() is False and not edges("coarse")
    forced = viewer.Scene(pv.Plotter(off_screen=True, window_size=list(SIZE)), edges=True)
    forced.update([("fine", fine)])
    assert forced.layers["fine"].parts["meshes"].actor.GetProperty().GetEdgeVisibility()
    forced.plotter.close()


def test_framing_fills_the_free_part_of_the_view(plotter):
    from formgraph.viewer.frame import project

    scene = viewer.Scene(plotter)
    w, h = SIZE
    for value in (box_mesh(), circle_curve(), Points([[0, 0, 0], [10, 0.5, 0.2]])):
        scene.update([("v", value)])
        scene.fit_camera()
        x0, y0, x1, y1 = scene.free
        assert scene.free in [
            (left / w, bottom / h, 1 - right / w, 1 - top / h)
            for left, bottom, right, top in scene.margin_options(view_axis(scene.bounds()))
        ]
        free_lo, free_hi = np.array([2 * x0 - 1, 2 * y0 - 1]), np.array([2 * x1 - 1, 2 * y1 - 1])
        xy = project(scene.renderer, scene.points())
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        # clear of the legend above and of the texts and scale bar below ...
        assert (lo >= free_lo - 1e-6).all() and (hi <= free_hi + 1e-6).all()
        # ... centred there, and filling it in one direction
        assert np.allclose((lo + hi) / 2, (free_lo + free_hi) / 2, atol=0.02)
        fill = ((hi - lo) / (free_hi - free_lo)).max()
        assert fill == pytest.approx(0.92, abs=0.02), type(value).__name__


def test_scale_bar_on_drawings_and_size_line_in_model_units(plotter):
    scene = viewer.Scene(plotter)
    scene.update([("c", circle_curve(2.0))])
    scene.fit_camera()
    length = scene.scale_bar.length
    assert length is not None and length in (0.5, 1.0, 2.0)
    assert scene.texts()["size"] == "size  x 4  y 4"
    scene.update([("m", box_mesh())])
    scene.fit_camera()
    plotter.screenshot()  # and the bar follows the camera at each render
    assert scene.scale_bar.length is None  # perspective: no single scale
    assert scene.texts()["size"] == "size  x 2  y 1  z 0.5"


def test_overlay_screenshot_has_one_region_per_node(tmp_path):
    g = two_boxes_graph()
    out = viewer.screenshot(g, tmp_path / "overlay.png", ["a", "b", "c"], size=SIZE)
    assert_not_blank(out)
    shares = hue_share(out, list(PALETTE[:3]), slice(int(0.25 * SIZE[1]), None))
    assert (shares > 0.1).all(), f"every node in its own colour, got {shares}"
    # ... and each colour a region of its own: seen from (1, 1, 1) the x and y axes run to
    # opposite sides, so the box at the origin lies between those at x = 3 and y = 3
    img = picture(out)[int(0.25 * SIZE[1]) :]
    centres = []
    for color in PALETTE[:3]:
        ref = np.array(pv.Color(color).float_rgb)
        near = np.abs(img / np.maximum(img.max(axis=-1, keepdims=True), 1e-6) - ref / ref.max())
        ys, xs = np.nonzero(near.max(axis=-1) < 0.12)
        assert xs.size > 200
        centres.append(xs.mean() / SIZE[0])
    a, b, c = centres
    assert min(b, c) < a < max(b, c) and abs(b - c) > 0.3


def test_side_layout_one_titled_view_per_node_with_linked_cameras(tmp_path):
    g = fg.Graph()  # the case: a box and two subdivisions of it, compared
    g.add("a", "mesh.box", size=[1, 1, 1])
    g.add("b", "mesh.catmull_clark", mesh="@a", levels=2)
    g.add("c", "mesh.doo_sabin", mesh="@a", levels=2)
    out = viewer.screenshot(
        g, tmp_path / "side.png", ["a", "b", "c"], size=(3 * SIZE[0], SIZE[1]), layout="side"
    )
    img = picture(out)
    assert img.shape[:2] == (SIZE[1], 3 * SIZE[0])
    for i in range(3):  # each third holds its node, drawn large, in its colour
        panel = tmp_path / f"panel{i}.png"
        from matplotlib.image import imsave

        imsave(panel, img[:, i * SIZE[0] : (i + 1) * SIZE[0]])
        assert_not_blank(panel)
        shares = hue_share(panel, list(PALETTE[:3]), slice(int(0.2 * SIZE[1]), None))
        assert shares.argmax() == i and shares[i] > 0.9
    p = viewer.make_plotter(3, "side", (3 * SIZE[0], SIZE[1]), off_screen=True)
    session = viewer.Session(g, ["a", "b", "c"], plotter=p, layout="side")
    assert len(session.scenes) == 3
    assert len({id(s.renderer.GetActiveCamera()) for s in session.scenes}) == 1
    assert session.scenes[1].texts()["title"] == "b"
    assert session.scenes[1].texts()["caption"] == "mesh.catmull_clark, Mesh, 96 faces"
    assert "evaluated in" in session.scenes[0].texts()["status"]  # under the first title
    assert session.apply_params() and session.scenes[0].layers["a"].kinds == ["meshes"]
    p.close()
    with pytest.raises(ValueError, match="shape"):
        viewer.Session(g, ["a", "b"], plotter=pv.Plotter(off_screen=True), layout="side")
    with pytest.raises(ValueError, match="layout must be one of overlay, side"):
        viewer.Session(g, plotter=pv.Plotter(off_screen=True), layout="grid")


def test_side_layout_puts_the_sliders_in_a_column_of_their_own(tmp_path):
    g = ring_graph(tmp_path)
    p = viewer.make_plotter(2, "side", (900, 300), off_screen=True, controls=True)
    assert p.shape == (1, 3)
    session = viewer.Session(g, ["outline", "grid"], plotter=p, layout="side")
    session.add_sliders()
    session.add_keys()
    assert set(session.widgets) == {"count", "radius", "height"}
    column = p.renderers[2]
    assert column.GetViewport()[0] > 0.7  # the narrow last column
    assert "status" in column.actors and "help" in column.actors
    assert all(s.view_shift == 0 for s in session.scenes)  # the views keep their width
    assert session.on_slider("count", 9)
    assert session.scenes[0].layers["outline"].parts["curves"].data.n_points == 10
    p.close()


def test_fg_show_takes_several_nodes_and_a_layout():
    session = fg.show(two_boxes_graph(), ["a", "c"], layout="side", size=SIZE)
    assert [list(s.layers) for s in session.scenes] == [["a"], ["c"]]
    p = viewer.make_plotter(2, "side", SIZE, off_screen=True)
    session = viewer.Session([box_mesh(), circle_curve()], plotter=p, layout="side")
    assert [s.texts()["caption"] for s in session.scenes] == ["Mesh, 6 faces", "NurbsCurve"]
    p.close()
    session = fg.show(two_boxes_graph(), ["a", "b"], size=SIZE)
    assert list(session.scene.layers) == ["a", "b"]


def test_cli_view_several_nodes_side_by_side(tmp_path):
    from formgraph.cli.main import main

    f = tmp_path / "boxes.yaml"
    two_boxes_graph().save(f)
    png = tmp_path / "side.png"
    args = ["view", str(f), "a", "b", "--layout", "side", "--screenshot", str(png)]
    assert main([*args, "--size", "600x300", "--edges"]) == 0
    assert picture(png).shape[:2] == (300, 600)


@settings(max_examples=12, deadline=None)
@given(
    st.integers(0, 2**31 - 1),
    st.sampled_from([(1, 1, 1), (10, 1, 0.1), (0.01, 0.02, 0.0), (5, 0, 3), (1e3, 2e3, 5e2)]),
)
def test_any_cloud_is_framed_inside_the_free_rectangle(seed, scale):
    from formgraph.viewer.frame import project

    pts = np.random.default_rng(seed).normal(size=(50, 3)) * scale + [3, -2, 1]
    p = pv.Plotter(off_screen=True, window_size=list(SIZE))
    try:
        scene = viewer.Scene(p)
        scene.update([("pts", Points(pts))])
        scene.fit_camera()
        x0, y0, x1, y1 = scene.free
        xy = (project(scene.renderer, scene.points()) + 1) / 2  # as fractions of the view
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        assert lo[0] >= x0 - 1e-6 and lo[1] >= y0 - 1e-6
        assert hi[0] <= x1 + 1e-6 and hi[1] <= y1 + 1e-6
        fill = max((hi[0] - lo[0]) / (x1 - x0), (hi[1] - lo[1]) / (y1 - y0))
        assert fill == pytest.approx(0.92, abs=0.03)
    finally:
        p.close()
