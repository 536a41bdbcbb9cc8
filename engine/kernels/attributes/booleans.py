"""Booleans that carry attributes, through manifold3d's vertex properties and face ids.

manifold3d keeps any number of properties per vertex beside x, y, z and interpolates them
linearly (barycentrically) at the vertices a boolean creates, so a point attribute that
is linear in space stays exactly linear. Each input triangle carries the id of the face it
was cut from (``face_id``); the ids of the second and later inputs are offset by the faces
before them, so every output triangle names its source face among all inputs.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..mesh import boolean as kb
from ..mesh.meshops import triangulate

__all__ = ["from_manifold", "to_manifold"]


def to_manifold(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    properties: np.ndarray,
    first_face: int,
    what: str = "the mesh",
    max_tests: int | None = None,
    fuse: bool = True,
) -> object:
    """A ``manifold3d.Manifold`` with ``properties`` (n, k) per vertex and each triangle's
    face id ``first_face + its face``; checked as :func:`..mesh.boolean.to_manifold`."""
    import manifold3d

    checked = kb.to_manifold(vertices, face_indices, face_offsets, what, max_tests, fuse=False)
    if checked.is_empty():  # type: ignore[attr-defined]
        return checked  # collapsed: the empty solid, as without attributes
    fo = np.asarray(face_offsets, dtype=np.int64)
    fi = np.asarray(face_indices, dtype=np.int64)
    used = np.zeros(len(vertices), bool)
    used[fi] = True  # as kb.to_manifold: an unused vertex would still set the tolerance
    renumber = np.cumsum(used) - 1
    v = np.asarray(vertices, dtype=np.float64)[used]
    _, tris, _ = triangulate(v, renumber[fi], fo, max_tests=max_tests)
    parent = first_face + np.repeat(np.arange(fo.size - 1, dtype=np.int64), np.diff(fo) - 2)
    props = np.ascontiguousarray(np.column_stack([v, properties[used]]), dtype=np.float64)
    mesh = manifold3d.Mesh64(
        vert_properties=props,
        tri_verts=np.ascontiguousarray(tris, dtype=np.int64).view(np.uint64).reshape(-1, 3),
        face_id=parent.view(np.uint64),
    )
    m = manifold3d.Manifold(mesh)
    return kb._fused(m, what) if fuse else m  # overlapping parts fused, as kb does


def from_manifold(
    m: object, n_properties: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Flat arrays, the interpolated properties (n, k) and each triangle's face id."""
    mesh = m.to_mesh64()  # type: ignore[attr-defined]
    vp = np.asarray(mesh.vert_properties, dtype=np.float64).reshape(-1, 3 + n_properties)
    tri = np.ascontiguousarray(mesh.tri_verts).view(np.int64).reshape(-1)
    face = np.asarray(mesh.face_id).view(np.int64).reshape(-1)
    fo = np.arange(0, tri.size + 1, 3, dtype=np.int64)
    # manifold3d keeps a vertex once per set of properties it has (a seam between the
    # inputs, where each side interpolated its own); its merge lists say which are one
    # point: join them, so the result is one closed surface again
    to = np.arange(len(vp), dtype=np.int64)
    src = np.asarray(mesh.merge_from_vert).view(np.int64).reshape(-1)
    dst = np.asarray(mesh.merge_to_vert).view(np.int64).reshape(-1)
    to[src] = dst
    tri = to[tri]
    used = np.zeros(len(vp), dtype=bool)
    used[tri] = True
    renumber = np.cumsum(used) - 1
    vp = vp[used]
    return np.ascontiguousarray(vp[:, :3]), renumber[tri], fo, vp[:, 3:], face


def union(
    meshes: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]],
    properties: Sequence[np.ndarray],
    max_tests: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Union of several solids (and of the parts within each), carrying properties."""
    import manifold3d

    solids, first = [], 0
    for i, (m, props) in enumerate(zip(meshes, properties, strict=True)):
        solids.append(to_manifold(*m, props, first, f"mesh {i}", max_tests, fuse=False))
        first += len(m[2]) - 1
    if solids:
        kb.check_precision(solids, [f"mesh {i}" for i in range(len(solids))])
    parts = [p for s in solids for p in s.decompose()]
    k = properties[0].shape[1] if properties else 0
    if not parts:
        empty = np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(1, np.int64)
        return (*empty, np.zeros((0, k)), np.zeros(0, np.int64))
    return from_manifold(manifold3d.Manifold.batch_boolean(parts, manifold3d.OpType.Add), k)
