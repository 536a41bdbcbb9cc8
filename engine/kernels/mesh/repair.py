"""Mesh repair on flat arrays: weld close vertices, orient faces, cap boundary loops.

- :func:`weld`: vertices closer than a tolerance merged (transitively), faces that collapse
  dropped; exact duplicates first (one sort of a hash), then neighbours in a sparse grid of
  cells (:mod:`.cells`), whatever the size of the coordinates;
- :func:`orient`: one orientation per connected part, found by a parity union-find over the
  faces (two faces sharing an edge the same way must differ), then each closed part turned
  outward by its signed volume;
- :func:`cap`: every boundary loop filled, planar ones as triangulated polygons (ear
  clipping, concave outlines too), others as a fan to the loop's centroid.
"""

from __future__ import annotations

import numpy as np

from ..io.meshdata import fan_triangles
from .cells import close_pairs
from .halfedge import boundary_loops
from .keys import mix64 as _mix
from .keys import sort_keys
from .measure import (
    FanColumns,
    edge_table,
    face_areas,
    flat_open_parts,
    next_corner,
    signed_volume,
    union_find,
)
from .memo import by_faces
from .meshops import reverse_faces, triangulate

__all__ = [
    "cap",
    "compact",
    "drop_collapsed",
    "flat_open_parts",
    "orient",
    "weld",
    "weld_tolerance",
]

MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]

#: default weld tolerance, relative to the bounding-box diagonal
RELATIVE_TOLERANCE = 1e-6


def weld_tolerance(vertices: np.ndarray) -> float:
    """The default tolerance: 1e-6 of the bounding-box diagonal (0 for a single point)."""
    v = np.asarray(vertices, dtype=np.float64)
    if len(v) == 0:
        return 0.0
    return RELATIVE_TOLERANCE * float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))


def weld(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    tolerance: float | None = None,
) -> MeshArrays:
    """Merge vertices closer than ``tolerance``, transitively; drop faces that collapse.

    Exact duplicates are merged first (one sort of the coordinates), then the remaining
    points are bucketed in cells ``tolerance`` wide: two points that close are in the same
    or neighbouring cells, so the pairs come from 14 vectorized cell look-ups, and
    :func:`~formgraph.kernels.mesh.measure.union_find` groups them. Each group keeps the
    position of its first vertex. Unused vertices are removed.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
    tolerance : float, optional
        Distance under which vertices merge; default :func:`weld_tolerance` (1e-6 of the
        bounding-box diagonal). 0 merges exact duplicates only.

    Returns
    -------
    vertices, face_indices, face_offsets
        Faces keep their order; a face left with fewer than 3 distinct corners, or that
        visits a vertex twice, is dropped.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    tol = 0.0 if tolerance is None else float(tolerance)
    if not np.isfinite(tol) or tol < 0:
        raise ValueError(f"tolerance must be a finite number >= 0, got {tolerance!r}")
    if len(v) == 0:
        return v.copy(), fi.copy(), fo.copy()
    first, inverse = exact_duplicates(v)
    uniq = np.take(v, first, axis=0)
    if tolerance is None:  # (the distinct points have the same box, and are fewer)
        tol = weld_tolerance(uniq)
    if tol > 0 and len(uniq) > 1:
        i, j = close_pairs(uniq, tol)
        root, _ = union_find(len(uniq), i, j)
    else:
        root = np.arange(len(uniq))
    # groups keep their smallest member: the first vertex met
    vmap = root[inverse]
    out_fi, out_fo = drop_collapsed(vmap[fi], fo, len(uniq))
    return compact(uniq, out_fi, out_fo)


def exact_duplicates(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Group identical rows: one sort of a hash of the coordinates' bits.

    The rows' positions ride in the low bits of the hash (one value sort gives the groups
    and the permutation, see :func:`~formgraph.kernels.mesh.keys.sort_keys`), so only the
    hash's top bits order the rows; rows whose hashes agree there are checked against the
    coordinates themselves, and a group that turns out to hold different rows (a hash
    collision) is split by a sort of its rows' coordinates.

    Returns
    -------
    first : (k,) int64
        The first row of each group, in the order the groups first appear.
    inverse : (n,) int64
        The group of each row.
    """
    p = np.ascontiguousarray(np.asarray(points, dtype=np.float64) + 0.0)  # -0.0 -> 0.0
    n = len(p)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    bits = p.view(np.uint64).reshape(-1, 3)
    shift = np.uint64(max(int(n - 1).bit_length(), 1))
    packed = _mix(_mix(_mix(bits[:, 0]) ^ bits[:, 1]) ^ bits[:, 2])
    packed >>= shift
    packed <<= shift
    packed |= np.arange(n, dtype=np.uint64)
    packed.sort(kind="stable")
    order = (packed & ((np.uint64(1) << shift) - np.uint64(1))).view(np.int64)
    packed >>= shift
    new = np.empty(n, dtype=bool)
    new[0] = True
    np.not_equal(packed[1:], packed[:-1], out=new[1:])
    del packed
    # the rows' bits in sorted order (a group's rows are neighbours); take, not fancy
    # indexing: 2.5 times faster on rows
    sb = np.take(bits, order, axis=0)
    differ = (sb[1:, 0] != sb[:-1, 0]) | (sb[1:, 1] != sb[:-1, 1]) | (sb[1:, 2] != sb[:-1, 2])
    clash = np.flatnonzero(differ & ~new[1:])
    if clash.size:
        _split_collisions(sb, order, new, clash)
    group_sorted = np.cumsum(new) - 1
    starts = np.flatnonzero(new)
    first = np.minimum.reduceat(order, starts)
    inverse = np.empty(n, dtype=np.int64)
    inverse[order] = group_sorted
    rank, _ = sort_keys(first, n)
    where = np.empty(rank.size, dtype=np.int64)
    where[rank] = np.arange(rank.size)
    return first[rank], where[inverse]


def _split_collisions(sb: np.ndarray, order: np.ndarray, new: np.ndarray, clash: np.ndarray):
    """Split, in place, the groups (runs of the sort) that hold different rows: each such
    run is re-sorted by its rows' coordinate bits and cut where they change."""
    gid = np.cumsum(new) - 1
    bad = np.zeros(int(gid[-1]) + 1, dtype=bool)
    bad[gid[clash + 1]] = True
    pos = np.flatnonzero(bad[gid])  # the runs' positions (each run is contiguous)
    rows = sb[pos]
    o = np.lexsort((pos, rows[:, 2], rows[:, 1], rows[:, 0], gid[pos]))
    pos_rows, pos_gid = rows[o], gid[pos][o]
    order[pos] = order[pos[o]]
    sb[pos] = pos_rows
    cut = np.ones(pos.size, dtype=bool)
    cut[1:] = (pos_gid[1:] != pos_gid[:-1]) | (pos_rows[1:] != pos_rows[:-1]).any(axis=1)
    new[pos] = cut


def drop_collapsed(
    face_indices: np.ndarray, face_offsets: np.ndarray, n_vertices: int
) -> tuple[np.ndarray, np.ndarray]:
    """Remove repeated consecutive corners; drop faces under 3 corners or repeating one.

    Returns
    -------
    face_indices, face_offsets
        The surviving faces, in order.
    """
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    n_faces = fo.size - 1
    if n_faces == 0:
        return fi.copy(), fo.copy()
    if fi.size == 3 * n_faces and (np.diff(fo) == 3).all():  # triangles: no sort needed
        t = fi.reshape(-1, 3)  # (two equal corners of a triangle are consecutive ones)
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        good = (a != b) & (b != c) & (a != c)
        return t[good].reshape(-1), np.arange(0, 3 * int(good.sum()) + 1, 3, dtype=np.int64)
    face = np.repeat(np.arange(n_faces), np.diff(fo))
    keep = fi != fi[next_corner(fo)]
    sizes = np.bincount(face[keep], minlength=n_faces)
    bad = sizes < 3
    kf, kv = face[keep], fi[keep]
    key = np.sort(kf * max(n_vertices, 1) + kv)
    dup = key[1:] == key[:-1]
    bad[key[1:][dup] // max(n_vertices, 1)] = True
    keep &= ~bad[face]
    sizes[bad] = 0
    out_fo = np.zeros(n_faces - int(bad.sum()) + 1, dtype=np.int64)
    np.cumsum(sizes[~bad], out=out_fo[1:])
    return fi[keep], out_fo


def compact(vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray) -> MeshArrays:
    """Drop the vertices that no face uses, renumbering the faces (order kept)."""
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    used = np.zeros(len(v), dtype=bool)
    used[fi] = True
    new = np.cumsum(used) - 1
    return v[used], new[fi], np.asarray(face_offsets, dtype=np.int64).copy()


def orient(
    vertices: np.ndarray, face_indices: np.ndarray, face_offsets: np.ndarray
) -> tuple[np.ndarray, int]:
    """Consistent face orientation, each closed part outward (positive signed volume).

    Faces sharing a manifold edge (one on exactly two faces) are linked; a link whose two
    faces run the edge the same way says "orientations differ". A parity union-find over
    these links (:func:`~formgraph.kernels.mesh.measure.union_find`) gives every face its
    orientation relative to its part's root face. A closed part is then turned so its signed
    volume is positive, unless it lies inside an odd number of the other closed parts (a
    cavity, such as the inner wall of a hollow shell): that one faces inward. An open part
    is turned so its signed volume about its own centroid is positive (its faces look away
    from its middle, like a cup's outside), or, when that volume is about 0 (a flat sheet),
    so that most of its area keeps the orientation it came with.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int

    Returns
    -------
    face_indices : (m,) int64
        Faces reversed where needed (first corner kept); a read-only ``face_indices`` that
        needs no change is handed back as it is (shared, not copied).
    conflicts : int
        Links that no orientation satisfies (non-orientable parts, e.g. a Moebius strip);
        0 for an orientable mesh.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    n_faces = fo.size - 1
    if n_faces == 0:
        return fi.copy(), 0
    sizes, face, root, flip, conflicts, roots, part, part_open = by_faces(
        "orient", fi, fo, len(v), lambda: _orient_topology(fi, fo, len(v))
    )
    triangles = fi.size == 3 * n_faces and bool((sizes == 3).all())
    n_parts = roots.size
    # decide each part's overall direction with the faces as they would be after the flips
    sign = np.where(flip, -1.0, 1.0)
    areas, corner_sums, cone = _face_measures(v, fi, fo, triangles)
    # only an open part can be flat, and only a flat one needs areas (taken before the
    # cones, which may reuse the corners' memory)
    face_area = areas() if part_open.any() else None
    corners = np.bincount(part, weights=sizes, minlength=n_parts)
    part_centroid = (
        np.stack([np.bincount(part, weights=c, minlength=n_parts) for c in corner_sums], 1)
        / np.maximum(corners, 1)[:, None]
    )
    vol = np.bincount(
        part, weights=sign * cone(np.take(part_centroid, part, axis=0)), minlength=n_parts
    )
    turn = vol < 0
    if face_area is not None:
        part_area = np.bincount(part, weights=face_area, minlength=n_parts)
        kept = np.bincount(part, weights=sign * face_area, minlength=n_parts)
        flat = np.abs(vol) <= 1e-9 * np.maximum(part_area, 1e-300) ** 1.5
        turn = np.where(part_open & flat, kept < 0, turn)
    if turn.any():
        flip = flip ^ turn[part]
    if not flip.any():  # every face agrees and faces out already
        out = fi if not fi.flags.writeable else fi.copy()
    elif triangles:  # (a, b, c) -> (a, c, b) where flipped
        out = fi.reshape(-1, 3).copy()
        turned = np.flatnonzero(flip)
        sub = out[turned]
        out[turned, 1], out[turned, 2] = sub[:, 2], sub[:, 1]
        out = out.reshape(-1)
    else:
        out = np.where(np.repeat(flip, sizes), reverse_faces(fi, fo), fi)
    closed_parts = roots[~part_open]
    if 1 < closed_parts.size <= MAX_NESTED_PARTS:
        inner = _nested_inside(v, out, fo, root, closed_parts)
        if inner.any():
            flip_part = np.zeros(n_faces, dtype=bool)
            flip_part[closed_parts[inner]] = True
            out = np.where(np.repeat(flip_part[root], sizes), reverse_faces(out, fo), out)
    return out, conflicts


#: parts of one mesh above which orient skips the nesting test (each part is tested
#: against the triangles of all the others)
MAX_NESTED_PARTS = 64


def _orient_topology(fi: np.ndarray, fo: np.ndarray, n_vertices: int) -> tuple:
    """What :func:`orient` finds from the faces alone (the same while only positions
    change): corners per face, the face of each corner, each face's root and parity, the
    conflicts, the parts' root faces, each face's part and which parts are open."""
    n_faces = fo.size - 1
    sizes = np.diff(fo)
    face = np.repeat(np.arange(n_faces), sizes)
    t = edge_table(fi, fo, n_vertices)
    two = t.starts[t.counts == 2]
    h0, h1 = t.order[two], t.order[two + 1]
    same = fi[h0] == fi[h1]  # both start at the same vertex: same direction
    f0, f1 = face[h0], face[h1]
    root, flip = union_find(n_faces, f0, f1, same)
    conflicts = int(np.count_nonzero((flip[f0] ^ flip[f1]) != same))
    # parts numbered 0 .. n_parts - 1 (by their root, the smallest face), so that every sum
    # over a part is a short array
    is_root = root == np.arange(n_faces)
    roots = np.flatnonzero(is_root)
    part = (np.cumsum(is_root) - 1)[root]
    part_open = np.zeros(roots.size, dtype=bool)
    part_open[part[face[t.order[t.starts[t.counts != 2]]]]] = True
    return sizes, face, root, flip, conflicts, roots, part, part_open


def _face_measures(v: np.ndarray, fi: np.ndarray, fo: np.ndarray, triangles: bool):
    """Per face: a function giving the areas (of the exported fan), the sums of its
    corners' coordinates (3 arrays) and a function giving the signed volume of the cone
    from one point per face (called last, once: it may move the gathered corners).

    Triangles take one pass over contiguous coordinate columns: ``N = (b - a) x (c - a)``
    gives the area ``|N| / 2`` and the cone from ``o``, ``(a - o) . N / 6``. Faces of a few
    corners (quads with triangles, as a capped tube has) gather their corners once
    (:class:`~formgraph.kernels.mesh.measure.FanColumns`) for all three."""
    if not triangles:
        columns = FanColumns.of(v, fi, fo)
        if columns is not None:
            return (
                columns.areas,
                columns.corner_sums(),
                lambda origin: columns.volumes(origin, overwrite=True),
            )
        face = np.repeat(np.arange(fo.size - 1), np.diff(fo))
        sums = [np.bincount(face, weights=v[fi, k], minlength=fo.size - 1) for k in range(3)]
        return (
            lambda: face_areas(v, fi, fo),
            sums,
            lambda origin: signed_volume(v, fi, fo, origin),
        )
    tri = fi.reshape(-1, 3)
    cols = [np.ascontiguousarray(v[:, k]) for k in range(3)]
    a = [np.take(c, tri[:, 0]) for c in cols]
    e1 = [np.take(c, tri[:, 1]) - ak for c, ak in zip(cols, a, strict=True)]
    e2 = [np.take(c, tri[:, 2]) - ak for c, ak in zip(cols, a, strict=True)]
    n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ]
    areas = 0.5 * np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
    sums = [3.0 * ak + d1 + d2 for ak, d1, d2 in zip(a, e1, e2, strict=True)]

    def cone(origin: np.ndarray) -> np.ndarray:
        return sum((a[k] - origin[:, k]) * n[k] for k in range(3)) / 6.0

    return lambda: areas, sums, cone


def _nested_inside(
    v: np.ndarray, fi: np.ndarray, fo: np.ndarray, root: np.ndarray, parts: np.ndarray
) -> np.ndarray:
    """(len(parts),) bool: the part lies inside an odd number of the other closed parts.

    With every closed part outward, the winding number of the others at a vertex of a part
    counts the parts around it (the generalized winding number: the solid angle of each
    triangle, Van Oosterom & Strackee 1983, summed over 4 pi). A cavity (inside one other
    part, like the inner wall of a hollow shell) must face inward, so it is turned back.
    """
    tris = fan_triangles(fi, fo)
    face_of_tri = np.repeat(np.arange(fo.size - 1), np.diff(fo) - 2)
    part_of_tri = root[face_of_tri]
    closed = np.isin(part_of_tri, parts)
    out = np.zeros(parts.size, dtype=bool)
    for k, part in enumerate(parts):  # one vectorized pass over the triangles per part
        p = v[fi[fo[np.flatnonzero(root == part)[0]]]]
        others = tris[closed & (part_of_tri != part)]
        a, b, c = v[others[:, 0]] - p, v[others[:, 1]] - p, v[others[:, 2]] - p
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        num = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = (
            la * lb * lc
            + np.einsum("ij,ij->i", a, b) * lc
            + np.einsum("ij,ij->i", a, c) * lb
            + np.einsum("ij,ij->i", b, c) * la
        )
        winding = np.sum(2.0 * np.arctan2(num, den)) / (4.0 * np.pi)
        out[k] = int(round(winding)) % 2 == 1
    return out


def cap(
    vertices: np.ndarray,
    face_indices: np.ndarray,
    face_offsets: np.ndarray,
    planar_tolerance: float = 1e-6,
    max_tests: int | None = None,
) -> MeshArrays:
    """Fill every boundary loop; the new faces are oriented with their neighbours.

    A loop runs with the mesh on its left, so its cap runs it backwards. A loop whose
    points lie within ``planar_tolerance`` (relative to the loop's size) of the plane of
    its Newell normal is triangulated as a polygon (ear clipping in that plane,
    :func:`~formgraph.kernels.mesh.meshops.triangulate`: concave outlines stay inside);
    any other loop becomes a fan of triangles to its centroid (one new vertex).

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (m,) int
    face_offsets : (n_faces + 1,) int
        An oriented manifold mesh (see :func:`orient`).
    planar_tolerance : float
        Largest distance from the plane, as a fraction of the loop's bounding-box diagonal.
    max_tests : int, optional
        Work limit of the ear clipping of planar loops (see ``triangulate``).

    Returns
    -------
    vertices : (n + k, 3) float64
        One vertex appended per non-planar loop.
    face_indices, face_offsets
        The original faces, then the caps' triangles.

    Raises
    ------
    MeshTopologyError
        Non-manifold or inconsistently oriented input.
    WorkLimitError
        The ear clipping would need more than ``max_tests`` triangle-corner tests.
    """
    v = np.asarray(vertices, dtype=np.float64)
    fi = np.asarray(face_indices, dtype=np.int64)
    fo = np.asarray(face_offsets, dtype=np.int64)
    loops = by_faces("loops", fi, fo, len(v), lambda: boundary_loops(fi, fo, len(v)))
    if not loops:
        return v.copy(), fi.copy(), fo.copy()
    lo_sizes = np.array([len(lp) for lp in loops], dtype=np.int64)
    lo_off = np.zeros(lo_sizes.size + 1, dtype=np.int64)
    np.cumsum(lo_sizes, out=lo_off[1:])
    ring = reverse_faces(np.concatenate(loops), lo_off)  # each loop backwards
    p = v[ring]
    starts = lo_off[:-1]
    centre = np.add.reduceat(p, starts, axis=0) / lo_sizes[:, None]
    nxt = next_corner(lo_off)
    normal = np.add.reduceat(np.cross(p - centre.repeat(lo_sizes, 0), p[nxt] - p), starts, 0)
    length = np.linalg.norm(normal, axis=1)
    unit = normal / np.where(length > 0, length, 1.0)[:, None]
    dist = np.abs(np.einsum("ij,ij->i", p - centre.repeat(lo_sizes, 0), unit.repeat(lo_sizes, 0)))
    size = np.linalg.norm(
        np.maximum.reduceat(p, starts, 0) - np.minimum.reduceat(p, starts, 0), axis=1
    )
    planar = (np.maximum.reduceat(dist, starts) <= planar_tolerance * size) & (length > 0)
    planar |= lo_sizes == 3
    corner_planar = planar.repeat(lo_sizes)
    pf, pfo = ring[corner_planar], np.concatenate([[0], np.cumsum(lo_sizes[planar])])
    _, tri, _ = triangulate(v, pf, pfo, max_tests=max_tests)
    # the fans: (centroid, a, b) for each edge a -> b of a non-planar loop
    fan = np.flatnonzero(~planar)
    new_v = centre[fan]
    centre_id = len(v) + np.repeat(np.arange(fan.size), lo_sizes[fan])
    h = np.flatnonzero(~corner_planar)
    fans = np.stack([centre_id, ring[h], ring[nxt[h]]], axis=1).reshape(-1)
    caps = np.concatenate([tri, fans])
    out_fo = np.concatenate([fo, fo[-1] + np.arange(3, caps.size + 1, 3)])
    return np.concatenate([v, new_v]), np.concatenate([fi, caps]), out_fo
