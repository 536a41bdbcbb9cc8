"""The immutable geometry values that flow along wires.

Every type is a frozen dataclass over read-only float64/int64 arrays, so a node can never
change what another node sees. Each has ``to_pyvista()`` (pyvista imported lazily),
``nbytes`` (for the memory cache) and ``state()`` / :func:`from_state` (plain arrays and
JSON-able scalars, for the on-disk cache; no pickle). ``Points`` and ``Mesh`` carry per-element
attributes (``point_data``, ``face_data``: read-only :class:`AttributeMap` of frozen arrays),
part of their equality, hash, state and ``to_pyvista()``. The math lives in
:mod:`formgraph.kernels`; these classes are thin, validated wrappers.

- ``base``: the :class:`Geometry` base, frozen arrays, attribute maps, the table of storable
  types
- ``points``: :class:`Points`
- ``curves``: :class:`Curve`, :class:`NurbsCurve`, :class:`ParametricCurve`
- ``surfaces``: :class:`Surface`, :class:`NurbsSurface`, :class:`ParametricSurface`
- ``mesh``: :class:`Mesh`
- ``field``: :class:`Field`, a signed distance function kept as its recipe
- ``solid``: :class:`Solid`, an exact B-rep solid (OpenCASCADE, the extra ``formgraph[brep]``)
"""

from __future__ import annotations

from .base import (
    STORABLE,
    AttributeMap,
    Geometry,
    as_xyz,
    attribute_map,
    from_state,
    frozen_array,
    is_frozen,
    storable,
)
from .curves import Curve, NurbsCurve, ParametricCurve
from .field import Field
from .mesh import Mesh
from .points import Points
from .solid import Solid
from .surfaces import NurbsSurface, ParametricSurface, Surface

__all__ = [
    "STORABLE",
    "AttributeMap",
    "Curve",
    "Field",
    "Geometry",
    "Mesh",
    "NurbsCurve",
    "NurbsSurface",
    "ParametricCurve",
    "ParametricSurface",
    "Points",
    "Solid",
    "Surface",
    "as_xyz",
    "attribute_map",
    "from_state",
    "frozen_array",
    "is_frozen",
    "storable",
]
