"""Mesh primitives: explicit faces, box, cylinder, sphere, torus and plane (closed ones
watertight and outward; :mod:`formgraph.kernels.mesh.primitives`).
"""

from __future__ import annotations

from typing import Annotated

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import Faces, Vec3
from formgraph.geometry import Mesh, Points
from formgraph.kernels.mesh import (
    meshops,
)
from formgraph.kernels.mesh import primitives as kp
from formgraph.nodes.mesh._common import (
    fmt,
    within_floats,
)

# The bytes a quad mesh takes a face (about a vertex a face): 3 coordinates, 4 corner
# indices and an offset, 8 bytes each -- what a primitive's guard charges against memory.
MESH_BYTES = 8 * (3 + 4 + 1)


@node("mesh.from_faces", version=1)
def from_faces(vertices: Points, faces: Faces) -> Mesh:
    """A polygon mesh from vertices and faces (lists of vertex indices), checked.

    Faces may mix sizes (triangles, quads, n-gons) and list their vertices
    counter-clockwise seen from outside. The mesh must be an oriented manifold, possibly
    with boundary: every index names a vertex, a face has at least 3 distinct vertices, an
    edge belongs to at most two faces, and neighbouring faces run their shared edge in
    opposite directions.

    Parameters
    ----------
    vertices : Points
        The vertex positions; [x, y] gets z = 0. Their point attributes become the mesh's.
    faces : list[list[int]]
        One list of 0-based vertex indices per face.

    Example
    -------
    ``quad: {type: mesh.from_faces, vertices: [[0, 0], [1, 0], [1, 1], [0, 1]],
    faces: [[0, 1, 2, 3]]}``
    """
    try:
        fi, fo = meshops.faces_from_lists(faces)
        v, fi, fo = meshops.validate_faces(vertices.xyz, fi, fo)
    except ValueError as exc:
        raise InputError("faces", str(exc)) from None
    return Mesh(v, fi, fo, vertices.point_data)  # the points' attributes on the vertices


@node("mesh.box", version=1)
def box(size: float | Vec3 = (1.0, 1.0, 1.0), center: Vec3 = (0.0, 0.0, 0.0)) -> Mesh:
    """An axis-aligned box of six outward quads.

    Parameters
    ----------
    size : float | Vec3
        Edge lengths [sx, sy, sz], or one number for a cube; each > 0.
    center : Vec3
        Centre of the box.
    """
    try:
        return Mesh(*meshops.box(size, center))
    except ValueError as exc:
        raise InputError("size", str(exc)) from None


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
    what = f"radius {radius:g}, height {height:g} and center {fmt(center)}"
    return Mesh(*within_floats(arrays, port, what))


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
    faces = segments * max(2, segments // 2)
    ctx.guard(faces, "faces", nbytes=MESH_BYTES * faces, port="segments")
    try:
        arrays = kp.sphere(radius, segments, center)
    except ValueError as exc:
        raise InputError("radius", str(exc)) from None
    what = f"radius {radius:g} and center {fmt(center)}"
    return Mesh(*within_floats(arrays, "radius", what))


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
    port = "segments_u" if segments_u >= segments_v else "segments_v"
    ctx.guard(
        segments_u * segments_v, "faces", nbytes=MESH_BYTES * segments_u * segments_v, port=port
    )
    try:
        arrays = kp.torus(major, minor, segments_u, segments_v, center)
    except ValueError as exc:
        raise InputError("minor", str(exc)) from None
    what = f"major {major:g}, minor {minor:g} and center {fmt(center)}"
    return Mesh(*within_floats(arrays, "major", what))


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
    count = float(divisions[0] + 1) * float(divisions[1] + 1)
    ctx.guard(count, "vertices", nbytes=MESH_BYTES * count, port="divisions")
    try:
        arrays = kp.plane(size, divisions, center)
    except ValueError as exc:
        raise InputError("size" if "size" in str(exc) else "divisions", str(exc)) from None
    return Mesh(*within_floats(arrays, "size", f"size {fmt(size)} and center {fmt(center)}"))
