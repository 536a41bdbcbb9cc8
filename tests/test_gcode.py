"""``export.gcode`` read back by independent parsers: pygcode (its word and modal-group
model, with our own state machine over its blocks) and LinuxCNC's rs274 interpreter where
it is installed. Rapid moves only at the safe height, depths never below the cut's, arcs
as G2/G3 whose centres are equidistant from both ends, a laser without Z."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest
from pygcode import Line

import formgraph as fg


def _part(tmp_path, **gcode):
    g = fg.Graph(out_dir=tmp_path)
    g.add("plate", "curves.rectangle", size=[60, 40], radius=5)
    g.add("hole", "nurbs.circle", radius=6, center=[12, 0, 0])
    g.add("recess", "curves.rectangle", size=[20, 20], radius=4, center=[-14, 0, 0])
    g.add("pocket", "cam.pocket", curves=["@recess"], tool_diameter=4, depth=3, step_down=1.5)
    g.add(
        "profile", "cam.profile", curves=["@plate", "@hole"], tool_diameter=4, depth=8, step_down=3
    )
    g.add("nc", "export.gcode", paths=["@pocket", "@profile"], path="part.nc", **gcode)
    return g, g.evaluate("nc")


def _run(text):
    """Every move as (code, start, end, params) from pygcode's blocks, the state ours."""
    pos = np.zeros(3)
    moves, others = [], []
    for raw in text.splitlines():
        block = Line(raw).block
        for code in block.gcodes:
            name = type(code).__name__
            params = code.get_param_dict()
            if name in ("GCodeRapidMove", "GCodeLinearMove", "GCodeArcMoveCW", "GCodeArcMoveCCW"):
                end = pos.copy()
                for k, axis in enumerate("XYZ"):
                    if axis in params:
                        end[k] = params[axis]
                moves.append((name, pos.copy(), end, params))
                pos = end
            else:
                others.append(name)
    return moves, others


def test_router_program_moves_safely_and_cuts_arcs(tmp_path):
    _, path = _part(tmp_path, safe_z=5, feed=1200, plunge=250, spindle=18000)
    text = open(path).read()
    assert text.splitlines()[1:5] == ["G21", "G90", "G17", "G94"]
    moves, others = _run(text)
    assert "GCodeStartSpindleCW" in others and others[-1] == "GCodeEndProgram"
    rapid = [m for m in moves if m[0] == "GCodeRapidMove"]
    # a rapid move either climbs to the safe height or travels at it
    for _, a, b, _ in rapid:
        assert b[2] == 5 and (a[2] == 5 or np.allclose(a[:2], b[:2]))
    cuts = [m for m in moves if m[0] != "GCodeRapidMove"]
    assert min(m[2][2] for m in cuts) == -8  # the profile's last pass, not deeper
    assert {round(m[2][2], 6) for m in cuts} == {0.0 - 1.5, -3, -6, -8}
    arcs = [m for m in cuts if "Arc" in m[0]]
    assert arcs
    for _, a, b, p in arcs:
        centre = a[:2] + [p["I"], p["J"]]
        assert np.linalg.norm(a[:2] - centre) == pytest.approx(
            np.linalg.norm(b[:2] - centre), abs=2e-4
        )
    # the hole (radius 6) cut inside by the 2 mm tool radius: arcs of radius 4
    radii = {round(float(np.hypot(p["I"], p["J"])), 3) for _, _, _, p in arcs}
    assert 4.0 in radii


def test_laser_program_has_no_z_and_switches_the_beam(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("hole", "nurbs.circle", radius=6)
    g.add("cut", "cam.profile", curves=["@hole"], tool_diameter=0.1, side="on", depth=0.1)
    g.add("nc", "export.gcode", paths="@cut", path="laser.nc", mode="laser", spindle=800)
    text = open(g.evaluate("nc")).read()
    assert " Z" not in text
    moves, others = _run(text)
    assert others.count("GCodeStartSpindleCCW") == 1 and "GCodeStopSpindle" in others
    assert "M4 S800" in text
    assert sum("Arc" in m[0] for m in moves) == 4  # the circle's four quarter arcs


@pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC's rs274 is not installed")
def test_linuxcnc_interprets_the_program_without_an_error(tmp_path):
    _, path = _part(tmp_path, spindle=12000)
    run = subprocess.run(
        ["rs274", "-g", str(path)], capture_output=True, text=True, timeout=60, cwd=tmp_path
    )
    lines = [ln for ln in run.stdout.splitlines() if ln.strip()]
    # every line of its output is a canonical machine command; an error is a line of prose
    bad = [ln for ln in lines if "N....." not in ln and ln.strip() != "executing"]
    assert not bad, bad[:3]
    assert any("ARC_FEED" in ln for ln in lines)
    traverse = [ln for ln in lines if "STRAIGHT_TRAVERSE" in ln]
    z = [float(ln.split("(")[1].split(",")[2]) for ln in traverse]
    assert set(z) == {5.0}


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"feed": 0}, r"feed.*must be positive"),
        ({"plunge": -5}, r"plunge.*must be positive"),
        ({"safe_z": -10}, r"safe_z.*safe height must be above the work \(z > 0"),
    ],
)
def test_bad_feeds_and_heights_are_located_errors(tmp_path, kwargs, message):
    with pytest.raises(fg.FormgraphError, match=message):
        _part(tmp_path, **kwargs)
    assert not (tmp_path / "part.nc").exists()


@pytest.mark.parametrize(("side", "radius"), [("outside", 3.0), ("inside", None)])
def test_a_sharp_rectangle_profile_has_its_round_corners_as_arcs(tmp_path, side, radius):
    g = fg.Graph(out_dir=tmp_path)
    g.add("plate", "curves.rectangle", size=[40, 30])
    g.add(
        "ell",
        "curves.polyline",
        points=[[0, 0, 0], [40, 0, 0], [40, 10, 0], [10, 10, 0], [10, 30, 0], [0, 30, 0]],
        closed=True,
    )
    g.add("p", "cam.profile", curves=["@plate" if radius else "@ell"], tool_diameter=6, side=side)
    g.add("nc", "export.gcode", paths="@p", path="p.nc")
    text = open(g.evaluate("nc")).read()
    moves, _ = _run(text)
    arcs = [m for m in moves if "Arc" in m[0]]
    lines = [m for m in moves if m[0] == "GCodeLinearMove" and m[1][2] == m[2][2]]
    centres = np.array([a[:2] + [p["I"], p["J"]] for _, a, _, p in arcs])
    if radius:  # outside a rectangle: four quarter arcs about its corners, four sides
        assert len(arcs) == 4 and len(lines) == 4
        assert all(m[0] == "GCodeArcMoveCCW" for m in arcs)  # the outer loop runs CCW
        corners = {(-20.0, -15.0), (20.0, -15.0), (20.0, 15.0), (-20.0, 15.0)}
        assert {tuple(np.round(c, 4)) for c in centres} == corners
    else:  # inside an L: one arc, about its inside corner, radius 3
        assert len(arcs) == 1 and len(lines) == 6
        assert centres[0] == pytest.approx([10, 10], abs=1e-4)
        radius = 3.0
    for _, a, b, _ in arcs:  # both ends on the circle of the tool's radius
        c = centres[[m[1] is a for m in arcs].index(True)]
        assert np.linalg.norm(a[:2] - c) == pytest.approx(radius, abs=1e-4)
        assert np.linalg.norm(b[:2] - c) == pytest.approx(radius, abs=1e-4)


def test_holding_tabs_lift_only_the_passes_below_their_top(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("plate", "curves.rectangle", size=[60, 40])
    g.add(
        "p",
        "cam.profile",
        curves=["@plate"],
        tool_diameter=6,
        depth=6,
        step_down=2,
        tabs=4,
        tab_width=5,
        tab_height=1.5,
    )
    g.add("nc", "export.gcode", paths="@p", path="tabs.nc")
    moves, _ = _run(open(g.evaluate("nc")).read())
    cuts = [m for m in moves if m[0] != "GCodeRapidMove" and not np.allclose(m[1], m[2])]
    assert min(m[2][2] for m in cuts) == -6  # never below the depth
    # the passes at -2 and -4 are above the tabs' top (-4.5): whole, exact arcs
    assert sum("Arc" in m[0] for m in cuts) == 2 * 4
    last = [m for m in cuts if m[1][2] in (-6, -4.5) and m[2][2] in (-6, -4.5)]
    flat = [m for m in last if m[1][2] == m[2][2]]
    ups = [m for m in last if m[2][2] > m[1][2]]
    downs = [m for m in last if m[2][2] < m[1][2]]
    # four tabs: straight up and straight down, in place
    assert len(ups) == len(downs) == 4
    assert all(np.allclose(m[1][:2], m[2][:2]) for m in ups + downs)
    length = {z: sum(np.linalg.norm(m[2][:2] - m[1][:2]) for m in flat if m[1][2] == z)
              for z in (-6, -4.5)}  # fmt: skip
    # over each tab for its width plus the tool's diameter; the whole loop as long as the
    # offset rectangle (chords of its corner arcs within the tolerance)
    assert length[-4.5] == pytest.approx(4 * (5 + 6), abs=1e-6)
    perimeter = 2 * (60 + 40) + 2 * np.pi * 3
    assert length[-6] + length[-4.5] == pytest.approx(perimeter, abs=1e-2)
