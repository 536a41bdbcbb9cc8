"""What ``field.mesh`` checks a smooth union against: the same recipe with its unions sharp,
and the planes of its inputs' flat faces (walked without recursion: a field is a DAG that
graphs of any depth build). The test itself is :mod:`formgraph.kernels.field.planar`.
"""

from __future__ import annotations

import numpy as np

from formgraph.geometry import Field
from formgraph.kernels.field import planar
from formgraph.kernels.io.meshdata import fan_triangles

_AXES = np.vstack([np.eye(3), -np.eye(3)])


def _children_first(field: Field) -> list[Field]:
    """Every field of the recipe once, each after the fields it is made of."""
    order, seen, stack = [], set(), [(field, False)]
    while stack:
        f, expanded = stack.pop()
        if expanded:
            order.append(f)
        elif id(f) not in seen:
            seen.add(id(f))
            stack.append((f, True))
            stack.extend((c, False) for c in f.children)
    return order


def smooth_unions(field: Field) -> list[float]:
    """The blend radii of the recipe's smooth unions (empty: none)."""
    return sorted(
        {f.args["smooth"] for f in _children_first(field) if f.op == "union" and f.args["smooth"]}
    )


def sharpened(field: Field) -> Field:
    """The recipe with every smooth union made sharp (the rest shared, caches included)."""
    made: dict[int, Field] = {}
    for f in _children_first(field):
        kids = tuple(made[id(c)] for c in f.children)
        if f.op == "union" and f.args["smooth"]:
            made[id(f)] = Field.union(list(kids))
        elif all(k is c for k, c in zip(kids, f.children, strict=True)):
            made[id(f)] = f
        else:
            made[id(f)] = Field(f.op, dict(f.args), kids, f.bounds, f.lipschitz)
    return made[id(field)]


def _own_planes(f: Field) -> np.ndarray:
    """(p, 4) rows ``n, c`` (outward unit normal, ``n . x = c``) of a primitive's flat faces."""
    a = f.args
    if f.op == "box":
        half = a["size"] / 2
        inner = half - min(max(a["radius"], 0.0), half.min())  # the flat part of each face
        has_face = np.array([(np.delete(inner, k) > 0).all() for k in range(3)] * 2)
        c = np.concatenate([a["center"] + half, -(a["center"] - half)])
        return np.column_stack([_AXES, c])[has_face]
    if f.op == "cylinder":
        z, h = a["center"][2], a["height"] / 2
        return np.array([[0, 0, 1, z + h], [0, 0, -1, -(z - h)]], dtype=np.float64)
    if f.op == "from_mesh":
        mesh = a["mesh"]
        tri = fan_triangles(mesh.face_indices, mesh.face_offsets)
        n, c = planar.coplanar_faces(np.asarray(mesh.vertices)[tri])
        return np.column_stack([n, c])
    return np.zeros((0, 4))


def _moved(f: Field, planes: np.ndarray) -> np.ndarray:
    """The planes of ``f``'s child as ``f`` makes them."""
    if not len(planes):
        return planes
    n, c = planes[:, :3], planes[:, 3]
    if f.op == "transform":  # x' = R (s x) + t: n' ~ R (n / s), c' = (c + m . t) / |m|
        a = f.args
        m = (n / a["scale"]) @ a["matrix"].T
        length = np.linalg.norm(m, axis=1)
        return np.column_stack([m / length[:, None], (c + m @ a["translate"]) / length])
    if f.op == "offset":
        return np.column_stack([n, c + f.args["distance"]])
    if f.op == "shell":
        t = f.args["thickness"] / 2
        return np.vstack([np.column_stack([n, c + t]), np.column_stack([-n, -(c - t)])])
    return planes


def flat_faces(field: Field) -> tuple[np.ndarray, np.ndarray]:
    """The planes of the flat faces of every field in the recipe, as they reach the top:
    ``normals (p, 3)`` (outward) and ``offsets (p,)``; a difference's cutter turns its
    faces inward. Repeated planes once."""
    made: dict[int, np.ndarray] = {}
    for f in _children_first(field):
        rows = [_own_planes(f)]
        for k, child in enumerate(f.children):
            sign = -1.0 if f.op == "difference" and k == 1 else 1.0
            rows.append(_moved(f, made[id(child)]) * sign)
        made[id(f)] = np.vstack(rows)
    planes = made[id(field)]
    if not len(planes):
        return np.zeros((0, 3)), np.zeros(0)
    planes = np.unique(np.round(planes, 9), axis=0)
    return planes[:, :3], planes[:, 3]
