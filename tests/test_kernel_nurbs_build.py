"""Tests of the NURBS kernel's constructions (formgraph.kernels.nurbs): circles and arcs,
interpolation, loft, extrusion, revolution, rotation-minimizing frames and sweep, and
their errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from geomdl import fitting
from hypothesis import given, settings
from hypothesis import strategies as st
from nurbs_shapes import T, random_curve

from formgraph.kernels import nurbs as K
from formgraph.kernels.nurbs.construct import _reflection_steps

# ------------------------------------------------------------------ circles and arcs


normals = st.tuples(*[st.floats(-1, 1) for _ in range(3)]).filter(
    lambda n: np.linalg.norm(n) > 1e-3
)


@settings(max_examples=40, deadline=None)
@given(
    normal=normals,
    radius=st.floats(0.01, 100),
    center=st.tuples(*[st.floats(-50, 50) for _ in range(3)]),
)
def test_circle_radius_is_exact_in_any_plane(normal, radius, center):
    cp, p, knots, w = K.circle(radius, center, normal)
    assert cp.shape == (9, 3) and p == 2
    pts = K.curve_evaluate(cp, p, knots, w, np.linspace(0, 1, 257))
    rel = pts - np.asarray(center)
    np.testing.assert_allclose(np.linalg.norm(rel, axis=1), radius, rtol=1e-12, atol=1e-12 * 50)
    n = np.asarray(normal) / np.linalg.norm(normal)
    assert np.abs(rel @ n).max() < 1e-12 * (radius + 50)
    np.testing.assert_allclose(pts[0], pts[-1], atol=0)


def test_circle_starts_at_plus_x_and_runs_counter_clockwise():
    cp, p, knots, w = K.circle(2.0, (1, 1, 0))
    np.testing.assert_allclose(K.curve_evaluate(cp, p, knots, w, 0.0), [3, 1, 0])
    np.testing.assert_allclose(K.curve_evaluate(cp, p, knots, w, 0.25), [1, 3, 0], atol=1e-15)
    d = K.curve_derivatives(cp, p, knots, w, np.array([0.0]), 1)[1, 0]
    assert d[1] > 0  # heading +y at +x: counter-clockwise around +z


@pytest.mark.parametrize(
    "start,end,pieces", [(0, 90, 1), (30, 200, 2), (-45, 240, 4), (10, -100, 2), (0, 360, 4)]
)
def test_arc_ends_pieces_and_radius(start, end, pieces):
    cp, p, knots, w = K.arc(1.5, start, end, (0, 0, 1), (0, 0, 1))
    assert len(cp) == 2 * pieces + 1
    ends = K.curve_evaluate(cp, p, knots, w, np.array([0.0, 1.0]))
    for pt, ang in zip(ends, (start, end), strict=True):
        a = math.radians(ang)
        np.testing.assert_allclose(pt, [1.5 * math.cos(a), 1.5 * math.sin(a), 1], atol=1e-14)
    pts = K.curve_evaluate(cp, p, knots, w, np.linspace(0, 1, 100))
    np.testing.assert_allclose(np.linalg.norm(pts[:, :2], axis=1), 1.5, rtol=1e-13)


def test_plane_frame_is_the_dxf_arbitrary_axis():
    np.testing.assert_allclose(K.plane_frame([0, 0, 1]), np.eye(3))
    f = K.plane_frame([0, 0, -1])
    np.testing.assert_allclose(f[0], [-1, 0, 0])
    f = K.plane_frame([1, 2, 3])
    np.testing.assert_allclose(f @ f.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(f) > 0


# --------------------------------------------------------------------- interpolation


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("parametrization", ["chord", "centripetal", "uniform"])
def test_interpolation_passes_through_its_points(closed, degree, parametrization):
    pts = np.random.default_rng(degree).normal(size=(9, 3))
    cp, p, knots, w = K.interpolate(pts, degree, closed, parametrization)
    K.validate_curve(cp, p, knots, w)
    u = K.interpolation_parameters(pts, closed, parametrization)
    np.testing.assert_allclose(K.curve_evaluate(cp, p, knots, w, u), pts, atol=1e-12)
    t0, t1 = knots[p], knots[len(cp)]
    assert (t0, t1) == (0.0, 1.0)  # open or closed, even or odd: starts at the first point
    ders = K.curve_derivatives(cp, p, knots, w, np.array([t0, t1]), min(p - 1, 2))
    if closed:  # closes with the continuity of the degree
        np.testing.assert_allclose(ders[:, 0], ders[:, 1], atol=1e-9 * np.abs(ders).max())
    else:
        np.testing.assert_allclose(ders[0], pts[[0, -1]], atol=1e-12)


@pytest.mark.parametrize("centripetal", [False, True])
def test_interpolation_matches_geomdl(centripetal):
    pts = np.random.default_rng(9).normal(size=(11, 3))
    ref = fitting.interpolate_curve(pts.tolist(), 3, centripetal=centripetal)
    cp, p, knots, _ = K.interpolate(
        pts, 3, parametrization="centripetal" if centripetal else "chord"
    )
    np.testing.assert_allclose(knots, ref.knotvector, atol=1e-14)
    np.testing.assert_allclose(cp, np.array(ref.ctrlpts), atol=1e-12)


def test_interpolation_degree_is_capped_by_the_count():
    pts = np.array([[0, 0, 0], [1, 1, 0.0]])
    cp, p, knots, _ = K.interpolate(pts, 3)
    assert p == 1
    assert K.interpolate(np.eye(3), 5, closed=True)[1] == 2
    assert K.interpolate(np.eye(3), 5)[1] == 2


def test_closed_interpolation_drops_a_repeated_first_point():
    pts = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [1, 0, 0.0]])
    a = K.interpolate(pts, 3, closed=True)
    b = K.interpolate(pts[:-1], 3, closed=True)
    np.testing.assert_allclose(a[0], b[0])


def test_periodic_curve_is_closed_and_smooth():
    poly = np.random.default_rng(11).normal(size=(7, 3))
    for p in (1, 2, 3, 4):
        cp, knots, w = K.periodic_curve(poly, p)
        K.validate_curve(cp, p, knots, w)
        assert knots[p] == 0 and knots[len(cp)] == 1
        d = K.curve_derivatives(cp, p, knots, w, np.array([0.0, 1.0]), p - 1)
        np.testing.assert_allclose(d[:, 0], d[:, 1], atol=1e-10 * np.abs(d).max())


# --------------------------------------------------------------------------- surfaces


def test_loft_passes_through_curves_of_different_degree_and_knots():
    rng = np.random.default_rng(12)
    curves = [
        K.circle(1.0),
        K.interpolate(rng.normal(size=(6, 3)) * 0.3 + [0, 0, 1], 3),
        (
            np.array([[1, 0, 2], [0, 1, 2], [-1, 0, 2], [0, -1, 2.0]]),
            1,
            np.array([0, 0, 1 / 3, 2 / 3, 1, 1.0]),
            None,
        ),
        K.arc(2.0, 0, 270, (0, 0, 3)),
        random_curve(rng, 5, n=8),
    ]
    surf = K.loft(curves)
    cp, pu, pv, ku, kv, w = surf
    K.validate_surface(*surf)
    assert pv == 3 and cp.shape[1] == len(curves)
    compat = K.make_compatible(curves)
    v = K.interpolation_parameters(np.stack([c[0] for c in compat]))
    for curve, vk in zip(curves, v, strict=True):
        np.testing.assert_allclose(
            K.surface_evaluate(*surf, T, vk), K.curve_evaluate(*curve, T), atol=1e-12
        )


def test_loft_of_two_curves_is_ruled_and_closed_loft_wraps():
    a, b = K.circle(1.0), K.circle(2.0, (0, 0, 1))
    surf = K.loft([a, b])
    assert surf[2] == 1
    mid = K.surface_evaluate(*surf, T, 0.5)
    np.testing.assert_allclose(
        mid, 0.5 * (K.curve_evaluate(*a, T) + K.curve_evaluate(*b, T)), atol=1e-12
    )
    rings = [
        K.circle(1.0, (3 * math.cos(x), 3 * math.sin(x), 0), (-math.sin(x), math.cos(x), 0))
        for x in np.linspace(0, 2 * np.pi, 6, endpoint=False)
    ]
    v = np.linspace(0, 1, 6, endpoint=False)  # equal spacing: the rings are congruent
    for degree_v in (2, 3, 4):
        torus = K.loft(rings, degree_v=degree_v, closed=True)
        cp, pu, pv, ku, kv, w = torus
        assert pv == degree_v and (kv[pv], kv[cp.shape[1]]) == (0.0, 1.0)
        np.testing.assert_allclose(
            K.surface_evaluate(*torus, T, 0.0), K.surface_evaluate(*torus, T, 1.0), atol=1e-12
        )
        for ring, vk in zip(rings, v, strict=True):
            np.testing.assert_allclose(
                K.surface_evaluate(*torus, T, vk), K.curve_evaluate(*ring, T), atol=1e-12
            )


def test_extrude_is_a_ruled_surface():
    curve = random_curve(np.random.default_rng(13), 3, n=6)
    surf = K.extrude(curve, (1, 2, 3))
    for v in (0.0, 0.3, 1.0):
        np.testing.assert_allclose(
            K.surface_evaluate(*surf, T, v),
            K.curve_evaluate(*curve, T) + v * np.array([1, 2, 3]),
            atol=1e-12,
        )


@pytest.mark.parametrize("angle", [360.0, 135.0, -90.0])
def test_revolve_keeps_the_profile_radii(angle):
    rng = np.random.default_rng(14)
    axis_point, axis = np.array([1.0, -2.0, 0.5]), np.array([1.0, 1.0, 2.0])
    profile = random_curve(rng, 3, n=6)
    surf = K.revolve(profile, axis_point, axis, angle)
    a = axis / np.linalg.norm(axis)
    prof = K.curve_evaluate(*profile, T) - axis_point
    pts = K.surface_evaluate(*surf, T[:, None], np.linspace(0, 1, 31)[None, :]) - axis_point
    height = prof @ a
    radius = np.linalg.norm(prof - height[:, None] * a, axis=1)
    h = pts @ a
    r = np.linalg.norm(pts - h[..., None] * a, axis=-1)
    np.testing.assert_allclose(h, np.broadcast_to(height[:, None], h.shape), atol=1e-12)
    np.testing.assert_allclose(r, np.broadcast_to(radius[:, None], r.shape), atol=1e-12)
    np.testing.assert_allclose(K.surface_evaluate(*surf, T, 0.0), prof + axis_point, atol=1e-12)
    # the far end is the profile turned by the angle (right-hand rule about the axis)
    end = K.surface_evaluate(*surf, T, 1.0) - axis_point
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    turned = prof * c + np.cross(a, prof) * s + np.outer(prof @ a, a) * (1 - c)
    np.testing.assert_allclose(end, turned, atol=1e-12)


def helix(turns=3.0, m=200, radius=2.0, pitch=1.0):
    s = np.linspace(0, 2 * np.pi * turns, m)
    x = np.stack([radius * np.cos(s), radius * np.sin(s), pitch * s / (2 * np.pi)], -1)
    t = np.stack(
        [-radius * np.sin(s), radius * np.cos(s), np.full_like(s, pitch / (2 * np.pi))], -1
    )
    return x, t


def s_bend(m=150):
    s = np.linspace(-3, 3, m)
    x = np.stack([s, np.tanh(2 * s) * 2, 0.2 * s**2], -1)
    t = np.stack([np.ones_like(s), 4 / np.cosh(2 * s) ** 2, 0.4 * s], -1)
    return x, t


@pytest.mark.parametrize("path", [helix, s_bend])
def test_rotation_minimizing_frames_do_not_flip_or_twist(path):
    x, t = path()
    f = K.rotation_minimizing_frames(x, t)
    np.testing.assert_allclose(
        np.einsum("mij,mkj->mik", f, f), np.broadcast_to(np.eye(3), f.shape), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(f), 1.0, atol=1e-12)
    # no flips: consecutive normals stay close
    assert np.min(np.sum(f[1:, 0] * f[:-1, 0], axis=1)) > 0.99
    # rotation-minimizing: the normal turns about the tangent as little as possible, so
    # its change has (almost) no component along the binormal
    dr = f[1:, 0] - f[:-1, 0]
    twist = np.abs(np.sum(dr * 0.5 * (f[1:, 1] + f[:-1, 1]), axis=1))
    assert twist.max() < 1e-3


def test_rotation_minimizing_frame_of_a_planar_curve_keeps_the_plane_normal():
    s = np.linspace(0, 4, 90)
    x = np.stack([s, np.sin(s), 0 * s], -1)
    t = np.stack([np.ones_like(s), np.cos(s), 0 * s], -1)
    f = K.rotation_minimizing_frames(x, t, initial=(0, 0, 1))
    np.testing.assert_allclose(f[:, 0], np.broadcast_to([0, 0, 1.0], (90, 3)), atol=1e-12)


def test_closed_path_frames_close_up():
    s = np.linspace(0, 2 * np.pi, 80, endpoint=False)
    # a closed curve off any plane: the transport alone would not come back to itself
    x = np.stack([np.cos(s), np.sin(s), 0.5 * np.sin(2 * s)], -1)
    t = np.stack([-np.sin(s), np.cos(s), np.cos(2 * s)], -1)
    f = K.rotation_minimizing_frames(x, t, closed=True)
    # one more step of transport from the last station returns to the first frame
    steps = _reflection_steps(
        x[-1:], t[-1:] / np.linalg.norm(t[-1]), x[:1], t[:1] / np.linalg.norm(t[0])
    )
    r_back = steps[0] @ f[-1, 0]
    # the distributed correction turns the last step by 1/80 of the holonomy only
    assert float(r_back @ f[0, 0]) > math.cos(2 * np.pi / 80)
    assert np.min(np.sum(f[1:, 0] * f[:-1, 0], axis=1)) > 0.99


@pytest.mark.parametrize("path", [helix, s_bend])
def test_sweep_keeps_the_profile_at_its_distance_from_the_path(path):
    x, t = path()
    surf = K.sweep(K.circle(0.3), x, t)
    v = K.interpolation_parameters(x)
    pts = K.surface_evaluate(*surf, np.linspace(0, 1, 40)[:, None], v[None, :])
    np.testing.assert_allclose(np.linalg.norm(pts - x[None], axis=-1), 0.3, atol=1e-12)
    # the profile's plane is normal to the path
    tn = t / np.linalg.norm(t, axis=1)[:, None]
    assert np.abs(np.einsum("umd,md->um", pts - x[None], tn)).max() < 1e-12
    # and between stations it stays close
    mid = 0.5 * (v[1:] + v[:-1])
    between = K.surface_evaluate(*surf, np.linspace(0, 1, 40)[:, None], mid[None, :])
    centre = 0.5 * (x[1:] + x[:-1])
    assert np.abs(np.linalg.norm(between - centre[None], axis=-1) - 0.3).max() < 0.01


def test_sweep_along_a_closed_path_is_periodic():
    s = np.linspace(0, 2 * np.pi, 65)
    x = np.stack([3 * np.cos(s), 3 * np.sin(s), 0.5 * np.sin(3 * s)], -1)
    t = np.stack([-3 * np.sin(s), 3 * np.cos(s), 1.5 * np.cos(3 * s)], -1)
    cp, pu, pv, ku, kv, w = surf = K.sweep(K.circle(0.5), x, t)
    a = K.surface_evaluate(*surf, T, kv[pv])
    b = K.surface_evaluate(*surf, T, kv[cp.shape[1]])
    np.testing.assert_allclose(a, b, atol=1e-12)


def test_sweep_places_the_profile_xy_plane_normal_to_the_path():
    # path straight up +z: the frame is the world's, so the profile keeps its coordinates
    x = np.stack([np.zeros(5), np.zeros(5), np.linspace(0, 4, 5)], -1)
    t = np.tile([0, 0, 1.0], (5, 1))
    profile = K.circle(1.0, (0.5, 0, 0))
    surf = K.sweep(profile, x, t)
    np.testing.assert_allclose(
        K.surface_evaluate(*surf, T, 0.0), K.curve_evaluate(*profile, T), atol=1e-12
    )


def test_construction_errors():
    with pytest.raises(ValueError, match="radius must be a positive number, got -1"):
        K.circle(-1)
    with pytest.raises(ValueError, match="normal must be a non-zero vector"):
        K.circle(1, normal=(0, 0, 0))
    with pytest.raises(ValueError, match="more than 0 and at most 360 degrees, got 10 to 10"):
        K.arc(1, 10, 10)
    with pytest.raises(ValueError, match="more than 0 and at most 360 degrees, got 0 to 400"):
        K.arc(1, 0, 400)
    with pytest.raises(ValueError, match="center must be a finite"):
        K.arc(1, 0, 90, center=(0, np.nan, 0))
    with pytest.raises(ValueError, match="points 1 and 2 coincide"):
        K.interpolate(np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0.0]]))
    with pytest.raises(ValueError, match="an open interpolating curve needs at least 2 points"):
        K.interpolate(np.zeros((1, 3)))
    with pytest.raises(ValueError, match="a closed interpolating curve needs at least 3 points"):
        K.interpolate(np.eye(3)[:2], closed=True)
    with pytest.raises(
        ValueError, match="parametrization must be one of chord, centripetal, uniform, got 'arc'"
    ):
        K.interpolate(np.eye(3), parametrization="arc")
    with pytest.raises(ValueError, match="a loft needs at least 2 curves, got 1"):
        K.loft([K.circle()])
    with pytest.raises(ValueError, match="a closed loft needs at least 3 curves, got 2"):
        K.loft([K.circle(), K.circle(2.0)], closed=True)
    with pytest.raises(ValueError, match="two consecutive curves of the loft coincide"):
        K.loft([K.circle(), K.circle(), K.circle(2.0)])
    with pytest.raises(ValueError, match="direction must be a non-zero vector"):
        K.extrude(K.circle(), (0, 0, 0))
    with pytest.raises(ValueError, match="axis must be a non-zero vector"):
        K.revolve(K.circle(), axis=(0, 0, 0))
    with pytest.raises(ValueError, match="angle must be more than 0 and at most 360"):
        K.revolve(K.circle(), angle_deg=0)
    with pytest.raises(ValueError, match="a sweep path needs at least 2 points"):
        K.sweep(K.circle(), np.zeros((1, 3)), np.ones((1, 3)))
    with pytest.raises(ValueError, match="tangents must be finite and non-zero"):
        K.sweep(K.circle(), np.eye(3), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="consecutive sweep path points coincide"):
        K.sweep(K.circle(), np.array([[0, 0, 0], [0, 0, 0], [0, 0, 1.0]]), np.ones((3, 3)))
