"""Mesh export: a 1,000,000-triangle mesh to binary STL, ASCII STL and OBJ.

Ours through ``export.stl`` / ``export.obj`` (the mesh a param, a new file name each call,
so the export runs: triangulation, normals, formatting and the atomic file write), the
kernel's bytes written to a file beside; against meshio, numpy-stl, trimesh and pyvista
(VTK's compiled writers), all writing a real file into a temporary folder, each
reference with its own mesh object built before the clock starts (trimesh's made each
call: it keeps face normals on the object). The ASCII STL is written in blocks; its peak
memory (tracemalloc) is set against the same text built whole. The slow references
(ASCII STL, OBJ) run one call each.
"""

from __future__ import annotations

import itertools
import os
import tempfile

import numpy as np

import formgraph as fg
from formgraph.kernels.io import obj_bytes, stl_ascii, stl_ascii_chunks, stl_binary
from formgraph.kernels.mesh import grid_faces

N_U, N_V = 1000, 500  # torus grid: 2 * N_U * N_V = 1,000,000 triangles


def torus_mesh() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed, outward-wound triangulated torus with slightly noisy coordinates."""
    u = np.linspace(0, 2 * np.pi, N_U, endpoint=False)[:, None]
    v = np.linspace(0, 2 * np.pi, N_V, endpoint=False)[None, :]
    r = 10.0 + 3.0 * np.cos(v)
    xyz = np.stack(
        np.broadcast_arrays(r * np.cos(u), r * np.sin(u), 3.0 * np.sin(v)), axis=-1
    ).reshape(-1, 3)
    xyz += np.random.default_rng(0).normal(scale=1e-4, size=xyz.shape)
    fi, _ = grid_faces(N_U, N_V, closed_u=True, closed_v=True)
    q = fi.reshape(-1, 4)
    tris = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
    return xyz, tris.ravel(), np.arange(0, tris.size + 1, 3)


def _write(path: str, data: bytes) -> None:
    with open(path, "wb") as f:
        f.write(data)


def _write_pieces(path: str, pieces) -> None:
    with open(path, "wb") as f:
        for piece in pieces:
            f.write(piece)


def _exporter(folder: str, node: str, mesh, **inputs):
    """``node`` writing ``mesh`` (a param) to a new file name each call."""
    g = fg.Graph(out_dir=folder)
    g.add_param("m", type="Mesh")
    g.add_param("name", "x")
    g.add("e", node, mesh="=m", path="=name", **inputs)
    names = itertools.count()
    ext = "obj" if node == "export.obj" else "stl"
    return lambda: g.evaluate("e", m=mesh, name=f"e{next(names)}.{ext}")


def _named(folder: str, stem: str, write):
    """``write(path)`` to a new file name each call (the number before the extension, which
    trimesh and pyvista read the format from)."""
    base, ext = os.path.splitext(stem)
    names = itertools.count()
    return lambda: write(os.path.join(folder, f"{base}{next(names)}{ext}"))


def run(table) -> None:
    v, fi, fo = torus_mesh()
    tris = fi.reshape(-1, 3)
    mesh = fg.Mesh(v, fi, fo)
    case = f"{len(tris):,} triangles"
    with tempfile.TemporaryDirectory() as d:
        import meshio
        import pyvista as pv
        import stl
        import trimesh

        mm = meshio.Mesh(v, [("triangle", tris)])
        sm = stl.mesh.Mesh(np.zeros(len(tris), dtype=stl.mesh.Mesh.dtype))
        sm.vectors[:] = v[tris]
        pm = pv.PolyData.from_regular_faces(v, tris)

        def trimesh_fresh(write):
            # a mesh made each call: trimesh caches face normals on the object
            return lambda path: write(trimesh.Trimesh(v, tris, process=False), path)

        table.compare(
            f"export.stl (binary) of {case}",
            api=_exporter(d, "export.stl", mesh),
            kernel=lambda: _write(os.path.join(d, "k.stl"), stl_binary(v, fi, fo)),
            references={
                "meshio": _named(d, "m.stl", lambda p: meshio.write(p, mm, "stl", binary=True)),
                "numpy-stl": _named(d, "s.stl", lambda p: sm.save(p, mode=stl.Mode.BINARY)),
                "trimesh": _named(d, "t.stl", trimesh_fresh(lambda m, p: m.export(p))),
                "pyvista (VTK)": _named(d, "v.stl", lambda p: pm.save(p, binary=True)),
            },
            rounds=5,
        )
        table.compare(
            f"export.stl (ASCII) of {case}",
            api=_exporter(d, "export.stl", mesh, ascii=True),
            kernel=lambda: _write_pieces(os.path.join(d, "k2.stl"), stl_ascii_chunks(v, fi, fo)),
            references={
                "pyvista (VTK)": _named(d, "v2.stl", lambda p: pm.save(p, binary=False)),
                "trimesh": _named(
                    d,
                    "t2.stl",
                    trimesh_fresh(
                        lambda m, p: _write(p, trimesh.exchange.stl.export_stl_ascii(m).encode())
                    ),
                ),
                "numpy-stl": _named(d, "s2.stl", lambda p: sm.save(p, mode=stl.Mode.ASCII)),
                "meshio": _named(d, "m2.stl", lambda p: meshio.write(p, mm, "stl", binary=False)),
            },
            rounds=1,
            warmup=False,
            note="written in blocks",
        )
        table.memory(
            f"export.stl (ASCII) of {case}: peak memory",
            api=_exporter(d, "export.stl", mesh, ascii=True),
            references={
                "the same text built whole (stl_ascii)": lambda: _write(
                    os.path.join(d, "w.stl"), stl_ascii(v, fi, fo)
                )
            },
        )
        table.compare(
            f"export.obj of {case}",
            api=_exporter(d, "export.obj", mesh),
            kernel=lambda: _write(os.path.join(d, "k.obj"), obj_bytes(v, fi, fo)),
            references={
                "pyvista (VTK)": _named(d, "v.obj", lambda p: pm.save(p)),
                "trimesh": _named(d, "t.obj", trimesh_fresh(lambda m, p: m.export(p))),
                "meshio": _named(d, "m.obj", lambda p: meshio.write(p, mm)),
            },
            rounds=1,
            warmup=False,
        )
