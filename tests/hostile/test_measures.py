"""Hostile measures: what mesh.measure reports is the surface we write."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import formgraph as fg


def _warped_grid(n: int = 12) -> fg.Mesh:
    """A saddle of non-planar quads (z = 2 x y), the kind surfaces.grid makes."""
    s = np.linspace(-1, 1, n)
    x, y = np.meshgrid(s, s, indexing="ij")
    v = np.stack([x, y, 2 * x * y], -1).reshape(-1, 3)
    i = np.arange(n * n).reshape(n, n)
    quads = np.stack([i[:-1, :-1], i[1:, :-1], i[1:, 1:], i[:-1, 1:]], -1).reshape(-1, 4)
    return fg.Mesh(v, quads)


def test_the_area_of_warped_quads_is_the_area_of_the_stl_we_write(tmp_path):
    m = _warped_grid()
    g = fg.Graph(out_dir=tmp_path)
    g.add("e", "export.stl", mesh=m, path="saddle.stl")
    g.add("m", "mesh.measure", mesh=m)
    g.evaluate("e")
    written = trimesh.load(tmp_path / "saddle.stl", process=False)
    # float32 coordinates in the file: agreement to their precision, far below 3.6e-4
    assert g.evaluate("m").area == pytest.approx(written.area, rel=1e-6)
    assert m.area == pytest.approx(written.area, rel=1e-6)


def test_a_planar_concave_face_still_measures_its_exact_area():
    # an L of area 3, fanned from a reflex-free corner and from its reflex corner
    ell = [[0, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0]]
    for shift in range(6):
        face = np.roll(np.arange(6), shift)
        assert fg.Mesh(ell, [face]).area == pytest.approx(3.0)
