"""Helpers shared by the ``field`` nodes: checked lengths and boxes."""

from __future__ import annotations

from typing import Any

import numpy as np

from formgraph.core.errors import InputError


def positive(port: str, value: float) -> float:
    if not value > 0:
        raise InputError(port, f"{port} must be > 0, got {value:g}")
    return float(value)


def bounds_box(port: str, bounds: Any) -> np.ndarray:
    b = np.asarray(bounds, dtype=np.float64)
    if b.shape != (2, 3) or not np.isfinite(b).all() or not (b[1] > b[0]).all():
        raise InputError(
            port, f"{port} must be [[x0, y0, z0], [x1, y1, z1]] with x0 < x1, y0 < y1, z0 < z1"
        )
    return b
