"""``geometry.filter``: keep the elements a per-element test is true for.

The test is one expression evaluated for all elements at once (the names of ``attr.set``:
``x y z``, ``nx ny nz``, ``i``, ``count``, the attributes, the params), giving one mask;
the kept elements and their attributes come out through the one propagation mechanism
(:mod:`formgraph.kernels.attributes.propagate`), never a loop per element.
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import PerElement, SameAs
from formgraph.geometry import Curve, Mesh, NurbsCurve, Points
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.curves import measure as kmeasure
from formgraph.kernels.mesh import select
from formgraph.language.elements import ElementValue, element_env
from formgraph.nodes.curves.sample import breaks_of


class Domain(str, Enum):
    """Which elements a test keeps or drops."""

    point = "point"
    face = "face"


def curve_env(curves: list[Curve]) -> dict[str, Any]:
    """The names a test over a list of curves reads, one value per curve: ``i``, ``count``,
    ``length``, ``closed`` (1 or 0), ``area`` (of a closed planar curve, positive when it
    runs counter-clockwise seen from +z, else negative; 0 when open or not planar) and the
    centroid ``x y z`` (of the curve itself: its points weighted by arc length).

    Gauss-Legendre quadrature on each knot span (as ``curves.measure``), one curve at a
    time: a curve is its own object, its quadrature vectorized."""
    n = len(curves)
    length, closed, area, centre = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros((n, 3))
    for j, c in enumerate(curves):  # one step per curve
        is_closed = c.closed
        breaks = breaks_of(c)
        t, w = kmeasure.gauss_nodes(breaks)
        p = np.asarray(c.evaluate(t), dtype=np.float64)
        speed = w * np.linalg.norm(np.asarray(c.derivative(t), dtype=np.float64), axis=1)
        length[j] = speed.sum()
        centre[j] = (speed @ p) / length[j] if length[j] > 0 else p.mean(axis=0)
        closed[j] = float(is_closed)
        if is_closed:
            _, a = kmeasure.length_and_area(c.evaluate, c.derivative, breaks, True)
            if a > 0:  # its sign: the turn of its points in the XY plane (a shoelace)
                q = (
                    np.asarray(c.control_points)
                    if isinstance(c, NurbsCurve) and c.degree == 1
                    else p
                )
                x, y = q[:, 0], q[:, 1]
                turn = float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
                area[j] = a if turn >= 0 else -a
    return {
        "x": centre[:, 0],
        "y": centre[:, 1],
        "z": centre[:, 2],
        "i": np.arange(n, dtype=np.float64),
        "count": float(n),
        "length": length,
        "closed": closed,
        "area": area,
    }


def _mask(keep: Any, env: Any, count: int, what: str) -> np.ndarray:
    if isinstance(keep, ElementValue):
        try:
            return keep.mask(env() if callable(env) else env, count, what)
        except ValueError as exc:
            raise InputError("keep", str(exc)) from None
    if not isinstance(keep, (bool, np.bool_)):
        raise InputError(
            "keep", f"keep must be true, false or a test such as '=z > 10', got {keep!r}"
        )
    return np.full(count, bool(keep))


@node("geometry.filter", version=1)
def filter_elements(
    geometry: Points | Mesh | list[Curve],
    keep: Annotated[bool, PerElement("geometry")],
    domain: Domain = Domain.point,
    *,
    ctx: Context,
) -> Annotated[Points | Mesh | list[Curve], SameAs("geometry")]:
    """Only the elements for which ``keep`` is true.

    ``keep`` is a test evaluated for every element at once: ``"=z > 10"``,
    ``"=rand(i) < 0.3"``, ``"=distance < 5 and nz > 0"`` over ``x y z`` (the point, or the
    face centre), ``nx ny nz``, ``i``, ``count``, the element's attributes and the params.
    Points keep their attributes. A mesh filtered by point keeps the faces whose corners are
    all kept; by face, the faces kept; either way the points no kept face uses are dropped,
    and point and face attributes follow. A list of curves keeps whole curves, the test
    over ``i``, ``count``, ``length``, ``closed``, ``area`` (signed: counter-clockwise seen
    from +z is positive) and the centroid ``x y z`` of each.

    Parameters
    ----------
    geometry : Points | Mesh | list[Curve]
        What to filter.
    keep : bool
        A test per element (true keeps it), or true / false for all.
    domain : Domain
        ``point`` or ``face`` (a mesh's faces).

    Example
    -------
    ``upper: {type: geometry.filter, geometry: "@cloud", keep: "=z > 0 and rand(i) < 0.5"}``
    """
    domain = Domain(domain)
    if isinstance(geometry, list):
        if domain is Domain.face:
            raise InputError("domain", "a list of curves keeps whole curves; use domain: point")
        mask = _mask(keep, lambda: curve_env(geometry), len(geometry), "curves")
        return [c for c, k in zip(geometry, mask.tolist(), strict=True) if k]
    if isinstance(geometry, Points):
        if domain is Domain.face:
            raise InputError("domain", "a point set has no faces; use domain: point")
        n = len(geometry)
        ctx.guard(n, "points")
        names = keep.names if isinstance(keep, ElementValue) else set()
        mask = _mask(keep, lambda: element_env(geometry, "point", names), n, "points")
        idx = np.flatnonzero(mask)
        return Points(geometry.xyz[idx], carry.carried(geometry, carry.copy(idx))["point_data"])
    m = geometry
    count = m.n_faces if domain is Domain.face else m.n_vertices
    ctx.guard(count, "elements")
    names = keep.names if isinstance(keep, ElementValue) else set()
    what = "faces" if domain is Domain.face else "points"
    mask = _mask(keep, lambda: element_env(m, domain.value, names), count, what)
    faces = mask if domain is Domain.face else select.faces_of_points(*m.arrays[1:], mask)
    vertex, fi, fo, face = select.keep_faces(m.face_indices, m.face_offsets, m.n_vertices, faces)
    data = carry.carried(m, carry.copy(vertex), carry.copy(face))
    return Mesh.trusted(m.vertices[vertex], fi, fo, data["point_data"], data["face_data"])
