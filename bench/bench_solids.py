"""Solids: a boolean of two 100k-triangle spheres, and the repair chain on 1M triangles.

- ``mesh.union`` of two overlapping 100,488-triangle UV spheres through a graph whose
  meshes are params (each call the first moved a tiny amount: new content, so the node
  runs; its input checked, manifold3d, back to a frozen ``Mesh``) beside the kernel path,
  against manifold3d called directly on ready-made arrays (``Mesh64``, ``+``,
  ``to_mesh64``), and trimesh's ``boolean.union`` with the manifold engine;
- weld + orient + cap of a 1,000,000-triangle open tube given as a triangle soup (every
  triangle with its own 3 vertices, half of them flipped, as an unrepaired STL holds it):
  ours through ``mesh.weld`` (tolerance 0: exact duplicates) -> ``mesh.orient`` ->
  ``mesh.cap`` in a graph made anew each call from the user's arrays (``fg.Mesh`` built
  and hashed in our time; the kernels' connectivity memo cleared: a cold call), the
  kernels alone beside, against pymeshlab's ``meshing_remove_duplicate_vertices`` +
  ``meshing_re_orient_faces_coherently`` + ``meshing_close_holes`` from the same arrays
  (its ``Mesh`` built in its time), the same work: both ends capped. trimesh's
  ``merge_vertices`` + ``fix_normals`` + ``fill_holes`` fills only holes of 3 or 4 edges
  (it leaves the two 1000-edge ends open) and takes over a minute: one timed call.
"""

from __future__ import annotations

import itertools

import numpy as np

import formgraph as fg
from formgraph.geometry import Mesh
from formgraph.kernels.mesh import boolean as kb
from formgraph.kernels.mesh import memo
from formgraph.kernels.mesh import primitives as kp
from formgraph.kernels.mesh import repair as kr
from formgraph.kernels.mesh.grid import grid_faces
from formgraph.kernels.mesh.meshops import triangulate


def _sphere(centre: tuple[float, float, float]) -> Mesh:
    return Mesh(*triangulate(*kp.sphere(1.0, 318, centre)))  # 2 * 318 * 158 triangles


def _manifold_direct(a: tuple, b: tuple):
    import manifold3d

    ma = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=a[0], tri_verts=a[1]))
    mb = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=b[0], tri_verts=b[1]))
    out = (ma + mb).to_mesh64()
    return np.asarray(out.vert_properties), np.asarray(out.tri_verts)


def _trimesh_union(a, b):
    import trimesh

    return trimesh.boolean.union([a, b], engine="manifold")


def _ours_union(a: Mesh, b: Mesh) -> Mesh:
    ma = kb.to_manifold(a.vertices, a.face_indices, a.face_offsets, "input a")
    mb = kb.to_manifold(b.vertices, b.face_indices, b.face_offsets, "input b")
    return Mesh(*kb.from_manifold(kb.combine(ma, mb, "union")))


def tube_soup(rows: int = 500, around: int = 1000, seed: int = 1):
    """An open tube of ``2 rows around`` triangles as a soup, half its faces flipped."""
    phi = 2 * np.pi * np.arange(around) / around
    z = np.linspace(0.0, 5.0, rows + 1)
    pts = np.stack(
        np.broadcast_arrays(np.cos(phi)[None, :], np.sin(phi)[None, :], z[:, None]), -1
    ).reshape(-1, 3)
    fi, fo = grid_faces(rows + 1, around, False, True)
    v, t, _ = triangulate(pts, fi, fo)
    tri = t.reshape(-1, 3).copy()
    flip = np.random.default_rng(seed).random(len(tri)) < 0.5
    tri[flip] = tri[flip][:, ::-1]
    soup = v[tri.reshape(-1)]
    return soup, np.arange(soup.shape[0]), np.arange(0, soup.shape[0] + 1, 3)


def _ours_repair(v, fi, fo):
    memo.clear()  # a cold call: the memo only serves the same faces again (a slider step)
    w = kr.weld(v, fi, fo)
    o, _ = kr.orient(*w)
    return kr.cap(w[0], o, w[2])


def _trimesh_repair(v, fi):
    import trimesh

    m = trimesh.Trimesh(v, fi.reshape(-1, 3), process=False)
    m.merge_vertices()
    m.fix_normals()
    m.fill_holes()
    return m


def _pymeshlab_repair(v, fi):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=fi.reshape(-1, 3)))
    ms.meshing_remove_duplicate_vertices()  # exact duplicates, as our weld at tolerance 0
    ms.meshing_re_orient_faces_coherently()
    ms.meshing_close_holes(maxholesize=2000, selfintersection=False)  # the 1000-edge ends
    return ms.current_mesh().face_number()


def _union_graph(a: Mesh, b: Mesh):
    g = fg.Graph()
    g.add_param("a", type="Mesh")
    g.add_param("b", type="Mesh")
    g.add("u", "mesh.union", meshes=["=a", "=b"])
    steps = itertools.count(1)

    def call():
        moved = Mesh.trusted(a.vertices * (1 + next(steps) * 1e-12), a.face_indices, a.face_offsets)
        return g.evaluate("u", a=moved, b=b)

    return call


def _repair_graph(v, fi, fo):
    def call():
        memo.clear()  # a cold call: the memo only serves the same faces again (a slider step)
        g = fg.Graph()
        g.add_param("m", type="Mesh")
        g.add("w", "mesh.weld", mesh="=m", tolerance=0)
        g.add("o", "mesh.orient", mesh="@w")
        g.add("c", "mesh.cap", mesh="@o")
        return g.evaluate("c", m=fg.Mesh(v, fi, fo))

    return call


def run(table) -> None:
    a, b = _sphere((0.0, 0.0, 0.0)), _sphere((0.6, 0.2, 0.1))
    raw = [
        (np.array(m.vertices), np.array(m.face_indices, np.uint64).reshape(-1, 3)) for m in (a, b)
    ]

    def trimesh_union():
        import trimesh

        ta = trimesh.Trimesh(raw[0][0], raw[0][1].astype(np.int64), process=False)
        tb = trimesh.Trimesh(raw[1][0], raw[1][1].astype(np.int64), process=False)
        return _trimesh_union(ta, tb)

    table.compare(
        f"mesh.union of two {a.n_faces // 1000}k-triangle spheres",
        api=_union_graph(a, b),
        kernel=lambda: _ours_union(a, b),
        references={
            "manifold3d direct": lambda: _manifold_direct(*raw),
            "trimesh (manifold engine)": trimesh_union,
        },
        rounds=5,
    )

    v, fi, fo = tube_soup()
    table.compare(
        "weld + orient + cap, 1M-triangle soup (open tube)",
        api=_repair_graph(v, fi, fo),
        kernel=lambda: _ours_repair(v, fi, fo),
        references={"pymeshlab": lambda: _pymeshlab_repair(v, fi)},
        rounds=3,
        note="each call cold: a new graph, the connectivity memo cleared",
        notes={"pymeshlab": "remove_duplicate_vertices + re_orient_faces_coherently + close_holes"},
    )
    table.compare(
        "weld + orient + cap, 1M-triangle soup: trimesh (one call)",
        api=_repair_graph(v, fi, fo),
        references={"trimesh": lambda: _trimesh_repair(v, fi)},
        rounds=1,
        warmup=False,
        notes={"trimesh": "merge_vertices + fix_normals + fill_holes; leaves the two ends open"},
    )
