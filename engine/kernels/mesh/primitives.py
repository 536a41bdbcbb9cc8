"""Primitive meshes: cylinder, UV sphere, torus, plane; closed ones watertight and outward.

Every vertex lies on the exact surface, so the polygon meshes are inscribed; their volumes
have closed forms (see each function) that converge to the smooth solid's as the segment
counts grow, with a relative error below ``(2 pi / segments)**2 / 6`` per direction.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .grid import grid_faces

__all__ = ["cylinder", "plane", "sphere", "torus"]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]


def _positive(value: float, name: str) -> float:
    x = float(value)
    if not np.isfinite(x) or x <= 0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    return x


def _count(value: int, name: str, least: int) -> int:
    if int(value) != value or value < least:
        raise ValueError(f"{name} must be a whole number >= {least}, got {value!r}")
    return int(value)


def _offsets(sizes: np.ndarray) -> np.ndarray:
    fo = np.zeros(sizes.size + 1, dtype=np.int64)
    np.cumsum(sizes, out=fo[1:])
    return fo


def cylinder(
    radius: float,
    height: float,
    segments: int = 64,
    caps: bool = True,
    center: Sequence[float] = (0.0, 0.0, 0.0),
) -> MeshArrays:
    """A cylinder along z, ``segments`` quads around, centred on ``center``.

    Volume (caps on): the prism over the inscribed regular polygon,
    ``(n / 2) r**2 sin(2 pi / n) h``; relative error to ``pi r**2 h`` below
    ``(2 pi / n)**2 / 6``.

    Returns
    -------
    vertices : (2 n, 3) float64
        Bottom ring, then top ring.
    face_indices, face_offsets
        ``n`` side quads, then (with ``caps``) the top and the bottom n-gon.
    """
    r = _positive(radius, "radius")
    h = _positive(height, "height")
    n = _count(segments, "segments", 3)
    c = np.asarray(center, dtype=np.float64)
    phi = 2.0 * np.pi * np.arange(n) / n
    ring = np.stack([r * np.cos(phi), r * np.sin(phi), np.zeros(n)], axis=1)
    vertices = np.concatenate([ring - [0, 0, h / 2], ring + [0, 0, h / 2]]) + c
    j = np.arange(n)
    k = (j + 1) % n
    side = np.stack([j, k, n + k, n + j], axis=1).reshape(-1)
    parts = [side]
    sizes = [np.full(n, 4)]
    if caps:
        parts += [n + j, (-j) % n]  # top counter-clockwise from above, bottom reversed
        sizes += [np.array([n]), np.array([n])]
    return vertices, np.concatenate(parts).astype(np.int64), _offsets(np.concatenate(sizes))


def sphere(
    radius: float, segments: int = 32, center: Sequence[float] = (0.0, 0.0, 0.0)
) -> MeshArrays:
    """A UV sphere: ``segments`` around, ``max(2, segments // 2)`` bands pole to pole.

    Quads between the rings, triangle fans at the poles (one vertex each). Between rings of
    radii a and b, h apart, the band is a prismatoid of volume
    ``h (n / 2) sin(2 pi / n) (a**2 + a b + b**2) / 3``; their sum is the exact volume.

    Returns
    -------
    vertices : (2 + n (m - 1), 3) float64
        North pole, rings from north to south, south pole.
    face_indices, face_offsets
        North fan, band quads, south fan.
    """
    r = _positive(radius, "radius")
    n = _count(segments, "segments", 3)
    m = max(2, n // 2)
    c = np.asarray(center, dtype=np.float64)
    theta = np.pi * np.arange(1, m) / m
    phi = 2.0 * np.pi * np.arange(n) / n
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    rings = np.stack(
        [r * st * np.cos(phi), r * st * np.sin(phi), np.broadcast_to(r * ct, (m - 1, n))], -1
    ).reshape(-1, 3)
    vertices = np.concatenate([[[0, 0, r]], rings, [[0, 0, -r]]]) + c
    south = 1 + n * (m - 1)
    j = np.arange(n)
    k = (j + 1) % n
    north_fan = np.stack([np.zeros(n, np.int64), 1 + j, 1 + k], axis=1)
    upper = 1 + n * np.arange(m - 2)[:, None]  # first vertex of each ring but the last
    bands = np.stack([upper + j, upper + n + j, upper + n + k, upper + k], axis=-1).reshape(-1)
    last = 1 + n * (m - 2)
    south_fan = np.stack([np.full(n, south), last + k, last + j], axis=1)
    fi = np.concatenate([north_fan.reshape(-1), bands, south_fan.reshape(-1)])
    sizes = np.concatenate([np.full(n, 3), np.full(n * (m - 2), 4), np.full(n, 3)])
    return vertices, fi.astype(np.int64), _offsets(sizes)


def torus(
    major: float,
    minor: float,
    segments_u: int = 64,
    segments_v: int = 32,
    center: Sequence[float] = (0.0, 0.0, 0.0),
) -> MeshArrays:
    """A ring torus about z: ``segments_u`` around the axis, ``segments_v`` around the tube.

    Each sector between two meridian planes Delta = 2 pi / nu apart is the inscribed tube
    polygon swept between them, of volume ``sin(Delta) * R * A`` (Pappus on the sector),
    so the mesh holds exactly ``nu sin(2 pi / nu) R (nv / 2) r**2 sin(2 pi / nv)``.

    Raises
    ------
    ValueError
        ``minor >= major`` (a self-intersecting horn or spindle torus).
    """
    big = _positive(major, "major")
    small = _positive(minor, "minor")
    if small >= big:
        raise ValueError(f"minor ({small:g}) must be smaller than major ({big:g})")
    nu = _count(segments_u, "segments_u", 3)
    nv = _count(segments_v, "segments_v", 3)
    phi = 2.0 * np.pi * np.arange(nu)[:, None] / nu
    theta = 2.0 * np.pi * np.arange(nv)[None, :] / nv
    rho = big + small * np.cos(theta)
    pts = np.stack(
        np.broadcast_arrays(rho * np.cos(phi), rho * np.sin(phi), small * np.sin(theta)), -1
    )
    fi, fo = grid_faces(nu, nv, closed_u=True, closed_v=True)
    return pts.reshape(-1, 3) + np.asarray(center, dtype=np.float64), fi, fo


def plane(
    size: Sequence[float] = (1.0, 1.0),
    divisions: Sequence[int] = (1, 1),
    center: Sequence[float] = (0.0, 0.0, 0.0),
) -> MeshArrays:
    """A flat grid of quads in the xy plane facing +z, ``size`` wide, centred on ``center``.

    Returns
    -------
    vertices : ((dx + 1) (dy + 1), 3) float64
    face_indices, face_offsets
        ``dx * dy`` quads, counter-clockwise seen from +z.
    """
    sx, sy = (_positive(s, "size") for s in size)
    dx, dy = (_count(d, "divisions", 1) for d in divisions)
    x = np.linspace(-sx / 2, sx / 2, dx + 1)
    y = np.linspace(-sy / 2, sy / 2, dy + 1)
    xx, yy = np.meshgrid(x, y, indexing="ij")
    pts = np.stack([xx, yy, np.zeros_like(xx)], -1).reshape(-1, 3)
    fi, fo = grid_faces(dx + 1, dy + 1)
    return pts + np.asarray(center, dtype=np.float64), fi, fo
