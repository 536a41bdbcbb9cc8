"""Curves: Catmull-Rom, polygon subdivision, resampling, the bisector offset.

Each through its node (``curves.catmull_rom``, ``curves.subdivide``, ``curves.resample``,
``curves.offset``) on input made anew each call (the points moved a hair: the input's
``Points`` or polyline built and hashed in our time, as a user's own arrays would be),
the kernel beside. There is no reference library for the Catmull-Rom -> NURBS conversion
or for the subdivision rule; scipy's ``make_interp_spline`` through the same points (a
global C2 interpolating spline, a banded solve) is shown as context. Resampling and
offsetting have shapely counterparts (``line_interpolate_point`` at equal distances;
``offset_curve`` with mitre joins).
"""

from __future__ import annotations

import numpy as np
from harness import through

from formgraph.geometry import NurbsCurve, Points
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


def _loop(polygon: np.ndarray):
    """A closed polyline of ``polygon``, moved by a new hair each call."""
    return lambda k: NurbsCurve.polyline(polygon * (1 + k * 1e-12), closed=True)


def run(table) -> None:
    rng = np.random.default_rng(0)
    walk = np.cumsum(rng.normal(size=(100_000, 3)), axis=0)

    def scipy_spline():
        from scipy.interpolate import make_interp_spline

        return make_interp_spline(np.arange(len(walk), dtype=float), walk, k=3)

    table.compare(
        "curves.catmull_rom through 100,000 points, uniform",
        api=through(
            "curves.catmull_rom", {"p": lambda k: Points(walk * (1 + k * 1e-12))}, points="=p"
        ),
        kernel=lambda: catmull_rom(walk),
        references={"scipy make_interp_spline": scipy_spline},
        notes={"scipy make_interp_spline": "context: global C2 interpolation, not Catmull-Rom"},
        rounds=5,
    )
    table.compare(
        "curves.catmull_rom through 100,000 points, centripetal closed",
        api=through(
            "curves.catmull_rom",
            {"p": lambda k: Points(walk * (1 + k * 1e-12))},
            points="=p",
            closed=True,
            spacing="centripetal",
        ),
        kernel=lambda: catmull_rom(walk, closed=True, spacing="centripetal"),
        rounds=5,
    )

    polygon = _wobbly_circle(10_000)
    table.compare(
        "curves.subdivide of a 10,000-point closed polygon x4",
        api=through("curves.subdivide", {"c": _loop(polygon)}, curve="=c", iterations=4),
        kernel=lambda: subdivide_polygon(polygon, closed=True, iterations=4),
        rounds=5,
    )

    def shapely_resample():
        import shapely

        ring = shapely.LinearRing(polygon[:, :2])
        s = np.arange(10_000) * (ring.length / 10_000)
        return shapely.get_coordinates(shapely.line_interpolate_point(ring, s))

    table.compare(
        "curves.resample of a 10,000-point polygon to 10,000 points",
        api=through("curves.resample", {"c": _loop(polygon)}, curve="=c", count=10_000),
        kernel=lambda: resample_polyline(polygon, count=10_000, closed=True),
        references={"shapely line_interpolate_point": shapely_resample},
        notes={"shapely line_interpolate_point": "the ring built from the array each call"},
        rounds=5,
    )

    def shapely_offset():
        import shapely

        line = shapely.LineString(np.vstack([polygon[:, :2], polygon[:1, :2]]))
        return shapely.offset_curve(line, 0.01, join_style="mitre")

    table.compare(
        "curves.offset of a 10,000-point closed polygon by 0.01, mitre",
        api=through("curves.offset", {"c": _loop(polygon)}, curve="=c", distance=0.01),
        kernel=lambda: bisector_offset(polygon, True, 0.01),
        references={"shapely offset_curve": shapely_offset},
        notes={"shapely offset_curve": "the line built from the array each call"},
        rounds=5,
    )
