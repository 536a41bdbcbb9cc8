"""Pocket tool paths by contour-parallel offsets, and what a round tool leaves behind.

A pocket is cleared by the tool's centre running on the level sets of the distance to the
region's boundary: the offsets inward by r (the tool's radius: the finishing pass along
the wall), r + s, r + 2 s, ... until nothing is left (Held, "On the Computational Geometry
of Pocket Machining", 1991: the contour-parallel strategy). Every offset is the offset
kernel's (:func:`formgraph.kernels.offset.offset_loops`: GEOS's buffer of the even-odd
region, or the distance field where it declines), each from the boundary itself, so no
error adds up from pass to pass.

No material left standing: a point p at distance f from the boundary with
r + k s <= f < r + (k + 1) s lies within f - (r + k s) < s of level k (the distance to a
level set of the distance function is the difference of the values), so with s <= r every
point the tool can reach is cut. With a stepover of more than half the tool (s > r), the
ridges between passes are looked for (the region the tool can reach less the passes swept
by the tool, by GEOS) and, where one stands, the levels halfway between are added where
they would cut it.

What the tool cannot reach: the region less its opening by the tool's disc (the erosion
by r dilated by r). Every inside corner keeps a fillet of radius r there; a piece whose
largest inscribed circle has a radius over a third of r is more than the fillet of a
corner of 60 degrees or wider: a gap narrower than the tool.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import shapely

from ..curves.regions import even_odd_region
from ..offset import offset_loops

__all__ = ["depths", "leftovers", "over_tabs", "pocket_levels", "tab_spans"]

_RIDGE = 1e-6  # of the reachable area: ridges below this are rounding, not material
_FILLET = 1 / 3  # inscribed radius, as a share of r, above which a leftover is reported
MAX_LEVELS = 100_000


def depths(depth: float, step_down: float | None) -> np.ndarray:
    """The z of each pass: -step_down, -2 step_down, ... down to -depth (the last pass at
    exactly -depth). One pass at -depth without ``step_down``.

    Raises
    ------
    ValueError
        A depth that is not positive and finite, a step down that is not positive.
    """
    if not (np.isfinite(depth) and depth > 0):
        raise ValueError(
            f"the depth must be positive (the cut goes down to z = -depth), got {depth}"
        )
    if step_down is None:
        return np.array([-float(depth)])
    if not (np.isfinite(step_down) and step_down > 0):
        raise ValueError(f"the step down must be positive, got {step_down}")
    count = int(np.ceil(depth / step_down - 1e-9))
    if count > MAX_LEVELS:
        raise ValueError(f"{count} passes of {step_down:g} to a depth of {depth:g}: too many")
    z = -np.minimum(step_down * np.arange(1, count + 1), depth)
    z[-1] = -float(depth)
    return z


def pocket_levels(
    rings: Sequence[np.ndarray],
    radius: float,
    step: float,
    tolerance: float,
    guard: Callable[[int], None] | None = None,
) -> list[list[np.ndarray]]:
    """The pocket's passes, level by level: the loops at distance r + k s inside the region.

    Parameters
    ----------
    rings : sequence of (m, 2) float
        Closed rings bounding the region by the even-odd rule.
    radius : float
        The tool's radius r.
    step : float
        The distance s between passes (the stepover times the diameter), 0 < s <= 2 r.
    tolerance : float
        Accuracy of the offsets (chords of their round joins).
    guard : callable of the level count, optional
        Called before each level, to refuse too many.

    Returns
    -------
    list of lists of (m, 2) float
        Level 0 (along the wall) first; each level's loops closed (first vertex not
        repeated), islands counter-clockwise and holes clockwise. Empty when the tool fits
        nowhere.
    """
    closed = [True] * len(rings)

    def level(d: float) -> list[np.ndarray]:
        return [
            np.asarray(lp)[:, :2]
            for lp in offset_loops(rings, closed, -d, tolerance=tolerance).loops
        ]

    levels: list[list[np.ndarray]] = []
    k = 0
    while True:  # one step per level: each an offset of the whole region
        if guard is not None:
            guard(k + 1)
        loops = level(radius + k * step)
        if not loops:
            break
        levels.append(loops)
        k += 1
    if step <= radius or len(levels) < 2:
        return levels
    ridges = _ridges(levels, radius)
    if ridges.is_empty:
        return levels
    out: list[list[np.ndarray]] = []
    for k, loops in enumerate(levels):  # one step per level: the one halfway after it
        out.append(loops)
        half = level(radius + (k + 0.5) * step)
        keep = [lp for lp in half if shapely.intersects(_swept(lp, radius), ridges)]
        if keep:
            out.append(keep)
    return out


def _swept(loop: np.ndarray, radius: float) -> shapely.Geometry:
    return shapely.buffer(shapely.LinearRing(loop), radius, quad_segs=16)


def _ridges(levels: list[list[np.ndarray]], radius: float) -> shapely.Geometry:
    """What the tool could reach (the opening: level 0's region grown by r) but no pass
    sweeps, pieces below the rounding left out (GEOS)."""
    reach = shapely.buffer(even_odd_region(levels[0]), radius, quad_segs=16)
    loops = np.array([shapely.LinearRing(lp) for loops in levels for lp in loops], dtype=object)
    cut = shapely.union_all(shapely.buffer(loops, radius * (1 + 1e-6), quad_segs=16))
    parts = shapely.get_parts(shapely.difference(reach, cut))
    return shapely.union_all(parts[shapely.area(parts) > _RIDGE * max(reach.area, 1e-300)])


def leftovers(
    rings: Sequence[np.ndarray], levels: list[list[np.ndarray]], radius: float
) -> list[tuple[float, float, float, float]]:
    """The pieces of the region the tool cannot reach that are more than a corner's fillet:
    (x, y, area, width) each, x y a point inside it, width twice its inscribed radius;
    largest first."""
    region = even_odd_region(rings)
    if not levels:
        reach = shapely.Polygon()
    else:
        reach = shapely.buffer(even_odd_region(levels[0]), radius, quad_segs=16)
    left = shapely.difference(region, shapely.buffer(reach, 1e-6 * radius))
    out = []
    for piece in shapely.get_parts(left):  # one step per piece left
        if piece.is_empty or piece.area <= 0:
            continue
        circle = shapely.maximum_inscribed_circle(piece, radius * 1e-3)
        centre = shapely.get_coordinates(circle)[0]
        width = 2 * shapely.length(circle)
        if width / 2 > _FILLET * radius or not levels:
            out.append((float(centre[0]), float(centre[1]), float(piece.area), float(width)))
    return sorted(out, key=lambda t: -t[2])


def tab_spans(length: float, count: int, span: float) -> np.ndarray:
    """Where a closed path of ``length`` is lifted over ``count`` holding tabs, evenly
    spaced along it (the first centred half a spacing from the start, so no tab sits on
    the path's start, where the tool plunges): (count, 2) arc lengths [start, end).

    Raises
    ------
    ValueError
        Tabs that would meet (count times ``span`` not less than the length).
    """
    if count * span >= length:
        raise ValueError(
            f"{count} tabs of {span:g} along the tool path (the tab's width plus the tool's "
            f"diameter) do not fit on a loop of length {length:.6g}: give fewer or narrower "
            "tabs"
        )
    centre = (np.arange(count) + 0.5) * (length / count)
    return np.c_[centre - span / 2, centre + span / 2]


def over_tabs(points: np.ndarray, spans: np.ndarray, z: float, z_tab: float) -> np.ndarray:
    """A closed path at depth ``z`` lifted to ``z_tab`` over the tabs: straight up at each
    tab's start, along it at ``z_tab``, straight down at its end.

    Parameters
    ----------
    points : (n, 2) float
        The path (within its tolerance), closed: the last point is the first.
    spans : (k, 2) float
        Arc lengths [start, end) of the tabs along it, sorted, apart (:func:`tab_spans`).
    z, z_tab : float
        The pass's depth and the tabs' top (z < z_tab).

    Returns
    -------
    (m, 3) float
        The lifted path: the points and the tabs' ends (each twice, at z and at z_tab),
        in order.
    """
    pts = np.asarray(points, dtype=np.float64)
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(pts, axis=0).T))]
    ends = spans.ravel()  # a0 b0 a1 b1 ...
    # the path's own points, less any that falls on a tab's end (the end stands for it)
    j = np.clip(np.searchsorted(ends, s), 1, len(ends) - 1)
    gap = np.minimum(np.abs(s - ends[j - 1]), np.abs(s - ends[j]))
    own = s[gap > 1e-12 * s[-1]]
    k = np.searchsorted(spans[:, 0], own, side="right") - 1
    inside = (k >= 0) & (own < spans[np.maximum(k, 0), 1])
    # each tab end twice: up at a start (low, then high), down at an end (high, then low)
    second = np.tile([False, True], len(ends))
    starts = np.repeat(np.tile([True, False], len(spans)), 2)
    high = np.where(starts, second, ~second)
    at = np.r_[own, np.repeat(ends, 2)]
    zs = np.r_[np.where(inside, z_tab, z), np.where(high, z_tab, z)]
    order = np.lexsort((np.r_[np.zeros(len(own)), second], at))
    at, zs = at[order], zs[order]
    xy = np.c_[np.interp(at, s, pts[:, 0]), np.interp(at, s, pts[:, 1])]
    return np.c_[xy, zs]
