"""Parts of a mesh chosen by a mask: the faces kept, and the vertices they still use.

One vectorized pass each (no loop per face): a face mask from a point mask (a face is kept
when all its corners are), the faces kept in their order, and the vertices renumbered in
theirs, with the provenance of every kept vertex and face so attributes follow
(:mod:`formgraph.kernels.attributes.propagate`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["faces_of_points", "keep_faces"]


def faces_of_points(
    face_indices: np.ndarray, face_offsets: np.ndarray, keep: np.ndarray
) -> np.ndarray:
    """(n_faces,) bool: the faces whose corners are all in the point mask ``keep`` (n,)."""
    fo = np.asarray(face_offsets, dtype=np.int64)
    if fo.size < 2:
        return np.zeros(0, dtype=bool)
    dropped = (~np.asarray(keep, dtype=bool)[np.asarray(face_indices, dtype=np.int64)]).astype(
        np.int64
    )
    return np.add.reduceat(dropped, fo[:-1]) == 0


def keep_faces(
    face_indices: np.ndarray, face_offsets: np.ndarray, n_vertices: int, keep: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The faces of mask ``keep`` (n_faces,) and only the vertices they use.

    Returns
    -------
    vertex : (k,) int
        The old index of each kept vertex (in the old order).
    face_indices, face_offsets : the kept faces on the new numbering
    face : (f,) int
        The old index of each kept face.
    """
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    keep = np.asarray(keep, dtype=bool)
    face = np.flatnonzero(keep)
    sizes = np.diff(fo)[face]
    corner = np.repeat(keep, np.diff(fo))
    kept = fi[corner]
    used = np.zeros(n_vertices, dtype=bool)
    used[kept] = True
    new = np.cumsum(used) - 1
    out_fo = np.zeros(len(face) + 1, dtype=np.int64)
    np.cumsum(sizes, out=out_fo[1:])
    return np.flatnonzero(used), new[kept], out_fo, face
