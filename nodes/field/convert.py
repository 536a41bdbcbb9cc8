"""Fields from other geometry: the signed distance to a mesh (winding number for the sign)
and the distance to curves (tubes).
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve, Field, Mesh, NurbsCurve
from formgraph.nodes.field._common import positive


@node("field.from_mesh", version=1)
def from_mesh(mesh: Mesh) -> Field:
    """The signed distance to a mesh: exact Euclidean distance to its nearest triangle, the
    sign by the generalized winding number (negative inside).

    The winding number (fast, by a tree of dipoles: Barill et al. 2018) is about 1 inside
    even where the mesh has small holes, so a slightly open scan still has an inside.

    Parameters
    ----------
    mesh : Mesh
        A closed (or nearly closed) outward mesh; polygons are fanned into triangles.
    """
    if mesh.n_faces == 0:
        raise InputError("mesh", "the mesh has no faces")
    return Field.from_mesh(mesh)


def _polyline(curve: Curve, samples: int) -> np.ndarray:
    """Points along a curve: a degree-1 NURBS exactly (its knots), others ``samples`` even t."""
    t0, t1 = curve.domain
    if isinstance(curve, NurbsCurve) and curve.degree == 1:
        knots = np.unique(np.asarray(curve.knots))
        t = knots[(knots >= t0) & (knots <= t1)]
    else:
        t = np.linspace(t0, t1, samples + 1)
    return np.asarray(curve.evaluate(t), dtype=np.float64)


@node("field.from_curves", version=1)
def from_curves(
    curves: list[Curve],
    radius: Annotated[float, Range(min=0)],
    samples: Annotated[int, Range(min=1)] = 256,
    *,
    ctx: Context,
) -> Field:
    """Tubes of ``radius`` round curves: the exact distance to their polylines less radius.

    Lattices of struts, frames, wire sculptures: every curve's tube, unioned (and sharp
    where tubes meet; ``field.union`` with ``smooth`` blends separate groups).

    Parameters
    ----------
    curves : list[Curve]
        The centre lines.
    radius : float
        Tube radius, > 0.
    samples : int
        Segments per curved curve (polylines keep their own vertices).
    """
    if not curves:
        raise InputError("curves", "needs at least one curve")
    ctx.guard(len(curves) * (samples + 1), "curve samples")
    segs = []
    for c in curves:
        p = _polyline(c, samples)
        if len(p) >= 2:
            segs.append(np.stack([p[:-1], p[1:]], axis=1))
    return Field.from_curves(list(curves), np.concatenate(segs), positive("radius", radius))
