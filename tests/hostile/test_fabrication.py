"""Hostile input to the fabrication nodes (layout.nest, cam.*, export.gcode): every attack a
located error or warning, never a traceback, a hang or a file outside the output folder."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import shapely

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
        ({"sheet": [10, 10]}, r"part 0 \(20 x 20\) does not fit on the 10 x 10 sheet"),
        ({"sheet": [20 * (1 - 1e-7), 100]}, r"part 0 \(20 x 20\) does not fit"),
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


@pytest.mark.parametrize(
    ("part", "sheet", "rotations"),
    [
        ([50, 50], [50, 50], 1),
        ([50 * (1 + 1e-10), 50], [50, 50], 1),  # equal within the relative 1e-9
        ([50, 30], [30, 50], 4),  # fits after a quarter turn
        ([49.99999, 50], [50, 50], 1),  # narrower than the sheet by less than the margin
    ],
)
def test_a_part_the_size_of_the_sheet_fits_it(part, sheet, rotations):
    g = fg.Graph()
    g.add("r", "curves.rectangle", size=part)
    g.add("n", "layout.nest", curves=["@r"], sheet=sheet, spacing=0, rotations=rotations)
    assert g.evaluate("n.sheets") == 1
    area = part[0] * part[1]
    assert g.evaluate("n.utilisation") == pytest.approx(1.0, abs=1e-6)
    (placed,) = g.evaluate("n.curves")
    xy = np.asarray(placed.control_points)[:, :2]
    assert xy.min() >= -1e-6 and np.all(xy.max(axis=0) <= np.array(sheet) + 1e-6)
    sheet_box = shapely.box(0, 0, *sheet)
    assert shapely.Polygon(xy).difference(sheet_box).area <= 1e-6 * area


def test_a_disc_as_wide_as_the_sheet_fits_it():
    g = _graph()  # a circle of radius 10: exact, sampled for the nesting
    g.add("n", "layout.nest", curves=["@disc"], sheet=[20, 20])
    assert g.evaluate("n.sheets") == 1
    assert g.evaluate("n.utilisation") == pytest.approx(np.pi / 4, rel=1e-4)


def test_a_spacing_beyond_the_sheet_gives_each_part_a_sheet_and_names_the_spacing():
    g = _graph()
    g.add("d2", "nurbs.circle", radius=5, center=[40, 0, 0])
    g.add("n", "layout.nest", curves=["@disc", "@d2"], sheet=[100, 100], spacing=1e9)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert g.evaluate("n.sheets") == 2
    said = " ".join(str(w.message) for w in caught)
    assert "spacing 1e+09 is more than the sheet's diagonal" in said
    assert "nesting grid" not in said


@pytest.mark.parametrize("name", ["x.stl", "part", "part.nc.txt", "g/code.svg"])
def test_gcode_refuses_a_file_name_that_is_not_g_code(tmp_path, name):
    g = _graph(tmp_path)
    g.add("cut", "cam.profile", curves=["@disc"], tool_diameter=2)
    g.add("nc", "export.gcode", paths="@cut", path=name)
    with pytest.raises(fg.FormgraphError, match=r"input 'path'.*not a G-code file name.*\.ngc"):
        g.evaluate("nc")
    assert not list(tmp_path.rglob("*.*"))


@pytest.mark.parametrize("name", ["part.NC", "a/b.ngc", "c.gcode", "d.tap", "e.cnc", "f.gc"])
def test_gcode_takes_every_g_code_extension(tmp_path, name):
    g = _graph(tmp_path)
    g.add("cut", "cam.profile", curves=["@disc"], tool_diameter=2)
    g.add("nc", "export.gcode", paths="@cut", path=name)
    assert open(g.evaluate("nc")).read().endswith("M2\n")


@pytest.mark.parametrize("safe_z", [-1, 0])
def test_a_safe_height_at_or_under_the_work_says_it_must_be_above_it(tmp_path, safe_z):
    g = _graph(tmp_path)
    g.add("cut", "cam.profile", curves=["@disc"], tool_diameter=2)
    g.add("nc", "export.gcode", paths="@cut", path="p.nc", safe_z=safe_z)
    with pytest.raises(fg.FormgraphError, match=r"safe_z.*must be above the work \(z > 0"):
        g.evaluate("nc")
    assert not (tmp_path / "p.nc").exists()


def test_a_path_above_the_work_is_a_warning_and_no_paths_too(tmp_path):
    g = _graph(tmp_path)
    g.add("up", "geometry.transform", geometry="@disc", translate=[0, 0, 3])
    g.add("nc", "export.gcode", paths=["@up"], path="air.nc")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        text = open(g.evaluate("nc")).read()
    said = " ".join(str(w.message) for w in caught)
    assert "1 path(s) (0) run above the work, up to z = 3" in said
    assert "G1 Z3" in text  # written as asked: a dry run above the stock is allowed
    g.add("low", "export.gcode", paths=["@up"], path="low.nc", safe_z=2)
    with pytest.raises(fg.FormgraphError, match=r"path 0 reaches z = 3, not below the safe"):
        g.evaluate("low")
    g.add("none", "export.gcode", paths=[], path="none.nc")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        g.evaluate("none")
    assert "no paths to cut" in " ".join(str(w.message) for w in caught)


def test_nest_refuses_marks_on_no_part_and_takes_none():
    g = _graph()
    g.add("far", "curves.text", text="X", size=5, position=[500, 0, 0])
    g.add("n", "layout.nest", curves=["@disc"], marks=["@far"], sheet=[100, 100])
    with pytest.raises(
        fg.FormgraphError, match=r"input 'marks'.*mark 0 \(from \(5\d\d.*on no part"
    ):
        g.evaluate("n")
    g = _graph()  # no marks: an empty list back
    g.add("n", "layout.nest", curves=["@disc"], marks=[], sheet=[100, 100])
    assert g.evaluate("n.marks") == []


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"tabs": 1000}, r"input 'tabs'.*1000 tabs of .* do not fit on a loop of length"),
        ({"tabs": 10**9}, r"tabs"),
        ({"tabs": 2, "tab_height": 1}, r"tab_height.*below the depth \(1\)"),
        ({"tabs": 2, "tab_height": 0}, r"tab_height"),
        ({"tabs": 2, "tab_width": math.nan}, r"tab_width"),
        ({"tabs": -1}, r"tabs"),
    ],
)
def test_profile_refuses_tabs_that_cannot_be(kwargs, message):
    g = _graph()
    g.add("p", "cam.profile", curves=["@disc"], tool_diameter=2, **kwargs)
    with pytest.raises(fg.FormgraphError, match=message):
        g.evaluate("p")
