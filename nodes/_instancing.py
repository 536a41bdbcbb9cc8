"""What the copy-to-points nodes share: per-point scale, rotation and alignment, read as
per-element inputs, and the linear maps they make (:mod:`formgraph.kernels.geometry.instancing`).
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.types import PerElement, Vec3
from formgraph.geometry import (
    Points,
)
from formgraph.kernels.geometry import affine
from formgraph.language.elements import ElementValue, element_env


def per_point(points: Points, **inputs: Any) -> dict[str, Any]:
    """The inputs written as per-element expressions, evaluated over every point at once."""
    out = dict(inputs)
    env = None
    for port, value in inputs.items():
        if isinstance(value, ElementValue):
            env = element_env(points, "point", value.names) if env is None else env
            try:
                out[port] = value.evaluate(env, len(points), "points")
            except ValueError as exc:
                raise InputError(port, str(exc)) from None
            a = out[port]
            vector = a.ndim == 2 and a.shape[1] == 3
            if not vector and (port != "scale" or a.ndim != 1):
                want = "[x, y, z]" if port == "align" else "[rx, ry, rz]"
                example = '"=normal"' if port == "align" else '[0, 0, "=360 * rand(i)"]'
                if port == "scale":
                    want, example = "one factor or [sx, sy, sz]", '"=0.5 + rand(i)"'
                got = a.shape[1] if a.ndim == 2 else 1
                raise InputError(
                    port,
                    f"{value.text} gives {got} number(s) per point; {port} needs {want} per "
                    f"point, e.g. {example}",
                )
    return out


def frames(n: int, scale: Any, rotate: Any, align: Any) -> np.ndarray:
    try:
        return affine.frames(
            n,
            scale,
            np.asarray(rotate, np.float64).reshape(-1, 3),
            None if align is None else np.asarray(align, np.float64).reshape(-1, 3),
        )
    except ValueError as exc:
        msg = str(exc)
        raise InputError(next((p for p in ("rotate", "align") if p in msg), "scale"), msg) from None


Scale = Annotated[float | list[float] | list[Vec3], PerElement("points")]


Rotate = Annotated[Vec3 | list[Vec3], PerElement("points")]


Align = Annotated[Vec3 | list[Vec3] | None, PerElement("points")]
