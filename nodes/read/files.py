"""Read: meshes, curves and points from the files designers already have.

A path is relative to the graph file's folder and may not leave it (no absolute path, no
``..``, no symlink out), unless the run names an inputs folder (``--inputs DIR``,
``fg.load(..., inputs_dir=)``). The engine reads the file once, regular files only and
capped in size, and hashes its bytes into the node's cache key: editing the file recomputes
what reads it, an unchanged file is not parsed again. The parsers are the kernels of
:mod:`formgraph.kernels.io` (``mesh_read``, ``ply_read``, ``threemf``, ``gltf``, ...).
"""

from __future__ import annotations

import struct
import zlib
from typing import NamedTuple

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import InputPath
from formgraph.geometry import Curve, Mesh, NurbsCurve, NurbsSurface, Points, Surface
from formgraph.kernels.io import readers, rhino
from formgraph.kernels.mesh import repair

# what a parser may raise on a malformed file (its sentence is kept, the traceback dropped)
PARSE_ERRORS = (
    ValueError,
    IndexError,
    KeyError,
    TypeError,
    OverflowError,
    struct.error,
    zlib.error,
)


def parsed(path: str, what: str, fn, *args):
    """Call a reader; a malformed file becomes an error naming the ``path`` input and file."""
    try:
        return fn(*args)
    except RecursionError:
        raise InputError("path", f"{path!r}: nested too deeply to read as {what}") from None
    except PARSE_ERRORS as exc:
        raise InputError(
            "path", f"{path!r}: cannot read it as {what}: {readers.in_words(exc)}"
        ) from None


@node("read.mesh", version=2)
def mesh(path: InputPath, weld: bool = False, *, ctx: Context) -> Mesh:
    """Read a mesh file: STL (binary and ASCII), OBJ, PLY, OFF, 3MF or glTF/GLB.

    The format comes from the extension. OBJ, PLY and OFF polygons are kept as they are;
    STL is a triangle soup (three vertices per facet) until welded; 3MF and glTF give every
    mesh their build or scene places, with its transform applied, joined into one mesh. A
    PLY's extra vertex properties come in as point attributes (``red green blue`` as a
    ``color`` in 0..1, ``nx ny nz`` as a ``normal``), as ``export.ply`` writes them; a
    glTF's ``COLOR_0`` and a 3MF colour group as ``color``.
    Units: 3MF's unit and glTF's metres become millimetres; the other formats have none.

    Parameters
    ----------
    path : InputPath
        The file, relative to the graph's folder (or the inputs folder), e.g. ``scan.stl``.
    weld : bool
        Merge vertices at exactly the same position (an STL's shared corners) and drop the
        faces that collapse; ``mesh.weld`` merges within a tolerance.

    Raises
    ------
    NodeError
        For an unknown extension, or a truncated or garbled file (naming it).

    Example
    -------
    ``part: {type: read.mesh, path: scan.stl, weld: true}``
    """
    _, data = ctx.read(path)
    v, fi, fo, attributes = parsed(path, "a mesh", readers.mesh_data, path, data, ctx.budget)
    ctx.guard(len(fo) - 1, "faces")
    if weld:
        if attributes:
            ctx.warn(f"{path}: welding drops the vertex attributes ({', '.join(attributes)})")
        attributes = {}
        v, fi, fo = repair.weld(v, fi, fo, 0.0)
    try:
        return Mesh(v, fi, fo, point_data=attributes or None)
    except ValueError as exc:
        raise InputError("path", f"{path!r}: {exc}") from None


@node("read.curves", version=1)
def curves(path: InputPath, layers: list[str] | None = None, *, ctx: Context) -> list[Curve]:
    """Read the curves of an SVG or DXF drawing, exactly, in millimetres.

    Lines come in as degree-1 curves, Beziers as Beziers, arcs, circles and ellipses as
    rational quadratics, DXF SPLINEs with their own degree, knots and weights, DXF polyline
    bulges as exact arcs; each SVG subpath and each DXF polyline is one curve. SVG: the
    document's ``width``/``height`` and ``viewBox`` give millimetres (else one user unit is
    one CSS pixel, 25.4/96 mm), transforms are applied, y points up with the page's
    lower-left corner at the origin; text not converted to paths and images are passed over
    (counted in a warning). DXF: blocks are expanded, ``$INSUNITS`` scales to mm, text,
    hatches and points are passed over (counted in a warning).

    Parameters
    ----------
    path : InputPath
        The drawing, relative to the graph's folder, e.g. ``logo.svg`` or ``plate.dxf``.
    layers : list[str] | None
        Keep only these layers: DXF layer names, SVG top-level group ids or Inkscape layer
        labels. None keeps everything.

    Example
    -------
    ``logo: {type: read.curves, path: logo.svg}``
    """
    _, data = ctx.read(path)
    ext = parsed(path, "a drawing", readers.extension, path, readers.CURVE_FORMATS)
    found, skipped = parsed(path, "a drawing", readers.CURVE_FORMATS[ext], data, ctx.budget)
    if skipped:
        kinds = ", ".join(f"{n} {k}" for k, n in sorted(skipped.items()))
        ctx.warn(f"{path}: passed over what is not a curve ({kinds})")
    if layers is not None:
        names = sorted({c.layer for c in found})
        for name in layers:
            if name not in names:
                ctx.warn(f"{path}: no curves on layer {name!r} (layers: {', '.join(names)})")
        found = [c for c in found if c.layer in set(layers)]
    ctx.guard(sum(len(c.curve[0]) for c in found), "control points")
    out = []
    for c in found:
        try:
            out.append(NurbsCurve(*c.curve))
        except ValueError as exc:
            raise InputError("path", f"{path!r}: a curve is malformed: {exc}") from None
    return out


@node("read.points", version=2)
def points(path: InputPath, *, ctx: Context) -> Points:
    """Read points: CSV (``.csv``), whitespace text (``.txt``, ``.xyz``) or PLY vertices.

    One point a line, ``x, y[, z]`` (z = 0 when missing; further columns are passed over).
    A first line that is not numbers is a header; when it names ``x``, ``y`` and ``z``
    columns, those are read, in any order. ``#`` starts a comment.

    Parameters
    ----------
    path : InputPath
        The file, relative to the graph's folder, e.g. ``survey.csv``.

    Example
    -------
    ``pts: {type: read.points, path: scan.xyz}``
    """
    _, data = ctx.read(path)
    ext = parsed(path, "points", readers.extension, path, readers.POINT_FORMATS)
    xyz = parsed(path, "points", readers.POINT_FORMATS[ext], data)
    ctx.guard(len(xyz), "points")
    attributes = parsed(path, "points", readers.vertex_attributes, path, data)
    return Points(xyz, point_data=attributes or None)


class RhinoContents(NamedTuple):
    curves: list[Curve]
    surfaces: list[Surface]
    meshes: list[Mesh]
    points: Points


@node("read.rhino", version=1)
def read_rhino(path: InputPath, *, ctx: Context) -> RhinoContents:
    """Read a Rhino ``.3dm`` file through rhino3dm: NURBS exact.

    Every curve (lines, arcs, polylines and poly-curves too) comes in as its NURBS form,
    every surface as a NURBS surface (a polysurface's faces as their untrimmed surfaces,
    with a warning), meshes as meshes, point objects and point clouds as one set of points;
    coordinates in the file's model units.

    Parameters
    ----------
    path : InputPath
        The file, relative to the graph's folder, e.g. ``model.3dm``.

    Example
    -------
    ``model: {type: read.rhino, path: model.3dm}``, then ``"@model.surfaces"``
    """
    _, data = ctx.read(path)
    got = parsed(path, "a Rhino model", rhino.read_3dm, data)
    if got.untrimmed:
        ctx.warn(f"{path}: {got.untrimmed} polysurface faces read as their untrimmed surfaces")
    ctx.guard(sum(len(m[0]) for m in got.meshes) + sum(s[0].size for s in got.surfaces), "vertices")
    try:
        curves = [NurbsCurve(*c) for c in got.curves]
        surfaces = [NurbsSurface(*s) for s in got.surfaces]
        meshes = [Mesh(*m) for m in got.meshes]
    except ValueError as exc:
        raise InputError("path", f"{path!r}: {exc}") from None
    pts = np.concatenate(got.points) if got.points else np.zeros((0, 3))
    return RhinoContents(curves, surfaces, meshes, Points(pts))
