"""The marching-cubes table, built from one rule on the cube's faces (not copied, not mirrored).

A cube's corner ``c`` is ``(x, y, z) = (c >> 2 & 1, c >> 1 & 1, c & 1)``; the sign case
has bit ``c`` set when corner ``c`` is inside (negative). Edge ``e`` runs from corner
``EDGE_START[e]`` one step along axis ``EDGE_AXIS[e]``.

The surface meets each face of the cube in segments joining the face's crossed edges. A
face with two crossed edges has one segment; a face with four (two inside corners on a
diagonal: the ambiguous face) is decided by one rule: **the inside corners are
separated** (each is cut off by its own segment). The rule reads only the face's four
signs, so the two cubes sharing a face draw the same segments on it, and the surface is
watertight: every segment is the edge of exactly one triangle in each cube. (The 15-case
table of Lorensen & Cline folds each case with its complement, which flips the rule on
ambiguous faces between neighbours and leaves holes; Nielson & Hamann 1991, Dürst 1988.)

Each segment is directed so the surface's normal points to the outside corners; the
directed segments of a case chain into closed loops on the cube's boundary, and each loop
becomes a fan of triangles (Bloomenthal's polygonizer makes its polygons the same way)
whose diagonals never join two edges of one face (a diagonal in a face could be drawn
by the neighbouring cube too: an edge of four triangles).
"""

from __future__ import annotations

import numpy as np

__all__ = ["EDGE_AXIS", "EDGE_START", "TRI_COUNT", "TRI_EDGES", "tables"]


def _corner(x: int, y: int, z: int) -> int:
    return x << 2 | y << 1 | z


def _pos(c: int) -> np.ndarray:
    return np.array([c >> 2 & 1, c >> 1 & 1, c & 1], dtype=np.float64)


# 12 edges: for each axis, the four starts whose coordinate along that axis is 0
_EDGES = [
    (_corner(*[0 if k == a else bits[k - (k > a)] for k in range(3)]), a)
    for a in range(3)
    for bits in ((0, 0), (0, 1), (1, 0), (1, 1))
]
EDGE_START = np.array([s for s, _ in _EDGES], dtype=np.int64)
EDGE_AXIS = np.array([a for _, a in _EDGES], dtype=np.int64)


def _edge_of(c0: int, c1: int) -> int:
    a, b = min(c0, c1), max(c0, c1)
    axis = {4: 0, 2: 1, 1: 2}[b - a]
    return _EDGES.index((a, axis))


def _faces():
    """Each face: its outward normal and its four corners in cyclic order."""
    out = []
    for axis in range(3):
        u, v = [k for k in range(3) if k != axis]
        for side in (0, 1):
            ring = []
            for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = [0, 0, 0]
                p[axis], p[u], p[v] = side, du, dv
                ring.append(_corner(*p))
            normal = np.zeros(3)
            normal[axis] = 1.0 if side else -1.0
            out.append((normal, ring))
    return out


def _mid(e: int) -> np.ndarray:
    p = _pos(int(EDGE_START[e]))
    p[EDGE_AXIS[e]] += 0.5
    return p


def _case_loops(case: int) -> list[list[int]]:
    """The closed loops of crossed edges for one sign case, oriented outward."""
    inside = [(case >> c) & 1 == 1 for c in range(8)]
    nxt: dict[int, int] = {}
    for normal, ring in _faces():
        crossed = [k for k in range(4) if inside[ring[k]] != inside[ring[(k + 1) % 4]]]
        if not crossed:
            continue
        edges = {k: _edge_of(ring[k], ring[(k + 1) % 4]) for k in crossed}
        if len(crossed) == 2:
            pairs = [(edges[crossed[0]], edges[crossed[1]])]
            cut = [next(c for c in ring if inside[c])]  # all inside corners are on one side
        else:  # ambiguous: each inside corner is cut off by the two edges next to it
            pairs, cut = [], []
            for k in range(4):
                if inside[ring[k]]:
                    pairs.append((edges[(k - 1) % 4], edges[k]))
                    cut.append(ring[k])
        for (a, b), c in zip(pairs, cut, strict=True):
            pa, pb = _mid(a), _mid(b)
            # the inside corner must lie to the right of a -> b seen from outside the cube
            if np.dot(np.cross(pb - pa, _pos(c) - pa), normal) > 0:
                a, b = b, a
            assert a not in nxt, "two segments leave one edge"
            nxt[a] = b
    assert sorted(nxt) == sorted(nxt.values()), "the segments do not close into loops"
    loops, seen = [], set()
    for start in sorted(nxt):
        if start in seen:
            continue
        loop, e = [], start
        while e not in seen:
            seen.add(e)
            loop.append(e)
            e = nxt[e]
        loops.append(loop)
    return loops


def _same_face(a: int, b: int) -> bool:
    """Whether cube edges ``a`` and ``b`` lie on one face of the cube."""
    pa, pb = _mid(a), _mid(b)
    return bool(np.any((pa == pb) & ((pa == 0) | (pa == 1))))


def _fan(loop: list[int]) -> list[tuple[int, int, int]]:
    """Triangles of a loop: a fan from the first apex whose diagonals cross the cube's
    inside. A diagonal between two edges of one face would lie in that face, and the cube
    on its other side could draw the same diagonal: four triangles on one edge."""
    k = len(loop)
    for r in range(k):
        lp = loop[r:] + loop[:r]
        if not any(_same_face(lp[0], lp[i]) for i in range(2, k - 1)):
            return [(lp[0], lp[i], lp[i + 1]) for i in range(1, k - 1)]
    raise AssertionError(f"no fan of {loop} keeps its diagonals off the faces")


def tables() -> tuple[np.ndarray, np.ndarray]:
    """``TRI_COUNT (256,)`` triangles per case and ``TRI_EDGES (256, 5, 3)`` their edges
    (``-1`` past the count), each triangle's normal toward the outside corners."""
    count = np.zeros(256, dtype=np.int64)
    tri = np.full((256, 5, 3), -1, dtype=np.int64)
    for case in range(256):
        fan = [t for lp in _case_loops(case) for t in _fan(lp)]
        count[case] = len(fan)
        if fan:
            tri[case, : len(fan)] = fan
    return count, tri


TRI_COUNT, TRI_EDGES = tables()
