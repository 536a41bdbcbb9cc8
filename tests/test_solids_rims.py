"""mesh.solidify's planar rims (nodes/mesh/offset.py, kernels/mesh/solidify.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import formgraph as fg
from formgraph.geometry import Field
from formgraph.kernels.mesh.solidify import planar_rim_directions

ROOT = Path(__file__).resolve().parents[1]


def shade(planar: bool) -> tuple[fg.Mesh, fg.Mesh]:
    g = fg.load(ROOT / "graphs" / "lamp_shade.yaml")
    g.add("s", "mesh.solidify", mesh="@band_mesh", thickness=0.08, offset=-1, planar_rims=planar)
    return g.evaluate("band_mesh"), g.evaluate("s")


def test_the_shade_stands_on_z0_and_keeps_its_wall():
    band, shell = shade(True)
    assert shell.is_watertight and shell.volume > 0
    assert shell.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-12)
    bottom = np.abs(shell.vertices[:, 2]) < 1e-12
    assert bottom.sum() == 2 * (np.abs(band.vertices[:, 2]) < 1e-12).sum()  # both copies
    # the rim's inner copy is a wall's thickness from the surface, measured on the surface
    n = band.n_vertices
    back = shell.vertices[n:][np.abs(band.vertices[:, 2]) < 1e-12]
    d = np.abs(Field.from_mesh(band).evaluate(back))
    assert d == pytest.approx(np.full(len(d), 0.08), rel=0.05)


def test_without_the_option_the_rim_sinks_below_the_bed():
    _, shell = shade(False)
    assert shell.vertices[:, 2].min() < -0.01


def test_non_planar_and_flat_rims_move_along_their_normals():
    # a flat sheet: its rim lies in its own plane, so nothing may move within it
    plane = fg.Graph()
    plane.add("p", "mesh.plane", size=[2, 2], divisions=[4, 4])
    plane.add("s", "mesh.solidify", mesh="@p", thickness=0.2)
    out = plane.evaluate("s")
    assert out.is_watertight and out.volume == pytest.approx(0.8, rel=1e-9)
    v = np.array([[0, 0, 0], [1, 0, 0.5], [1, 1, 0], [0, 1, 0.5]], dtype=float)
    e = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    n = np.tile([0.0, 0.0, 1.0], (4, 1))
    np.testing.assert_array_equal(planar_rim_directions(v, e, n), n)  # a saddle: not planar
