"""Export of drawings: SVG, PDF and DXF, exact arcs and splines where the format has them.

Each node builds the file's bytes with a kernel (:mod:`formgraph.kernels.io.drawing`,
:mod:`~formgraph.kernels.io.dxf`) and hands them to ``ctx.write``, which writes atomically
inside the output directory, creates sub-folders, refuses paths that leave it, and leaves a
file alone when it already holds these bytes. Each returns the written file's path.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import OutputPath, entries_of
from formgraph.geometry import Curve, Mesh, NurbsCurve
from formgraph.kernels import nurbs
from formgraph.kernels.io import (
    Path2D,
    dxf_bytes,
    pdf_bytes,
    svg_bytes,
)
from formgraph.kernels.io.colors import css_color

_CIRCLE_TOL = 1e-9  # relative: a rational quadratic piece closer than this to a circle is one


@node("export.svg", version=2)
def svg(
    curves: list[Curve],
    path: OutputPath,
    margin: Annotated[float, Range(min=0)] = 1.0,
    stroke_width: Annotated[float, Range(min=1e-6)] = 0.1,
    samples: Annotated[int, Range(min=2)] = 1024,
    layers: list[str] | None = None,
    colors: list[str] | None = None,
    *,
    ctx: Context,
) -> str:
    """Draw curves (seen from +z, the XY plane) as SVG in millimetres, for a laser cutter.

    One drawing unit is one millimetre, the view box fits the drawing plus ``margin``, and
    +y points up. Curves that are cubic or lower-degree Beziers/B-splines (Catmull-Rom,
    Bezier chains) become exact ``C`` commands, circles and arcs exact ``A`` commands,
    polylines ``L``; anything else a fine polyline.

    With ``layers``, each entry of ``curves`` goes on a layer — a ``<g id=NAME>`` group
    (an Inkscape layer too) stroked in the layer's colour, which is how laser software
    tells cut from engrave: ``curves: ["@cut", "@engrave"]`` with ``layers: [cut,
    engrave]`` puts every loop of ``@cut`` on ``cut``, however many it holds (the last
    name takes any further entries). Colours are CSS colours, ``red`` or ``#ff0000``;
    layers without one take red, blue, green, magenta, cyan, yellow in turn.

    Parameters
    ----------
    curves : list[Curve]
        The curves to draw; z is dropped.
    path : OutputPath
        File path relative to the output directory.
    margin : float
        Space around the drawing, in mm.
    stroke_width : float
        Line width, in mm.
    samples : int
        Points per curve for curves that can only be drawn as polylines.
    layers : list[str] | None
        Layer of each entry of ``curves`` (the last repeats for the rest): names start
        with a letter and hold letters, digits, ``_ . -``.
    colors : list[str] | None
        Stroke colour (CSS) of each entry of ``layers``.
    """
    _guard_samples(curves, samples, ctx)
    paths = [curve_path(c, samples) for c in curves]
    names, styles = _drawing_layers(curves, layers, colors)
    data = _drawing(
        svg_bytes, paths, margin=margin, stroke_width=stroke_width, layers=names, colors=styles
    )
    return str(ctx.write(path, data))


@node("export.pdf", version=2)
def pdf(
    curves: list[Curve],
    path: OutputPath,
    margin: Annotated[float, Range(min=0)] = 1.0,
    stroke_width: Annotated[float, Range(min=1e-6)] = 0.1,
    samples: Annotated[int, Range(min=2)] = 1024,
    layers: list[str] | None = None,
    colors: list[str] | None = None,
    *,
    ctx: Context,
) -> str:
    """Draw curves (the XY plane) as a one-page PDF at true scale, in millimetres.

    The page fits the drawing plus ``margin``. Beziers are exact; arcs become cubic Beziers
    within 1e-7 of the radius (PDF has no arc operator); anything else a fine polyline.

    ``layers`` and ``colors`` as in ``export.svg``: each entry of ``curves`` on its layer
    (a PDF optional content group, listed in a viewer's layers panel), stroked in the
    layer's CSS colour.

    Parameters
    ----------
    curves : list[Curve]
        The curves to draw; z is dropped.
    path : OutputPath
        File path relative to the output directory.
    margin : float
        Space around the drawing, in mm.
    stroke_width : float
        Line width, in mm.
    samples : int
        Points per curve for curves that can only be drawn as polylines.
    layers : list[str] | None
        Layer of each entry of ``curves`` (the last repeats for the rest).
    colors : list[str] | None
        Stroke colour (CSS) of each entry of ``layers``.
    """
    _guard_samples(curves, samples, ctx)
    paths = [curve_path(c, samples) for c in curves]
    names, styles = _drawing_layers(curves, layers, colors)
    data = _drawing(
        pdf_bytes, paths, margin=margin, stroke_width=stroke_width, layers=names, colors=styles
    )
    return str(ctx.write(path, data))


def _drawing_layers(
    curves: list[Curve], layers: list[str] | None, colors: list[str] | None
) -> tuple[list[str] | None, dict[str, str] | None]:
    """Each curve's layer (by the entry of ``curves`` it came on) and each layer's colour."""
    if layers is None:
        if colors is not None:
            raise InputError("colors", "colours are given per layer: give layers too")
        return None, None
    names = _curve_layers(layers, entries_of(curves))
    if colors is None:
        return names, None
    if len(colors) != len(layers):
        raise InputError(
            "colors",
            f"one colour per entry of layers is needed: {len(layers)} layers, "
            f"{len(colors)} colours",
        )
    styles: dict[str, str] = {}
    for name, color in zip(layers, colors, strict=True):
        try:
            value = css_color(color)
        except ValueError as exc:
            raise InputError("colors", str(exc)) from None
        if styles.setdefault(name, value) != value:
            raise InputError(
                "colors", f"layer {name!r} is given two colours, {styles[name]} and {value}"
            )
    return names, styles


def _drawing(write, paths, **kwargs) -> bytes:  # type: ignore[no-untyped-def]
    """SVG or PDF bytes; a bad layer name is the ``layers`` input's error."""
    try:
        return write(paths, **kwargs)
    except ValueError as exc:
        if str(exc).startswith("layer"):
            raise InputError("layers", str(exc)) from None
        raise


_PALETTE = (1, 5, 3, 6, 4, 2)  # ACI red, blue, green, magenta, cyan, yellow: default layers


@node("export.dxf", version=3)
def dxf(
    path: OutputPath,
    curves: list[Curve] | None = None,
    mesh: Mesh | None = None,
    samples: Annotated[int, Range(min=2)] = 1024,
    layers: list[str] | None = None,
    colors: list[int] | list[str] | None = None,
    mesh_layer: str = "mesh",
    *,
    ctx: Context,
) -> str:
    """Write curves and a mesh as DXF for CAD: NURBS as exact SPLINEs, meshes as MESH.

    A NURBS curve keeps its degree, knots, weights and control points (a circle stays a
    circle), and a closed one gets the SPLINE's closed flag; degree-1 curves become
    polylines (LWPOLYLINE when flat at z = 0, else a 3-D POLYLINE); other curves a
    polyline of ``samples`` points. Units are millimetres.

    Each curve goes on a layer, so that cut, engrave and each tool path can be told apart:
    by default all curves on ``curves`` and the mesh on ``mesh_layer``; with ``layers``,
    the curves of entry i of ``curves`` on ``layers[i]`` — the layer follows the wire, so
    ``curves: ["@cut", "@engrave"]`` puts every loop of ``@cut`` on the first layer however
    many it holds — the last name also taking any entries after it. Each layer gets a
    colour: ``colors[i]`` for ``layers[i]``, an AutoCAD Color Index (1 to 255) or a CSS
    colour (``red``, ``#ff8000``: written as the layer's true colour, with the nearest
    index beside it for older programs); else red, blue, green, magenta, cyan, yellow in
    turn.

    Parameters
    ----------
    path : OutputPath
        File path relative to the output directory.
    curves : list[Curve] | None
        Curves to write.
    mesh : Mesh | None
        A mesh to write.
    samples : int
        Points per curve for curves that are not NURBS.
    layers : list[str] | None
        Layer name of each entry of ``curves``, in order (the last repeats for the rest).
    colors : list[int] | list[str] | None
        Colour of each entry of ``layers``: all ACI numbers (1 to 255) or all CSS colours.
    mesh_layer : str
        Layer of the mesh.
    """
    curves = curves or []
    _guard_samples(curves, samples, ctx, drawing=False)
    names = _curve_layers(layers, entries_of(curves)) if layers is not None else None
    names = names or ["curves"] * len(curves)
    layer_colors = _layer_colors(layers, colors, names, mesh_layer if mesh is not None else None)
    splines, polylines = [], []
    for c, layer in zip(curves, names, strict=True):  # one iteration per curve
        if isinstance(c, NurbsCurve) and c.degree == 1:
            pts = np.asarray(c.control_points)
            closed = len(pts) > 2 and np.array_equal(pts[0], pts[-1])
            polylines.append((pts[:-1] if closed else pts, closed, layer))
        elif isinstance(c, NurbsCurve):
            w = np.asarray(c.weights) if c.rational else None
            splines.append((c.control_points, c.degree, c.knots, w, bool(c.closed), layer))
        else:
            pts, closed = c.sample(samples), bool(c.closed)
            polylines.append((pts[:-1] if closed else pts, closed, layer))
    meshes = []
    if mesh is not None:
        meshes = [(mesh.vertices, mesh.face_indices, mesh.face_offsets, mesh_layer)]
    if not splines and not polylines and not meshes:
        raise ValueError("export.dxf needs curves or a mesh to write, got neither")
    try:
        data = dxf_bytes(splines, polylines, meshes, layer_colors=layer_colors)
    except ValueError as exc:
        if "layer" in str(exc):
            port = "mesh_layer" if str(exc).startswith("mesh") else "layers"
            raise InputError(port, str(exc)) from None
        raise
    return str(ctx.write(path, data))


def _curve_layers(layers: list[str], entries: list[int]) -> list[str]:
    """The layer of each curve: that of the entry of the port it came on (the last layer
    takes the entries past the end)."""
    if not layers:
        raise InputError("layers", "give at least one layer name, or leave layers out")
    return [layers[min(e, len(layers) - 1)] for e in entries]


def _layer_colors(
    layers: list[str] | None,
    colors: list[int] | list[str] | None,
    names: list[str],
    mesh_layer: str | None,
) -> dict[str, int | str]:
    order = list(dict.fromkeys([*(layers or names), *([mesh_layer] if mesh_layer else [])]))
    given: dict[str, int | str] = {}
    if colors is not None:
        if layers is None or len(colors) != len(layers):
            raise InputError(
                "colors",
                f"one colour per entry of layers is needed: {len(layers or [])} layers, "
                f"{len(colors)} colours",
            )
        for name, aci in zip(layers, colors, strict=True):
            if isinstance(aci, str):
                try:
                    aci = css_color(aci)
                except ValueError as exc:
                    raise InputError("colors", str(exc)) from None
            elif not 1 <= aci <= 255:
                raise InputError(
                    "colors", f"a colour is an AutoCAD Color Index 1 to 255, got {aci}"
                )
            if given.setdefault(name, aci) != aci:
                raise InputError(
                    "colors", f"layer {name!r} is given two colours, {given[name]} and {aci}"
                )
    return {name: given.get(name, _PALETTE[i % len(_PALETTE)]) for i, name in enumerate(order)}


def _guard_samples(curves: list[Curve], samples: int, ctx: Context, drawing: bool = True) -> None:
    """Refuse, before sampling, more polyline points than the budget (all curves together).

    Only curves written as polylines of ``samples`` points count: in a drawing, those that
    are neither polylines nor Beziers of degree <= 3 nor rational quadratics (the circle
    test may still send one of those to the polyline path); in DXF, curves that are not
    NURBS.
    """

    def sampled(c: Curve) -> bool:
        if not isinstance(c, NurbsCurve):
            return True
        return drawing and not (c.degree <= 3 and (not c.rational or c.degree <= 2))

    ctx.guard(samples * sum(sampled(c) for c in curves), "sample points")


def curve_path(curve: Curve, samples: int = 1024) -> Path2D:
    """The drawing path of a curve seen from +z (z dropped), exact where it can be.

    - degree 1 NURBS: a polyline through its control points;
    - non-rational NURBS of degree 2 or 3: its Bezier pieces (knot insertion, The NURBS
      Book A5.6), quadratics raised to cubics exactly, as a cubic chain;
    - rational quadratic NURBS whose every piece is a circular arc (equal tangent lengths
      and middle weight cos(half angle) once the end weights are 1): an arc chain;
    - anything else: a polyline of ``samples`` points evenly spaced in the parameter.
    """
    closed = bool(curve.closed)
    if isinstance(curve, NurbsCurve):
        cp = np.asarray(curve.control_points)
        if curve.degree == 1:
            pts = cp[:, :2]
            if closed and len(pts) > 2 and np.array_equal(pts[0], pts[-1]):
                pts = pts[:-1]
            return Path2D("polyline", pts, closed=closed)
        w = np.asarray(curve.weights) if curve.rational else None
        if curve.degree <= 3 and w is None:
            seg = _bezier_form(cp, curve.degree, np.asarray(curve.knots))
            if seg is None:
                seg = nurbs.decompose_bezier(cp, curve.degree, curve.knots, None)[0]
            seg = seg[:, :, :2]
            if curve.degree == 2:  # degree elevation of a quadratic Bezier (exact)
                seg = np.stack(
                    [
                        seg[:, 0],
                        (seg[:, 0] + 2 * seg[:, 1]) / 3,
                        (2 * seg[:, 1] + seg[:, 2]) / 3,
                        seg[:, 2],
                    ],
                    axis=1,
                )
            chain = np.concatenate([seg[:1, 0], seg[:, 1:].reshape(-1, 2)])
            return Path2D("cubic", chain, closed=closed)
        if curve.degree == 2 and w is not None:
            arcs = _circular_pieces(cp, curve.knots, w)
            if arcs is not None:
                return Path2D("arc", arcs, closed=closed)
    pts = np.asarray(curve.sample(samples))[:, :2]
    if closed:
        pts = pts[:-1]
    return Path2D("polyline", pts, closed=closed)


def _bezier_form(cp: np.ndarray, p: int, knots: np.ndarray) -> np.ndarray | None:
    """The Bezier pieces (k, p + 1, 3) of a curve already in Bezier form (clamped, every
    inner knot of multiplicity p: glyph outlines, rounded rectangles), read off its control
    points without knot insertion; None for any other knot vector."""
    n = len(cp)
    if (n - 1) % p or len(knots) != n + p + 1:
        return None
    k = (n - 1) // p
    ends = knots[: p + 1], knots[n:]
    inner = knots[p + 1 : n].reshape(k - 1, p)
    breaks = np.concatenate([ends[0][:1], inner[:, 0], ends[1][:1]])
    if not (
        np.all(ends[0] == ends[0][0])
        and np.all(ends[1] == ends[1][0])
        and np.all(inner == inner[:, :1])
        and np.all(np.diff(breaks) > 0)
    ):
        return None
    at = np.arange(k)[:, None] * p + np.arange(p + 1)
    return cp[at]


def _circular_pieces(cp: np.ndarray, knots: np.ndarray, w: np.ndarray) -> np.ndarray | None:
    """The arc chain (2k+1, 2) of a rational quadratic in XY, or None if a piece is no arc."""
    seg, sw = nurbs.decompose_bezier(cp, 2, knots, w)
    p = seg[:, :, :2]
    # standard form: end weights 1, middle weight w1 / sqrt(w0 w2) (a reparametrization)
    wm = sw[:, 1] / np.sqrt(sw[:, 0] * sw[:, 2])
    t0 = np.linalg.norm(p[:, 1] - p[:, 0], axis=1)
    t1 = np.linalg.norm(p[:, 2] - p[:, 1], axis=1)
    half_chord = 0.5 * np.linalg.norm(p[:, 2] - p[:, 0], axis=1)
    scale = np.maximum(np.maximum(t0, t1), 1e-300)
    cos_half = half_chord / scale
    # a straight piece (weight 1, middle point halfway: a rounded rectangle's side) is a
    # collinear piece of the chain, which the drawings write as a line
    circular = (
        (np.abs(t0 - t1) <= _CIRCLE_TOL * scale)
        & (np.abs(wm - cos_half) <= _CIRCLE_TOL)
        & (wm > 0)
        & ((wm < 1) | (np.abs(1 - cos_half) <= _CIRCLE_TOL))
    )
    if not np.all(circular):
        return None
    return np.concatenate([p[:1, 0], p[:, 1:].reshape(-1, 2)])
