"""Export for the next tool: 3MF for slicers, GLB for the web, STEP for CAD, .3dm for Rhino.

Each node builds the file's bytes with a kernel (:mod:`formgraph.kernels.io.threemf`,
``.gltf``, ``.step``, ``.rhino``) and hands them to ``ctx.write``: written atomically,
inside the output directory, left alone when the file already holds these bytes. Each
returns the written file's path.
"""

from __future__ import annotations

from enum import Enum
from typing import Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import OutputPath
from formgraph.geometry import Curve, Mesh, NurbsCurve, NurbsSurface, Solid, Surface
from formgraph.kernels.io import colors, gltf, rhino, step, threemf
from formgraph.kernels.io.meshdata import mesh_report
from formgraph.kernels.mesh import meshops


class Unit(str, Enum):
    micron = "micron"
    millimeter = "millimeter"
    centimeter = "centimeter"
    inch = "inch"
    foot = "foot"
    meter = "meter"


def css_rgba(text: str) -> tuple[float, float, float, float]:
    """A CSS colour (:func:`formgraph.kernels.io.colors.css_color`) as opaque 0..1 RGBA."""
    r, g, b = colors.rgb(text)
    return (r / 255, g / 255, b / 255, 1.0)


def _triangles(meshes: list[Mesh], ctx: Context) -> list[tuple[np.ndarray, np.ndarray]]:
    ctx.guard(sum(int(np.sum(m.face_sizes - 2)) for m in meshes), "triangles")
    out = []
    for m in meshes:
        v, fi, fo = meshops.triangulate(
            m.vertices, m.face_indices, m.face_offsets, max_tests=ctx.budget
        )
        out.append((v, fi.reshape(-1, 3)))
    return out


def _vertex_colour(mesh: Mesh) -> np.ndarray | None:
    """A mesh's ``color`` point attribute when it is RGB or RGBA (0..1), else None."""
    c = mesh.point_data.get("color")
    return c if c is not None and c.ndim == 2 and c.shape[1] in (3, 4) else None


def _per_mesh(values: list | None, meshes: list[Mesh], port: str) -> list | None:
    if values is not None and len(values) != len(meshes):
        raise InputError(port, f"{len(values)} {port} for {len(meshes)} meshes: give one each")
    return values


@node("export.3mf", version=2)
def export_3mf(
    meshes: list[Mesh],
    path: OutputPath,
    names: list[str] | None = None,
    colors: list[str] | None = None,
    units: Unit = Unit.millimeter,
    *,
    ctx: Context,
) -> str:
    """Write meshes as a 3MF package, for slicers: one object and one build item each.

    A valid 3MF core package (content types, relationships, the model with its unit);
    polygons are triangulated (ear clipping for concave ones); each object carries its name
    and, given ``colors``, a base material of that colour; a mesh with a ``color`` point
    attribute (3 or 4 components in 0..1) carries it per vertex instead, as a colour group
    of the Materials extension. Slicers read the unit, so a part arrives at its size.

    Parameters
    ----------
    meshes : list[Mesh]
        The parts, one object each.
    path : OutputPath
        File path relative to the output directory, e.g. ``parts/plate.3mf``.
    names : list[str] | None
        One name per mesh (default ``mesh 1``, ``mesh 2``, ...).
    colors : list[str] | None
        One CSS colour per mesh (``red``, ``#ff8800``).
    units : Unit
        What one model unit is.
    """
    _per_mesh(names, meshes, "names")
    _per_mesh(colors, meshes, "colors")
    try:
        rgba = [css_rgba(c) for c in colors] if colors is not None else None
    except ValueError as exc:
        raise InputError("colors", str(exc)) from None
    try:
        data = threemf.write_3mf(
            _triangles(meshes, ctx),
            names=names,
            colors=rgba,
            unit=units.value,
            vertex_colors=[_vertex_colour(m) for m in meshes],
        )
    except ValueError as exc:
        raise InputError("meshes", str(exc)) from None
    return str(ctx.write(path, data))


@node("export.gltf", version=2)
def export_gltf(
    meshes: list[Mesh],
    path: OutputPath,
    names: list[str] | None = None,
    units: Unit = Unit.millimeter,
    *,
    ctx: Context,
) -> str:
    """Write meshes as binary glTF 2.0 (``.glb``), for the web and AR viewers.

    One node and mesh each: float32 positions (with their bounds), smooth vertex normals
    (area-weighted) and uint32 triangle indices in one binary chunk, and vertex colours
    (``COLOR_0``) from a ``color`` point attribute (3 or 4 components in 0..1). glTF's unit
    is the metre, so coordinates are scaled from ``units`` (a 100 mm vase is 0.1 m).

    Parameters
    ----------
    meshes : list[Mesh]
        The meshes, one node each.
    path : OutputPath
        File path relative to the output directory, e.g. ``web/vase.glb``.
    names : list[str] | None
        One name per mesh.
    units : Unit
        What one model unit is.
    """
    _per_mesh(names, meshes, "names")
    scale = threemf.UNITS[units.value] / 1000.0
    colors = [_vertex_colour(m) for m in meshes]  # a ``color`` point attribute: COLOR_0
    try:
        data = gltf.write_glb(_triangles(meshes, ctx), names=names, scale=scale, colors=colors)
    except ValueError as exc:
        raise InputError("meshes", str(exc)) from None
    return str(ctx.write(path, data))


def _nurbs_curves(curves: list[Curve], port: str) -> list[tuple]:
    out = []
    for k, c in enumerate(curves):
        if not isinstance(c, NurbsCurve):
            raise InputError(
                port,
                f"curve {k} is a {type(c).__name__}; STEP and .3dm hold NURBS exactly (make it "
                f"one with nurbs.interpolate through its points)",
            )
        out.append((c.control_points, c.degree, c.knots, c.weights if c.rational else None))
    return out


def _nurbs_surfaces(surfaces: list[Surface], port: str) -> list[tuple]:
    out = []
    for k, s in enumerate(surfaces):
        if not isinstance(s, NurbsSurface):
            raise InputError(
                port,
                f"surface {k} is a {type(s).__name__}; STEP and .3dm hold NURBS exactly "
                f"(tessellate it and pass it as a mesh)",
            )
        w = s.weights if s.rational else None
        out.append((s.control_points, s.degree_u, s.degree_v, s.knots_u, s.knots_v, w))
    return out


@node("export.step", version=1)
def export_step(
    path: OutputPath,
    curves: list[Curve] | None = None,
    surfaces: list[Surface] | None = None,
    meshes: list[Mesh] | None = None,
    solids: list[Solid] | None = None,
    names: list[str] | None = None,
    colors: list[str] | None = None,
    *,
    ctx: Context,
) -> str:
    """Write exact solids, NURBS geometry and meshes as STEP, ISO 10303-21 AP214, for CAD.

    Solids (``brep.*``) become manifold solid B-reps of faces on their exact surfaces
    (planes, cylinders, tori, B-splines), each its own product, named (``names``, default
    ``solid 1``, ``solid 2``, ...) and coloured (``colors``), as OpenCASCADE's STEP
    translator writes them: what CAD and CAM programs machine from.
    Surfaces become ``B_SPLINE_SURFACE_WITH_KNOTS`` (rational where weighted), each the face
    of its own shell in a shell-based surface model, bounded by its parameter domain's edges
    (a pole left out, a seam one edge used both ways): Fusion, SolidWorks and FreeCAD open
    them as surface bodies. Curves become ``B_SPLINE_CURVE_WITH_KNOTS``. A closed mesh
    becomes a faceted solid (a closed shell of planar faces), an open one an open shell.
    Millimetres; every number its shortest round-trip decimal, so the file is exact.

    Parameters
    ----------
    path : OutputPath
        File path relative to the output directory, e.g. ``cad/vase.step``.
    curves : list[Curve] | None
        NURBS curves.
    surfaces : list[Surface] | None
        NURBS surfaces.
    meshes : list[Mesh] | None
        Meshes, as faceted solids when closed.
    solids : list[Solid] | None
        Exact solids, as manifold solid B-reps.
    names : list[str] | None
        One name per solid (its product's name in CAD's tree).
    colors : list[str] | None
        One CSS colour per solid (``"#c0392b"``, ``"steelblue"``).

    Example
    -------
    ``step: {type: export.step, path: bracket.step, solids: ["@bracket"], names: [bracket]}``
    """
    solids = solids or []
    if not solids:
        for port, given in (("names", names), ("colors", colors)):
            if given:
                raise InputError(port, f"{port} are given per solid, and there are no solids")
        _something(curves, surfaces, meshes, "STEP")
    c = _nurbs_curves(curves or [], "curves")
    s = _nurbs_surfaces(surfaces or [], "surfaces")
    meshes = meshes or []
    ctx.guard(
        sum(len(x[0]) for x in c)
        + sum(x[0].shape[0] * x[0].shape[1] for x in s)
        + 8 * sum(m.n_faces for m in meshes),
        "STEP entities",
    )
    attach = _solids_step(solids, names, colors, path) if solids else b""
    if solids and not (c or s or meshes):
        return str(ctx.write(path, attach))
    m = [
        (x.vertices, x.face_indices, x.face_offsets, mesh_report(*_arrays(x)).watertight)
        for x in meshes
    ]
    data = step.write_step(curves=c, surfaces=s, meshes=m, attach=attach)
    return str(ctx.write(path, data))


def _solids_step(
    solids: list[Solid], names: list[str] | None, colours: list[str] | None, path: str
) -> bytes:
    """The STEP file of the solids, one named (coloured) product each."""
    from formgraph.kernels.brep import BrepError, stepwrite

    n = len(solids)
    for port, given in (("names", names), ("colors", colours)):
        if given is not None and len(given) != n:
            raise InputError(port, f"{len(given)} {port} for {n} solids: give one each")
    for k, x in enumerate(solids):
        if x.is_empty:
            raise InputError("solids", f"solid {k} is empty: there is nothing to write")
    rgb = []
    for value in colours or [None] * n:
        if value is None:
            rgb.append(None)
            continue
        try:
            r, g, b = colors.rgb(value)
        except ValueError as exc:
            raise InputError("colors", str(exc)) from None
        rgb.append((r / 255, g / 255, b / 255))
    label = names or [f"solid {k + 1}" for k in range(n)]
    title = path.rsplit("/", 1)[-1].rsplit(".", 1)[0] or "formgraph"
    try:
        return stepwrite.write([x.shape for x in solids], list(label), rgb, title)
    except BrepError as exc:
        raise InputError("solids", str(exc)) from None


@node("export.rhino", version=1)
def export_rhino(
    path: OutputPath,
    curves: list[Curve] | None = None,
    surfaces: list[Surface] | None = None,
    meshes: list[Mesh] | None = None,
    layers: list[str] | None = None,
    *,
    ctx: Context,
) -> str:
    """Write a Rhino ``.3dm`` file (through rhino3dm): NURBS exact, meshes as meshes.

    Degree, knots and weights go across as they are (openNURBS's knot and homogeneous point
    conventions are converted); model units are millimetres.

    Parameters
    ----------
    path : OutputPath
        File path relative to the output directory, e.g. ``vase.3dm``.
    curves : list[Curve] | None
        NURBS curves.
    surfaces : list[Surface] | None
        NURBS surfaces.
    meshes : list[Mesh] | None
        Meshes.
    layers : list[str] | None
        One layer name per object, curves first, then surfaces, then meshes; the last name
        takes any further objects (default: a layer per kind, ``curves``, ``surfaces``,
        ``meshes``).
    """
    _something(curves, surfaces, meshes, ".3dm")
    c = _nurbs_curves(curves or [], "curves")
    s = _nurbs_surfaces(surfaces or [], "surfaces")
    m = [_arrays(x) for x in meshes or []]
    ctx.guard(sum(len(x[0]) for x in m) + sum(x[0].size for x in s), "3dm vertices")
    try:
        data = rhino.write_3dm(curves=c, surfaces=s, meshes=m, layers=layers)
    except ValueError as exc:
        raise InputError("layers" if "layers" in str(exc) else "path", str(exc)) from None
    return str(ctx.write(path, data))


def _something(curves: Any, surfaces: Any, meshes: Any, kind: str) -> None:
    """Refuse to write a file of nothing (before anything is written)."""
    if curves or surfaces or meshes:
        return
    given = [
        n
        for n, v in (("curves", curves), ("surfaces", surfaces), ("meshes", meshes))
        if v is not None
    ]
    if given:
        raise InputError(
            given[0],
            f"{' and '.join(given)} hold nothing: a {kind} file of no geometry is not written",
        )
    raise InputError(
        "curves", f"give curves, surfaces or meshes: a {kind} file of no geometry is not written"
    )


def _arrays(m: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return m.vertices, m.face_indices, m.face_offsets
