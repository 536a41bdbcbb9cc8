"""``attr.set``: named per-element data on points and meshes.

``attr.set`` computes an attribute for every point (or face) at once, from a number, a
vector, or expressions over the element (``x y z``, ``nx ny nz``, ``i``, ``count``, its other
attributes, the params, and ``rand`` / ``noise`` for variation). Other nodes carry the
attributes along by the rules they declare (:mod:`formgraph.kernels.attributes.propagate`).
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import PerElement, SameAs
from formgraph.geometry import Mesh, Points
from formgraph.language.elements import VARIABLES, ElementValue, element_env


class Domain(str, Enum):
    """Which elements an attribute belongs to."""

    point = "point"
    face = "face"


@node("attr.set", version=1)
def set_attribute(
    geometry: Points | Mesh,
    name: str,
    value: Annotated[float | list[float], PerElement("geometry")],
    domain: Domain = Domain.point,
    *,
    ctx: Context,
) -> Annotated[Points | Mesh, SameAs("geometry")]:
    """Set (add or replace) an attribute on every point or face, computed per element.

    ``value`` is a number, a list of numbers (a vector, the same on every element), or an
    expression evaluated for all elements at once over ``x y z`` (the point, or the face
    centre), ``nx ny nz`` (the normal: a ``normal`` attribute, else the mesh's vertex or face
    normals), ``i`` (the index), ``count``, the element's other attributes by name and the
    params; a list with expressions in it makes a vector attribute, one expression per
    component (``[ "=z / 10", 0.2, "=rand(i)" ]``). ``rand(key, [seed])`` and
    ``noise(x, [y], [z])`` make variation.

    Parameters
    ----------
    geometry : Points | Mesh
        What to set the attribute on.
    name : str
        The attribute's name (letters, digits and _), e.g. ``color``, ``height``.
    value : float | list[float]
        A number, a vector, or per-element expressions: one ("=z / 10"), or a list with
        one per component (["=x", 0, "=rand(i)"]), over x y z, nx ny nz, i, count, the
        element's attributes and the params.
    domain : Domain
        ``point`` (points, or a mesh's vertices) or ``face`` (a mesh's faces).

    Example
    -------
    ``shade: {type: attr.set, geometry: "@vase", name: color,
    value: ["=z / 20", 0.3, "=1 - z / 20"]}``
    """
    if not isinstance(name, str) or not name.isidentifier() or name.startswith("_"):
        raise InputError("name", f"{name!r} is not a name: letters, digits and _, not first _")
    if name in VARIABLES:
        raise InputError(
            "name", f"{name!r} is a variable of per-element expressions; choose another name"
        )
    domain = Domain(domain)
    if domain is Domain.face and not isinstance(geometry, Mesh):
        raise InputError("domain", "a point set has no faces; use domain: point")
    if isinstance(geometry, Mesh):
        count = geometry.n_faces if domain is Domain.face else geometry.n_vertices
    else:
        count = len(geometry)
    ctx.guard(count, "elements")
    what = "faces" if domain is Domain.face else "points"
    checked = isinstance(value, ElementValue)  # its evaluate refuses a value not finite
    if checked:
        env = element_env(geometry, domain.value, value.names)
        try:
            values: Any = value.evaluate(env, count, what)
        except ValueError as exc:
            raise InputError("value", str(exc)) from None
    else:
        v = np.asarray(value, dtype=np.float64)
        values = np.broadcast_to(v, (count,) + v.shape)
    if domain is Domain.face:
        data = geometry.face_data.with_(name, values, finite=checked)
        return geometry.with_data(geometry.point_data, data)
    data = geometry.point_data.with_(name, values, finite=checked)
    if isinstance(geometry, Mesh):
        return geometry.with_data(data, geometry.face_data)
    return geometry.with_point_data(data)
