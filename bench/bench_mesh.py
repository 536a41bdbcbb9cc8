"""Mesh: Catmull-Clark and Doo-Sabin of a 10,000-quad torus, ear clipping of concave stars.

- ``mesh.catmull_clark`` of the torus, 1 and 2 levels, through a graph whose mesh is a
  param moved a tiny amount each call (a slider's step: new content, the same faces),
  against pymeshlab (``iterations=levels``: one call runs that many levels) and
  pyOpenSubdiv (OpenSubdiv 3.4 through ctypes). pyOpenSubdiv's ``pysubdivide`` takes and
  returns Python lists: its row counts that conversion (what its users pay: there is no
  other entry point), and a second row times the lists made beforehand, so only the
  conversion back is its own;
- ``mesh.doo_sabin`` of the torus, 1 level, against pymeshlab (which does one level,
  80k triangles); and 2 levels, ours alone;
- Doo-Sabin's new points alone (the kernel's two sparse products in the cosine form)
  against the per-size einsum of the circulant weights it replaced
  (``tests/doo_sabin_reference.py``), on level 2 of the torus and on a 4,000-gon prism;
- ``mesh.triangulate`` of one concave star face of 1,200 and 10,000 corners, through a
  graph whose mesh is a param (each call the user's arrays made into a new ``fg.Mesh``,
  moved a tiny amount, so the node runs: building and checking the mesh is in our time)
  against mapbox_earcut (compiled ear clipping with z-order hashing) called on the same
  arrays, and shapely's constrained Delaunay triangulation of the polygon.
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np

import formgraph as fg
from formgraph.geometry import Mesh
from formgraph.kernels.mesh.polygon import triangulate_polygon
from formgraph.kernels.mesh.subdivision import catmull_clark, doo_sabin

# the benchmarks measure the tests' canonical shapes
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from mesh_shapes import prism, torus  # noqa: E402


def _pymeshlab(v: np.ndarray, fi: np.ndarray, filter_name: str, levels: int):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_list_of_indices=fi.reshape(-1, 4)))
    ms.apply_filter(filter_name, iterations=levels)
    return ms.current_mesh().face_number()


def moved(node: str, mesh: Mesh, **inputs):
    """``node(mesh=param m)`` on ``mesh`` moved by a new tiny amount each call."""
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("n", node, mesh="=m", **inputs)
    steps = itertools.count(1)

    def call():
        v = mesh.vertices * (1.0 + next(steps) * 1e-12)
        return g.evaluate("n", m=Mesh.trusted(v, mesh.face_indices, mesh.face_offsets))

    return call


def run(table) -> None:
    v, fi, fo = torus(100, 100)  # 10,000 quads
    m = Mesh(v, fi, fo)
    faces = fi.reshape(-1, 4)
    for levels in (1, 2):
        n_faces = 10_000 * 4**levels

        def opensubdiv_lists(lv=levels):
            from pyOpenSubdiv.pysubdivision import pysubdivide

            return pysubdivide(lv, v.tolist(), faces.tolist(), fi.tolist(), np.diff(fo).tolist())

        lists = (v.tolist(), faces.tolist(), fi.tolist(), np.diff(fo).tolist())

        def opensubdiv_ready(lv=levels, lists=lists):
            from pyOpenSubdiv.pysubdivision import pysubdivide

            return pysubdivide(lv, *lists)

        table.compare(
            f"catmull_clark 10k-quad torus, {levels} lvl -> {n_faces // 1000}k quads",
            api=moved("mesh.catmull_clark", m, levels=levels),
            kernel=lambda lv=levels: catmull_clark(v, fi, fo, lv),
            references={
                "pymeshlab": lambda lv=levels: _pymeshlab(
                    v, fi, "meshing_surface_subdivision_catmull_clark", lv
                ),
                "pyOpenSubdiv (arrays to lists and back)": opensubdiv_lists,
                "pyOpenSubdiv (lists made beforehand)": opensubdiv_ready,
            },
            rounds=5,
        )
    table.compare(
        "doo_sabin 10k-quad torus, 1 lvl -> 40k faces",
        api=moved("mesh.doo_sabin", m, levels=1),
        kernel=lambda: doo_sabin(v, fi, fo, 1),
        references={
            "pymeshlab": lambda: _pymeshlab(v, fi, "meshing_surface_subdivision_doo_sabin", 1)
        },
        rounds=5,
        notes={"pymeshlab": "80k triangles (the 40k faces split)"},
    )
    table.compare(
        "doo_sabin 10k-quad torus, 2 lvl -> 160k faces",
        api=moved("mesh.doo_sabin", m, levels=2),
        kernel=lambda: doo_sabin(v, fi, fo, 2),
        rounds=5,
        note="pymeshlab's Doo-Sabin does one level whatever its iterations",
    )
    _doo_sabin_points(table, v, fi, fo)
    for k in (1_200, 10_000):
        _ear_clipping(table, k)


def _ear_clipping(table, k: int) -> None:  # noqa: ANN001
    xy = _star(k)
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("t", "mesh.triangulate", mesh="=m")
    steps = itertools.count(1)
    ring = [np.arange(k)]

    def ours():
        return g.evaluate("t", m=fg.Mesh(xy * (1.0 + next(steps) * 1e-12), ring))

    table.compare(
        f"mesh.triangulate of a concave {k:,}-corner star",
        api=ours,
        kernel=lambda: triangulate_polygon(xy),
        references={
            "mapbox_earcut": lambda: _earcut(xy),
            "shapely (constrained Delaunay)": lambda: _shapely_cdt(xy),
            "our own clipper (the fallback, numpy rounds)": lambda: _own_clipper(xy),
        },
        rounds=9 if k < 5000 else 5,
        note="the arrays made into a new fg.Mesh each call, in our time",
    )


def _doo_sabin_points(table, v: np.ndarray, fi: np.ndarray, fo: np.ndarray) -> None:  # noqa: ANN001
    """The new points of a Doo-Sabin level alone (the connectivity is the same code in
    both): the kernel's two sparse products in the cosine form against the per-size
    circulant weights by einsum it replaced (tests/doo_sabin_reference.py). On the level-1
    torus (40k faces, 3 and 5 columns) and on a 4,000-gon prism, where the circulant has
    k^2 entries a face."""
    from doo_sabin_reference import doo_sabin_points

    from formgraph.kernels.mesh import build_halfedges
    from formgraph.kernels.mesh import subdivision as sd

    def ours(x: np.ndarray, he) -> np.ndarray:  # noqa: ANN001 - HalfEdges
        fans = he.fans
        corner = ~fans.closed & (fans.sizes == 1) & he.is_manifold_vertex[fans.vertex]
        sums, points = sd._doo_sabin_points(he, x.shape[0], fans.vertex[corner])
        stacked = np.empty((x.shape[0] + sums.shape[0], x.shape[1]))
        stacked[: x.shape[0]] = x
        stacked[x.shape[0] :] = sums @ x
        return points @ stacked

    v1, fi1, fo1 = doo_sabin(v, fi, fo, 1)
    cases = [
        ("doo_sabin points, level 2 of the torus (160k corners)", v1, fi1, fo1),
        ("the same with 2 point attributes (5 columns)", np.c_[v1, v1[:, :2]], fi1, fo1),
        ("doo_sabin points of a 4,000-gon prism", *prism(4000)),
    ]
    for case, x, f, o in cases:
        x = np.asarray(x, dtype=np.float64)
        he = build_halfedges(f, o, len(x))
        he.fans, he.is_manifold_vertex, he.boundary_halfedges, he.face  # noqa: B018 - cached
        assert np.allclose(ours(x, he), doo_sabin_points(x, he), rtol=0, atol=1e-12 * abs(x).max())
        table.compare(
            case,
            api=lambda x=x, he=he: ours(x, he),
            references={
                "per-size einsum (the kernel before)": lambda x=x, he=he: doo_sabin_points(x, he)
            },
            rounds=5,
            note="the kernel: cosine form, 2 sparse products",
        )


def _star(k: int) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    r = np.where(np.arange(k) % 2 == 0, 1.0, 0.4)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def _earcut(xy: np.ndarray):
    import mapbox_earcut

    return mapbox_earcut.triangulate_float64(xy, np.array([len(xy)], dtype=np.uint32))


def _own_clipper(xy: np.ndarray):
    """The vectorized ear clipping ``triangulate_polygon`` falls back on where earcut's
    answer does not tile the loop: why mapbox-earcut is a dependency."""
    from formgraph.kernels.mesh.polygon import _ear_clip_rounds, polygon_plane

    return _ear_clip_rounds(polygon_plane(xy), None)


def _shapely_cdt(xy: np.ndarray):
    import shapely

    return shapely.constrained_delaunay_triangles(shapely.Polygon(xy))
