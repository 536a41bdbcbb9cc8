"""``geometry.sample_surface``: points, normals and parameters on a u x v grid of a surface."""

from __future__ import annotations

from typing import Annotated, NamedTuple

import numpy as np

from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Vec3
from formgraph.geometry import (
    Points,
    Surface,
)


class Samples(NamedTuple):
    points: Points
    normals: list[Vec3]


@node("geometry.sample_surface", version=2)
def sample_surface(
    surface: Surface,
    u: Annotated[int, Range(min=1)] = 8,
    v: Annotated[int, Range(min=1)] = 8,
    *,
    ctx: Context,
) -> Samples:
    """Points at the centres of a u x v grid of cells over a surface, with unit normals.

    Cell (i, j) is centred at parameters ``u0 + (i + 1/2) (u1 - u0) / u`` and likewise in
    v; points run along v first (row i holds v points). The points carry ``normal``,
    ``u`` and ``v`` point attributes (so ``align: "=normal"`` works). Normals are ``S_u x S_v``
    normalized: exact derivatives on a NURBS surface (The NURBS Book A3.6) and on a
    parametric one (its expressions differentiated; central differences only for noise).

    Parameters
    ----------
    surface : Surface
        Any surface.
    u : int
        Cells along u.
    v : int
        Cells along v.
    """
    ctx.guard(u * v, "points", nbytes=48 * u * v, port="u" if u >= v else "v")  # xyz, normals
    (u0, u1), (v0, v1) = surface.domain_u, surface.domain_v
    uu = u0 + (np.arange(u) + 0.5) * (u1 - u0) / u
    vv = v0 + (np.arange(v) + 0.5) * (v1 - v0) / v
    gu, gv = (a.reshape(-1) for a in np.meshgrid(uu, vv, indexing="ij"))
    xyz = np.asarray(surface.evaluate(gu, gv), dtype=np.float64).reshape(-1, 3)
    normals = np.asarray(surface.normals(gu, gv), dtype=np.float64).reshape(-1, 3)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    if (length <= 1e-300).any():
        ctx.warn("the surface is degenerate at some samples; their normal is +z")
    normals = np.where(length > 1e-300, normals / np.where(length > 0, length, 1), [0, 0, 1.0])
    # the points carry their normal and their surface parameters as attributes too
    return Samples(Points(xyz, {"normal": normals, "u": gu, "v": gv}), normals)
