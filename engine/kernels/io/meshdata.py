"""What the mesh writers share, and what they check: validated flat face arrays, polygons
fanned into triangles, triangle normals, and the mesh report (open and non-manifold edges,
zero-area faces, orientation) behind the export warnings.

Meshes come as ``vertices`` (n, 3) float64, ``face_indices`` (flat int) and ``face_offsets``
(n_faces + 1,): face ``k`` is ``face_indices[face_offsets[k]:face_offsets[k + 1]]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MeshReport", "check_mesh", "fan_triangles", "mesh_report", "triangle_normals"]


def check_mesh(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    *,
    min_face: int = 3,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validate a flat polygon mesh and return it as contiguous float64 / int64 arrays.

    Parameters
    ----------
    vertices : (n, 3) float
        Finite coordinates.
    face_indices : (m,) int
        Vertex indices, each in ``[0, n)``.
    face_offsets : (n_faces + 1,) int
        Starts at 0, ends at ``m``, each face at least ``min_face`` long.

    Raises
    ------
    ValueError
        With a sentence naming what was expected and what came.
    """
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must be an (n, 3) array, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError("vertices must be finite; found NaN or infinity")
    fi = np.asarray(face_indices)
    fo = np.asarray(face_offsets)
    if fi.ndim != 1 or fo.ndim != 1:
        raise ValueError(
            f"face_indices and face_offsets must be flat arrays, got shapes {fi.shape} and "
            f"{fo.shape}"
        )
    if fi.size and not np.issubdtype(fi.dtype, np.integer):
        raise ValueError(f"face_indices must be integers, got dtype {fi.dtype}")
    if not np.issubdtype(fo.dtype, np.integer) and fo.size:
        raise ValueError(f"face_offsets must be integers, got dtype {fo.dtype}")
    fi = fi.astype(np.int64, copy=False)
    fo = fo.astype(np.int64, copy=False)
    if fo.size == 0 or fo[0] != 0 or fo[-1] != fi.size:
        raise ValueError(
            f"face_offsets must start at 0 and end at len(face_indices) = {fi.size}, got "
            f"{fo[:1].tolist()} ... {fo[-1:].tolist()}"
        )
    sizes = np.diff(fo)
    if sizes.size and sizes.min() < min_face:
        k = int(np.argmin(sizes))
        raise ValueError(
            f"every face needs at least {min_face} vertices, face {k} has {int(sizes[k])}"
        )
    if fi.size and (fi.min() < 0 or fi.max() >= len(v)):
        bad = int(fi[(fi < 0) | (fi >= len(v))][0])
        raise ValueError(f"face index {bad} is out of range for {len(v)} vertices")
    return np.ascontiguousarray(v), np.ascontiguousarray(fi), np.ascontiguousarray(fo)


def fan_triangles(face_indices: np.ndarray, face_offsets: np.ndarray) -> np.ndarray:
    """Triangulate every polygon as a fan from its first vertex, keeping the winding.

    A face ``(a, b, c, d, ...)`` becomes ``(a, b, c), (a, c, d), ...``. Exact for convex
    faces (and for any triangle or planar convex quad); all faces at once, whatever their
    sizes, without grouping by size.

    Parameters
    ----------
    face_indices : (m,) int64
    face_offsets : (n_faces + 1,) int64
        Faces of at least 3 vertices.

    Returns
    -------
    (sum(size - 2), 3) int64
        Triangles in face order.
    """
    sizes = np.diff(face_offsets)
    per_face = sizes - 2
    if np.all(per_face == 1):  # already triangles: nothing to fan
        return face_indices.reshape(-1, 3)
    face = np.repeat(np.arange(sizes.size), per_face)
    first = face_offsets[:-1][face]
    tri_start = np.cumsum(per_face) - per_face
    j = np.arange(face.size) - tri_start[face]  # triangle number within its face
    return np.stack(
        [face_indices[first], face_indices[first + j + 1], face_indices[first + j + 2]], axis=1
    )


def triangle_normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Unit normals from the winding (right-hand rule); (0, 0, 0) for zero-area triangles.

    Parameters
    ----------
    vertices : (n, 3) float64
    triangles : (t, 3) int

    Returns
    -------
    (t, 3) float64
    """
    a = vertices[triangles[:, 0]]
    n = np.cross(vertices[triangles[:, 1]] - a, vertices[triangles[:, 2]] - a)
    length = np.sqrt(np.einsum("ij,ij->i", n, n))
    with np.errstate(invalid="ignore", divide="ignore"):
        n /= length[:, None]
    n[length == 0] = 0.0
    return n


@dataclass(frozen=True)
class MeshReport:
    """What a 3-D printer's slicer will think of a mesh.

    Attributes
    ----------
    n_vertices, n_faces, n_triangles, n_edges : int
        Counts (triangles after fan triangulation; edges undirected).
    boundary_edges : int
        Edges used by one face only (holes).
    nonmanifold_edges : int
        Edges shared by more than two faces.
    misoriented_edges : int
        Edges two faces run through in the same direction (their windings disagree).
    degenerate_triangles : int
        Triangles of zero area (they get a zero normal).
    volume : float
        Signed volume by the divergence theorem; positive when closed and wound outward.
        Meaningful only when the mesh is watertight and consistently oriented.
    """

    n_vertices: int
    n_faces: int
    n_triangles: int
    n_edges: int
    boundary_edges: int
    nonmanifold_edges: int
    misoriented_edges: int
    degenerate_triangles: int
    volume: float

    @property
    def watertight(self) -> bool:
        """Every edge shared by exactly two faces."""
        return self.boundary_edges == 0 and self.nonmanifold_edges == 0

    @property
    def consistently_oriented(self) -> bool:
        """No edge is run through twice in the same direction."""
        return self.misoriented_edges == 0

    def warnings(self) -> list[str]:
        """Sentences about each problem found (empty for a clean, closed, outward mesh)."""
        out = []
        if self.boundary_edges:
            out.append(
                f"mesh is not watertight: {self.boundary_edges} boundary edges "
                "(edges of only one face)"
            )
        if self.nonmanifold_edges:
            out.append(f"mesh has {self.nonmanifold_edges} non-manifold edges (shared by 3+ faces)")
        if self.misoriented_edges:
            out.append(
                f"faces are not consistently oriented: {self.misoriented_edges} edges are run "
                "through in the same direction by two faces"
            )
        elif self.watertight and self.volume < 0:
            out.append(
                f"mesh is inside out: its faces wind inward (signed volume {self.volume:.6g})"
            )
        if self.degenerate_triangles:
            out.append(
                f"{self.degenerate_triangles} triangles have zero area and get a zero normal"
            )
        return out


def mesh_report(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> MeshReport:
    """Count boundary, non-manifold and misoriented edges, degenerate triangles, and the volume.

    Every face contributes its directed edges (a -> b around its winding). An undirected edge
    seen once is a boundary, more than twice non-manifold; a directed edge seen twice means
    two faces cross it the same way, so their orientations disagree. One sort of the edge
    keys (undirected edge, then direction) does the counting for all edges at once.

    Parameters
    ----------
    vertices : (n, 3) float64
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int

    Returns
    -------
    MeshReport
    """
    v, fi, fo = check_mesh(vertices, face_indices, face_offsets)
    nv = max(len(v), 1)
    nxt = np.arange(1, fi.size + 1)
    nxt[fo[1:] - 1] = fo[:-1]  # the last corner of each face wraps to its first
    a, b = fi, fi[nxt]
    # one sort does it all: the key is the undirected edge, then its direction as a last bit
    key = np.sort((np.minimum(a, b) * nv + np.maximum(a, b)) * 2 + (a > b))
    edge = key >> 1
    starts = np.flatnonzero(np.r_[edge.size > 0, edge[1:] != edge[:-1]])
    counts = np.diff(np.r_[starts, edge.size])
    # equal neighbours are the same directed edge twice: count each such edge once
    same = key[1:] == key[:-1]
    misoriented = int(np.count_nonzero(same & ~np.r_[False, same[:-1]]))
    tris = fan_triangles(fi, fo)
    p0, p1, p2 = v[tris[:, 0]], v[tris[:, 1]], v[tris[:, 2]]
    cross = np.cross(p1 - p0, p2 - p0)
    degenerate = int(np.count_nonzero(~np.any(cross, axis=1)))
    # divergence theorem, with the centroid as origin to keep the sum well conditioned
    c = v.mean(axis=0) if len(v) else np.zeros(3)
    volume = float(np.einsum("ij,ij->", p0 - c, np.cross(p1 - c, p2 - c)) / 6.0)
    return MeshReport(
        n_vertices=len(v),
        n_faces=fo.size - 1,
        n_triangles=len(tris),
        n_edges=int(starts.size),
        boundary_edges=int(np.count_nonzero(counts == 1)),
        nonmanifold_edges=int(np.count_nonzero(counts > 2)),
        misoriented_edges=misoriented,
        degenerate_triangles=degenerate,
        volume=volume,
    )
