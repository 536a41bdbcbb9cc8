"""Exchange formats: reading a 1M-triangle STL and OBJ, writing GLB and 3MF, a STEP surface.

- binary STL read (our ``read_stl``: one structured ``np.frombuffer``, then float64) against
  numpy-stl's ``Mesh.from_file`` on the same file;
- OBJ read (our vectorized line scan: numbers by ``np.fromstring``, face indices by integer
  arithmetic on the digit runs) against ``trimesh.load`` (``process=False``);
- GLB and 3MF written from the same triangles against trimesh's exporters (GLB: trimesh
  writes no normals unless asked; the row that asks computes them from a fresh mesh, as
  ours does);
- STEP of a 100 x 100 control-point bicubic B-spline surface (bytes of an AP214 file with
  the face and its four edges) against OpenCASCADE's ``STEPControl_Writer`` writing the same
  surface as a face (from a ``Geom_BSplineSurface`` built before the clock starts).

Every reader starts from the file's bytes in memory, or the file on a warm page cache for
the references that insist on a path.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np
from bench_export import torus_mesh

from formgraph.kernels.io.exporters import obj_bytes, stl_binary
from formgraph.kernels.io.gltf import write_glb
from formgraph.kernels.io.mesh_read import read_obj, read_stl
from formgraph.kernels.io.step import write_step
from formgraph.kernels.io.threemf import write_3mf


def _surface(n: int = 100):
    u = np.linspace(0, 100, n)
    x, y = np.meshgrid(u, u, indexing="ij")
    cp = np.stack([x, y, 5 * np.sin(x / 9) * np.cos(y / 13)], axis=-1)
    k = np.concatenate([[0.0] * 4, np.linspace(0, 1, n - 2)[1:-1], [1.0] * 4])
    return cp, 3, 3, k, k.copy(), None


def _occ_step(cp, k, path: str):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    try:  # OCP 8 names NCollection's arrays by their element type
        from OCP.collections import Array1_double as TColStd_Array1OfReal
        from OCP.collections import Array1_int as TColStd_Array1OfInteger
        from OCP.collections import Array2_gp_Pnt as TColgp_Array2OfPnt
    except ImportError:
        from OCP.TColgp import TColgp_Array2OfPnt
        from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    n = cp.shape[0]
    poles = TColgp_Array2OfPnt(1, n, 1, n)
    for i in range(n):
        for j in range(n):
            poles.SetValue(i + 1, j + 1, gp_Pnt(*map(float, cp[i, j])))
    values, counts = np.unique(k, return_counts=True)
    knots = TColStd_Array1OfReal(1, len(values))
    mults = TColStd_Array1OfInteger(1, len(values))
    for i, (v, c) in enumerate(zip(values, counts, strict=True)):
        knots.SetValue(i + 1, float(v))
        mults.SetValue(i + 1, int(c))
    surface = Geom_BSplineSurface(poles, knots, knots, mults, mults, 3, 3)
    face = BRepBuilderAPI_MakeFace(surface, 1e-6).Face()

    def write():
        w = STEPControl_Writer()
        w.Transfer(face, STEPControl_AsIs)
        w.Write(path)

    return write


def run(table) -> None:
    v, fi, fo = torus_mesh()
    tris = fi.reshape(-1, 3)
    n = len(tris)
    with tempfile.TemporaryDirectory() as d:
        stl_path, obj_path = os.path.join(d, "m.stl"), os.path.join(d, "m.obj")
        stl = stl_binary(v, fi, fo)
        obj = obj_bytes(v, fi, fo)
        for path, data in ((stl_path, stl), (obj_path, obj)):
            with open(path, "wb") as fh:
                fh.write(data)

        case = f"read {n:,} triangles: binary STL"
        table.time(case, "formgraph", lambda: read_stl(stl), repeat=3)
        try:
            from stl import mesh as npstl

            table.time(case, "numpy-stl", lambda: npstl.Mesh.from_file(stl_path), repeat=3)
        except ImportError as exc:
            table.add(case, "numpy-stl", None, f"not installed ({exc.name})")

        import trimesh

        case = f"read {n:,} triangles: OBJ"
        table.time(case, "formgraph", lambda: read_obj(obj), repeat=2)
        table.time(
            case,
            "trimesh",
            lambda: trimesh.load(obj_path, process=False, force="mesh"),
            repeat=1,
        )

        tm = trimesh.Trimesh(v, tris, process=False)
        case = f"write {n:,} triangles: GLB"
        table.time(case, "formgraph", lambda: write_glb([(v, tris)]), repeat=2)
        table.time(case, "trimesh", lambda: tm.export(file_type="glb"), repeat=2, note="no normals")
        table.time(
            case,
            "trimesh (normals)",
            lambda: trimesh.Trimesh(v, tris, process=False).export(
                file_type="glb", include_normals=True
            ),
            repeat=2,
            note="normals computed, as ours",
        )

        case = f"write {n:,} triangles: 3MF"
        table.time(case, "formgraph", lambda: write_3mf([(v, tris)]), repeat=1)
        try:
            import lxml  # noqa: F401  (trimesh's 3MF writer needs it)

            table.time(case, "trimesh", lambda: tm.export(file_type="3mf"), repeat=1)
        except ImportError as exc:
            table.add(case, "trimesh", None, f"not installed ({exc.name})")

        surface = _surface()
        case = "write STEP: 100 x 100 bicubic surface"
        table.time(case, "formgraph", lambda: write_step(surfaces=[surface]), repeat=3)
        try:
            occ = _occ_step(surface[0], surface[3], os.path.join(d, "occ.step"))
            table.time(case, "OpenCASCADE", occ, repeat=3)
        except ImportError as exc:
            table.add(case, "OpenCASCADE", None, f"not installed ({exc.name})")


if __name__ == "__main__":
    from harness import Table

    t = Table()
    run(t)
    print(t.render())
