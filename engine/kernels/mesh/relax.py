"""Form finding of spring networks by dynamic relaxation, on plain arrays.

The network is a set of vertices joined by edges (springs); it moves toward the equilibrium
of the springs' tensions, a load on each vertex (gravity: a hanging net; turned upside
down, a vault in pure compression) and a pressure on its faces (the inflation of a closed
mesh), with some vertices (the anchors) held fixed.

Dynamic relaxation (Day 1965; Barnes, "Form finding and analysis of tension structures by
dynamic relaxation", 1999): every vertex gets a fictitious mass from the stiffness of its
springs, which makes the unit time step stable, and a velocity that integrates the
out-of-balance force. Kinetic damping: whenever the kinetic energy passes a peak, the
velocities are zeroed, which takes the network to rest far sooner than viscous damping.
All of it is numpy over every edge and vertex at once; anchors never move (their
coordinates are copied, bit for bit).

A spring's tension is ``stiffness * (length - rest) / rest`` (``stiffness`` is the force per
unit strain, EA for a bar), pulling its ends together when stretched and apart when
compressed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Network", "network", "relax", "forces", "vertex_normals_area"]


@dataclass(frozen=True)
class Network:
    """What stays the same from step to step: topology, rest lengths, stiffness, loads.

    Attributes
    ----------
    edges : (e, 2) int64
    rest : (e,) float, > 0
    stiffness : (e,) float, >= 0
    load : (n, 3) float
    pressure : float
    triangles : (t, 3) int64
        A fan triangulation of the faces (for the pressure), or empty.
    free : (n,) bool
        False at the anchors.
    """

    edges: np.ndarray
    rest: np.ndarray
    stiffness: np.ndarray
    load: np.ndarray
    pressure: float
    triangles: np.ndarray
    free: np.ndarray


def fan_triangles(face_indices: np.ndarray, face_offsets: np.ndarray) -> np.ndarray:
    """The fan triangles (c0, ci, ci+1) of every face; their area vectors sum to each
    face's vector area whatever corner the fan starts at."""
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    sizes = np.diff(fo)
    per = np.maximum(sizes - 2, 0)
    face = np.repeat(np.arange(sizes.size), per)
    k = np.arange(face.size) - np.repeat(np.cumsum(per) - per, per)
    start = fo[:-1][face]
    return np.stack([fi[start], fi[start + k + 1], fi[start + k + 2]], axis=1)


def network(
    n_vertices: int,
    edges: np.ndarray,
    rest: np.ndarray,
    *,
    stiffness: float | np.ndarray = 1.0,
    load: np.ndarray | None = None,
    pressure: float = 0.0,
    triangles: np.ndarray | None = None,
    anchors: np.ndarray | None = None,
) -> Network:
    """Check and gather the parts of a spring network.

    Parameters
    ----------
    n_vertices : int
    edges : (e, 2) int
    rest : (e,) float
        Rest lengths, > 0.
    stiffness : float or (e,) float
        Force per unit strain of each spring, >= 0.
    load : (3,) or (n, 3) float, optional
        The force on each vertex (one vector for all, or one per vertex).
    pressure : float
        Force per unit area along the faces' normals (positive inflates an outward mesh).
    triangles : (t, 3) int, optional
        The faces the pressure acts on (see :func:`fan_triangles`).
    anchors : (a,) int, optional
        Vertices held fixed.

    Raises
    ------
    ValueError
        An index out of range, a rest length not positive, a stiffness negative, or a
        value not finite.
    """
    n = int(n_vertices)
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if e.size and (e.min() < 0 or e.max() >= n):
        raise ValueError(f"an edge joins a vertex outside 0..{n - 1}")
    r = np.broadcast_to(np.asarray(rest, dtype=np.float64), (len(e),)).copy()
    if not (np.isfinite(r).all() and (r > 0).all()):
        raise ValueError("rest lengths must be finite and > 0")
    k = np.broadcast_to(np.asarray(stiffness, dtype=np.float64), (len(e),)).copy()
    if not (np.isfinite(k).all() and (k >= 0).all()):
        raise ValueError("stiffness must be finite and >= 0")
    f = np.zeros((n, 3)) if load is None else np.asarray(load, dtype=np.float64)
    f = np.broadcast_to(f, (n, 3)).copy()
    if not np.isfinite(f).all() or not np.isfinite(pressure):
        raise ValueError("load and pressure must be finite")
    t = np.zeros((0, 3), np.int64) if triangles is None else np.asarray(triangles, np.int64)
    free = np.ones(n, dtype=bool)
    if anchors is not None:
        a = np.asarray(anchors, dtype=np.int64).reshape(-1)
        if a.size and (a.min() < -n or a.max() >= n):
            raise ValueError(f"an anchor is not a vertex index in 0..{n - 1}")
        free[a] = False
    return Network(e, r, k, f, float(pressure), t, free)


def vertex_normals_area(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals: a third of the vector area of every triangle at a
    vertex (the gradient of the enclosed volume, for a closed outward mesh)."""
    out = np.zeros_like(vertices)
    if len(triangles) == 0:
        return out
    a, b, c = (vertices[triangles[:, i]] for i in range(3))
    area = np.cross(b - a, c - a) / 6.0  # half the cross product, a third to each corner
    for i in range(3):
        for axis in range(3):
            out[:, axis] += np.bincount(triangles[:, i], area[:, axis], minlength=len(out))
    return out


def forces(vertices: np.ndarray, net: Network) -> tuple[np.ndarray, np.ndarray]:
    """The out-of-balance force on every vertex (zero at anchors) and every vertex's
    stiffness (the sum of its springs' axial and geometric stiffness)."""
    x = vertices
    i, j = net.edges[:, 0], net.edges[:, 1]
    d = x[j] - x[i]
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    safe = np.where(length > 0, length, 1.0)
    tension = net.stiffness * (length - net.rest) / net.rest
    pull = d * (tension / safe)[:, None]
    n = len(x)
    f = net.load.copy()
    if net.pressure != 0.0:
        f += net.pressure * vertex_normals_area(x, net.triangles)
    for axis in range(3):
        f[:, axis] += np.bincount(i, pull[:, axis], minlength=n)
        f[:, axis] -= np.bincount(j, pull[:, axis], minlength=n)
    # a spring's stiffness along itself (EA / rest) and across (tension / length)
    s = net.stiffness / net.rest + np.abs(tension) / safe
    stiff = np.bincount(i, s, minlength=n) + np.bincount(j, s, minlength=n)
    f[~net.free] = 0.0
    return f, stiff


def relax(
    vertices: np.ndarray,
    net: Network,
    steps: int = 1,
    velocity: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Run ``steps`` steps of dynamic relaxation with kinetic damping.

    Parameters
    ----------
    vertices : (n, 3) float
    net : Network
    steps : int
    velocity : (n, 3) float, optional
        The velocities to start from (at rest when omitted).

    Returns
    -------
    vertices, velocity : (n, 3) float
        New arrays; anchors' rows are the input's, bit for bit.
    """
    x0 = np.asarray(vertices, dtype=np.float64)
    x = x0.copy()
    v = np.zeros_like(x) if velocity is None else np.array(velocity, dtype=np.float64)
    fixed = ~net.free
    energy = np.inf
    floor = None
    for _ in range(int(steps)):
        f, stiff = forces(x, net)
        if floor is None:
            floor = _floor(net, stiff)
        # the fictitious mass: the largest stable step of a vertex's springs with dt = 1
        mass = stiff + floor
        v += f / mass[:, None]
        v[fixed] = 0.0
        e = float(np.einsum("ij,ij,i->", v, v, mass))
        if e < energy and np.isfinite(energy):
            # past the peak of kinetic energy: stop, and start again from rest
            v[:] = 0.0
            energy = np.inf
            continue
        energy = e
        x += v
    x[fixed] = x0[fixed]
    return x, v


def _floor(net: Network, stiff: np.ndarray) -> np.ndarray:
    """A mass for vertices without springs (a loose vertex under load still moves, by the
    load over the network's typical stiffness, not by an infinite step)."""
    typical = float(np.median(stiff[stiff > 0])) if (stiff > 0).any() else 1.0
    return np.where(stiff > 0, 0.0, typical)
