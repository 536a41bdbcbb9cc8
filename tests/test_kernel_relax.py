"""Tests of formgraph.kernels.mesh.relax: a hanging chain against the elastic catenary's
closed form (the error falls as 1 / links**2), a net symmetric under its square's
symmetries, anchors fixed bit for bit, convergence, and pressure against an inflated
octahedron's closed form."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from formgraph.kernels.mesh import relax as kr


def square_net(n: int, spacing: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    idx = np.arange(n * n).reshape(n, n)
    g = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    x = np.c_[g * spacing - spacing * (n - 1) / 2, np.zeros(n * n)]
    edges = np.r_[
        np.c_[idx[:-1].ravel(), idx[1:].ravel()], np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()]
    ]
    return x, edges, idx


def elastic_catenary(a: float, length: float, w: float, ea: float):
    """Irvine's elastic catenary between (-a, 0) and (a, 0): the point at unstretched arc
    length s from the lowest point, for a cable of unstretched ``length`` and weight ``w``
    per unstretched length."""

    def x(s: np.ndarray, h: float) -> np.ndarray:
        return h * s / ea + h / w * np.arcsinh(w * s / h)

    def y(s: np.ndarray, h: float) -> np.ndarray:
        return w * s * s / (2 * ea) + h / w * (np.sqrt(1 + (w * s / h) ** 2) - 1)

    h = brentq(lambda h: x(length / 2, h) - a, 1e-9, 1e6)
    return lambda s: (x(s, h), y(s, h))


@pytest.mark.parametrize("links", [8, 16, 32])
def test_a_hanging_chain_is_an_elastic_catenary(links: int) -> None:
    a, length, w, ea = 4.0, 10.0, 1.0, 200.0
    s = np.linspace(-length / 2, length / 2, links + 1)
    x0 = np.c_[np.linspace(-a, a, links + 1), np.zeros((links + 1, 2))]
    edges = np.c_[np.arange(links), np.arange(1, links + 1)]
    net = kr.network(
        links + 1,
        edges,
        np.full(links, length / links),
        stiffness=ea,
        load=[0.0, 0.0, -w * length / links],
        anchors=[0, links],
    )
    x, v = kr.relax(x0, net, steps=4000)
    again, _ = kr.relax(x, net, steps=1, velocity=v)
    assert np.abs(again - x).max() < 1e-9  # at rest
    cx, cy = elastic_catenary(a, length, w, ea)(s)
    err = max(np.abs(x[:, 0] - cx).max(), np.abs(x[:, 2] - x[links // 2, 2] - cy).max())
    # the point loads' error is second order: about 1.5 / links**2 here
    assert err < 2.0 / links**2
    assert err > 0.5 / links**2  # (and really there: the check sees the discretization)


def test_a_net_hangs_symmetric_with_anchors_fixed_to_the_bit() -> None:
    x0, edges, idx = square_net(9)
    x0 = x0 + np.array([0.1, 0.2, 0.3]) / 3.0  # not at the origin: the bits are not zeros
    corners = [idx[0, 0], idx[0, -1], idx[-1, 0], idx[-1, -1]]
    rest = 0.9 * np.linalg.norm(x0[edges[:, 1]] - x0[edges[:, 0]], axis=1)
    net = kr.network(len(x0), edges, rest, stiffness=10.0, load=[0, 0, -0.05], anchors=corners)
    x, v = kr.relax(x0, net, steps=1500)
    assert x[corners].tobytes() == x0[corners].tobytes()
    again, _ = kr.relax(x, net, steps=1, velocity=v)
    assert np.abs(again - x).max() < 1e-9
    z = (x[:, 2] - x0[0, 2]).reshape(9, 9)
    # the square's eight symmetries
    for image in (z[::-1], z[:, ::-1], z.T, z[::-1, ::-1].T):
        assert np.allclose(image, z, atol=1e-9)
    assert z.min() < -1.0  # it hangs
    xy = (x[:, :2] - x0[0, :2]).reshape(9, 9, 2)
    assert np.allclose(xy[::-1, :, 0], -xy[:, :, 0] + 2 * xy[4, 4, 0], atol=1e-9)


def test_pressure_inflates_an_octahedron_to_its_closed_form() -> None:
    # vertices +-r e_i; a vertex's area-weighted normal is (2/3) r**2 outward and its four
    # springs (length r sqrt 2) pull it in by 2 sqrt 2 t, t = k (r sqrt 2 - L0) / L0, so
    # (2 p / 3) r**2 - (4 k / L0) r + 2 sqrt 2 k = 0
    v = np.r_[np.eye(3), -np.eye(3)]
    faces = np.array(
        [[0, 1, 2], [1, 3, 2], [3, 4, 2], [4, 0, 2], [1, 0, 5], [3, 1, 5], [4, 3, 5], [0, 4, 5]]
    )
    edges = np.unique(np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    k, p, rest = 1.0, 0.3, np.sqrt(2.0)
    net = kr.network(6, edges, rest, stiffness=k, pressure=p, triangles=faces)
    x, _ = kr.relax(v, net, steps=2000)
    f, _ = kr.forces(x, net)
    assert np.abs(f).max() < 1e-9
    qa, qb, qc = 2 * p / 3, -4 * k / rest, 2 * np.sqrt(2) * k
    r = (-qb - np.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    assert np.linalg.norm(x, axis=1) == pytest.approx(np.full(6, r), rel=1e-9)
    assert r > 1.05  # inflated
    # the opposite pressure shrinks it
    net = kr.network(6, edges, rest, stiffness=k, pressure=-p, triangles=faces)
    assert np.linalg.norm(kr.relax(v, net, steps=2000)[0], axis=1).max() < 1.0


def test_bad_networks_are_refused() -> None:
    with pytest.raises(ValueError, match="outside"):
        kr.network(3, [[0, 3]], [1.0])
    with pytest.raises(ValueError, match="rest lengths"):
        kr.network(3, [[0, 1]], [0.0])
    with pytest.raises(ValueError, match="stiffness"):
        kr.network(3, [[0, 1]], [1.0], stiffness=-1.0)
    with pytest.raises(ValueError, match="anchor"):
        kr.network(3, [[0, 1]], [1.0], anchors=[7])
