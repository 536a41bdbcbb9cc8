"""Closed solids from planar regions: linear extrusion (with twist and scale) and revolution.

A region comes as its boundary rings in the plane: ``xy (N, 2)`` ring after ring, each
without its closing point, ``offsets`` (ring i is ``xy[offsets[i]:offsets[i + 1]]``) and
``hole``, outer rings counter-clockwise and their holes clockwise after them (as
:func:`formgraph.kernels.curves.regions.rings_of` gives them). Every solid made here is
closed, outward and consistently wound by construction: each ring edge makes side faces
that run it in one direction and its caps run it in the other.

- :func:`cap_triangles`: the region as triangles on its own vertices, no point added
  (mapbox_earcut per polygon, its answer checked; where it is not a tiling, manifold3d's
  triangulator, which always returns a triangulation running the input's edges);
- :func:`extrude`: OpenSCAD's ``linear_extrude``: the region swept along +z while it turns by
  ``twist`` and is scaled linearly to ``scale`` at the top (scale applied after the turn, as
  manifold3d's ``CrossSection.extrude``); a scale of 0 ends every ring in an apex (a cone);
- :func:`revolve`: the region in the (r, z) half plane turned about the z axis; points on
  the axis are one vertex each (no face of zero area), edges on the axis make no faces;
  a partial turn is capped at both ends;
- :func:`twist_slices`, :func:`turn_segments`: how many steps keep a turning point's chords
  within a tolerance (the sagitta ``r (1 - cos(a / 2))`` of a step of angle ``a``).
"""

from __future__ import annotations

import math

import numpy as np

from .measure import next_corner
from .polygon import tiling

__all__ = [
    "MAX_TWIST_STEP",
    "cap_triangles",
    "extrude",
    "refine_edges",
    "revolve",
    "turn_segments",
    "twist_slices",
]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]

#: the largest turn between two slices of a twisted extrusion (degrees): past it the side
#: triangles between slices cut across the solid instead of following its surface
MAX_TWIST_STEP = 45.0


def cap_triangles(xy: np.ndarray, offsets: np.ndarray, hole: np.ndarray) -> np.ndarray:
    """Counter-clockwise triangles (t, 3) of the region, indices into ``xy``.

    Each polygon (an outer ring and the holes after it) goes to mapbox_earcut (Mapbox's
    earcut: ear clipping with the holes bridged in, z-order hashed); its answer is taken when
    it tiles the polygon (:func:`~.polygon.tiling`: the ``n + 2 h - 2`` triangles of a
    tiling of ``n`` points and ``h`` holes, none turned clockwise, their edges and the
    rings' pairing up exactly). Otherwise (rings that touch,
    where earcut may drop or overlap triangles) the polygon goes to manifold3d's
    ``triangulate``, which always returns triangles running the input's edges.
    """
    import mapbox_earcut

    xy = np.ascontiguousarray(xy, dtype=np.float64)
    off = np.asarray(offsets, dtype=np.int64)
    starts = np.flatnonzero(~np.asarray(hole, dtype=bool))
    bounds = np.append(starts, len(off) - 1)
    out = []
    for a, b in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):  # per polygon
        lo, hi = int(off[a]), int(off[b])
        pts = xy[lo:hi]
        ends = (off[a + 1 : b + 1] - lo).astype(np.uint32)
        tri = tiling(pts, ends, mapbox_earcut.triangulate_float64(pts, ends))
        if tri is None:
            tri = _manifold_triangles(pts, ends)
        out.append(tri + lo)
    return np.concatenate(out) if out else np.zeros((0, 3), np.int64)


def _manifold_triangles(pts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    import manifold3d

    rings = np.split(pts, ends[:-1].astype(np.int64))
    tri = np.asarray(manifold3d.triangulate([np.ascontiguousarray(r) for r in rings]))
    return tri.astype(np.int64).reshape(-1, 3)


def twist_slices(twist_degrees: float, radius: float, tolerance: float) -> int:
    """Slices of a twisted extrusion that keep every side chord within ``tolerance`` of the
    helix its point follows at ``radius`` (the largest distance from the axis): a step of
    angle ``a`` leaves a sagitta ``radius (1 - cos(a / 2))``; never more than
    :data:`MAX_TWIST_STEP` per slice."""
    turn = abs(math.radians(twist_degrees))
    if turn == 0.0:
        return 1
    step = math.radians(MAX_TWIST_STEP)
    if 0 < tolerance < radius:
        step = min(step, 2.0 * math.acos(1.0 - tolerance / radius))
    return max(1, math.ceil(turn / step - 1e-9))


def refine_edges(
    xy: np.ndarray,
    offsets: np.ndarray,
    twist: float,
    scale: tuple[float, float],
    slices: int,
    tolerance: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The rings with points added along their edges, so that the side of a twisted or
    unequally scaled extrusion stays within ``tolerance`` of the exact solid.

    Between two slices an edge a -> b sweeps a bilinear patch (the edge at the lower
    level, the same edge turned and scaled at the upper); its two triangles leave that
    patch by a quarter of the patch's twist ``(M' - M)(b - a)`` across it, M the map of a
    level. Only the part of ``M' - M`` that does not move points along the edge counts:
    the turn (``max(sx, sy) * twist / slices`` radians) and the unequal part of the scale
    (``|sx - sy| / 2 / slices``; an equal scale keeps each side in its plane). An edge is
    cut into ``ceil(|M' - M| |b - a| / (4 tolerance))`` equal pieces.

    Returns
    -------
    xy, offsets
        The refined rings (the input's points kept, in order).
    """
    sx, sy = scale
    step = (abs(sx - sy) / 2 + max(1.0, sx, sy) * abs(math.radians(twist))) / slices
    xy = np.asarray(xy, dtype=np.float64)
    off = np.asarray(offsets, dtype=np.int64)
    if step == 0.0 or not tolerance > 0:
        return xy, off
    nxt = next_corner(off)
    length = np.hypot(*(xy[nxt] - xy).T)
    pieces = np.maximum(1, np.ceil(step * length / (4.0 * tolerance) - 1e-9)).astype(np.int64)
    if np.all(pieces == 1):
        return xy, off
    start = np.repeat(np.arange(len(xy)), pieces)
    f = np.arange(len(start)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    f = f / pieces[start]
    out = xy[start] + f[:, None] * (xy[nxt[start]] - xy[start])
    out[f == 0] = xy[start[f == 0]]  # the input's points exactly
    ring_points = np.add.reduceat(pieces, off[:-1])
    return out, np.concatenate([[0], np.cumsum(ring_points)])


def turn_segments(angle_degrees: float, radius: float, tolerance: float) -> int:
    """Segments of a revolution whose chords stay within ``tolerance`` of the circle of
    ``radius`` each point turns on: at least 3 for a whole turn (1 for a part), at most
    12 degrees each."""
    turn = math.radians(angle_degrees)
    step = math.radians(12.0)
    if 0 < tolerance < radius:
        step = min(step, 2.0 * math.acos(1.0 - tolerance / radius))
    least = 3 if angle_degrees >= 360.0 else 1
    return max(least, math.ceil(turn / step - 1e-9))


def extrude(
    xy: np.ndarray,
    offsets: np.ndarray,
    hole: np.ndarray,
    height: float,
    twist: float = 0.0,
    scale: tuple[float, float] = (1.0, 1.0),
    slices: int = 1,
    bottom: float = 0.0,
    caps: np.ndarray | None = None,
) -> MeshArrays:
    """The region extruded along +z from ``z = bottom`` to ``bottom + height``.

    Level k of ``slices + 1`` (``t = k / slices``) holds every ring point p turned by
    ``t twist`` degrees about the z axis, then scaled by ``1 + t (scale - 1)`` in x and y
    (OpenSCAD's ``linear_extrude``, the scale after the turn as manifold3d has it). Sides
    between levels are quads where they are planar (no twist, equal scales: each quad
    lies in the plane of its edge and the apex of the frustum), else two triangles each.
    A scale of (0, 0) ends each ring in one apex vertex on the axis.

    Parameters
    ----------
    xy : (N, 2) float
    offsets : (r + 1,) int
    hole : (r,) bool
        The region's rings (see the module docstring).
    height : float
        > 0.
    twist : float
        Degrees, counter-clockwise seen from +z.
    scale : (sx, sy) float
        Both > 0, or both 0.
    slices : int
        Levels between bottom and top, >= 1.
    bottom : float
        z of the bottom cap.
    caps : (t, 3) int, optional
        :func:`cap_triangles` of the region, if the caller has them.

    Returns
    -------
    vertices, face_indices, face_offsets
        A closed, outward mesh.
    """
    xy = np.asarray(xy, dtype=np.float64)
    off = np.asarray(offsets, dtype=np.int64)
    n, r = len(xy), len(off) - 1
    sx, sy = (float(s) for s in scale)
    cone = sx == 0.0 and sy == 0.0
    levels = slices + 1
    t = np.arange(levels) / slices
    turn = np.radians(twist) * t
    kx, ky = 1.0 + t * (sx - 1.0), 1.0 + t * (sy - 1.0)
    c, s = np.cos(turn)[:, None], np.sin(turn)[:, None]
    x, y = xy[:, 0][None, :], xy[:, 1][None, :]
    ring_levels = levels - 1 if cone else levels
    v = np.empty((ring_levels, n, 3))
    v[..., 0] = (kx[:, None] * (c * x - s * y))[:ring_levels]
    v[..., 1] = (ky[:, None] * (s * x + c * y))[:ring_levels]
    v[..., 2] = (bottom + height * t)[:ring_levels, None]
    v = v.reshape(-1, 3)
    if cone:
        apex = np.zeros((r, 3))
        apex[:, 2] = bottom + height
        v = np.concatenate([v, apex])
    j = np.arange(n)
    nxt = next_corner(off)
    k = np.arange(slices)[:, None]
    a, b = k * n + j, k * n + nxt
    d, e = a + n, b + n  # the same points one level up
    if cone:  # the last band runs to each ring's apex
        ring = np.repeat(np.arange(r), np.diff(off))
        apex_id = ring_levels * n + ring
        d[-1], e[-1] = apex_id, apex_id
    planar = twist == 0.0 and sx == sy
    sides: list[tuple[np.ndarray, int]] = []
    full = slice(None, -1) if cone else slice(None)
    if planar:
        sides.append((np.stack([a[full], b[full], e[full], d[full]], axis=-1).reshape(-1), 4))
    else:
        quads = np.stack([a[full], b[full], e[full], a[full], e[full], d[full]], axis=-1)
        sides.append((quads.reshape(-1), 3))
    if cone:
        sides.append((np.stack([a[-1], b[-1], d[-1]], axis=-1).reshape(-1), 3))

    def build(tri: np.ndarray) -> MeshArrays:
        parts = list(sides)
        parts.append((tri[:, [0, 2, 1]].reshape(-1), 3))  # bottom, facing -z
        if not cone:
            parts.append(((tri + slices * n).reshape(-1), 3))  # top, facing +z
        return v, *_faces(parts)

    return build(cap_triangles(xy, off, hole) if caps is None else caps)


def revolve(
    rz: np.ndarray,
    offsets: np.ndarray,
    hole: np.ndarray,
    angle: float = 360.0,
    segments: int = 64,
    caps: np.ndarray | None = None,
) -> MeshArrays:
    """The region of the (r, z) half plane turned about the z axis by ``angle`` degrees.

    Point (r, z) of the region goes to ``(r cos a, r sin a, z)`` for ``a`` from 0 to
    ``angle`` in ``segments`` equal steps; each ring edge sweeps a band of planar quads (an
    isosceles trapezoid each), a triangle fan where one end is on the axis (r = 0), nothing
    where both are. A whole turn closes on itself; a part is capped by the region's
    triangles at both ends (the one at 0 facing -y, as the solid lies on the side of
    increasing angle).

    Parameters
    ----------
    rz : (N, 2) float
        Ring points as (r, z), r >= 0.
    offsets, hole
        The rings (see the module docstring).
    angle : float
        Degrees, in (0, 360].
    segments : int
        Steps around, >= 3 for a whole turn.
    caps : (t, 3) int, optional
        :func:`cap_triangles` of the region (used when the turn is not whole).

    Returns
    -------
    vertices, face_indices, face_offsets
        A closed, outward mesh.
    """
    rz = np.asarray(rz, dtype=np.float64)
    off = np.asarray(offsets, dtype=np.int64)
    n = len(rz)
    whole = angle >= 360.0
    copies = segments if whole else segments + 1
    on_axis = rz[:, 0] == 0.0
    rank = np.empty(n, dtype=np.int64)
    n_off = int(np.count_nonzero(~on_axis))
    rank[~on_axis] = np.arange(n_off)
    rank[on_axis] = copies * n_off + np.arange(n - n_off)

    def vid(k: np.ndarray, p: np.ndarray) -> np.ndarray:
        """The vertex of point p at copy k (points on the axis have one vertex)."""
        return np.where(on_axis[p], rank[p], (k % copies) * n_off + rank[p])

    phi = np.radians(angle) * np.arange(copies) / segments
    ring_r, ring_z = rz[~on_axis, 0], rz[~on_axis, 1]
    v = np.empty((copies, n_off, 3))
    v[..., 0] = np.cos(phi)[:, None] * ring_r
    v[..., 1] = np.sin(phi)[:, None] * ring_r
    v[..., 2] = ring_z
    axis_points = np.column_stack([np.zeros(n - n_off), np.zeros(n - n_off), rz[on_axis, 1]])
    v = np.concatenate([v.reshape(-1, 3), axis_points])
    a = np.arange(n)
    b = next_corner(off)
    k = np.arange(segments)[:, None]
    pa, pb = np.broadcast_to(a, (segments, n)), np.broadcast_to(b, (segments, n))
    a0, a1, b0, b1 = vid(k, pa), vid(k + 1, pa), vid(k, pb), vid(k + 1, pb)
    ax, bx = on_axis[pa], on_axis[pb]
    band = ~ax & ~bx
    sides = [
        (np.stack([a0[band], a1[band], b1[band], b0[band]], axis=-1).reshape(-1), 4),
        (np.stack([a0[ax & ~bx], b1[ax & ~bx], b0[ax & ~bx]], axis=-1).reshape(-1), 3),
        (np.stack([a0[bx & ~ax], a1[bx & ~ax], b0[bx & ~ax]], axis=-1).reshape(-1), 3),
    ]

    def build(tri: np.ndarray) -> MeshArrays:
        parts = list(sides)
        if not whole:
            start = vid(np.zeros_like(tri), tri)
            end = vid(np.full_like(tri, segments), tri)
            parts += [(start.reshape(-1), 3), (end[:, [0, 2, 1]].reshape(-1), 3)]
        return v, *_faces(parts)

    if whole:
        return build(np.zeros((0, 3), np.int64))
    return build(cap_triangles(rz, off, hole) if caps is None else caps)


def _faces(parts: list[tuple[np.ndarray, int]]) -> tuple[np.ndarray, np.ndarray]:
    """Flat face indices and offsets of blocks of faces of one size each."""
    fi = np.concatenate([p for p, _ in parts]) if parts else np.zeros(0, np.int64)
    sizes = np.concatenate([np.full(len(p) // m, m, dtype=np.int64) for p, m in parts])
    fo = np.zeros(len(sizes) + 1, dtype=np.int64)
    np.cumsum(sizes, out=fo[1:])
    return fi.astype(np.int64, copy=False), fo
