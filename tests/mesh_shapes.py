"""Canonical meshes for the mesh tests, as (vertices, face_indices, face_offsets)."""

from __future__ import annotations

import numpy as np

from formgraph.kernels.mesh import grid_faces


def flat(faces: list[list[int]]) -> tuple[np.ndarray, np.ndarray]:
    fi = np.concatenate([np.asarray(f, dtype=np.int64) for f in faces])
    fo = np.concatenate([[0], np.cumsum([len(f) for f in faces])]).astype(np.int64)
    return fi, fo


def cube(half: float = 1.0):
    """Cube [-half, half]^3, six outward quads."""
    v = np.array([[x, y, z] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)], dtype=float) * half
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    return (v, *flat(faces))


def tetrahedron():
    v = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    faces = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]
    return (v, *flat(faces))


def prism(n: int, height: float = 1.0):
    """n-gon prism: two n-gon caps and n quads."""
    a = 2 * np.pi * np.arange(n) / n
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(n)], axis=1)
    v = np.concatenate([ring, ring + [0, 0, height]])
    faces = [list(range(n - 1, -1, -1)), list(range(n, 2 * n))]
    faces += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    return (v, *flat(faces))


def antiprism(n: int, height: float = 1.0):
    """n-gon antiprism: two n-gon caps and 2n triangles."""
    a = 2 * np.pi * np.arange(n) / n
    b = a + np.pi / n
    v = np.concatenate(
        [
            np.stack([np.cos(a), np.sin(a), np.zeros(n)], axis=1),
            np.stack([np.cos(b), np.sin(b), np.full(n, height)], axis=1),
        ]
    )
    faces = [list(range(n - 1, -1, -1)), list(range(n, 2 * n))]
    for i in range(n):
        j = (i + 1) % n
        faces += [[i, j, n + i], [j, n + j, n + i]]
    return (v, *flat(faces))


def torus(nu: int = 8, nv: int = 6, r_major: float = 3.0, r_minor: float = 1.0):
    u = np.linspace(0, 2 * np.pi, nu, endpoint=False)[:, None]
    w = np.linspace(0, 2 * np.pi, nv, endpoint=False)[None, :]
    ring = r_major + r_minor * np.cos(w)
    v = np.stack(
        np.broadcast_arrays(ring * np.cos(u), ring * np.sin(u), r_minor * np.sin(w)), axis=-1
    ).reshape(-1, 3)
    return (v, *grid_faces(nu, nv, closed_u=True, closed_v=True))


def grid(nu: int, nv: int, z: np.ndarray | None = None):
    """Open (nu x nv)-vertex grid, x = i, y = j, counter-clockwise seen from +z."""
    i, j = np.meshgrid(np.arange(nu, dtype=float), np.arange(nv, dtype=float), indexing="ij")
    zz = np.zeros((nu, nv)) if z is None else z
    v = np.stack([i, j, zz], axis=-1).reshape(-1, 3)
    return (v, *grid_faces(nu, nv))


def split_quads(fi: np.ndarray, fo: np.ndarray, which: np.ndarray):
    """Split the quads flagged in ``which`` along their 0-2 diagonal into two triangles."""
    faces = [fi[fo[f] : fo[f + 1]].tolist() for f in range(fo.size - 1)]
    out = []
    for f, face in enumerate(faces):
        if which[f] and len(face) == 4:
            out += [[face[0], face[1], face[2]], [face[0], face[2], face[3]]]
        else:
            out.append(face)
    return flat(out)


def pillow():
    """Two skew quads glued along all four edges: every vertex has valence 2."""
    v = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    return (v, *flat([[0, 1, 2, 3], [0, 3, 2, 1]]))


def quad_and_pentagon():
    """A closed mesh: two pentagons glued along their whole boundary; vertex 4 splits what
    would be a quad's edge (valence 2)."""
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.2], [0, 1, 0], [0.5, 0, 0.5]], dtype=float)
    return (v, *flat([[0, 4, 1, 2, 3], [0, 3, 2, 1, 4]]))
