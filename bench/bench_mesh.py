"""Subdivision benchmark: Catmull-Clark and Doo-Sabin of a 10,000-quad torus.

References, timed in the same run: pyopensubdiv (OpenSubdiv 3.4.4 through ctypes; its
Python wrapper converts the mesh to and from lists, which is part of what a caller pays)
and pymeshlab when it imports (it is optional and usually not installed).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from formgraph.kernels.mesh.subdivision import catmull_clark, doo_sabin

# the benchmarks measure the tests' canonical shapes
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from mesh_shapes import torus  # noqa: E402


def _opensubdiv(levels: int, verts: list, faces: list, flat: list, sizes: list):
    from pyOpenSubdiv.pysubdivision import pysubdivide

    return pysubdivide(levels, verts, faces, flat, sizes)


def _pymeshlab(v: np.ndarray, fi: np.ndarray, filter_name: str, levels: int):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_list_of_indices=fi.reshape(-1, 4)))
    for _ in range(levels):
        ms.apply_filter(filter_name)
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
    case = "doo_sabin 10k-quad torus, 1 lvl -> 30k faces"
    table.time(case, "formgraph", lambda: doo_sabin(v, fi, fo, 1))
    table.time(
        case, "pymeshlab", lambda: _pymeshlab(v, fi, "meshing_surface_subdivision_doo_sabin", 1)
    )
