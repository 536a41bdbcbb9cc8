"""Outlines for cutting: rounded rectangles, polygons, region booleans, text, divide.

The nodes of the ``curves`` family a laser cutter or a CNC router needs; each adapts a
kernel of :mod:`formgraph.kernels.curves` (``shapes``, ``sampling``, ``regions``, ``text``).
Region nodes read a list of closed curves in the XY plane as one region by the even-odd
rule, as ``offset.marching_squares`` does, and give back closed outlines: outer
boundaries counter-clockwise, holes clockwise.
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated, Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import InputPath, Vec3
from formgraph.geometry import Curve, NurbsCurve, Points, frozen_array
from formgraph.kernels import curves as kc
from formgraph.kernels.curves import arcs as karcs
from formgraph.kernels.curves import regions as kregions
from formgraph.kernels.curves import sampling as ksampling
from formgraph.kernels.curves import shapes as kshapes
from formgraph.kernels.curves import text as ktext

_TOLERANCE = 1e-5  # default sampling tolerance of region booleans, relative to the extent
_LARGEST = 1e150  # the largest extent whose areas (its square, times vertex counts) are finite


def _kernel(port: str, fn: Any, *args: Any, **kwargs: Any) -> Any:
    """Call a kernel; its ValueError names the node input it is about."""
    try:
        return fn(*args, **kwargs)
    except ValueError as exc:
        raise InputError(port, str(exc)) from None


@node("curves.rectangle", version=1)
def rectangle(
    size: list[float],
    center: Vec3 = (0.0, 0.0, 0.0),
    radius: Annotated[float, Range(min=0)] = 0.0,
) -> NurbsCurve:
    """A closed rectangle with exact circular corners, counter-clockwise.

    With ``radius`` 0 the corners are sharp (a degree-1 polygon). Otherwise the outline is
    one rational quadratic NURBS: every corner an exact quarter circle (middle weight
    sqrt(2)/2, The NURBS Book A7.1), every side a straight quadratic piece, joined by
    double knots; SVG, PDF and DXF export it exactly (arcs and lines). It starts at the
    bottom-right corner and runs counter-clockwise.

    Parameters
    ----------
    size : list[float]
        [width, height], both positive.
    center : Vec3
        Centre of the rectangle.
    radius : float
        Corner radius, at most half the shorter side (then the short sides vanish: a
        slot, or a circle when square).

    Example
    -------
    ``plate: {type: curves.rectangle, size: [80, 30], radius: 4}``
    """
    try:
        cp, degree, knots, w = kshapes.rounded_rectangle(size, center, radius)
    except ValueError as exc:
        port = next((q for q in ("size", "center") if str(exc).startswith(q)), "radius")
        raise InputError(port, str(exc)) from None
    return NurbsCurve(cp, degree, knots, w)


@node("curves.polygon", version=1)
def polygon(
    sides: Annotated[int, Range(min=3)],
    radius: Annotated[float, Range(min=0)],
    center: Vec3 = (0.0, 0.0, 0.0),
    angle: float = 0.0,
    *,
    ctx: Context,
) -> NurbsCurve:
    """A regular polygon, closed, counter-clockwise, its corners on a circle of ``radius``.

    Parameters
    ----------
    sides : int
        Number of sides (>= 3).
    radius : float
        Distance from the centre to every corner (> 0).
    center : Vec3
        Centre.
    angle : float
        Direction of the first corner, degrees counter-clockwise from +x.

    Example
    -------
    ``hex: {type: curves.polygon, sides: 6, radius: 5}``
    """
    ctx.guard(sides, "polygon corners")
    port = "sides" if sides < 3 else "radius"
    corners = _kernel(port, kshapes.regular_polygon, sides, radius, center, angle)
    return NurbsCurve.polyline(corners, closed=True)


class Operation(str, Enum):
    """A region boolean."""

    union = "union"  # in a or in b
    difference = "difference"  # in a and not in b
    intersection = "intersection"  # in both
    xor = "xor"  # in exactly one


def _extent(curves: list[Curve]) -> float:
    """The largest side of the XY box around the curves (their control points when NURBS:
    the curve lies in their hull)."""
    box = np.array([np.inf, np.inf, -np.inf, -np.inf])
    for c in curves:  # one step per curve; a column at a time (numpy's axis=0 min is slow)
        p = np.asarray(c.control_points) if isinstance(c, NurbsCurve) else c.sample(65)
        x, y = p[:, 0], p[:, 1]
        box = np.r_[
            np.minimum(box[:2], [x.min(), y.min()]), np.maximum(box[2:], [x.max(), y.max()])
        ]
    return float((box[2:] - box[:2]).max())


def _closed(c: Curve) -> bool:
    """Whether a curve closes: a clamped NURBS ends on its first and last control points
    (no evaluation needed); any other curve is asked."""
    if isinstance(c, NurbsCurve):
        p, k = c.degree, np.asarray(c.knots)
        if k[0] == k[p] and k[-1] == k[-1 - p]:
            cp = np.asarray(c.control_points)
            scale = max(1.0, float(np.abs(cp[[0, -1]]).max()))
            return bool(np.linalg.norm(cp[0] - cp[-1]) <= 1e-9 * scale)
    return c.closed


def _rings(
    curves: list[Curve], port: str, tol: float, ctx: Context
) -> tuple[list[np.ndarray], list[np.ndarray | None], list[karcs.Source | None]]:
    """Each closed curve sampled to ``tol`` in XY; (for curves that are not polylines) the
    same rings again, to recognize the curves a boolean leaves whole; and (for NURBS of
    degree >= 2) the curve with its samples' parameters, to rebuild the arcs it cuts."""
    rings: list[np.ndarray] = []
    sampled: list[np.ndarray | None] = []
    sources: list[karcs.Source | None] = [None] * len(curves)
    total = 0

    def guard(n: int) -> None:
        ctx.guard(total + n, "curve samples")

    # NURBS of degree >= 2 are sampled together, a batch per degree (one vectorized pass)
    batched: dict[int, np.ndarray] = {}
    by_degree: dict[int, list[int]] = {}
    tilted: list[int] = []
    for i, c in enumerate(curves):
        if not _closed(c):
            raise InputError(
                port,
                f"curve {i} is open: a region is bounded by closed curves (close it, or "
                "offset it with offset.marching_squares to get a band around it)",
            )
        if isinstance(c, NurbsCurve) and c.degree >= 2:
            by_degree.setdefault(c.degree, []).append(i)
        z = np.asarray(c.control_points)[:, 2] if isinstance(c, NurbsCurve) else c.sample(65)[:, 2]
        lo, hi = float(z.min()), float(z.max())
        if hi - lo > 1e-9 * max(1.0, -lo, hi):
            tilted.append(i)
    if tilted:
        shown = ", ".join(str(i) for i in tilted[:10]) + (", ..." if len(tilted) > 10 else "")
        ctx.warn(
            f"{port}: curve(s) {shown} are not parallel to the XY plane: their projection "
            "onto it (z dropped) bounds the region"
        )
    for members in by_degree.values():
        batch = [
            (
                curves[i].control_points,
                curves[i].degree,
                curves[i].knots,
                curves[i].weights if curves[i].rational else None,
            )
            for i in members
        ]
        sampled_batch = _kernel(port, ksampling.sample_closed_batch, batch, tol, guard, params=True)
        batched.update(zip(members, sampled_batch, strict=True))
    for i, c in enumerate(curves):  # one step per curve; its samples are vectorized
        poly = isinstance(c, NurbsCurve) and c.degree == 1
        if poly:
            # a polyline is its own sampling: its control points, closed, as they are (with
            # their z, which GEOS's planar overlay ignores: no copy into an (n, 2) array)
            ring = np.asarray(c.control_points)
            guard(len(ring))
        elif i in batched:
            ring, t = batched[i]
            x, y = ring[:, 0], ring[:, 1]
            keep = np.r_[True, (x[1:] != x[:-1]) | (y[1:] != y[:-1])]
            ring, t = ring[keep], t[keep]
            w = np.asarray(c.weights) if c.rational else None
            flat = _flat(c)
            sources[i] = karcs.Source(
                np.asarray(flat.control_points), c.degree, np.asarray(c.knots), w, ring, t
            )
        elif isinstance(c, NurbsCurve):
            w = np.asarray(c.weights) if c.rational else None
            ring = _kernel(
                port,
                ksampling.sample_nurbs,
                c.control_points,
                c.degree,
                c.knots,
                w,
                tol,
                closed=True,
                guard=guard,
            )
        else:
            t0, t1 = c.domain
            u = np.linspace(t0, t1, max(65, getattr(c, "samples", 256) + 1))

            def at(uu: np.ndarray, c: Curve = c) -> np.ndarray:
                return np.asarray(c.evaluate(uu))[:, :2]

            _, ring = ksampling.refine_chords(at, u, at(u), tol, guard)
            ring = ring[:-1]
        ring = _distinct(ring, closed=poly)
        if len(ring) - poly < 3:
            raise InputError(port, f"curve {i} encloses no area (fewer than 3 distinct points)")
        total += len(ring)
        rings.append(ring)
        sampled.append(None if poly else ring)
    return rings, sampled, sources


def _distinct(ring: np.ndarray, closed: bool = False) -> np.ndarray:
    """The ring without consecutive repeats; ``closed``: its last point is its first again
    (and stays), else a repeat of the first point at the end is dropped."""
    x, y = ring[:, 0], ring[:, 1]
    repeat = (x[1:] == x[:-1]) & (y[1:] == y[:-1])
    r = ring if not repeat.any() else ring[np.r_[True, ~repeat]]
    if not closed and len(r) > 1 and np.array_equal(r[0], r[-1]):
        r = r[:-1]
    return r


def _reversed(c: NurbsCurve) -> NurbsCurve:
    """The same curve run the other way (control points, weights and knots mirrored)."""
    k = np.asarray(c.knots)
    w = np.asarray(c.weights)[::-1] if c.rational else None
    return NurbsCurve(np.asarray(c.control_points)[::-1], c.degree, k[0] + k[-1] - k[::-1], w)


def _flat(c: NurbsCurve) -> NurbsCurve:
    """The curve projected onto z = 0 (exact: projection is affine)."""
    cp = np.asarray(c.control_points)
    if not np.any(cp[:, 2]):
        return c
    w = np.asarray(c.weights) if c.rational else None
    return NurbsCurve(np.c_[cp[:, :2], np.zeros(len(cp))], c.degree, c.knots, w)


def _outlines(
    region: Any,
    curves: list[Curve],
    sampled: list[np.ndarray | None],
    sources: list[karcs.Source | None],
    tol: float,
    ctx: Context,
) -> list[Curve]:
    """The region's boundary as closed curves; an input curve the operation left whole
    comes back as itself (exact), turned to the right direction, and the arcs of exact
    curves it cut come back as arcs of those curves (:mod:`formgraph.kernels.curves.arcs`)."""
    coords, offsets, _ = kregions.rings_of(region, with_z=True)
    if len(offsets) < 2:
        ctx.warn("the result is empty: the regions leave no area")
        return []
    if any(g is not None for g in sampled):
        out_rings = [coords[offsets[i] : offsets[i + 1] - 1, :2] for i in range(len(offsets) - 1)]
        matches = kregions.match_rings(out_rings, sampled)
    else:  # polylines only: nothing to keep exact
        matches = [None] * (len(offsets) - 1)
    xyz = frozen_array(coords)  # every outline's points: each curve's are a view of them
    knots = frozen_array(_chord_knots(coords, offsets))
    exact = [x for x in sources if x is not None]
    index = karcs.SampleIndex(exact) if exact else None
    result: list[Curve] = []
    for i, match in enumerate(matches):  # one step per outline
        a, b = offsets[i], offsets[i + 1]
        rebuilt = (
            karcs.exact_outline(coords[a : b - 1, :2], exact, index, tol)
            if index is not None and match is None
            else None
        )
        if match is not None:
            c = curves[match[0]]
            assert isinstance(c, NurbsCurve)
            result.append(_flat(c) if match[1] else _flat(_reversed(c)))
        elif rebuilt is not None:
            result.append(NurbsCurve(*rebuilt))
        else:
            # GEOS's points of finite input and their running length: valid by making
            result.append(NurbsCurve._of_valid(xyz[a:b], 1, knots[a + 2 * i : b + 2 * i + 2]))
    return result


def _chord_knots(coords: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The knots of every closed ring as a polyline, in one array: ring i's running chord
    length with its first and last value doubled, at ``[offsets[i] + 2 i, offsets[i + 1] +
    2 i + 2)`` (so t is arc length along each outline)."""
    m, r = len(coords), len(offsets) - 1
    x, y = coords[:, 0], coords[:, 1]
    seg = np.hypot(x[1:] - x[:-1], y[1:] - y[:-1])  # seg[j - 1]: from point j - 1 to j
    knots = np.zeros(m + 2 * r)
    if r == 1:  # the usual case, without the scatter: [0, 0, running length, last again]
        np.cumsum(seg, out=knots[2 : m + 1])
        knots[m + 1] = knots[m]
        return knots
    # point j of ring i sits at j + 2 i + 1; the step into it (none into a ring's first
    # point, so each ring starts at 0 and its doubled ends repeat their neighbours)
    ring = np.repeat(np.arange(r), np.diff(offsets))
    inside = np.flatnonzero(ring[1:] == ring[:-1])
    knots[inside + 2 + 2 * ring[inside + 1]] = seg[inside]
    np.cumsum(knots, out=knots)
    knots -= np.repeat(knots[offsets[:-1] + 2 * np.arange(r)], np.diff(offsets) + 2)
    return knots


def _tolerance(tolerance: float | None, curves: list[Curve], port: str = "curves") -> float:
    """The sampling tolerance: given (and checked), else 1e-5 of the curves' extent. Polylines
    are taken at their vertices, so when every curve is one no extent is needed."""
    polylines = all(isinstance(c, NurbsCurve) and c.degree == 1 for c in curves)
    if tolerance is None and polylines:
        return 1.0  # unused: nothing is sampled
    extent = _extent(curves)
    if not extent < _LARGEST:
        raise InputError(
            "curves" if port == "curves" else "a",
            f"the curves span {extent:.3g}: too large for a region boolean, whose areas "
            f"(squares of lengths) overflow double precision past {_LARGEST:.0e}; scale them "
            "down",
        )
    if tolerance is None:
        return _TOLERANCE * (extent if extent > 0 else 1.0)
    if not tolerance > 0:
        raise InputError("tolerance", f"the tolerance must be positive, got {tolerance}")
    if extent > 0 and tolerance < 1e-12 * extent:
        raise InputError(
            "tolerance",
            f"tolerance {tolerance:g} is below 1e-12 of the curves' size ({extent:g}): "
            "finer than double precision resolves",
        )
    return float(tolerance)


@node("curves.boolean", version=1)
def boolean(
    a: list[Curve],
    b: list[Curve],
    operation: Operation = Operation.union,
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """Union, difference, intersection or xor of two regions bounded by closed curves.

    ``a`` and ``b`` are each read as one region by the even-odd rule (nested curves make
    holes), as ``offset.marching_squares`` reads its input; z is dropped. Curves are
    sampled so that every chord is within ``tolerance`` of its curve (NURBS by a bound on
    their curvature, then checked at every chord's midpoint; polylines exactly at their
    vertices), and the regions are combined by GEOS (shapely's overlay). Out come closed
    outlines at z = 0, outer boundaries counter-clockwise and holes clockwise; a curve the
    operation leaves whole (a hole that touches nothing, the plate around it) comes back
    exact, as the input curve itself, and a NURBS curve it cuts comes back as its exact
    arcs between the cuts (the cuts found by Newton's method on the exact curves), joined
    with straight pieces into one NURBS outline.

    Parameters
    ----------
    a : list[Curve]
        Closed curves bounding the first region.
    b : list[Curve]
        Closed curves bounding the second region.
    operation : Operation
        union, difference (a minus b), intersection or xor.
    tolerance : float
        Largest distance between a curve and its sampling. Default: 1e-5 of the size of
        the inputs.

    Example
    -------
    ``plate: {type: curves.boolean, a: ["@outline"], b: ["@hole1", "@hole2"],
    operation: difference}``
    """
    if isinstance(a, Curve):
        a = [a]
    if isinstance(b, Curve):
        b = [b]
    everything = [*a, *b]
    if not everything:
        raise InputError("a", "give curves to a or b, got none")
    tol = _tolerance(tolerance, everything, "a")
    ra, sa, xa = _rings(a, "a", tol, ctx)
    rb, sb, xb = _rings(b, "b", tol, ctx)
    region = kregions.boolean(
        kregions.even_odd_region(ra), kregions.even_odd_region(rb), operation.value
    )
    return _outlines(region, everything, [*sa, *sb], [*xa, *xb], tol, ctx)


@node("curves.union", version=1)
def union(
    curves: list[Curve],
    tolerance: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """The union of the regions of closed curves: overlapping outlines merged into one.

    Each curve bounds its own region (by the even-odd rule: a self-intersecting curve is
    fine) and the regions are united, so two overlapping circles become one outline where
    ``offset.marching_squares`` (which reads the whole list by the even-odd rule) would cut
    their overlap out. A curve inside another is swallowed; to keep a hole, subtract it
    with ``curves.boolean``. Sampling, orientation and exactness as ``curves.boolean``.

    Parameters
    ----------
    curves : list[Curve]
        Closed curves in the XY plane (z is dropped).
    tolerance : float
        Largest distance between a curve and its sampling. Default: 1e-5 of the size of
        the inputs.

    Example
    -------
    ``blob: {type: curves.union, curves: ["@circle_a", "@circle_b"]}``
    """
    if isinstance(curves, Curve):
        curves = [curves]
    if not curves:
        raise InputError("curves", "the union needs at least one curve, got none")
    tol = _tolerance(tolerance, curves)
    rings, sampled, sources = _rings(curves, "curves", tol, ctx)
    return _outlines(kregions.each_region(rings), curves, sampled, sources, tol, ctx)


class Align(str, Enum):
    """Where a line of text sits on its position."""

    left = "left"  # starts there
    center = "center"  # its middle there
    right = "right"  # ends there


def _font(font: str, font_file: str | None, ctx: Context) -> ktext.Font:
    """The parsed font: the file the graph names (its bytes key the node), else a bundled
    one."""
    if font_file is not None:
        if not font_file.lower().endswith((".ttf", ".otf")):
            raise InputError("font_file", f"{font_file!r}: a font file is a .ttf or .otf")
        _, data = ctx.read(font_file)
        try:
            return ktext.load_font(data)
        except ValueError as exc:
            raise InputError("font_file", f"{font_file!r}: {exc}") from None
    path = _kernel("font", ktext.bundled_font_path, font)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError("font", f"cannot read the bundled font {font!r}: {exc}") from None
    return _kernel("font", ktext.load_font, data)


@node("curves.text", version=1)
def text(
    text: str,
    size: Annotated[float, Range(min=0)] = 10.0,
    font: str = "DejaVu Sans",
    align: Align = Align.left,
    position: Vec3 = (0.0, 0.0, 0.0),
    font_file: InputPath | None = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """Text as closed outlines: each glyph's contours as exact NURBS, holes included.

    The font's own Bezier outlines become NURBS without approximation: TrueType's
    quadratic contours (implied on-curve points restored) as closed degree-2 curves, CFF's
    cubic ones as degree 3. Outer contours run counter-clockwise and holes (the counter of
    an ``o``) clockwise, so the list is a region by the even-odd rule as the region nodes
    and ``offset.marching_squares`` read it. Glyphs advance by the font's widths and
    kerning (GPOS pair adjustments, else the ``kern`` table); lines (split at newlines)
    are the font's line height apart, the first baseline through ``position``.

    Parameters
    ----------
    text : str
        The text; ``\\n`` starts a new line.
    size : float
        The em size in model units (a capital of DejaVu Sans is 0.73 of it).
    font : str
        A bundled font (they ship with matplotlib): DejaVu Sans, DejaVu Sans Bold, DejaVu
        Sans Oblique, DejaVu Sans Bold Oblique, DejaVu Sans Mono, DejaVu Sans Mono Bold,
        DejaVu Serif, DejaVu Serif Bold, DejaVu Serif Italic.
    align : Align
        left, center or right: each line starts at, is centred on or ends at ``position``.
    position : Vec3
        Where the first line's baseline meets the alignment point.
    font_file : InputPath | None
        A TrueType or OpenType font (``.ttf``, ``.otf``) in the graph's folder (or the
        inputs folder), e.g. ``fonts/Inter.otf``: used instead of ``font``. Confined as
        every input path (no absolute path, no ``..``, no symlink out); its bytes are part
        of the node's key, so editing the font recomputes the text.

    Example
    -------
    ``label: {type: curves.text, text: "FORMGRAPH", size: 8, align: center}``
    """
    if not size > 0:
        raise InputError("size", f"size must be positive, got {size}")
    ctx.guard(len(text) * 64, "glyph control points")  # a glyph has tens of points
    f = _font(font, font_file, ctx)
    degree, pts, offsets, missing = _kernel("text", ktext.layout, f, text, size, align.value)
    if missing:
        chars = "".join(missing[:20])
        ctx.warn(
            f"the font {font_file or font!r} has no glyph for {chars!r}: drawn as its "
            "missing-glyph box"
        )
    ctx.guard(len(pts), "glyph control points")
    # one frozen array for all the control points: each curve's are a view of it (shared,
    # not copied), and the knots of each piece count are made once
    xyz = frozen_array(np.c_[pts, np.zeros(len(pts))] + np.asarray(position))
    knots: dict[int, np.ndarray] = {}
    out: list[Curve] = []
    for i in range(len(offsets) - 1):  # one curve per contour
        cp = xyz[offsets[i] : offsets[i + 1]]
        pieces = (len(cp) - 1) // degree
        if pieces not in knots:
            inner = np.repeat(np.arange(1, pieces), degree)
            ends = [0.0] * (degree + 1), [float(pieces)] * (degree + 1)
            knots[pieces] = frozen_array(np.concatenate([ends[0], inner, ends[1]]))
        out.append(NurbsCurve(cp, degree, knots[pieces]))
    return out


@node("curves.divide", version=1)
def divide(
    curve: Curve,
    count: Annotated[int | None, Range(min=2)] = None,
    spacing: Annotated[float | None, Range(min=0)] = None,
    *,
    ctx: Context,
) -> Points:
    """Points on a curve at equal arc length, with ``tangent`` and ``t`` point attributes.

    Give ``count`` or ``spacing``. The arc length is integrated by Gauss-Legendre
    quadrature on every knot span and inverted by safeguarded Newton steps, so the points
    lie exactly on the curve (a polyline: along its straight segments); an open curve gets
    both ends, a closed one its start and no repeat of it. ``tangent`` is the unit tangent
    (the direction of travel) and ``t`` the curve parameter of each point: copy parts onto
    the points aligned to the curve, or drive expressions by position along it.

    Parameters
    ----------
    curve : Curve
        Any curve.
    count : int
        Number of points (open: both ends included; closed: >= 3).
    spacing : float
        Distance along the curve between points; rounded so it divides the length evenly.

    Example
    -------
    ``studs: {type: curves.divide, curve: "@rim", spacing: 5}``
    """
    if (count is None) == (spacing is None):
        raise InputError("count", "give exactly one of count and spacing")
    closed = _closed(curve)
    k0, k1 = np.asarray(curve.knots)[[0, 1]] if isinstance(curve, NurbsCurve) else (0, 1)
    if isinstance(curve, NurbsCurve) and curve.degree == 1 and k0 == k1:  # clamped polyline
        cp = np.asarray(curve.control_points)
        length = float(np.sum(np.linalg.norm(np.diff(cp, axis=0), axis=1)))
        n = _divisions(length, count, spacing, closed, ctx)
        s = np.arange(n) * (length / n) if closed else np.linspace(0.0, length, n)
        t, xyz, tangent, _ = ksampling.polyline_at_lengths(cp, curve.knots, s)
        return Points(xyz, point_data={"tangent": tangent, "t": t})
    if isinstance(curve, NurbsCurve):
        k = np.asarray(curve.knots)
        breaks = np.unique(k[curve.degree : len(curve.control_points) + 1])
        pieces = 1 if curve.degree == 1 else 16
    else:
        breaks, pieces = np.array(curve.domain), max(64, getattr(curve, "samples", 256))

    def speed(tt: np.ndarray) -> np.ndarray:
        return np.linalg.norm(curve.derivative(tt), axis=-1)

    edges, cum = kc.arc_length_table(speed, breaks, pieces)
    length = float(cum[-1])
    n = _divisions(length, count, spacing, closed, ctx)
    s = np.arange(n) * (length / n) if closed else np.linspace(0.0, length, n)
    t = kc.parameters_at_lengths(speed, edges, cum, s)
    xyz = np.asarray(curve.evaluate(t))
    d = np.asarray(curve.derivative(t))
    norm = np.linalg.norm(d, axis=1)
    tangent = np.divide(d, norm[:, None], out=np.zeros_like(d), where=norm[:, None] > 0)
    return Points(xyz, point_data={"tangent": tangent, "t": t})


def _divisions(
    length: float, count: int | None, spacing: float | None, closed: bool, ctx: Context
) -> int:
    """How many points divide a curve of ``length``: ``count``, or from ``spacing``."""
    if not length > 0.0:
        raise InputError("curve", "cannot divide a curve of zero length")
    n = (
        count
        if count is not None
        else _kernel("spacing", kc.resample_count, length, spacing, closed)
    )
    if closed and n < 3:
        raise InputError("count", f"dividing a closed curve needs count >= 3, got {n}")
    ctx.guard(n, "points")
    return int(n)
