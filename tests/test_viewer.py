"""The viewer, off screen: pictures of every geometry type and example graph, sliders
re-evaluating through the cache, watch mode surviving broken edits, the gallery."""

from __future__ import annotations

import os
from collections import namedtuple
from pathlib import Path

import numpy as np
import pytest

import formgraph as fg
from formgraph.core.registry import node
from formgraph.core.types import OutputPath
from formgraph.geometry import (
    Mesh,
    NurbsCurve,
    NurbsSurface,
    ParametricCurve,
    ParametricSurface,
    Points,
)
from formgraph.kernels import nurbs
from formgraph.kernels.mesh import meshops

pv = pytest.importorskip("pyvista")
pv.OFF_SCREEN = True

from formgraph import viewer  # noqa: E402
from formgraph.viewer import gallery  # noqa: E402
from formgraph.viewer.datasets import expand  # noqa: E402
from formgraph.viewer.scene import nice_range, view_axis  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
GRAPHS = sorted((ROOT / "graphs").glob("*.yaml"))
SIZE = (400, 300)


@node("viewertest.save", version=1)
def save(points: Points, path: OutputPath, *, ctx: fg.core.registry.Context) -> str:
    """A test export: writes the number of points.

    Parameters
    ----------
    points : Points
        What to save.
    path : OutputPath
        Where.
    """
    return str(ctx.write(path, str(len(points)).encode()))


# ------------------------------------------------------------------------------ helpers


def picture(path: Path) -> np.ndarray:
    from matplotlib.image import imread

    img = imread(str(path))[..., :3].astype(np.float64)
    assert img.max() <= 1.0
    return img


def assert_not_blank(path: Path, min_cover: float = 0.3) -> None:
    """The PNG shows something: its pixels vary, and what is not background (white) spans a
    good part of the frame; coloured (geometry) pixels are there too, below the legend."""
    img = picture(path)
    h, w, _ = img.shape
    assert img.var() > 1e-3, f"{path.name}: an almost uniform picture"
    drawn = np.abs(img - 1.0).max(axis=-1) > 0.04
    ys, xs = np.nonzero(drawn)
    assert xs.size, f"{path.name}: nothing but background"
    assert (np.ptp(xs) + 1) / w > min_cover, f"{path.name}: drawing spans too little width"
    assert (np.ptp(ys) + 1) / h > min_cover, f"{path.name}: drawing spans too little height"
    colour = img.max(axis=-1) - img.min(axis=-1) > 0.2
    colour[: int(0.2 * h)] = False  # the legend's coloured text
    assert colour.mean() > 0.002, f"{path.name}: no coloured geometry in the picture"


def circle_curve(radius: float = 2.0) -> NurbsCurve:
    cp, degree, knots, weights = nurbs.circle(radius)
    return NurbsCurve(cp, degree, knots, weights)


def wavy_surface() -> NurbsSurface:
    u, v = np.meshgrid(np.linspace(0, 3, 5), np.linspace(0, 3, 4), indexing="ij")
    cp = np.stack([u, v, np.sin(u) * np.cos(v)], axis=-1)
    k5, k4 = nurbs.clamped_uniform_knots(5, 3), nurbs.clamped_uniform_knots(4, 3)
    return NurbsSurface(cp, 3, 3, k5, k4)


def box_mesh() -> Mesh:
    return Mesh(*meshops.box([2.0, 1.0, 0.5]))


def ring_graph(tmp_path: Path) -> fg.Graph:
    """count and radius reach ring and outline; the grid only depends on height."""
    g = fg.Graph(out_dir=tmp_path / "out")
    g.add_param("count", 6, min=3, max=24, doc="corners")
    g.add_param("radius", 2.0, min=0.5, max=5.0)
    g.add_param("height", 1.0, min=0.0, max=3.0)
    g.add_param("name", "ring")  # not numeric: no slider
    g.add("ring", "points.circle", count="=count", radius="=radius")
    g.add("outline", "curves.polyline", points="@ring", closed=True)
    g.add("grid", "points.grid", nx=3, ny=3, nz=2, spacing="=height")
    return g


@pytest.fixture
def plotter():
    p = pv.Plotter(off_screen=True, window_size=list(SIZE))
    yield p
    p.close()


# ---------------------------------------------------------------------- pictures


GEOMETRY = {
    "points": lambda: Points(np.random.default_rng(1).random((40, 3)) * [3, 2, 1]),
    "nurbs_curve_circle": circle_curve,
    "polyline": lambda: NurbsCurve.polyline([[0, 0, 0], [1, 1, 0.5], [2, 0, 1], [3, 1, 0]]),
    "nurbs_surface": wavy_surface,
    "mesh": box_mesh,
    "parametric_curve": lambda: ParametricCurve(
        lambda t: np.cos(t), lambda t: np.sin(t), lambda t: t / 4, (0.0, 12.0)
    ),
    "parametric_surface": lambda: ParametricSurface(
        lambda u, v: u, lambda u, v: v, lambda u, v: np.sin(3 * u) * v, (0, 2), (0, 2)
    ),
}


@pytest.mark.parametrize("kind", list(GEOMETRY))
def test_screenshot_of_each_geometry_type(kind, tmp_path):
    out = viewer.screenshot(GEOMETRY[kind](), tmp_path / "deep" / f"{kind}.png", size=SIZE)
    assert out == tmp_path / "deep" / f"{kind}.png" and out.is_file()
    assert picture(out).shape[:2] == (SIZE[1], SIZE[0])
    assert_not_blank(out)


def test_blank_detector_catches_an_empty_frame(tmp_path):
    p = pv.Plotter(off_screen=True, window_size=list(SIZE))
    p.set_background("white")
    p.screenshot(str(tmp_path / "empty.png"))
    p.close()
    with pytest.raises(AssertionError, match="uniform"):
        assert_not_blank(tmp_path / "empty.png")


@pytest.mark.parametrize("path", GRAPHS, ids=[p.stem for p in GRAPHS])
def test_screenshot_of_every_example_graph(path, tmp_path):
    g = fg.load(path, out_dir=tmp_path / "out")
    out = viewer.screenshot(g, tmp_path / f"{path.stem}.png", size=SIZE)
    assert_not_blank(out)
    assert not (tmp_path / "out").exists(), "viewing a graph must not run its exports"


def test_a_list_of_mixed_geometry_draws_each_kind(plotter):
    session = viewer.Session(
        [circle_curve(), box_mesh(), wavy_surface(), Points([[0, 0, 3]])], plotter=plotter
    )
    (layer,) = session.scene.layers.values()
    assert layer.kinds == ["meshes", "surfaces", "curves", "points"]
    assert layer.summary == "4 x geometry"


# ------------------------------------------------------------------ what is shown


def test_default_shows_the_inputs_of_exports_else_the_sinks(tmp_path):
    g = ring_graph(tmp_path)
    assert viewer.shown_nodes(g) == ["outline", "grid"]  # no exports: the sinks
    g.add("save_ring", "viewertest.save", points="@ring", path="ring.txt")
    g.add("save_grid", "viewertest.save", points="@grid", path="grid.txt")
    assert viewer.shown_nodes(g) == ["ring", "grid"]
    assert viewer.shown_nodes(g, "outline") == ["outline"]
    with pytest.raises(fg.GraphError, match="^no node 'outlin'.*did you mean 'outline'"):
        viewer.shown_nodes(g, "outlin")
    with pytest.raises(fg.GraphError, match=r"node 'ring' \(points.circle\) has no output 'xyz'"):
        viewer.shown_nodes(g, "ring.xyz")


def test_each_shown_node_has_its_colour_and_legend_entry(tmp_path, plotter):
    session = viewer.Session(ring_graph(tmp_path), ["outline", "grid", "ring"], plotter=plotter)
    layers = session.scene.layers
    assert list(layers) == ["outline", "grid", "ring"]
    assert len({layer.color for layer in layers.values()}) == 3
    legend = plotter.legend
    assert legend.GetNumberOfEntries() == 3
    assert legend.GetEntryString(1) == "grid (Points, 18)"
    assert layers["outline"].kinds == ["curves"]


def test_a_multi_output_tuple_is_one_layer_per_output(plotter):
    Pair = namedtuple("Pair", "shell path")
    assert [label for label, _ in expand("n", Pair(1, 2))] == ["n.shell", "n.path"]
    scene = viewer.Scene(plotter)
    scene.update([("n", Pair(box_mesh(), circle_curve()))])
    assert {k: v.kinds for k, v in scene.layers.items()} == {
        "n.shell": ["meshes"],
        "n.path": ["curves"],
    }


def test_a_value_that_is_not_geometry_says_so(plotter):
    scene = viewer.Scene(plotter)
    scene.update([("path", "out/x.stl")])
    assert scene.layers["path"].kinds == []
    assert "nothing to draw" in scene.layers["path"].summary


# ------------------------------------------------------------------ camera, grid


def test_flat_input_gets_a_top_view_and_3d_an_isometric_one(plotter):
    scene = viewer.Scene(plotter)
    scene.update([("c", circle_curve())])
    scene.fit_camera()
    assert plotter.camera.parallel_projection
    assert np.allclose(np.abs(plotter.camera.direction), [0, 0, 1])
    scene.update([("m", box_mesh())])
    scene.fit_camera()
    assert not plotter.camera.parallel_projection
    d = np.abs(plotter.camera.direction)
    assert np.allclose(d, d[0])  # looking along (1, 1, 1)


def test_view_axis_and_round_grid_ticks():
    assert view_axis([0, 4, 0, 2, 0, 0]) == 2
    assert view_axis([0, 4, 1, 1, 0, 3]) == 1
    assert view_axis([0, 4, 0, 2, 0, 1]) is None
    assert view_axis([1, 1, 1, 1, 1, 1]) is None  # a single point
    assert nice_range(0.0274, 0.997, 1.0) == (0.0, 1.0, 5)
    assert nice_range(-0.439, 0.878, 1.7) == (-0.5, 1.0, 4)
    assert nice_range(-2.6, 2.6, 6.0) == (-3.0, 3.0, 7)  # widened least
    assert nice_range(2.0, 2.0, 5.0) == (2.0, 2.0, 1)
    assert nice_range(0.0, 0.001, 10.0) == (0.0, 0.001, 0)  # thin: kept, no labels


# ------------------------------------------------------------------------- overlays


def test_control_polygon_and_net_toggle(plotter):
    scene = viewer.Scene(plotter)
    scene.update([("c", circle_curve()), ("s", wavy_surface())])
    polygon = scene.layers["c"].parts["polygon"]
    net = scene.layers["s"].parts["net"]
    assert polygon.data.n_points == 9 and polygon.data.n_lines == 1
    assert net.data.n_points == 20 and net.data.n_lines == 5 + 4  # rows and columns
    assert not polygon.actor.GetVisibility() and not net.actor.GetVisibility()
    assert scene.toggle("polygon") is True
    assert polygon.actor.GetVisibility() and polygon.vertex_actor.GetVisibility()
    assert not net.actor.GetVisibility()
    scene.toggle("net")
    assert net.actor.GetVisibility()
    scene.toggle("polygon")
    assert not polygon.actor.GetVisibility()
    with pytest.raises(ValueError, match="'polygon' or 'net'"):
        scene.toggle("hull")


def test_keys_toggle_overlays_and_grid(plotter):
    session = viewer.Session([circle_curve(), wavy_surface()], plotter=plotter)
    session.add_keys()
    part = session.scene.layers[""].parts["polygon"]

    def press(key):
        for callback in plotter.iren._key_press_event_callbacks[key]:
            callback()

    press("c")
    assert part.actor.GetVisibility() and session.scene.show_polygons
    press("n")
    assert session.scene.layers[""].parts["net"].actor.GetVisibility()
    assert plotter.renderer.cube_axes_actor is None  # no grid until asked for
    press("g")
    assert plotter.renderer.cube_axes_actor is not None and session.scene.show_grid
    press("g")
    assert plotter.renderer.cube_axes_actor is None and not session.scene.show_grid


# -------------------------------------------------------------------------- sliders


def test_sliders_for_ranged_numeric_params(tmp_path, plotter):
    session = viewer.Session(ring_graph(tmp_path), plotter=plotter)
    sliders = {s.name: s for s in session.sliders()}
    assert list(sliders) == ["count", "radius", "height"]
    assert sliders["count"].integer and not sliders["radius"].integer
    assert (sliders["radius"].min, sliders["radius"].max) == (0.5, 5.0)
    session.add_sliders()
    assert set(session.widgets) == {"count", "radius", "height"}
    session.add_keys()
    assert session.scene.texts()["help"].startswith("c control polygons")
    assert session.widgets["count"].GetRepresentation().GetValue() == 6


def test_slider_redraws_in_place_and_hits_the_cache(tmp_path, plotter):
    g = ring_graph(tmp_path)
    session = viewer.Session(g, ["outline", "grid", "ring"], plotter=plotter)
    session.add_sliders()
    outline = session.scene.layers["outline"].parts["curves"]
    actor, data = outline.actor, outline.data
    assert data.n_points == 7  # six corners, closed
    assert session.on_slider("count", 9.4) is True  # an int param: rounded
    assert session.params["count"] == 9
    # the same actor and dataset object, now holding the new geometry
    assert session.scene.layers["outline"].parts["curves"].actor is actor
    assert data.n_points == 10
    plotter.render()
    assert actor.GetMapper().GetInput().GetNumberOfPoints() == 10
    assert {n: s.status for n, s in g.stats.items()} == {
        "ring": "computed",
        "outline": "computed",
        "grid": "cached",  # the count does not reach it
    }
    assert session.scene.texts()["status"].startswith("graph: evaluated in ")
    assert "(2 computed, 1 cached)" in session.scene.texts()["status"]

    before = np.array(session.scene.layers["grid"].parts["points"].data.points)
    assert session.on_slider("height", 2.0)
    after = np.array(session.scene.layers["grid"].parts["points"].data.points)
    assert np.allclose(after, before * [2, 2, 2])
    assert g.stats["ring"].status == "cached" and g.stats["grid"].status == "computed"
    # a repeat of the same value does not evaluate again
    g.stats = {}
    assert session.on_slider("height", 2.0) and g.stats == {}


def test_apply_params_from_code_moves_the_slider(tmp_path, plotter):
    session = viewer.Session(ring_graph(tmp_path), plotter=plotter)
    session.add_sliders()
    assert session.apply_params(radius=3.5)
    assert session.widgets["radius"].GetRepresentation().GetValue() == 3.5


def test_failed_evaluation_shows_the_error_and_keeps_the_geometry(tmp_path, plotter, capsys):
    session = viewer.Session(ring_graph(tmp_path), ["outline"], plotter=plotter)
    data = session.scene.layers["outline"].parts["curves"].data
    assert session.apply_params(count=2) is False
    assert "param 'count': must be >= 3, got 2" in session.scene.texts()["error"]
    assert "must be >= 3" in capsys.readouterr().err
    assert data.n_points == 7 and session.params == {}
    assert session.apply_params(count=4) and "error" not in session.scene.texts()


def test_a_geometry_value_has_no_params(plotter):
    session = viewer.Session(box_mesh(), plotter=plotter)
    assert session.sliders() == []
    with pytest.raises(ValueError, match="no params"):
        session.apply_params(x=1)


# ---------------------------------------------------------------------------- watch

RING = """\
formgraph: 1
description: a ring
params:
  count: {{default: {count}, min: 3, max: 24}}
nodes:
  ring:
    type: points.circle
    count: "=count"
    radius: 2
  outline:
    type: curves.polyline
    points: "@ring"
    closed: true
  grid:
    type: points.grid
    nx: 3
    ny: 3
"""


def write(path: Path, text: str) -> None:
    path.write_text(text, encoding="utf-8")
    st = path.stat()  # a new stamp even when the clock has not moved
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))


# ------------------------------------------------------------------------ CLI, gallery


def test_cli_view_screenshot(tmp_path, capsys):
    from formgraph.cli.main import main

    f = tmp_path / "ring.yaml"
    write(f, RING.format(count=7))
    png = tmp_path / "shots" / "ring.png"
    args = ["view", str(f), "outline", "--screenshot", str(png), "--size", "320x240"]
    assert main([*args, "--set", "count=12"]) == 0
    assert_not_blank(png)
    assert picture(png).shape[:2] == (240, 320)
    assert main(["view", str(f), "nope", "--screenshot", str(png)]) == 1
    assert capsys.readouterr().err.strip() == f"{f}: no node 'nope'"


def test_show_and_watch_entry_points_off_screen(tmp_path):
    # with pyvista off screen, show() and watch() draw and return instead of blocking
    f = tmp_path / "ring.yaml"
    write(f, RING.format(count=7))
    session = viewer.show(fg.load(f), size=SIZE, count=9)
    assert session.params == {"count": 9} and set(session.widgets) == {"count"}
    watcher = viewer.watch(f, "outline", sets=["count=5"], size=SIZE)
    assert watcher.session.scene.layers["outline"].parts["curves"].data.n_points == 6


def test_gallery_renders_every_graph_and_prints_a_table(tmp_path, capsys):
    graphs = tmp_path / "graphs"
    graphs.mkdir()
    write(graphs / "ring.yaml", RING.format(count=7))
    write(graphs / "broken.yaml", RING.format(count=7).replace("curves.polyline", "nope.x"))
    out = tmp_path / "docs" / "gallery"
    code = gallery.main(["--graphs", str(graphs), "--out", str(out), "--base", str(tmp_path)])
    assert code == 1  # the broken graph
    captured = capsys.readouterr()
    assert "broken: " in captured.err and "unknown node type 'nope.x'" in captured.err
    assert captured.out.splitlines() == [
        "| Graph | What it makes | Picture |",
        "| --- | --- | --- |",
        "| [ring](graphs/ring.yaml) | a ring | ![ring](docs/gallery/ring.png) |",
    ]
    assert_not_blank(out / "ring.png")
    assert picture(out / "ring.png").shape[:2] == (480, 640)
    assert not (out / "broken.png").exists()
    # each picture records what it was drawn from: an edit of its graph makes it stale
    (graphs / "broken.yaml").unlink()
    assert gallery.stale(graphs, out) == []
    write(graphs / "ring.yaml", RING.format(count=8))
    write(graphs / "new.yaml", RING.format(count=5))
    assert gallery.stale(graphs, out) == ["new", "ring"]
    assert gallery.main(["--graphs", str(graphs), "--out", str(out), "--stale"]) == 0
    assert gallery.stale(graphs, out) == []
    assert gallery.main(["--graphs", str(graphs), "--out", str(out), "nope"]) == 1
    assert "gallery: no graph nope" in capsys.readouterr().err


def test_bool_params_get_check_boxes(plotter):
    g = fg.Graph()
    g.add_param("closed", False)
    g.add_param("n", 5, min=3, max=12)
    g.add("pts", "points.circle", count="=n", radius=2)
    g.add("outline", "curves.polyline", points="@pts", closed="=closed")
    session = viewer.Session(g, ["outline"], plotter=plotter)
    assert session.toggles() == ["closed"]
    session.add_sliders()
    assert set(session.widgets) == {"n", "closed"}
    data = session.scene.layers["outline"].parts["curves"].data
    assert data.n_points == 5  # open: five corners
    assert session.on_toggle("closed", True)
    assert session.params["closed"] is True
    assert session.scene.layers["outline"].parts["curves"].data.n_points == 6
    assert g.stats["pts"].status == "cached" and g.stats["outline"].status == "computed"
