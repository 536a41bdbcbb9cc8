"""Solids for fabrication (mesh family): primitives, repair, thickening, booleans, measures.

Thin adapters over :mod:`formgraph.kernels.mesh.primitives`, ``.repair``, ``.solidify``,
``.boolean`` (manifold3d) and ``.measure``. Closed primitives come out watertight and
outward; ``mesh.weld`` -> ``mesh.orient`` -> ``mesh.cap`` turns a triangle soup or an open
tube into a printable solid.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Annotated, Any, NamedTuple

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Expression, Variables, Vec3
from formgraph.geometry import Mesh
from formgraph.kernels.attributes import booleans as kab
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import MeshTopologyError, meshops
from formgraph.kernels.mesh import boolean as kb
from formgraph.kernels.mesh import primitives as kp
from formgraph.kernels.mesh import repair as kr
from formgraph.kernels.mesh import solidify as ks


def _arrays(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return mesh.vertices, mesh.face_indices, mesh.face_offsets


def _topology(port: str, fn: Callable[..., Any], *args: Any) -> Any:
    """Call a kernel that needs an oriented manifold; say which node fixes what it lacks."""
    try:
        return fn(*args)
    except MeshTopologyError as exc:
        hint = (
            "mesh.orient makes the faces agree"
            if "orientation" in str(exc)
            else "mesh.weld or a cleaner source may help"
        )
        raise InputError(port, f"{exc}; {hint}") from None


def _clipping(ctx: Context, fn: Callable[..., Any], *args: Any) -> Any:
    """Call a kernel that may ear-clip faces, with the budget as its work limit."""
    try:
        return fn(*args, max_tests=ctx.budget)
    except meshops.WorkLimitError as exc:
        ctx.guard(exc.work, "triangle-corner tests of ear clipping")
        raise


def _within_floats(arrays: Any, port: str, inputs: str) -> Any:
    """Kernel output arrays, or an error naming the scalar input that overflowed them.

    The inputs are finite, so a non-finite vertex means a size (or thickness) large enough
    that a coordinate passed the largest float: that input is to blame, not the mesh.
    """
    v = arrays[0]
    ok = np.isfinite(v).all(axis=1)
    if not ok.all():
        i = int(np.argmin(ok))
        raise InputError(
            port,
            f"{inputs} put vertex {i} at [{', '.join(f'{c:g}' for c in v[i])}], beyond the "
            f"largest float (about {np.finfo(np.float64).max:.3g}); use smaller values",
        )
    return arrays


def _fmt(x: Any) -> str:
    a = np.atleast_1d(np.asarray(x, dtype=float))
    return f"{a[0]:g}" if a.size == 1 else f"[{', '.join(f'{c:g}' for c in a)}]"


# ------------------------------------------------------------------------------ primitives


@node("mesh.cylinder", version=1)
def cylinder(
    radius: Annotated[float, Range(min=0)],
    height: Annotated[float, Range(min=0)],
    segments: Annotated[int, Range(min=3)] = 64,
    caps: bool = True,
    center: Vec3 = (0.0, 0.0, 0.0),
    *,
    ctx: Context,
) -> Mesh:
    """A cylinder along z: quads around, an n-gon at each end; watertight and outward.

    Its vertices lie on the true cylinder, so its volume is the inscribed prism's,
    (n / 2) r^2 sin(2 pi / n) h, within (2 pi / n)^2 / 6 of pi r^2 h (relative).

    Parameters
    ----------
    radius : float
        Radius, > 0.
    height : float
        Length along z, > 0; the cylinder spans center.z - height/2 .. center.z + height/2.
    segments : int
        Quads around.
    caps : bool
        Close both ends (false: an open tube).
    center : Vec3
        Centre of the cylinder.
    """
    ctx.guard(6 * segments, "face corners")
    try:
        arrays = kp.cylinder(radius, height, segments, caps, center)
    except ValueError as exc:
        raise InputError("radius" if "radius" in str(exc) else "height", str(exc)) from None
    port = "radius" if radius >= height / 2 else "height"
    what = f"radius {radius:g}, height {height:g} and center {_fmt(center)}"
    return Mesh(*_within_floats(arrays, port, what))


@node("mesh.sphere", version=1)
def sphere(
    radius: Annotated[float, Range(min=0)],
    segments: Annotated[int, Range(min=3)] = 32,
    center: Vec3 = (0.0, 0.0, 0.0),
    *,
    ctx: Context,
) -> Mesh:
    """A UV sphere: segments around, segments / 2 bands, triangle fans at the poles.

    Watertight and outward; inscribed in the true sphere (volume and area converge from
    below as segments grow).

    Parameters
    ----------
    radius : float
        Radius, > 0.
    segments : int
        Faces around the equator; the bands pole to pole are half as many (at least 2).
    center : Vec3
        Centre of the sphere.
    """
    ctx.guard(segments * max(2, segments // 2), "faces")
    try:
        arrays = kp.sphere(radius, segments, center)
    except ValueError as exc:
        raise InputError("radius", str(exc)) from None
    what = f"radius {radius:g} and center {_fmt(center)}"
    return Mesh(*_within_floats(arrays, "radius", what))


@node("mesh.torus", version=1)
def torus(
    major: Annotated[float, Range(min=0)],
    minor: Annotated[float, Range(min=0)],
    segments_u: Annotated[int, Range(min=3)] = 64,
    segments_v: Annotated[int, Range(min=3)] = 32,
    center: Vec3 = (0.0, 0.0, 0.0),
    *,
    ctx: Context,
) -> Mesh:
    """A ring torus about the z axis, all quads, watertight and outward.

    Parameters
    ----------
    major : float
        Distance from the axis to the centre of the tube.
    minor : float
        Radius of the tube, smaller than major.
    segments_u : int
        Quads around the z axis.
    segments_v : int
        Quads around the tube.
    center : Vec3
        Centre of the torus.
    """
    ctx.guard(segments_u * segments_v, "faces")
    try:
        arrays = kp.torus(major, minor, segments_u, segments_v, center)
    except ValueError as exc:
        raise InputError("minor", str(exc)) from None
    what = f"major {major:g}, minor {minor:g} and center {_fmt(center)}"
    return Mesh(*_within_floats(arrays, "major", what))


@node("mesh.plane", version=1)
def plane(
    size: list[float] = (1.0, 1.0),  # type: ignore[assignment]
    divisions: list[int] = (1, 1),  # type: ignore[assignment]
    center: Vec3 = (0.0, 0.0, 0.0),
    *,
    ctx: Context,
) -> Mesh:
    """A flat grid of quads in the xy plane, facing +z (an open sheet).

    Parameters
    ----------
    size : list[float]
        [width along x, depth along y], each > 0.
    divisions : list[int]
        [quads along x, quads along y], each >= 1.
    center : Vec3
        Centre of the sheet.
    """
    if len(size) != 2:
        raise InputError("size", f"size takes [width, depth], got {list(size)}")
    if len(divisions) != 2:
        raise InputError("divisions", f"divisions takes [nx, ny], got {list(divisions)}")
    ctx.guard(float(divisions[0] + 1) * float(divisions[1] + 1), "vertices")
    try:
        arrays = kp.plane(size, divisions, center)
    except ValueError as exc:
        raise InputError("size" if "size" in str(exc) else "divisions", str(exc)) from None
    return Mesh(*_within_floats(arrays, "size", f"size {_fmt(size)} and center {_fmt(center)}"))


# ---------------------------------------------------------------------------------- repair


@node("mesh.weld", version=1)
def weld(
    mesh: Mesh, tolerance: Annotated[float | None, Range(min=0)] = None, *, ctx: Context
) -> Mesh:
    """Merge vertices closer than the tolerance; drop the faces that collapse.

    Closeness is transitive (a chain of close vertices becomes one); each group keeps the
    position of its first vertex; unused vertices are removed. Sparse cells one tolerance wide
    make it O(n log n).

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh, e.g. an STL-like triangle soup.
    tolerance : float | None
        Merge distance. None: 1e-6 of the bounding-box diagonal (joins seams and
        duplicated vertices, never features); 0: exact duplicates only.
    """
    try:
        v, fi, fo = kr.weld(*_arrays(mesh), tolerance)
    except ValueError as exc:
        raise InputError("tolerance", str(exc)) from None
    dropped = mesh.n_faces - (fo.size - 1)
    # each group keeps its first vertex's position, and so its attributes
    points = carry.copy(carry.by_position(mesh.vertices, v))
    faces = carry.SAME
    if dropped:
        ctx.warn(f"{dropped} faces collapsed and were dropped")
        if mesh.face_data:
            faces = carry.DROP
            ctx.warn("with faces dropped, the face attributes were dropped too")
    return Mesh(v, fi, fo, **carry.carried(mesh, points, faces))


@node("mesh.orient", version=1)
def orient(mesh: Mesh, *, ctx: Context) -> Mesh:
    """Consistent face orientation; every closed part outward (positive volume).

    Faces that share an edge are made to run it in opposite directions (a parity
    union-find over the edges, all at once); then each closed part is turned so its signed
    volume is positive, except a cavity (a part inside an odd number of the others, by the
    generalized winding number), which faces inward so a hollow stays hollow. An open part
    is turned so its faces look away from its centroid, or, if it is flat, so most of its
    area keeps the side it had.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh; edges on more than two faces do not link their faces.
    """
    fi, conflicts = kr.orient(*_arrays(mesh))
    if conflicts:
        ctx.warn(
            f"part of the mesh cannot be oriented (it is one-sided, like a Moebius strip): "
            f"faces still disagree across {conflicts} of its edges"
        )
    # the same faces, some reversed: valid by construction (and shared when none turned)
    return Mesh.trusted(mesh.vertices, fi, mesh.face_offsets, mesh.point_data, mesh.face_data)


@node("mesh.flip", version=1)
def flip(mesh: Mesh) -> Mesh:
    """Reverse every face (inside out), keeping each face's first vertex.

    Parameters
    ----------
    mesh : Mesh
        The mesh to turn.
    """
    return Mesh(
        mesh.vertices,
        meshops.reverse_faces(mesh.face_indices, mesh.face_offsets),
        mesh.face_offsets,
        mesh.point_data,
        mesh.face_data,
    )


@node("mesh.cap", version=1)
def cap(mesh: Mesh, *, ctx: Context) -> Mesh:
    """Fill every boundary loop, so an open tube comes out watertight.

    A planar loop becomes its polygon, triangulated by ear clipping in its plane (concave
    outlines stay inside); any other loop a fan of triangles to its centroid. The new
    faces run each loop opposite to its neighbours, so orientation stays consistent.

    A flat open sheet (a part lying in one plane, e.g. ``mesh.plane`` or two triangles of a
    square) has nothing to enclose: its outline's cap lies on the sheet itself, giving a
    two-sided shell of zero volume (doubled faces, often non-manifold edges) that no slicer
    prints. It is still capped as asked, with a warning; ``mesh.solidify`` is the way to make
    a flat sheet printable (it gives it a thickness).

    Parameters
    ----------
    mesh : Mesh
        An oriented manifold mesh (mesh.weld and mesh.orient make one).
    """
    v, fi, fo = _topology("mesh", _clipping, ctx, kr.cap, *_arrays(mesh))
    # the old faces and triangles of their own loops' vertices: valid by construction
    out = Mesh.trusted(v, fi, fo, **carry.carried(mesh, *_cap_rules(mesh, v, fi, fo)))
    if out.n_faces > mesh.n_faces:
        flat = kr.flat_open_parts(*_arrays(mesh))
        if flat:
            ctx.warn(
                f"{flat} part{'s' if flat != 1 else ''} of the mesh "
                f"{'are flat open sheets' if flat != 1 else 'is a flat open sheet'}: capping "
                "its outline lays the cap on the sheet, a two-sided shell of zero volume "
                "(not printable); use mesh.solidify to give a flat sheet a thickness"
            )
    return out


def _cap_rules(mesh: Mesh, v: np.ndarray, fi: np.ndarray, fo: np.ndarray) -> tuple:
    """The old vertices and faces keep theirs; a fan's centre vertex gets the mean of its
    loop's vertices (the centre is their mean too), a cap face 0."""
    n, f = mesh.n_vertices, mesh.n_faces
    caps = fi[mesh.face_offsets[-1] :].reshape(-1, 3)
    fan = caps[caps[:, 0] >= n]
    count = np.bincount(fan[:, 0] - n, minlength=len(v) - n)
    rows = np.concatenate([np.arange(n), fan[:, 0]])
    index = np.concatenate([np.arange(n), fan[:, 1]])
    weight = np.concatenate([np.ones(n), 1.0 / count[fan[:, 0] - n]])
    faces = np.concatenate([np.arange(f), np.full(fo.size - 1 - f, -1)])
    return carry.mix(rows, index, weight, len(v)), carry.copy(faces)


@node("mesh.solidify", version=2)
def solidify(
    mesh: Mesh,
    thickness: Annotated[float, Range(min=0)],
    offset: Annotated[float, Range(min=-1, max=1)] = 0.0,
    thickness_map: Annotated[Expression | None, Variables("x", "y", "z", "thickness")] = None,
    planar_rims: bool = True,
    *,
    ctx: Context,
) -> Mesh:
    """Thicken a surface into a closed shell: two offset copies joined along the rims.

    Vertices move along angle-weighted normals (Thuermer & Wuethrich 1998); every boundary
    edge gets a quad joining the two sides. An oriented manifold surface, open or closed,
    gives a watertight, outward shell; a closed one gives a hollow solid. The wall stays
    clean while the thickness is below the surface's smallest radius of curvature.

    Parameters
    ----------
    mesh : Mesh
        An oriented manifold surface.
    thickness : float
        Wall thickness, > 0 (an expression like "=wall" reads the graph's params).
    offset : float
        Where the wall sits: -1 behind the surface (inside), 0 centred, 1 in front.
    thickness_map : Expression | None
        A wall that varies: the thickness at each vertex as an expression in its position
        x, y, z and ``thickness``, e.g. "thickness * (1 + z / 5)". Each value must be > 0.
    planar_rims : bool
        Keep every planar boundary loop in its own plane: its vertices move along their
        normals projected into the plane (the wall's thickness kept), so a shade whose
        bottom rim lies on z = 0 still stands on z = 0. Loops that are not planar, or
        whose surface lies nearly in the loop's plane, move along their normals.
    """
    if thickness <= 0:
        raise InputError("thickness", f"thickness must be > 0, got {thickness:g}")
    ctx.guard(3 * mesh.face_indices.size, "face corners")
    t: float | np.ndarray = thickness
    if thickness_map is not None:
        v = mesh.vertices
        t = np.broadcast_to(
            np.asarray(thickness_map(x=v[:, 0], y=v[:, 1], z=v[:, 2], thickness=thickness), float),
            (mesh.n_vertices,),
        )
        bad = np.flatnonzero(~(np.isfinite(t) & (t > 0)))
        if bad.size:
            i = int(bad[0])
            raise InputError(
                "thickness_map",
                f"{getattr(thickness_map, 'text', 'the expression')!r} gives {t[i]:g} at vertex "
                f"{i} ({', '.join(f'{c:.6g}' for c in v[i])}); a thickness must be > 0",
            )
    try:
        arrays = _topology("mesh", ks.solidify, *_arrays(mesh), t, offset, planar_rims)
    except ValueError as exc:
        raise InputError("mesh", str(exc)) from None
    port, what = (
        ("thickness_map", f"the thickness map's values (up to {float(np.max(t)):g})")
        if thickness_map is not None
        else ("thickness", f"thickness {thickness:g}")
    )
    v, fi, fo = _within_floats(arrays, port, f"{what} with offset {offset:g}")
    # front and back copies of every vertex and face, a rim quad per boundary edge
    he = mesh.halfedges
    points = carry.copy(np.tile(np.arange(mesh.n_vertices), 2))
    rims = he.face[he.boundary_halfedges]
    faces = carry.copy(np.concatenate([np.arange(mesh.n_faces)] * 2 + [rims]))
    return Mesh(v, fi, fo, **carry.carried(mesh, points, faces))


# -------------------------------------------------------------------------------- booleans


def _solid(port: str, fn: Callable[..., Any], *args: Any) -> Any:
    try:
        return fn(*args)
    except kb.NotSolidError as exc:
        raise InputError(port, str(exc)) from None


@node("mesh.boolean", version=1)
def boolean(
    a: Mesh, b: Mesh, operation: kb.Operation = kb.Operation.union, *, ctx: Context
) -> Mesh:
    """Union, difference (a minus b) or intersection of two solids, through manifold3d.

    Both meshes must be closed, manifold and outward; anything else is refused with the
    count of open or non-manifold edges and where one is. The result is a manifold
    triangle mesh.

    Parameters
    ----------
    a : Mesh
        The first solid.
    b : Mesh
        The second solid (the one removed by difference).
    operation : Operation
        union, difference or intersection.
    """
    attributed = bool(a.point_data or b.point_data or a.face_data or b.face_data)
    if attributed:
        points, faces = _joined([a, b], ctx)
        pa, pb = _split_props(points, [a.n_vertices, b.n_vertices])
        ma = _solid("a", _clipping, ctx, kab.to_manifold, *_arrays(a), pa, 0, "the mesh")
        mb = _solid("b", _clipping, ctx, kab.to_manifold, *_arrays(b), pb, a.n_faces, "the mesh")
    else:
        ma = _solid("a", _clipping, ctx, kb.to_manifold, *_arrays(a), "the mesh")
        mb = _solid("b", _clipping, ctx, kb.to_manifold, *_arrays(b), "the mesh")
    for port, mesh, m in (("a", a, ma), ("b", b, mb)):
        if m.is_empty() and mesh.n_faces:
            ctx.warn(f"input {port} bounds no volume (its faces collapsed): an empty solid")
    try:
        both = kb.combine(ma, mb, operation, whats=("the mesh", "the mesh"))
    except kb.NotSolidError as exc:
        raise InputError("ab"[exc.operand or 0], str(exc)) from None
    if attributed:
        out = _attributed(*kab.from_manifold(both, pa.shape[1]), points, faces)
    else:
        out = Mesh(*kb.from_manifold(both))
    if out.n_faces == 0:
        ctx.warn(f"the {kb.Operation(operation).value} is empty")
    return out


@node("mesh.union", version=1)
def union(meshes: list[Mesh], *, ctx: Context) -> Mesh:
    """The union of several solids at once, through manifold3d.

    Parameters
    ----------
    meshes : list[Mesh]
        Closed, manifold, outward meshes; they may overlap.
    """
    ctx.guard(sum(m.n_faces for m in meshes), "faces")
    if not any(m.point_data or m.face_data for m in meshes):
        out = Mesh(*_solid("meshes", _clipping, ctx, kb.union, [_arrays(m) for m in meshes]))
    else:
        points, faces = _joined(meshes, ctx)
        props = _split_props(points, [m.n_vertices for m in meshes])
        v, fi, fo, p, face = _solid(
            "meshes", _clipping, ctx, kab.union, [_arrays(m) for m in meshes], props
        )
        out = _attributed(v, fi, fo, p, face, points, faces)
    if out.n_faces == 0 and any(m.n_faces for m in meshes):
        ctx.warn("the union is empty: every mesh bounds no volume (their faces collapsed)")
    return out


def _joined(meshes: list[Mesh], ctx: Context) -> tuple[dict, dict]:
    points, p_bad = carry.concat([m.point_data for m in meshes], [m.n_vertices for m in meshes])
    faces, f_bad = carry.concat([m.face_data for m in meshes], [m.n_faces for m in meshes])
    for name in p_bad + f_bad:
        ctx.warn(f"attribute {name!r} has different shapes on the inputs; it was dropped")
    return points, faces


def _split_props(points: dict, sizes: list[int]) -> list[np.ndarray]:
    stacked = carry.columns(np.zeros((sum(sizes), 3)), points)[:, 3:]
    return np.split(stacked, np.cumsum(sizes)[:-1])


def _attributed(
    v: np.ndarray,
    fi: np.ndarray,
    fo: np.ndarray,
    props: np.ndarray,
    face: np.ndarray,
    points: dict,
    faces: dict,
) -> Mesh:
    """A boolean's result with its point attributes (interpolated by manifold3d) and face
    attributes (from each triangle's source face)."""
    _, point_data = carry.split_columns(np.column_stack([v, props]), points)
    face_data = {k: a[face] for k, a in faces.items()}
    return Mesh(v, fi, fo, point_data, face_data)


# -------------------------------------------------------------------------------- measures


class MeshMeasures(NamedTuple):
    area: float
    volume: float
    watertight: bool
    size: Vec3
    center: Vec3
    faces: int


@node("mesh.measure", version=1)
def measure(mesh: Mesh, *, ctx: Context) -> MeshMeasures:
    """Area, volume, watertightness, bounding box and face count of a mesh.

    Outputs: ``area`` (sum of face areas), ``volume`` (enclosed volume by the divergence
    theorem; 0, with a warning, for a mesh that is not watertight), ``watertight`` (every
    edge on exactly two faces), ``size`` and ``center`` of the bounding box, ``faces``.

    The volume is signed: a closed mesh whose faces point inward measures negative, with a
    warning (``mesh.orient`` turns it outward); a closed mesh whose faces disagree across
    some edges warns that its volume means nothing until it is oriented.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh.
    """
    watertight = mesh.is_watertight
    volume = mesh.volume if watertight else 0.0
    if mesh.n_faces == 0:
        ctx.warn("mesh has no faces: area and volume 0")
    elif not watertight:
        open_edges = int(np.count_nonzero(mesh.edge_table.counts != 2))
        ctx.warn(f"mesh is not watertight ({open_edges} open or non-manifold edges): volume 0")
    else:
        disagree = int(np.count_nonzero(mesh.edge_table.same_way))
        if disagree:
            ctx.warn(
                f"the faces disagree in orientation across {disagree} edges, so the volume "
                f"({volume:g}) means nothing; mesh.orient makes them agree"
            )
        elif volume < 0:
            ctx.warn(
                f"the mesh faces inward: its volume is negative ({volume:g}); mesh.orient "
                "turns it outward"
            )
    lo, hi = mesh.bounds
    return MeshMeasures(
        area=mesh.area,
        volume=float(volume),
        watertight=watertight,
        size=[float(x) for x in hi - lo],  # type: ignore[arg-type]
        center=[float(x) for x in (lo + hi) / 2],  # type: ignore[arg-type]
        faces=mesh.n_faces,
    )
