"""Point sets."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .base import Geometry, as_xyz, storable

__all__ = ["Points"]


@storable
@dataclass(frozen=True, eq=False, init=False)
class Points(Geometry):
    """A set of points. ``xyz`` is ``(n, 3)`` float64; ``np.asarray(points)`` gives it.

    Example
    -------
    >>> Points([[0, 0], [1, 2]]).xyz.tolist()
    [[0.0, 0.0, 0.0], [1.0, 2.0, 0.0]]
    """

    xyz: np.ndarray

    def __init__(self, xyz: Any):
        object.__setattr__(self, "xyz", as_xyz(xyz))

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return self.xyz if dtype is None else self.xyz.astype(dtype)

    def __len__(self) -> int:
        return len(self.xyz)

    def __repr__(self) -> str:
        return f"Points(n={len(self.xyz)})"

    def to_pyvista(self) -> Any:
        import pyvista as pv

        return pv.PolyData(np.array(self.xyz))

    def state(self) -> dict[str, Any]:
        return {"xyz": self.xyz}
