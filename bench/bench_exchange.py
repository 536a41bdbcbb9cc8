"""Exchange formats: reading a 1M-triangle STL and OBJ, writing GLB and 3MF, a STEP surface.

Readers read the file from disk on both sides (a warm page cache):

- ``read.mesh`` of a binary STL, through a graph made anew each call (so neither the cache
  nor the graph's memo of the file's hash answers: the file is read, hashed for the key,
  parsed and frozen into a ``Mesh``) against numpy-stl's ``Mesh.from_file``; the parser
  alone (``read_stl`` on bytes already in memory) beside; and the peak memory of each
  (tracemalloc: what Python and numpy allocate while the call runs);
- ``read.mesh`` of an OBJ likewise against ``trimesh.load`` (``process=False``);

Writers write a file into a temporary folder on both sides:

- GLB from the same triangles, ours through ``export.gltf`` (normals computed) against
  trimesh's exporter with and without normals;
- 3MF through ``export.3mf`` against trimesh's exporter, the time and the peak memory;
- STEP of a 100 x 100 control-point bicubic B-spline surface, ours through
  ``export.step`` (an AP214 file with the face and its four edges) against OpenCASCADE's
  ``STEPControl_Writer`` writing the same surface as a face (from a ``Geom_BSplineSurface``
  built before the clock starts).

Each export call writes a new file name, so the export runs every time.
"""

from __future__ import annotations

import itertools
import os
import tempfile
from pathlib import Path

import numpy as np
from bench_export import torus_mesh

import formgraph as fg
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


def reader(folder: str, name: str):
    """``read.mesh`` of ``folder/name`` through a new graph each call."""

    def call():
        g = fg.Graph(inputs_dir=folder)
        g.add("m", "read.mesh", path=name)
        return g.evaluate("m")

    return call


def exporter(folder: str, node: str, value, **inputs):
    """An export node writing ``value`` (a param) to a new file name each call."""
    g = fg.Graph(out_dir=folder)
    g.add_param("m", type="Mesh")
    g.add_param("name", "x")
    g.add("e", node, meshes=["=m"], path="=name", **inputs)
    names = itertools.count()
    ext = {"export.gltf": "glb", "export.3mf": "3mf", "export.step": "step"}[node]
    return lambda: g.evaluate("e", m=value, name=f"out{next(names)}.{ext}")


def run(table) -> None:
    v, fi, fo = torus_mesh()
    tris = fi.reshape(-1, 3)
    n = len(tris)
    mesh = fg.Mesh(v, fi, fo)
    with tempfile.TemporaryDirectory() as d:
        stl_path, obj_path = os.path.join(d, "m.stl"), os.path.join(d, "m.obj")
        stl = stl_binary(v, fi, fo)
        obj = obj_bytes(v, fi, fo)
        Path(stl_path).write_bytes(stl)
        Path(obj_path).write_bytes(obj)

        def numpy_stl():
            from stl import mesh as npstl

            return npstl.Mesh.from_file(stl_path)

        case = f"read.mesh, binary STL of {n:,} triangles"
        table.compare(
            case,
            api=reader(d, "m.stl"),
            kernel=lambda: read_stl(stl),
            references={"numpy-stl Mesh.from_file": numpy_stl},
            rounds=7,
            note="the file read, hashed for the key, parsed, frozen",
        )
        table.memory(
            f"read.mesh, binary STL of {n:,} triangles: peak memory",
            api=reader(d, "m.stl"),
            references={"numpy-stl Mesh.from_file": numpy_stl},
        )

        def trimesh_obj():
            import trimesh

            return trimesh.load(obj_path, process=False, force="mesh")

        table.compare(
            f"read.mesh, OBJ of {n:,} triangles",
            api=reader(d, "m.obj"),
            kernel=lambda: read_obj(obj),
            references={"trimesh.load": trimesh_obj},
            rounds=3,
        )

        def trimesh_export(file_type: str, **kw):
            import trimesh

            names = itertools.count()
            tm = trimesh.Trimesh(v, tris, process=False)

            def call():
                tm.export(os.path.join(d, f"t{next(names)}.{file_type}"), **kw)

            return call

        def trimesh_glb_normals():
            import trimesh

            # a fresh mesh each call: trimesh caches the normals on the object
            names = itertools.count()

            def call():
                tm = trimesh.Trimesh(v, tris, process=False)
                tm.export(os.path.join(d, f"tn{next(names)}.glb"), include_normals=True)

            return call

        table.compare(
            f"export.gltf (GLB) of {n:,} triangles",
            api=exporter(d, "export.gltf", mesh),
            kernel=lambda: write_glb([(v, tris)]),
            references={
                "trimesh (normals)": trimesh_glb_normals(),
                "trimesh (no normals)": trimesh_export("glb"),
            },
            rounds=5,
            note="normals computed",
        )

        table.compare(
            f"export.3mf of {n:,} triangles",
            api=exporter(d, "export.3mf", mesh),
            kernel=lambda: write_3mf([(v, tris)]),
            references={"trimesh": trimesh_export("3mf")},
            rounds=3,
        )
        table.memory(
            f"export.3mf of {n:,} triangles: peak memory",
            api=exporter(d, "export.3mf", mesh),
            references={"trimesh": trimesh_export("3mf")},
        )

        surface = _surface()
        nurbs = fg.NurbsSurface(surface[0], 3, 3, surface[3], surface[4])
        references = {}
        try:
            references["OpenCASCADE STEPControl_Writer"] = _occ_step(
                surface[0], surface[3], os.path.join(d, "occ.step")
            )
        except ImportError as exc:
            references["OpenCASCADE STEPControl_Writer"] = _missing(exc)
        table.compare(
            "export.step: 100 x 100 bicubic surface",
            api=_step_export(d, nurbs),
            kernel=lambda: write_step(surfaces=[surface]),
            references=references,
            rounds=7,
        )


def _step_export(folder: str, surface):
    g = fg.Graph(out_dir=folder)
    g.add_param("s", type="Surface")
    g.add_param("name", "x")
    g.add("e", "export.step", surfaces=["=s"], path="=name")
    names = itertools.count()
    return lambda: g.evaluate("e", s=surface, name=f"s{next(names)}.step")


def _missing(exc: ImportError):
    def call():
        raise exc

    return call
