"""``brep.box`` and ``brep.cylinder``: exact solids from numbers (OCC's primitives)."""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import node
from formgraph.core.types import Range, Vec3
from formgraph.geometry import Solid

from ._common import call, requires, solid

# OpenCASCADE's Precision::Confusion: points closer than this are one point
PRECISION = 1e-7
TOO_SMALL = "OpenCASCADE's precision (points closer are the same point)"


def _finite(value: Vec3, port: str) -> np.ndarray:
    c = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(c)):
        raise InputError(port, f"must be finite, got {c.tolist()}")
    return c


@node("brep.box", version=1, requires=requires)
def box(size: float | Vec3 = (1.0, 1.0, 1.0), center: Vec3 = (0.0, 0.0, 0.0)) -> Solid:
    """An axis-aligned box: six planar faces, twelve straight edges.

    Parameters
    ----------
    size : float | Vec3
        Edge lengths [sx, sy, sz], or one number for a cube; each > 0.
    center : Vec3
        Centre of the box.

    Example
    -------
    ``block: {type: brep.box, size: [60, 40, 10], center: [0, 0, 5]}``
    """
    from formgraph.kernels.brep import build

    s = np.broadcast_to(np.asarray(size, dtype=np.float64), (3,))
    if not np.all((s > 0) & np.isfinite(s)):
        raise InputError("size", f"every side must be finite and > 0, got {s.tolist()}")
    if np.any(s < PRECISION):
        raise InputError("size", f"every side must be at least {PRECISION:g}, {TOO_SMALL}")
    c = _finite(center, "center")
    return solid(call("size", build.box, s, c), "box", size=s, center=c)


@node("brep.cylinder", version=1, requires=requires)
def cylinder(
    radius: Annotated[float, Range(min=0)],
    height: Annotated[float, Range(min=0)],
    center: Vec3 = (0.0, 0.0, 0.0),
) -> Solid:
    """A cylinder along z: a cylindrical face and two discs, exact circles at its rims.

    Parameters
    ----------
    radius : float
        Radius, > 0.
    height : float
        Length along z, > 0; the cylinder spans center.z - height/2 .. center.z + height/2.
    center : Vec3
        Centre of the cylinder.

    Example
    -------
    ``drill: {type: brep.cylinder, radius: 3, height: 20}``
    """
    from formgraph.kernels.brep import build

    for port, v in (("radius", radius), ("height", height)):
        if not (v > 0 and np.isfinite(v)):
            raise InputError(port, f"must be finite and > 0, got {v:g}")
        if v < PRECISION:
            raise InputError(port, f"must be at least {PRECISION:g}, {TOO_SMALL}")
    c = _finite(center, "center")
    shape = call("radius", build.cylinder, float(radius), float(height), c)
    return solid(shape, "cylinder", radius=radius, height=height, center=c)
