"""``mesh.split``: a mesh's connected parts, each its own mesh
(:mod:`formgraph.kernels.mesh.parts`)."""

from __future__ import annotations

from formgraph.core.registry import Context, node
from formgraph.geometry import Mesh
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.mesh import parts as kparts


@node("mesh.split", version=1)
def split(mesh: Mesh, *, ctx: Context) -> list[Mesh]:
    """The connected parts of a mesh, each its own mesh, largest first.

    Faces belong to one part when they are joined through shared edges once coincident
    vertices are merged (a triangle soup as STL holds it splits as its welded mesh would;
    two parts that touch at a single point stay two). Closed parts come first by volume
    (the enclosed one, whatever the orientation), then open ones by area. Each part is
    made on the merged vertices it uses: a point attribute comes from the first of the
    coincident vertices, a face attribute from the face.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh (a soup too).

    Example
    -------
    ``pieces: {type: mesh.split, mesh: "@scan"}``, then ``{type: export.3mf, meshes:
    "@pieces"}`` writes one object per part
    """
    if mesh.n_faces == 0:
        ctx.warn("mesh has no faces: no parts")
        return []
    parts = kparts.face_parts(*mesh.arrays)
    out = []
    for v, fi, fo, vsrc, fsrc in kparts.split(*mesh.arrays, parts):  # one step per part
        data = carry.carried(mesh, carry.copy(vsrc), carry.copy(fsrc))
        out.append(Mesh.trusted(v, fi, fo, **data))
    return out
