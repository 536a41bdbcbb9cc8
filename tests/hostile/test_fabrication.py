"""Hostile input to the fabrication nodes (layout.nest, cam.*, export.gcode): every attack a
located error or warning, never a traceback, a hang or a file outside the output folder."""

from __future__ import annotations

import math

import pytest

import formgraph as fg


def _graph(tmp_path=None):
    g = fg.Graph(out_dir=tmp_path) if tmp_path else fg.Graph()
    g.add("disc", "nurbs.circle", radius=10)
    return g


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"sheet": [math.nan, 100]}, r"sheet"),
        ({"sheet": [100]}, r"sheet.*\[width, height\]"),
        ({"sheet": [1e300, 1e300]}, r"sheet .* is too large for the nesting grid"),
        ({"sheet": [1e9, 1e9]}, r"sheet .* is too large for the nesting grid"),
        ({"sheet": [10, 10]}, r"part 0 .*does not fit"),
        ({"sheet": [100, 100], "spacing": math.inf}, r"spacing"),
        ({"sheet": [100, 100], "rotations": 0}, r"rotations"),
        ({"sheet": [100, 100], "effort": 10**9}, r"effort"),
        ({"sheet": [100, 100], "tolerance": -1}, r"tolerance"),
    ],
)
def test_nest_refuses_bad_sheets_and_options(kwargs, message):
    g = _graph()
    with pytest.raises(fg.FormgraphError, match=message):
        g.add("n", "layout.nest", curves=["@disc"], **kwargs)
        g.evaluate("n")


def test_nest_refuses_nothing_and_nan_curves():
    g = fg.Graph()
    g.add("n", "layout.nest", curves=[], sheet=[100, 100])
    with pytest.raises(fg.FormgraphError, match=r"curves.*got none"):
        g.evaluate("n")
    g = fg.Graph()
    g.add("pts", "points.list", points=[[0, 0], [1, 0], [1, 0]])
    g.add("flat", "curves.polyline", points="@pts", closed=True)
    g.add("n", "layout.nest", curves=["@flat"], sheet=[100, 100])
    with pytest.raises(fg.FormgraphError, match=r"encloses no area"):
        g.evaluate("n")


def test_a_huge_nest_is_refused_by_the_budget_before_it_runs():
    g = _graph()
    g.add(
        "many",
        "geometry.transform",
        repeat={"i": 3000},
        geometry="@disc",
        translate=["=30 * i", 0, 0],
    )
    g.add("n", "layout.nest", curves="@many", sheet=[1000, 1000], effort=10000, rotations=360)
    with pytest.raises(fg.FormgraphError, match=r"budget|elements|placements"):
        g.evaluate("n")


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"tool_diameter": math.nan}, r"tool_diameter"),
        ({"tool_diameter": -3}, r"tool_diameter"),
        ({"tool_diameter": 2, "depth": math.inf}, r"depth"),
        ({"tool_diameter": 2, "depth": 1e9, "step_down": 1e-3}, r"too many|budget|passes"),
        ({"tool_diameter": 2, "stepover": 0}, r"stepover"),
        ({"tool_diameter": 2, "tolerance": math.nan}, r"tolerance"),
    ],
)
def test_pocket_refuses_bad_tools_depths_and_steps(kwargs, message):
    g = _graph()
    g.add("p", "cam.pocket", curves=["@disc"], **kwargs)
    with pytest.raises(fg.FormgraphError, match=message):
        g.evaluate("p")


def test_an_open_outline_is_refused_by_the_cam_nodes():
    g = fg.Graph()
    g.add("pts", "points.list", points=[[0, 0], [10, 0], [10, 10]])
    g.add("line", "curves.polyline", points="@pts")
    for node in ("cam.profile", "cam.pocket"):
        g.add(node, node, curves=["@line"], tool_diameter=1)
        with pytest.raises(fg.FormgraphError, match=r"curve 0 is open"):
            g.evaluate(node)


@pytest.mark.parametrize("path", ["../escape.nc", "/tmp/absolute.nc", "sub/../../x.nc"])
def test_gcode_stays_in_the_output_folder(tmp_path, path):
    out = tmp_path / "out"
    g = _graph(out)
    g.add("cut", "cam.profile", curves=["@disc"], tool_diameter=2)
    g.add("nc", "export.gcode", paths="@cut", path=path)
    with pytest.raises(fg.FormgraphError):
        g.evaluate("nc")
    assert not (tmp_path / "escape.nc").exists() and not (tmp_path / "x.nc").exists()


def test_gcode_of_no_paths_is_a_program_that_does_nothing(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("nc", "export.gcode", paths=[], path="empty.nc")
    text = open(g.evaluate("nc")).read()
    assert text.endswith("M2\n") and "\nG1 " not in text
