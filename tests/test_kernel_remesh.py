"""Isotropic remeshing (engine/kernels/mesh/remesh.py): Botsch & Kobbelt, batched."""

from __future__ import annotations

import manifold3d
import numpy as np
import pytest
import trimesh

from formgraph.kernels.geometry import meshdist
from formgraph.kernels.mesh import remesh as krem
from formgraph.kernels.mesh import simplify as ksimp


def _edge_lengths(v, t):
    m = trimesh.Trimesh(v, t, process=False)
    return m.edges_unique_length


def _min_angles(v, t):
    return trimesh.Trimesh(v, t, process=False).face_angles.min(axis=1)


def _hausdorff(v, t, v0, t0):
    """Both ways, sampled at vertices and triangle centres, exact distances."""
    a = meshdist.Nearest(v0[t0]).distance(np.concatenate([v, v[t].mean(axis=1)]))
    b = meshdist.Nearest(v[t]).distance(np.concatenate([v0, v0[t0].mean(axis=1)]))
    return max(a.max(), b.max())


def test_a_sphere_gets_even_near_equilateral_triangles_closed_and_outward():
    s = trimesh.creation.icosphere(3)
    edge = 0.1
    v, t = krem.isotropic_remesh(s.vertices, s.faces, edge, iterations=8)
    m = trimesh.Trimesh(v, t, process=False)
    assert ksimp.is_closed(t) and m.is_winding_consistent and m.volume > 0
    assert m.euler_number == 2  # still a sphere
    lengths = _edge_lengths(v, t)
    assert np.median(lengths) == pytest.approx(edge, rel=0.15)
    # within the thresholds (4/5, 4/3) but what the last relaxation moved a little
    assert (lengths > 0.5 * edge).all() and (lengths < 1.6 * edge).all()
    assert np.percentile(lengths, 1) > 0.75 * edge and np.percentile(lengths, 99) < 4 / 3 * edge
    assert np.degrees(_min_angles(v, t)).min() > 25
    # on the sphere (projected onto its input) and as many vertices as the area asks
    r = np.linalg.norm(v, axis=1)
    assert np.abs(r - 1).max() < 0.01
    assert len(v) == pytest.approx(krem.vertex_estimate(s.vertices, s.faces, edge), rel=0.15)


def test_a_box_keeps_its_creases_and_corners_exactly():
    box = trimesh.creation.box([2.0, 1.0, 0.6])
    v, t = krem.isotropic_remesh(box.vertices, box.faces, 0.15, iterations=6)
    m = trimesh.Trimesh(v, t, process=False)
    assert ksimp.is_closed(t) and m.is_winding_consistent
    # the creases stay sharp: every vertex on the box's surface, the volume the box's
    assert m.volume == pytest.approx(2.0 * 1.0 * 0.6, rel=1e-9)
    assert _hausdorff(v, t, box.vertices, box.faces) < 1e-9
    for corner in box.vertices:  # the eight corners stay where they were
        assert np.linalg.norm(v - corner, axis=1).min() < 1e-12
    # the long input faces were cut into triangles of the target size
    assert np.median(_edge_lengths(v, t)) == pytest.approx(0.15, rel=0.2)


def test_a_boolean_with_sharp_creases_stays_within_a_fraction_of_the_edge():
    cut = manifold3d.Manifold.cube([2, 2, 2], center=True) - manifold3d.Manifold.sphere(
        1.3, circular_segments=32
    )
    mm = cut.to_mesh()
    v0, t0 = np.asarray(mm.vert_properties[:, :3], float), np.asarray(mm.tri_verts, np.int64)
    edge = 0.15
    v, t = krem.isotropic_remesh(v0, t0, edge, iterations=5)
    assert ksimp.is_closed(t)
    m0 = trimesh.Trimesh(v0, t0, process=False)
    m = trimesh.Trimesh(v, t, process=False)
    h = _hausdorff(v, t, v0, t0)
    assert h < 0.1 * edge
    # outward still, and the volume moved by no more than the surface times the distance
    assert m.is_winding_consistent and abs(m.volume - m0.volume) < m0.area * h
    # thin triangles are rare (the input was all long slivers)
    assert (np.degrees(_min_angles(v, t)) < 30).mean() < 0.08


def test_an_open_surface_keeps_its_boundary_in_place():
    # a wavy square sheet: the boundary is a feature, its vertices stay on the input's rim
    n = 12
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    z = 0.05 * np.sin(3 * x) * np.cos(2 * y)
    v0 = np.stack([x, y, z], -1).reshape(-1, 3)
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).reshape(-1)
    t0 = np.concatenate([np.stack([a, a + 1, a + n + 1], 1), np.stack([a, a + n + 1, a + n], 1)])
    v, t = krem.isotropic_remesh(v0, t0, 0.05, iterations=5)
    e = krem._Edges(t)
    rim = np.unique(e.ends[e.count == 1])
    p = v[rim]
    on_rim = np.isclose(p[:, 0], 0) | np.isclose(p[:, 0], 1)
    on_rim |= np.isclose(p[:, 1], 0) | np.isclose(p[:, 1], 1)
    assert on_rim.all()
    assert trimesh.Trimesh(v, t, process=False).area == pytest.approx(
        trimesh.Trimesh(v0, t0, process=False).area, rel=0.01
    )
    # one boundary loop: no hole was opened, no flap folded over
    m = trimesh.Trimesh(v, t, process=False)
    assert m.euler_number == 1 and m.is_winding_consistent


def test_bad_meshes_are_refused_with_a_reason():
    s = trimesh.creation.icosphere(1)
    flap = np.concatenate([s.faces, [[s.faces[0, 0], s.faces[0, 1], 0]]])
    flap[-1, 2] = np.setdiff1d(np.arange(len(s.vertices)), s.faces[0])[0]
    with pytest.raises(ValueError, match="more than two triangles"):
        krem.isotropic_remesh(s.vertices, flap, 0.3)
    bad = s.faces.copy()
    bad[0] = bad[0, ::-1]
    with pytest.raises(ValueError, match="consistently oriented"):
        krem.isotropic_remesh(s.vertices, bad, 0.3)


def test_the_result_is_deterministic_for_a_seed():
    s = trimesh.creation.icosphere(2)
    one = krem.isotropic_remesh(s.vertices, s.faces, 0.2, iterations=3, seed=4)
    two = krem.isotropic_remesh(s.vertices, s.faces, 0.2, iterations=3, seed=4)
    assert np.array_equal(one[0], two[0]) and np.array_equal(one[1], two[1])
