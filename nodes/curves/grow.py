"""``curves.grow``: one step of differential growth of a curve (made to step with
``simulate:``; its output, fed back as its input, is the next step). A thin adapter over
:mod:`formgraph.kernels.curves.growth`.
"""

from __future__ import annotations

import zlib
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Curve, NurbsCurve
from formgraph.kernels.curves import growth as kg

#: what one point of a growth step costs against the element budget: its neighbour pairs
#: and the arrays over them (about 50 numbers a point); the default budget allows a step of
#: a million points, a few seconds
GROWTH_POINT_ELEMENTS = 50


def _polygon(curve: Curve, spacing: float, port: str) -> tuple[np.ndarray, bool]:
    """A curve's vertices (the control polygon of a polyline, else points about
    ``spacing`` apart), without a closing repeat, and whether it is closed."""
    closed = curve.closed
    if isinstance(curve, NurbsCurve) and curve.degree == 1:
        p = np.asarray(curve.control_points)
    else:
        fine = np.asarray(curve.display_points())
        length = float(np.linalg.norm(np.diff(fine, axis=0), axis=1).sum())
        count = int(min(max(16, np.ceil(length / spacing)), 100_000))
        p = curve.sample(count + (1 if closed else 0))
    if closed and len(p) > 1 and np.allclose(p[0], p[-1], rtol=0, atol=1e-12):
        p = p[:-1]
    z = p[:, 2]
    scale = max(1.0, float(np.abs(p).max()))
    if np.ptp(z) > 1e-9 * scale:
        raise InputError(
            port,
            f"{port} must lie in a plane z = constant (growth is in the XY plane); its z "
            f"runs from {z.min():g} to {z.max():g}",
        )
    return p, closed


@node("curves.grow", version=1)
def grow(
    curve: Curve,
    split: Annotated[float, Range(min=1e-9)] = 1.0,
    repulsion: Annotated[float, Range(min=0)] = 0.5,
    radius: Annotated[float | None, Range(min=1e-9)] = None,
    bounds: Curve | None = None,
    jitter: Annotated[float, Range(min=0)] = 0.3,
    seed: int = 0,
    *,
    ctx: Context,
) -> NurbsCurve:
    """One step of differential growth of a curve in the XY plane.

    Neighbours nearer than ``radius`` repel, springs along the edges pull toward half of
    ``split``, each vertex is drawn toward its neighbours' midpoint, and edges longer than
    ``split`` divide: the curve lengthens and folds (Nervous System's and inconvergent's
    differential growth). Neighbours come from a spatial hash grid, so a step costs
    O(n log n). The curve never crosses itself or ``bounds``: each vertex moves less than a
    quarter of the clearance around its edges. Use with ``simulate:``; with the defaults a
    few dozen steps visibly lengthen a curve of unit-spaced points.

    Parameters
    ----------
    curve : Curve
        A simple curve (closed or open) in a plane z = constant; a polyline's vertices are
        used as they are, another curve is sampled about ``split / 2`` apart.
    split : float
        Edges longer than this divide; the scale of the pattern (model units).
    repulsion : float
        How hard near vertices push apart: a pair at distance d moves apart by
        ``repulsion * (radius - d)`` per step (before the limit).
    radius : float | None
        How near is near (default ``2 * split``).
    bounds : Curve | None
        A closed curve around ``curve`` that it stays inside (its edges repel too).
    jitter : float
        A random push per vertex, up to about ``jitter * split / 2``, which breaks a
        regular seed's symmetry; the same on every run (drawn from ``seed`` and the state).
    seed : int
        Chooses the jitter's pattern.

    Example
    -------
    ``grown: {type: curves.grow, simulate: {state: curve, from: "@seed", steps: 40}}``
    """
    radius = 2.0 * split if radius is None else radius
    p, closed = _polygon(curve, 0.5 * split, "curve")
    fence = None
    if bounds is not None:
        if not bounds.closed:
            raise InputError("bounds", "bounds must be a closed curve")
        fence, _ = _polygon(bounds, 0.5 * split, "bounds")
    edges = np.diff(np.vstack([p, p[:1]]) if closed else p, axis=0)
    pieces = np.ceil(np.linalg.norm(edges[:, :2], axis=1) / split).sum()
    # a step at most doubles a divided edge, and each point costs its neighbour pairs
    ctx.guard(GROWTH_POINT_ELEMENTS * 2 * max(pieces, len(p)), "elements (growing points)")
    mixed = zlib.crc32(np.ascontiguousarray(p[:, :2]).tobytes())
    try:
        out = kg.grow_step(
            p[:, :2],
            closed,
            split=split,
            radius=radius,
            repulsion=repulsion,
            bounds=None if fence is None else fence[:, :2],
            jitter=jitter,
            seed=int(np.random.SeedSequence([abs(seed), mixed]).generate_state(1)[0]),
        )
    except ValueError as exc:
        message = str(exc)
        port = "radius" if "search radius" in message else "curve"
        raise InputError("bounds" if "bounds" in message else port, message) from None
    xyz = np.c_[out, np.full(len(out), p[0, 2])]
    return NurbsCurve.polyline(xyz, closed=closed)
