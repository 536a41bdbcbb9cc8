"""Point sets."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .base import AttributeMap, Geometry, as_xyz, attribute_map, storable

__all__ = ["Points"]


@storable
@dataclass(frozen=True, eq=False, init=False)
class Points(Geometry):
    """A set of points. ``xyz`` is ``(n, 3)`` float64; ``np.asarray(points)`` gives it.

    Parameters
    ----------
    xyz : (n, 2) or (n, 3) float
    point_data : mapping name -> (n,) or (n, k) float, optional
        Per-point attributes (:class:`~.base.AttributeMap`, read-only, frozen).

    Example
    -------
    >>> p = Points([[0, 0], [1, 2]], point_data={"h": [0.5, 1.5]})
    >>> p.xyz.tolist(), p.point_data["h"].tolist()
    ([[0.0, 0.0, 0.0], [1.0, 2.0, 0.0]], [0.5, 1.5])
    """

    xyz: np.ndarray
    point_data: AttributeMap

    def __init__(self, xyz: Any, point_data: Any = None):
        v = as_xyz(xyz)
        object.__setattr__(self, "xyz", v)
        object.__setattr__(self, "point_data", attribute_map(point_data, len(v), "point attribute"))

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return self.xyz if dtype is None else self.xyz.astype(dtype)

    def __len__(self) -> int:
        return len(self.xyz)

    def __repr__(self) -> str:
        extra = f", point_data={list(self.point_data)}" if self.point_data else ""
        return f"Points(n={len(self.xyz)}{extra})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Points):
            return NotImplemented
        return self is other or (
            np.array_equal(self.xyz, other.xyz) and self.point_data == other.point_data
        )

    def __hash__(self) -> int:
        return self._content_hash()

    @property
    def nbytes(self) -> int:
        return self.xyz.nbytes + self.point_data.nbytes

    def with_point_data(self, point_data: Any) -> Points:
        """The same points with other attributes (the coordinates shared, not copied, and
        not checked again: they are this value's own)."""
        out = type(self).__new__(type(self))
        object.__setattr__(out, "xyz", self.xyz)
        data = attribute_map(point_data, len(self.xyz), "point attribute")
        object.__setattr__(out, "point_data", data)
        return out

    def to_pyvista(self) -> Any:
        import pyvista as pv

        poly = pv.PolyData(np.array(self.xyz))
        for name, a in self.point_data.items():
            poly.point_data[name] = np.array(a)
        return poly

    def state(self) -> dict[str, Any]:
        if not self.point_data:  # the state (and so the cache key) of a plain point set
            return {"xyz": self.xyz}
        return {"xyz": self.xyz, "point_data": self.point_data.pairs()}
