"""3MF builds expanded: the object graph counted against the budget before anything is
copied, then every placement of a mesh object made by one vectorized transform.

A build item places an object; an object of components places other objects, each under
its own transform, to any depth. What one placement of each object makes (vertices,
triangles, placements, with components' placements counted too: each costs work) is
summed up the object graph once, children before parents (:func:`topological`, iterative,
cycles refused), so a fan-out of 10 components over 10 levels is 10^10 triangles refused
in the time it takes to read its 800 bytes. Then the placements flow down the graph as
arrays of (k, 4, 3) transforms and output offsets, one batch per object, and each mesh
object's k placements are one ``einsum`` (written straight into the output when they
follow one another there). Vertex colours come from the property groups the triangles'
corners (or the object) point into.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["Components", "MeshObject", "Read3MF", "build"]


class Read3MF(NamedTuple):
    """What a 3MF package builds, every item placed and joined, in millimetres."""

    vertices: np.ndarray  # (n, 3) float64
    triangles: np.ndarray  # (t, 3) int64
    colors: np.ndarray | None  # (n, 4) RGBA in 0..1 when every placed mesh has colours
    items: int  # build items


class MeshObject(NamedTuple):
    vertices: np.ndarray  # (n, 3), millimetres
    triangles: np.ndarray  # (t, 3)
    props: np.ndarray | None  # (t, 4): the triangle's pid, p1, p2, p3 (-1: not given)
    pid: int  # the object's property group (-1: none)
    pindex: int


class Components(NamedTuple):
    children: list  # (part, objectid) per component
    transforms: np.ndarray  # (k, 4, 3), translations in millimetres


def build(parts: dict, root: str, max_elements: int) -> Read3MF:
    objects: dict[tuple[str, int], MeshObject | Components] = {
        (name, oid): o for name, part in parts.items() for oid, o in part.objects.items()
    }
    top = parts[root]
    ids = np.concatenate([i for i, _, _ in top.items]) if top.items else np.zeros(0, np.int64)
    transforms = np.concatenate([m for _, m, _ in top.items]) if top.items else np.zeros((0, 4, 3))
    # the items' objects as codes into the few distinct (part, id) pairs: every step below
    # is an array operation over the items, however many millions
    if any(p for _, _, ps in top.items for p in ps):  # Production items naming other parts
        names = [p or root for _, _, ps in top.items for p in ps]
        _, part_code = np.unique(np.array(names, dtype=object), return_inverse=True)
        pair = part_code.astype(np.int64) * (int(ids.max(initial=0)) + 1) + ids
    else:
        names, pair = None, ids
    _, first, item_code = np.unique(pair, return_index=True, return_inverse=True)
    keys = [(names[k] if names else root, int(ids[k])) for k in first]
    for key in keys:
        if key not in objects:
            raise ValueError(f"a build item names object {key[1]} ({key[0]!r}), which is not there")
    order = topological(objects, set(keys))
    # what one placement of each object makes: vertices, triangles, placements (Python
    # ints: a fan-out multiplies past int64 long before it is refused)
    size: dict = {}
    for key in reversed(order):
        o = objects[key]
        if isinstance(o, MeshObject):
            size[key] = (len(o.vertices), len(o.triangles), 1)
        else:  # every placement counts, an object of components too: each costs work
            size[key] = (*(sum(size[c][k] for c in o.children) for k in range(2)),
                         1 + sum(size[c][2] for c in o.children))  # fmt: skip
    counts = np.bincount(item_code, minlength=len(keys))
    totals = [sum(int(n) * size[k][j] for k, n in zip(keys, counts, strict=True)) for j in range(3)]
    if max(totals) > max_elements:
        raise ValueError(
            f"the build places {totals[1]:,} triangles and {totals[0]:,} vertices in "
            f"{totals[2]:,} object placements (from {len(item_code):,} build items through "
            f"their components), over the budget of {max_elements:,}: refused before expanding"
        )
    nv, nt = totals[0], totals[1]
    # each placement of an object: its transform and where its vertices and triangles go
    per_v = np.array([size[k][0] for k in keys], np.int64)[item_code]
    per_t = np.array([size[k][1] for k in keys], np.int64)[item_code]
    starts_v, starts_t = np.cumsum(per_v) - per_v, np.cumsum(per_t) - per_t
    placed: dict = {}
    if len(keys) == 1:  # every item places the same object: no gathered copies
        placed[keys[0]] = [(transforms, starts_v, starts_t)]
    else:
        grouped = np.argsort(item_code, kind="stable")
        bounds = np.concatenate([[0], np.cumsum(counts)])
        for u, key in enumerate(keys):
            w = grouped[bounds[u] : bounds[u + 1]]
            placed[key] = [(transforms[w], starts_v[w], starts_t[w])]
    del transforms, starts_v, starts_t, per_v, per_t
    top.items = []  # the items' arrays live on in the placements only
    out_v = np.empty((nv, 3))
    out_t = np.empty((nt, 3), np.int64)
    colors = _Colors(parts, nv)
    for key in order:
        batches = placed.pop(key, [])
        if not batches:
            continue
        if len(batches) == 1:
            m, sv, st = batches[0]
        else:
            m, sv, st = (np.concatenate([b[j] for b in batches]) for j in range(3))
        del batches
        o = objects[key]
        if isinstance(o, MeshObject):
            _place(o, m, sv, st, out_v, out_t)
            colors.place(key, o, sv)
            continue
        dv = dt = 0
        for child, c in zip(o.children, o.transforms, strict=True):
            # the child's placement: its component transform, then the parent's
            full = np.concatenate([c[:3] @ m[:, :3], (c[3] @ m[:, :3] + m[:, 3])[:, None]], 1)
            if size[child][0] or size[child][1]:  # nothing to place in an empty one
                placed.setdefault(child, []).append((full, sv + dv, st + dt))
            dv, dt = dv + size[child][0], dt + size[child][1]
    return Read3MF(out_v, out_t, colors.result(), len(item_code))


def topological(objects: dict, roots: set) -> list:
    """The objects reachable from ``roots``, every parent before its components; a cycle is
    refused (iteratively: no recursion however deep the components nest)."""
    state: dict = {}  # 1: on the path, 2: done
    post: list = []
    for root in sorted(roots, key=str):
        if root in state:
            continue
        stack = [(root, iter(_children(objects, root)))]
        state[root] = 1
        while stack:
            key, it = stack[-1]
            child = next(it, None)
            if child is None:
                stack.pop()
                state[key] = 2
                post.append(key)
                continue
            if child not in objects:
                raise ValueError(
                    f"object {key[1]} ({key[0]!r}) has a component naming object {child[1]} "
                    f"({child[0]!r}), which is not there"
                )
            if state.get(child) == 1:
                raise ValueError(
                    f"object {child[1]} ({child[0]!r}) contains itself through its components "
                    "(a cycle)"
                )
            if child not in state:
                state[child] = 1
                stack.append((child, iter(_children(objects, child))))
    return post[::-1]


def _children(objects: dict, key) -> list:
    o = objects[key]
    return list(dict.fromkeys(o.children)) if isinstance(o, Components) else []


def _place(o: MeshObject, m: np.ndarray, sv: np.ndarray, st: np.ndarray, out_v, out_t) -> None:
    """Every placement of one mesh, in one vectorized pass: (k, n, 3) copies written where
    each placement's vertices and triangles go (straight into the output when the
    placements follow one another there, as the items of one object do)."""
    n, t, k = len(o.vertices), len(o.triangles), len(m)
    if n:
        if _consecutive(sv, n):
            view = out_v[sv[0] : sv[0] + k * n].reshape(k, n, 3)
            np.einsum("nj,kji->kni", o.vertices, m[:, :3], out=view)
            view += m[:, None, 3]
        else:
            copies = np.einsum("nj,kji->kni", o.vertices, m[:, :3]) + m[:, None, 3]
            out_v[(sv[:, None] + np.arange(n)).ravel()] = copies.reshape(-1, 3)
    if t:
        if _consecutive(st, t):
            view = out_t[st[0] : st[0] + k * t].reshape(k, t, 3)
            np.add(o.triangles[None], sv[:, None, None], out=view)
        else:
            copies = (o.triangles[None] + sv[:, None, None]).reshape(-1, 3)
            out_t[(st[:, None] + np.arange(t)).ravel()] = copies


def _consecutive(starts: np.ndarray, size: int) -> bool:
    """Whether placement i starts ``size`` after placement i - 1, for every i."""
    return bool(starts.size) and bool(np.all(np.diff(starts) == size))


class _Colors:
    """A colour a placed vertex, from the property groups its mesh's triangles and object
    point into; None unless every placed mesh has colours."""

    def __init__(self, parts: dict, n: int):
        self.parts = parts
        self.out = np.zeros((n, 4))
        self.complete = n > 0
        self.cache: dict = {}

    def place(self, key, o: MeshObject, starts: np.ndarray) -> None:
        if not self.complete:
            return
        if key not in self.cache:
            self.cache[key] = _mesh_colors(self.parts[key[0]], key[1], o)
        c = self.cache[key]
        if c is None:
            self.complete = False
            return
        self.out[(starts[:, None] + np.arange(len(c))).ravel()] = np.tile(c, (len(starts), 1))

    def result(self) -> np.ndarray | None:
        return self.out if self.complete else None


def _mesh_colors(part, oid: int, o: MeshObject) -> np.ndarray | None:
    """A colour a vertex of one mesh object, or None when it has none: the object's default
    (its pid and pindex) where its triangles name none, each corner's where they do."""
    groups, n = part.groups, len(o.vertices)
    out = np.zeros((n, 4))
    has_default = o.pid in groups
    if has_default:
        group = groups[o.pid]
        if not 0 <= o.pindex < len(group):
            raise ValueError(
                f"{part.name!r}, object {oid}: its pindex {o.pindex} is outside its property "
                f"group ({len(group)} entries)"
            )
        out[:] = group[o.pindex]
    if o.props is None:
        return out if has_default else None
    pid = np.where(o.props[:, 0] >= 0, o.props[:, 0], o.pid)
    given = o.props[:, 1] >= 0
    if not has_default and not (given & np.isin(pid, list(groups))).all():
        return None  # some corner has no colour to take
    for gid in np.unique(pid[given]):
        if gid not in groups:
            continue  # a texture or composite group: no colour of its own
        rows = given & (pid == gid)
        idx = o.props[rows, 1:]
        group = groups[int(gid)]
        if idx.max(initial=0) >= len(group):
            raise ValueError(
                f"{part.name!r}, object {oid}: a triangle's colour index is outside property "
                f"group {gid} ({len(group)} entries)"
            )
        out[o.triangles[rows].ravel()] = group[idx.ravel()]
    return out
