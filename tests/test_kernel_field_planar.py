"""The flat-face check of smooth blends (engine/kernels/field/planar.py)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from formgraph.kernels.field import planar, sdf


def test_coplanar_faces_of_a_box_are_its_six_planes_and_a_sphere_has_none():
    box = trimesh.creation.box([2, 4, 6])
    n, c = planar.coplanar_faces(box.triangles)
    order = np.lexsort(n.T)
    got = np.column_stack([n, c])[order]
    want = np.array(
        [[0, 0, -1, 3], [0, -1, 0, 2], [-1, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 2], [0, 0, 1, 3]],
        float,
    )
    np.testing.assert_allclose(got, want[np.lexsort(want[:, :3].T)], atol=1e-12)
    ball = trimesh.creation.icosphere(subdivisions=2)  # 320 faces, each < 1 % of the area
    assert len(planar.coplanar_faces(ball.triangles)[0]) == 0


def test_project_lands_on_a_sphere():
    f = lambda p: sdf.sphere(p, 2.0, np.array([1.0, 0, 0]))  # noqa: E731
    p = np.random.default_rng(1).normal(size=(50, 3)) * 3
    one = planar.project(f, p, step=1e-4, iterations=1)  # the gradient's error only
    np.testing.assert_allclose(np.linalg.norm(one - [1, 0, 0], axis=1), 2.0, atol=1e-4)
    two = planar.project(f, p, step=1e-4)
    np.testing.assert_allclose(np.linalg.norm(two - [1, 0, 0], axis=1), 2.0, atol=1e-8)


def blocks(points: np.ndarray, k: float) -> tuple[np.ndarray, np.ndarray]:
    """Two unit cubes side by side on z = 0 (seam at x = 1): blended and sharp values."""
    a = sdf.box(points, np.ones(3), np.array([0.5, 0.5, 0.5]))
    b = sdf.box(points, np.ones(3), np.array([1.5, 0.5, 0.5]))
    return sdf.smooth_min(a, b, k), np.minimum(a, b)


def test_a_ridge_under_a_seam_is_found_with_its_depth_and_place():
    k = 0.4
    # where the blended surface crosses the seam's line below the bed: k / 4 deep at x = 1
    z = np.linspace(-0.2, 0, 20001)
    line = np.column_stack([np.ones_like(z), np.full_like(z, 0.5), z])
    bottom = z[np.argmin(np.abs(blocks(line, k)[0]))]
    assert bottom == pytest.approx(-k / 4, abs=1e-4)
    on_bed = np.array([[0.2, 0.5, 0.0], [1.8, 0.5, 0.0], [1.0, 0.5, bottom]])
    sharp = lambda p: blocks(p, k)[1]  # noqa: E731
    found = planar.overshoots(on_bed, sharp, [[0, 0, -1.0], [0, 0, 1.0]], [0.0, 1.0], tol=0.01)
    assert len(found) == 1
    assert found[0].excess == pytest.approx(k / 4, abs=1e-4)
    np.testing.assert_allclose(found[0].where, on_bed[2])
    assert found[0].count == 1


def test_a_fillet_in_a_corner_and_a_bump_the_blend_swallowed_are_not_reported():
    k = 0.5
    plate = lambda p: sdf.box(p, np.array([4, 4, 1.0]), np.array([0, 0, -0.5]))  # noqa: E731
    post = lambda p: sdf.cylinder(p, 0.5, 2.0, np.array([0, 0, 1.0]))  # noqa: E731
    bump = lambda p: sdf.sphere(p, 0.1, np.array([1.5, 0, 0]))  # noqa: E731
    sharp = lambda p: np.minimum(np.minimum(plate(p), post(p)), bump(p))  # noqa: E731

    def blended(p):
        return sdf.smooth_min(sdf.smooth_min(plate(p), post(p), k), bump(p), k)

    # points on the blended surface above the plate's top: in the fillet, on the post
    # (untouched by the blend), and over the small bump the blend covered whole
    rays = np.array([[0.6, 0, 0], [0.0, 0.5, 1.5], [1.5, 0, 0]])
    t = np.linspace(0, 0.5, 50001)
    pts = rays[:, None, :] + t[None, :, None] * np.array([0, 0, 1.0])
    hits = [p[np.argmin(np.abs(blended(p)))] for p in pts]
    v = np.array(hits)
    assert (v[:, 2] > 0.05).all()  # every one is past the top's plane z = 0
    found = planar.overshoots(v, sharp, [[0, 0, 1.0]], [0.0], tol=0.01)
    assert found == []
    # each alone: the post's point is untouched by the blend; the fillet's and the bump's
    # points project onto the post and the sphere, both past the plane
    assert blended(v[[1]]) == sharp(v[[1]])
    for i in range(3):
        assert planar.overshoots(v[[i]], sharp, [[0, 0, 1.0]], [0.0], 0.01) == []
    # the bed under the plate is passed nowhere: z = -1 stays the support
    assert planar.overshoots(v, sharp, [[0, 0, -1.0]], [1.0], tol=0.01) == []
