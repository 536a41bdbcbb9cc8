"""Mesh benchmark: Catmull-Clark and Doo-Sabin of a 10,000-quad torus (Doo-Sabin's new
points also alone, against the per-size einsum they were computed by before); ear clipping of a
concave star of 1,200 and 10,000 corners (against mapbox_earcut, compiled C++ ear clipping
with z-order hashing, and shapely's constrained Delaunay triangulation).

References, timed in the same run: pyopensubdiv (OpenSubdiv 3.4.4 through ctypes; its
Python wrapper converts the mesh to and from lists, which is part of what a caller pays)
and pymeshlab when it imports (it is optional and usually not installed).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from formgraph.kernels.mesh.polygon import triangulate_polygon
from formgraph.kernels.mesh.subdivision import catmull_clark, doo_sabin

# the benchmarks measure the tests' canonical shapes
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from mesh_shapes import prism, torus  # noqa: E402


def _opensubdiv(levels: int, verts: list, faces: list, flat: list, sizes: list):
    from pyOpenSubdiv.pysubdivision import pysubdivide

    return pysubdivide(levels, verts, faces, flat, sizes)


def _pymeshlab(v: np.ndarray, fi: np.ndarray, filter_name: str, levels: int):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_list_of_indices=fi.reshape(-1, 4)))
    # One call with the level count: each call runs `iterations` levels (default 2), so a
    # call per level would do twice the work asked.
    ms.apply_filter(filter_name, iterations=levels)
    return ms.current_mesh().face_number()


def run(table) -> None:
    v, fi, fo = torus(100, 100)  # 10,000 quads
    verts = v.tolist()
    faces = fi.reshape(-1, 4).tolist()
    flat = fi.tolist()
    sizes = np.diff(fo).tolist()
    for levels in (1, 2):
        n_faces = 10_000 * 4**levels
        case = f"catmull_clark 10k-quad torus, {levels} lvl -> {n_faces // 1000}k quads"
        table.time(case, "formgraph", lambda lv=levels: catmull_clark(v, fi, fo, lv))
        table.time(
            case, "pyopensubdiv", lambda lv=levels: _opensubdiv(lv, verts, faces, flat, sizes)
        )
        table.time(
            case,
            "pymeshlab",
            lambda lv=levels: _pymeshlab(v, fi, "meshing_surface_subdivision_catmull_clark", lv),
        )
    for k in (1_200, 10_000):
        xy = _star(k)
        case = f"triangulate a concave {k:,}-corner star"
        table.time(case, "formgraph", lambda xy=xy: triangulate_polygon(xy), repeat=3)
        table.time(case, "mapbox_earcut", lambda xy=xy: _earcut(xy), repeat=3)
        table.time(case, "shapely (constrained Delaunay)", lambda xy=xy: _shapely_cdt(xy), repeat=3)
    case = "doo_sabin 10k-quad torus, 1 lvl -> 40k faces"
    table.time(case, "formgraph", lambda: doo_sabin(v, fi, fo, 1))
    table.time(
        case,
        "pymeshlab",
        lambda: _pymeshlab(v, fi, "meshing_surface_subdivision_doo_sabin", 1),
        note="80k triangles (the 40k quads split)",
    )
    # pymeshlab's Doo-Sabin does one level whatever its iterations: ours alone at two
    table.time(
        "doo_sabin 10k-quad torus, 2 lvl -> 160k faces",
        "formgraph",
        lambda: doo_sabin(v, fi, fo, 2),
    )
    _doo_sabin_points(table, v, fi, fo)


def _doo_sabin_points(table, v: np.ndarray, fi: np.ndarray, fo: np.ndarray) -> None:  # noqa: ANN001
    """The new points of a Doo-Sabin level alone (the connectivity is the same code in
    both): the kernel's two sparse products in the cosine form against the per-size
    circulant weights by einsum it replaced (tests/doo_sabin_reference.py), interleaved.
    On the level-1 torus (40k faces, 3 and 5 columns) and on a 4,000-gon prism, where the
    circulant has k^2 entries a face."""
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
        table.time_together(
            case,
            [
                ("formgraph", lambda x=x, he=he: ours(x, he), "cosine form, 2 sparse products"),
                (
                    "per-size einsum",
                    lambda x=x, he=he: doo_sabin_points(x, he),
                    "the kernel before",
                ),
            ],
            rounds=5,
        )


def _star(k: int) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    r = np.where(np.arange(k) % 2 == 0, 1.0, 0.4)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def _earcut(xy: np.ndarray):
    import mapbox_earcut

    return mapbox_earcut.triangulate_float64(xy, np.array([len(xy)], dtype=np.uint32))


def _shapely_cdt(xy: np.ndarray):
    import shapely

    return shapely.constrained_delaunay_triangles(shapely.Polygon(xy))
