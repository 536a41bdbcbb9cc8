"""Fields combined and changed: smooth booleans, shells, offsets and transforms (recipes,
evaluated lazily).
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Range, node
from formgraph.core.types import Vec3
from formgraph.geometry import Field
from formgraph.kernels.mesh.meshops import rotation_matrix
from formgraph.nodes.field._common import positive


def _smooth(smooth: float) -> float:
    if smooth < 0:
        raise InputError("smooth", f"smooth must be >= 0, got {smooth:g}")
    return float(smooth)


@node("field.union", version=1)
def union(fields: list[Field], smooth: Annotated[float, Range(min=0)] = 0.0) -> Field:
    """The union of fields (min), blended over ``smooth`` by the polynomial smooth minimum.

    The blend ``min(a, b) - h^2 smooth / 4`` (``h = max(smooth - |a - b|, 0) / smooth``)
    adds at most ``smooth / 4`` where the shapes meet and keeps the field Lipschitz, so the
    mesher's culling stays exact (Quilez, "smooth minimum").

    Parameters
    ----------
    fields : list[Field]
        At least one field.
    smooth : float
        Blend radius, >= 0 (0: a sharp union).
    """
    if not fields:
        raise InputError("fields", "needs at least one field")
    return Field.union(list(fields), _smooth(smooth))


@node("field.intersection", version=1)
def intersection(fields: list[Field], smooth: Annotated[float, Range(min=0)] = 0.0) -> Field:
    """The intersection of fields (max), blended over ``smooth`` (a smooth maximum).

    Parameters
    ----------
    fields : list[Field]
        At least one field.
    smooth : float
        Blend radius, >= 0.
    """
    if not fields:
        raise InputError("fields", "needs at least one field")
    return Field.intersection(list(fields), _smooth(smooth))


@node("field.difference", version=1)
def difference(a: Field, b: Field, smooth: Annotated[float, Range(min=0)] = 0.0) -> Field:
    """``a`` with ``b`` cut away: ``max(a, -b)``, blended over ``smooth``.

    Parameters
    ----------
    a : Field
        What remains.
    b : Field
        What is removed.
    smooth : float
        Blend radius of the cut's edge, >= 0.
    """
    return Field.difference(a, b, _smooth(smooth))


@node("field.shell", version=1)
def shell(field: Field, thickness: Annotated[float, Range(min=0)]) -> Field:
    """A wall of ``thickness`` centred on the field's surface: ``|f| - thickness / 2``.

    Intersect with the solid (or offset by ``-thickness / 2`` first) for a wall inside it.

    Parameters
    ----------
    field : Field
        The surface to thicken.
    thickness : float
        Full wall thickness, > 0.
    """
    return Field.shell(field, positive("thickness", thickness))


@node("field.offset", version=1)
def offset(field: Field, distance: float) -> Field:
    """The field grown by ``distance`` (``f - distance``; negative shrinks it).

    Parameters
    ----------
    field : Field
        A distance field (exact growth needs a true distance).
    distance : float
        How far the surface moves outward.
    """
    if not np.isfinite(distance):
        raise InputError("distance", "distance must be finite")
    return Field.offset(field, float(distance))


@node("field.transform", version=1)
def transform(
    field: Field,
    translate: Vec3 = (0.0, 0.0, 0.0),
    rotate: Vec3 = (0.0, 0.0, 0.0),
    scale: float | Vec3 = 1.0,
) -> Field:
    """The field's shape scaled, then rotated (degrees about x, y, z), then translated.

    The points are mapped back into the field's frame; a uniform scale multiplies the
    distance by ``scale`` so it stays a distance, a non-uniform one by its smallest factor.

    Parameters
    ----------
    field : Field
        The field to move.
    translate : Vec3
        Translation.
    rotate : Vec3
        Rotation in degrees about x, then y, then z (fixed axes), as mesh.transform.
    scale : float | Vec3
        Scale factors, each > 0.
    """
    s = np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))
    if not (s > 0).all():
        raise InputError("scale", f"scale factors must be > 0, got {s.tolist()}")
    return Field.transform(field, rotation_matrix(rotate), translate, s)
