"""The viewer and simulated nodes: the steps slider scrubs (back from the caches, forward
computing only the new steps) and ``node.frames`` draws every step at once."""

from __future__ import annotations

import pytest

pv = pytest.importorskip("pyvista")

import formgraph as fg  # noqa: E402
from formgraph import viewer  # noqa: E402

GROW = """\
formgraph: 1
params:
  steps: {type: int, default: 12, min: 0, max: 40}
nodes:
  circle: {type: nurbs.circle, radius: 3}
  seed: {type: curves.resample, curve: "@circle", count: 20}
  grown:
    type: curves.grow
    simulate: {state: curve, from: "@seed", steps: "=steps"}
"""


@pytest.fixture
def plotter():
    p = pv.Plotter(off_screen=True, window_size=[400, 300])
    yield p
    p.close()


def test_the_steps_slider_scrubs_from_the_cache(plotter):
    g = fg.Graph.from_text(GROW)
    session = viewer.Session(g, "grown", plotter=plotter)
    session.add_sliders()
    assert [s.name for s in session.sliders()] == ["steps"]
    assert session.on_slider("steps", 5.2)  # back: every step is cached
    st = g.stats["grown"]
    assert (st.status, st.items, st.computed_items) == ("cached", 5, 0)
    assert session.on_slider("steps", 15)  # forward: three new steps
    assert (g.stats["grown"].items, g.stats["grown"].computed_items) == (15, 3)
    drawn = session.scene.layers["grown"].parts["curves"].data.n_points
    assert drawn == len(g.evaluate("grown", steps=15).control_points)


def test_frames_draw_every_step(plotter):
    g = fg.Graph.from_text(GROW)
    session = viewer.Session(g, "grown.frames", plotter=plotter)
    ((label, value),) = session.evaluate()
    assert label == "grown.frames" and len(value) == 12
    assert value[-1].control_points.tobytes() == g.evaluate("grown").control_points.tobytes()
    assert (
        g.frames("grown", steps=3)[0].control_points.tobytes() == value[0].control_points.tobytes()
    )
    with pytest.raises(fg.GraphError, match="'seed' is not a simulated node"):
        g.frames("seed")
    with pytest.raises(fg.GraphError, match="has no output 'frames'"):
        viewer.Session(g, "seed.frames", plotter=plotter)
