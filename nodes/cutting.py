"""Outlines for cutting: rounded rectangles, polygons, region booleans, text, divide.

The nodes of the ``curves`` family a laser cutter or a CNC router needs; each adapts a
kernel of :mod:`formgraph.kernels.curves` (``shapes``, ``sampling``, ``regions``, ``text``).
Region nodes read a list of closed curves in the XY plane as one region by the even-odd
rule, as ``offset.marching_squares`` does, and give back closed outlines: outer
boundaries counter-clockwise, holes clockwise; their sampling and the curves back from the
region are :mod:`formgraph.nodes._outlines`.
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import InputPath, Vec3
from formgraph.geometry import Curve, NurbsCurve, Points, frozen_array
from formgraph.kernels import curves as kc
from formgraph.kernels.curves import regions as kregions
from formgraph.kernels.curves import sampling as ksampling
from formgraph.kernels.curves import shapes as kshapes
from formgraph.kernels.curves import text as ktext
from formgraph.nodes import _outlines as _o


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
    corners = InputError.call(port, kshapes.regular_polygon, sides, radius, center, angle)
    return NurbsCurve.polyline(corners, closed=True)


class Operation(str, Enum):
    """A region boolean."""

    union = "union"  # in a or in b
    difference = "difference"  # in a and not in b
    intersection = "intersection"  # in both
    xor = "xor"  # in exactly one


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
    tol = _o.sampling_tolerance(tolerance, everything, "a")
    ra, sa, xa = _o.sample_rings(a, "a", tol, ctx)
    rb, sb, xb = _o.sample_rings(b, "b", tol, ctx)
    region = kregions.boolean(
        _o.make_region(kregions.even_odd_region, ra, "a"),
        _o.make_region(kregions.even_odd_region, rb, "b"),
        operation.value,
    )
    return _o.outline_curves(region, everything, [*sa, *sb], [*xa, *xb], tol, ctx)


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
    tol = _o.sampling_tolerance(tolerance, curves)
    rings, sampled, sources = _o.sample_rings(curves, "curves", tol, ctx)
    region = _o.make_region(kregions.each_region, rings, "curves")
    return _o.outline_curves(region, curves, sampled, sources, tol, ctx)


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
    path = InputError.call("font", ktext.bundled_font_path, font)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError("font", f"cannot read the bundled font {font!r}: {exc}") from None
    return InputError.call("font", ktext.load_font, data)


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
    degree, pts, offsets, missing = InputError.call(
        "text", ktext.layout, f, text, size, align.value
    )
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


@node("curves.divide", version=2)
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
    closed = _o.closes(curve)
    k0, k1 = np.asarray(curve.knots)[[0, 1]] if isinstance(curve, NurbsCurve) else (0, 1)
    if isinstance(curve, NurbsCurve) and curve.degree == 1 and k0 == k1:  # clamped polyline
        cp = np.asarray(curve.control_points)
        length = float(np.sum(np.linalg.norm(np.diff(cp, axis=0), axis=1)))
        n = _o.divisions(length, count, spacing, closed, ctx, "divide")
        s = kc.even_lengths(length, n, closed)
        t, xyz, tangent, _ = ksampling.polyline_at_lengths(cp, curve.knots, s)
        return Points(xyz, point_data={"tangent": tangent, "t": t})
    t = _o.even_parameters(curve, closed, count, spacing, ctx, "divide")
    xyz = np.asarray(curve.evaluate(t))
    d = np.asarray(curve.derivative(t))
    norm = np.linalg.norm(d, axis=1)
    tangent = np.divide(d, norm[:, None], out=np.zeros_like(d), where=norm[:, None] > 0)
    return Points(xyz, point_data={"tangent": tangent, "t": t})
