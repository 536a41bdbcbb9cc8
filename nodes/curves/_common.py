"""Helpers shared by the ``curves`` nodes: polylines made from point arrays and back."""

from __future__ import annotations

import numpy as np

from formgraph.geometry import Curve, NurbsCurve
from formgraph.geometry.base import as_xyz, frozen_array
from formgraph.geometry.curves import chord_lengths
from formgraph.kernels import curves as kc


def polyline_curve(points: np.ndarray, closed: bool) -> NurbsCurve:
    """A degree-1 curve through ``points``, merging repeated consecutive points (a
    subdivided or offset polygon can repeat a point; a polyline needs no zero spans)."""
    p = kc.drop_repeats(points, closed)
    for _ in range(3):  # NurbsCurve.polyline's knots are cumulative chords: keep them distinct
        ring = np.vstack([p, p[:1]]) if closed else p
        cum = np.concatenate([[0.0], np.cumsum(chord_lengths(ring))])
        grows = np.diff(cum) > 0.0
        keep = np.concatenate([[True], grows[: len(p) - 1]])
        if closed and not grows[-1]:
            keep[-1] = False
        if keep.all():
            break
        p = p[keep]
    if len(p) < 2:
        raise ValueError("the result has fewer than two distinct points")
    if keep.all() and len(ring) == len(cum):
        # what NurbsCurve.polyline makes of these points (the same ring, the same chords),
        # from the chords found here: not measured and checked a second time
        knots = frozen_array(np.concatenate([cum[:1], cum, cum[-1:]]))
        return NurbsCurve._of_valid(as_xyz(ring), 1, knots)
    return NurbsCurve.polyline(p, closed=closed)


def control_polygon(curve: Curve) -> tuple[np.ndarray, bool]:
    """The control polygon of a NURBS curve (or the drawn polyline of any other curve),
    without the repeated closing point, and whether it is closed."""
    if isinstance(curve, NurbsCurve):
        p = np.asarray(curve.control_points)
    else:
        p = np.asarray(curve.display_points())
    closed = curve.closed
    if closed and len(p) > 1:
        p = p[:-1]
    return p, closed
