"""Solids from outlines, parts and sections (issue 34), each through the public API beside
the kernel alone and the reference as its users write it.

- ``mesh.extrude`` of the nameplate's region (graphs/nameplate.yaml's ``blank``: the
  rounded plate minus three holes, exact arcs): ours samples the exact curves, reads the
  region (GEOS) and builds the solid; manifold3d's ``CrossSection(polygons,
  EvenOdd).extrude`` gets the same polygons ready made, and its mesh is read back as
  arrays. A second case hands ours those very polygons as polylines (no sampling).
- ``mesh.split`` of a soup of 1,000 closed tori of 1,000 triangles (1,000,000 triangles,
  each with its own three vertices, shuffled): ours from the arrays as ``fg.Mesh`` into a
  graph param, against ``trimesh.Trimesh(vertices, faces).split(only_watertight=False)``
  (which merges the vertices when it is made). Both start from fresh arrays each call.
- ``mesh.slice`` of a UV sphere of 499,000 quads (998,000 triangles as exported), a new
  height each call as a stack or a slider asks: ours, the mesh upstream in the graph;
  manifold3d's ``slice`` of a ``Manifold`` built once from the same triangles (and its
  loops read out), and manifold3d building that ``Manifold`` from the arrays and then
  slicing, what one section of a mesh costs it.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

import formgraph as fg
from formgraph.core.registry import Context
from formgraph.kernels.io.meshdata import fan_triangles
from formgraph.kernels.mesh import extrude as ke
from formgraph.kernels.mesh import parts as kparts
from formgraph.kernels.mesh import section as ks
from formgraph.kernels.mesh.meshops import triangulate
from formgraph.nodes import _outlines as _o

ROOT = Path(__file__).resolve().parents[1]


def _nameplate() -> tuple[fg.Graph, list]:
    g = fg.load(ROOT / "graphs" / "nameplate.yaml")
    g.add_param("thickness", 3.0)
    g.add("solid", "mesh.extrude", curves="@blank", height="=thickness")
    return g, g.evaluate("blank")


def _extrude_rows(table) -> None:
    g, blank = _nameplate()
    ctx = Context("bench", ROOT)
    xy, off, hole, _ = _o.region_rings(blank, None, ctx)
    rings = [np.ascontiguousarray(xy[a:b]) for a, b in zip(off[:-1], off[1:], strict=True)]
    heights = itertools.count(1)

    def api():
        return g.evaluate("solid", thickness=3.0 + next(heights) * 1e-6)

    def kernel():
        return ke.extrude(xy, off, hole, 3.0)

    def manifold():
        import manifold3d

        m = manifold3d.CrossSection(rings, manifold3d.FillRule.EvenOdd).extrude(3.0)
        mesh = m.to_mesh64()
        return np.asarray(mesh.vert_properties), np.asarray(mesh.tri_verts)

    solid = api()
    assert solid.is_watertight
    case = f"mesh.extrude, nameplate region ({len(xy)} pts)"
    table.compare(
        case,
        api=api,
        kernel=kernel,
        references={"manifold3d": manifold},
        note="from its exact curves (sampled, region by GEOS)",
        notes={
            "formgraph kernel": "the solid from the region's rings",
            "manifold3d": "CrossSection(the same polygons, EvenOdd).extrude, to arrays",
        },
    )
    polylines = [fg.NurbsCurve.polyline(r, closed=True) for r in rings]
    p = fg.Graph()
    p.add_param("thickness", 3.0)
    p.add("solid", "mesh.extrude", curves=polylines, height="=thickness")
    table.compare(
        f"mesh.extrude, the same {len(xy)} polygon points",
        api=lambda: p.evaluate("solid", thickness=3.0 + next(heights) * 1e-6),
        references={"manifold3d": manifold},
        note="the polygons as polylines",
    )


def torus_soup(parts: int = 1000, seed: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """``parts`` closed tori of 1,000 triangles each, as a shuffled triangle soup."""
    g = fg.Graph()
    g.add("t", "mesh.torus", major=1.0, minor=0.3, segments_u=25, segments_v=20)
    t = g.evaluate("t")
    v, fi, _ = triangulate(t.vertices, t.face_indices, t.face_offsets)
    tri = fi.reshape(-1, 3)
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-60, 60, (parts, 3))
    pts = (v[tri.reshape(-1)][None, :, :] + centres[:, None, :]).reshape(-1, 3, 3)
    pts = pts[rng.permutation(len(pts))].reshape(-1, 3)
    return pts, np.arange(len(pts)).reshape(-1, 3)


def _split_rows(table) -> None:
    base, faces = torus_soup()
    flat = faces.reshape(-1)
    offsets = np.arange(0, len(flat) + 1, 3)
    g = fg.Graph()
    g.add_param("soup", type="Mesh")
    g.add("parts", "mesh.split", mesh="=soup")
    shift = itertools.count(1)

    def api():  # fresh coordinates each call: the graph's cache must not answer
        v = base + next(shift) * 1e-3
        return g.evaluate("parts", soup=fg.Mesh(v, flat, offsets))

    def kernel():
        v = base + next(shift) * 1e-3
        p = kparts.face_parts(v, flat, offsets)
        return kparts.split(v, flat, offsets, p)

    def trimesh_split():
        import trimesh

        v = base + next(shift) * 1e-3
        return trimesh.Trimesh(v, faces).split(only_watertight=False)

    assert len(api()) == 1000
    table.compare(
        f"mesh.split, {len(faces):,}-triangle soup of 1,000 parts",
        api=api,
        kernel=kernel,
        references={"trimesh": trimesh_split},
        rounds=5,
        note="fg.Mesh of the arrays into a graph param",
        notes={"trimesh": "Trimesh(vertices, faces).split(only_watertight=False)"},
    )


def _slice_rows(table) -> None:
    g = fg.Graph()
    g.add_param("z", 0.0)
    g.add("sphere", "mesh.sphere", radius=1.0, segments=1000)
    g.add("layer", "mesh.slice", mesh="@sphere", height="=z")
    mesh = g.evaluate("sphere")
    tri = fan_triangles(mesh.face_indices, mesh.face_offsets)
    v = np.array(mesh.vertices)
    # a new height every call, never one seen before (the graph's cache would answer it)
    heights = (-0.95 + (k * 0.6180339887498949) % 1.9 for k in itertools.count(1))

    def api():
        return g.evaluate("layer", z=float(next(heights)))

    def kernel():  # a plane through every triangle: no index
        xy, off, _ = ks.slice_loops(v, tri, float(next(heights)))
        return ks.region_of_loops(xy, off)

    import manifold3d

    tris = np.ascontiguousarray(tri, dtype=np.uint64)
    built = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=v, tri_verts=tris))

    def manifold_built():
        return built.slice(float(next(heights))).to_polygons()

    def manifold_cold():
        m = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=v, tri_verts=tris))
        return m.slice(float(next(heights))).to_polygons()

    api()
    api()  # (the second section of a mesh builds its index of triangles by height)
    table.compare(
        f"mesh.slice, {len(tri):,}-triangle sphere, new height",
        api=api,
        kernel=kernel,
        references={"manifold3d (built once)": manifold_built, "manifold3d": manifold_cold},
        note="the mesh upstream; its z index built by the 2nd slice",
        notes={
            "formgraph kernel": "scan of every triangle (a mesh's first slice)",
            "manifold3d (built once)": "Manifold made once, then slice + to_polygons",
            "manifold3d": "Manifold(Mesh64(arrays)), slice, to_polygons",
        },
    )


def run(table) -> None:
    _extrude_rows(table)
    _split_rows(table)
    _slice_rows(table)
