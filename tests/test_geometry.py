"""The geometry types: validation, immutability, pyvista conversion."""

from __future__ import annotations

import numpy as np
import pytest

import formgraph as fg


def test_points_validation():
    with pytest.raises(ValueError, match=r"shape \(2, 4\)"):
        fg.Points(np.zeros((2, 4)))
    with pytest.raises(ValueError, match="coordinate 1 is not finite"):
        fg.Points([[0, 0, 0], [np.nan, 0, 0]])
    p = fg.Points([[1, 2]])
    assert p.xyz.tolist() == [[1, 2, 0]]
    src = np.array([[1.0, 2.0, 3.0]])
    q = fg.Points(src)
    src[0, 0] = 9  # the value does not change when the caller's array does
    assert q.xyz[0, 0] == 1.0


def test_polyline_is_parametrized_by_arc_length():
    c = fg.NurbsCurve.polyline([[0, 0], [3, 0], [3, 4]])
    assert c.domain == (0.0, 7.0)
    np.testing.assert_allclose(c.evaluate(5.0), [3, 2, 0])
    np.testing.assert_allclose(
        c.evaluate(np.array([0.0, 3.0, 7.0])), [[0, 0, 0], [3, 0, 0], [3, 4, 0]]
    )
    assert not c.closed
    closed = fg.NurbsCurve.polyline([[0, 0], [1, 0], [0, 1]], closed=True)
    assert closed.closed
    assert len(closed.control_points) == 4


def test_polyline_with_repeated_points_has_no_nan():
    c = fg.NurbsCurve.polyline([[0, 0], [1, 0], [1, 0], [1, 1]])
    assert np.all(np.isfinite(c.sample(50)))


def test_mesh_validation_names_the_face():
    with pytest.raises(ValueError, match="face 1 refers to vertex 7, but there are 3 vertices"):
        fg.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2], [0, 1, 7]])
    with pytest.raises(ValueError, match="face 0 has 2 vertices"):
        fg.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1]])


def test_mesh_flat_storage_and_faces():
    m = fg.Mesh([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0]], [[0, 1, 2, 3], [1, 4, 2]])
    assert m.n_vertices == 5 and m.n_faces == 2
    assert m.face_offsets.tolist() == [0, 4, 7]
    assert [f.tolist() for f in m.faces] == [[0, 1, 2, 3], [1, 4, 2]]
    with pytest.raises(ValueError):
        m.face_indices[0] = 3


def test_to_pyvista_round_trip():
    pv = pytest.importorskip("pyvista")
    m = fg.Mesh([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0]], [[0, 1, 2, 3], [1, 4, 2]])
    poly = m.to_pyvista()
    assert isinstance(poly, pv.PolyData)
    assert poly.n_points == 5 and poly.n_cells == 2
    c = fg.NurbsCurve.polyline([[0, 0], [1, 0], [1, 1]])
    assert c.to_pyvista().n_points == 3
    assert fg.Points([[0, 0, 0], [1, 1, 1]]).to_pyvista().n_points == 2


def test_polyline_drops_points_that_add_no_length():
    c = fg.NurbsCurve.polyline(
        [[0, 0], [1, 0], [1, 0], [1, 0], [1e3, 0], [1e3 + 1e-14, 0], [1e3, 5]]
    )
    assert len(c.control_points) == 4
    np.testing.assert_allclose(c.evaluate(c.domain[1]), [1e3, 5, 0])
    with pytest.raises(ValueError, match="two distinct points"):
        fg.NurbsCurve.polyline([[1, 1], [1, 1], [1, 1]])
