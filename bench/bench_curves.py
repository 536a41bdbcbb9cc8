"""Curve kernels: Catmull-Rom conversion, polygon subdivision, resampling, bisector offset.

There is no reference library for the Catmull-Rom -> NURBS conversion or for the subdivision
rule; scipy's make_interp_spline through the same points (a global C2 interpolating spline,
a linear solve) is shown as context. Resampling and offsetting have shapely counterparts
(line_interpolate_point; offset_curve with mitre joins).
"""

from __future__ import annotations

import numpy as np

from formgraph.kernels.curves import (
    bisector_offset,
    catmull_rom,
    resample_polyline,
    subdivide_polygon,
)


def _wobbly_circle(n: int) -> np.ndarray:
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = 1.0 + 0.1 * np.sin(7 * a)
    return np.stack([r * np.cos(a), r * np.sin(a), np.zeros(n)], axis=1)


def run(table) -> None:
    rng = np.random.default_rng(0)
    walk = np.cumsum(rng.normal(size=(100_000, 3)), axis=0)

    case = "catmull_rom 100,000 points, uniform"
    table.time(case, "formgraph", lambda: catmull_rom(walk))
    try:
        from scipy.interpolate import make_interp_spline

        t = np.arange(len(walk), dtype=float)
        table.time(
            case,
            "scipy make_interp_spline",
            lambda: make_interp_spline(t, walk, k=3),
            note="context: global C2 interpolation, not Catmull-Rom",
        )
    except ImportError as exc:
        table.add(case, "scipy make_interp_spline", None, f"not installed ({exc.name})")

    case = "catmull_rom 100,000 points, centripetal closed"
    table.time(case, "formgraph", lambda: catmull_rom(walk, closed=True, spacing="centripetal"))

    polygon = _wobbly_circle(10_000)
    case = "subdivide 10,000-point closed polygon x4"
    table.time(case, "formgraph", lambda: subdivide_polygon(polygon, closed=True, iterations=4))

    case = "resample 10,000-point polygon to 10,000 points"
    table.time(case, "formgraph", lambda: resample_polyline(polygon, count=10_000, closed=True))
    try:
        import shapely

        ring = shapely.LinearRing(polygon[:, :2])
        s = np.arange(10_000) * (ring.length / 10_000)
        table.time(
            case,
            "shapely interpolate",
            lambda: shapely.get_coordinates(shapely.line_interpolate_point(ring, s)),
        )
    except ImportError as exc:
        table.add(case, "shapely interpolate", None, f"not installed ({exc.name})")

    case = "offset 10,000-point closed polygon, mitre"
    table.time(case, "formgraph", lambda: bisector_offset(polygon, True, 0.01))
    try:
        import shapely

        line = shapely.LineString(np.vstack([polygon[:, :2], polygon[:1, :2]]))
        table.time(
            case,
            "shapely offset_curve",
            lambda: shapely.offset_curve(line, 0.01, join_style="mitre"),
        )
    except ImportError as exc:
        table.add(case, "shapely offset_curve", None, f"not installed ({exc.name})")
