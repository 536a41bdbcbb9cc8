"""Colouring by an attribute in the viewer (viewer/scene.py ``colour_by``) and
``formgraph view --color NAME`` (engine/cli/main.py)."""

from __future__ import annotations

import numpy as np
import pytest

from formgraph.geometry import Mesh, Points
from formgraph.kernels.mesh import primitives

pv = pytest.importorskip("pyvista")

from formgraph import viewer  # noqa: E402
from formgraph.cli.main import main  # noqa: E402


@pytest.fixture
def plotter():
    p = pv.Plotter(off_screen=True, window_size=[400, 300])
    yield p
    p.close()


def _sphere() -> Mesh:
    m = Mesh(*primitives.sphere(1.0, 32))
    z = m.vertices[:, 2]
    rgb = np.column_stack([(z + 1) / 2, np.zeros_like(z), 1 - (z + 1) / 2])
    return m.with_data({"height": z, "color": rgb}, {"id": np.arange(m.n_faces)})


def _mapped(session) -> list:
    scene = session.scenes[0]
    return [p.actor.mapper for layer in scene.layers.values() for p in layer.parts.values()]


def test_a_scalar_attribute_is_mapped_with_a_colour_bar(plotter):
    session = viewer.Session(_sphere(), plotter=plotter, color="height")
    mesh_mapper = _mapped(session)[0]
    assert mesh_mapper.scalar_visibility and mesh_mapper.array_name == "height"
    lo, hi = mesh_mapper.scalar_range
    assert lo == pytest.approx(-1, abs=0.01) and hi == pytest.approx(1, abs=0.01)
    assert "height" in plotter.scalar_bars


def test_a_face_attribute_and_rgb_colours(plotter):
    session = viewer.Session(_sphere(), plotter=plotter, color="id")
    assert _mapped(session)[0].array_name == "id" and "id" in plotter.scalar_bars
    other = pv.Plotter(off_screen=True, window_size=[400, 300])
    try:
        session = viewer.Session(_sphere(), plotter=other, color="color")
        mapper = _mapped(session)[0]
        assert mapper.array_name == "color" and mapper.color_mode == "direct"
        assert not other.scalar_bars
    finally:
        other.close()


def test_points_and_an_absent_attribute(plotter):
    pts = Points(np.random.default_rng(0).normal(size=(50, 3)), {"t": np.linspace(0, 1, 50)})
    session = viewer.Session(pts, plotter=plotter, color="t")
    assert _mapped(session)[0].array_name == "t"
    plain = pv.Plotter(off_screen=True, window_size=[400, 300])
    try:  # no such attribute: the layer's own colour, no bar
        session = viewer.Session(pts, plotter=plain, color="nothing")
        assert not _mapped(session)[0].scalar_visibility and not plain.scalar_bars
    finally:
        plain.close()


def test_view_color_writes_a_picture_with_the_bar(tmp_path):
    from matplotlib.image import imread

    graph = tmp_path / "g.yaml"
    graph.write_text(
        "formgraph: 1\nnodes:\n"
        "  s: {type: mesh.sphere, radius: 1}\n"
        '  h: {type: attr.set, geometry: "@s", name: h, value: "=z"}\n'
    )
    png = tmp_path / "h.png"
    assert main(["view", str(graph), "h", "--color", "h", "--screenshot", str(png)]) == 0
    image = imread(png)[..., :3]
    # the bar on the right holds viridis' ends: dark purple and yellow
    right = image[:, int(image.shape[1] * 0.85) :].reshape(-1, 3)
    assert (np.linalg.norm(right - [0.267, 0.005, 0.329], axis=1) < 0.08).any()
    assert (np.linalg.norm(right - [0.993, 0.906, 0.144], axis=1) < 0.08).any()
