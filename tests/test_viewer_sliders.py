"""The desktop viewer's slider panel and closed plotters (the studio issue's viewer fixes):
eleven sliders whose labels do not run into each other, and a session whose plotter pyvista
has closed saying so instead of failing deep in vtk."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg

pv = pytest.importorskip("pyvista")
pv.OFF_SCREEN = True

from formgraph import viewer  # noqa: E402

ELEVEN = "\n".join(
    ["formgraph: 1", "params:"]
    + [f"  p{i}_long_name: {{default: {i + 1}.0, min: 0.0, max: 20.0}}" for i in range(11)]
    + ["nodes:", "  pts:", "    type: points.circle", "    count: 12"]
    + ["    radius: =p0_long_name + p1_long_name", ""]
)


@pytest.fixture
def eleven(tmp_path):
    path = tmp_path / "eleven.yaml"
    path.write_text(ELEVEN)
    return fg.load(path)


def _title_box(rep, size):
    """The pixel box (x0, y0, x1, y1) of a slider's title and of its track."""
    width, height = size
    a = np.array(rep.GetPoint1Coordinate().GetValue()[:2]) * [width, height]
    b = np.array(rep.GetPoint2Coordinate().GetValue()[:2]) * [width, height]
    track_half = rep.GetSliderWidth() * height / 2
    title_h = rep.GetTitleHeight() * height
    return a, b, track_half, title_h


def test_eleven_sliders_keep_their_labels_apart(eleven):
    size = (1024, 768)
    p = pv.Plotter(off_screen=True, window_size=list(size))
    try:
        s = viewer.Session(eleven, plotter=p)
        s.add_sliders()
        p.render()
        reps = [s.widgets[f"p{i}_long_name"].GetRepresentation() for i in range(11)]
        # no value label over the knob (it ran into the title of the slider above); the
        # value is in the title
        assert not any(r.GetShowSliderLabel() for r in reps)
        assert reps[3].GetTitleText() == "p3_long_name = 4   (0 to 20)"
        ys = []
        for r in reps:
            a, b, half, title_h = _title_box(r, size)
            ys.append((a[1], half, title_h))
        for (y_top, half_top, title_top), (y_low, half_low, _) in zip(ys[:-1], ys[1:], strict=True):
            # the upper slider's title (below its track) ends above the lower one's knob
            assert y_top - half_top - title_top > y_low + half_low
    finally:
        p.close()


def test_slider_titles_follow_the_value(eleven):
    p = pv.Plotter(off_screen=True, window_size=[800, 600])
    try:
        s = viewer.Session(eleven, plotter=p)
        s.add_sliders()
        assert s.on_slider("p0_long_name", 7.25)
        rep = s.widgets["p0_long_name"].GetRepresentation()
        assert rep.GetTitleText() == "p0_long_name = 7.25   (0 to 20)"
        assert s.apply_params(p1_long_name=12.5)
        assert (
            s.widgets["p1_long_name"]
            .GetRepresentation()
            .GetTitleText()
            .startswith("p1_long_name = 12.5 ")
        )
    finally:
        p.close()


def test_a_closed_plotter_says_so(eleven, capsys):
    p = pv.Plotter(off_screen=True, window_size=[400, 300])
    s = viewer.Session(eleven, plotter=p)
    p.show(auto_close=True)  # off screen, pyvista closes it here
    assert s.closed()
    with pytest.raises(RuntimeError, match=r"plotter is closed.*auto_close=False"):
        s.apply_params(p0_long_name=3.0)
    with pytest.raises(RuntimeError, match="plotter is closed"):
        s.replace_graph(eleven)
    s.report("an error with no window to show it")  # no AttributeError from vtk
    assert "no window to show it" in capsys.readouterr().err
