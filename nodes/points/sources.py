"""Point sources: explicit lists, grids, circles and seeded random points."""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Vec3
from formgraph.geometry import Points


@node("points.list", version=1)
def points_list(points: Points) -> Points:
    """Points given explicitly, as a list of [x, y] or [x, y, z].

    Parameters
    ----------
    points : Points
        The coordinates; [x, y] gets z = 0.

    Example
    -------
    ``pts: {type: points.list, points: [[0, 0], [1, 0], [1, 1]]}``
    """
    return points


@node("points.grid", version=1)
def grid(
    nx: Annotated[int, Range(min=1)],
    ny: Annotated[int, Range(min=1)],
    nz: Annotated[int, Range(min=1)] = 1,
    spacing: float | Vec3 = 1.0,
    origin: Vec3 = (0.0, 0.0, 0.0),
    *,
    ctx: Context,
) -> Points:
    """A regular grid of points, x varying fastest, then y, then z.

    Parameters
    ----------
    nx, ny, nz : int
        Number of points along x, y and z.
    spacing : float | Vec3
        Distance between neighbours: one number, or [dx, dy, dz].
    origin : Vec3
        Position of the first point (the minimum corner).
    """
    counts = {"nx": nx, "ny": ny, "nz": nz}
    n = nx * ny * nz
    ctx.guard(n, "points", nbytes=24 * n, port=max(counts, key=counts.__getitem__))
    step = np.broadcast_to(np.asarray(spacing, dtype=np.float64), (3,))
    o = np.asarray(origin, dtype=np.float64)
    # each coordinate written in place along its axis: the output is the only array of its
    # size made here (meshgrids, their stack and the products were four more)
    out = np.empty((nz, ny, nx, 3))
    out[..., 0] = o[0] + np.arange(nx) * step[0]
    out[..., 1] = (o[1] + np.arange(ny) * step[1])[:, None]
    out[..., 2] = (o[2] + np.arange(nz) * step[2])[:, None, None]
    return Points(out.reshape(n, 3))


@node("points.circle", version=1)
def circle(
    count: Annotated[int, Range(min=1)],
    radius: float = 1.0,
    center: Vec3 = (0.0, 0.0, 0.0),
    *,
    ctx: Context,
) -> Points:
    """Points evenly spaced on a circle in the XY plane, counter-clockwise from +x.

    Parameters
    ----------
    count : int
        Number of points.
    radius : float
        Radius of the circle.
    center : Vec3
        Centre of the circle.
    """
    ctx.guard(count, "points", nbytes=24 * count, port="count")
    a = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
    xyz = np.stack([np.cos(a), np.sin(a), np.zeros(count)], axis=-1) * radius
    return Points(np.asarray(center) + xyz)


@node("points.random", version=1)
def random(
    count: Annotated[int, Range(min=0)],
    seed: Annotated[int, Range(min=0)] = 0,
    min: Vec3 = (0.0, 0.0, 0.0),
    max: Vec3 = (1.0, 1.0, 1.0),
    *,
    ctx: Context,
) -> Points:
    """Uniformly random points in a box; the same seed gives the same points everywhere.

    Uses numpy's PCG64 generator, whose stream is stable across platforms and versions.

    Parameters
    ----------
    count : int
        Number of points.
    seed : int
        Seed of the generator.
    min : Vec3
        Lower corner of the box.
    max : Vec3
        Upper corner of the box (each coordinate >= the lower one).
    """
    lo, hi = np.asarray(min), np.asarray(max)
    if np.any(hi < lo):
        raise ValueError(f"max {hi.tolist()} is below min {lo.tolist()} on some axis")
    ctx.guard(count, "points", nbytes=24 * count, port="count")
    rng = np.random.Generator(np.random.PCG64(seed))
    xyz = rng.random((count, 3))  # the same draws as ever, scaled in place
    xyz *= hi - lo
    xyz += lo
    return Points(xyz)
