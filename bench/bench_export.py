"""Mesh export: a 1,000,000-triangle mesh to binary STL, ASCII STL and OBJ.

The ASCII STL is timed twice for us: built whole (``stl_ascii``) and written in blocks
(``stl_ascii_chunks``, as ``export.stl`` writes it), the latter with its peak memory over
the mesh (tracemalloc, in a call of its own: the timed calls run untraced).

Ours (``formgraph.kernels.io``) against numpy-stl, trimesh, meshio and pyvista (VTK's
compiled writers), all writing a real file into a temporary directory; our times include
triangulation, normals, formatting and the file write. Each reference gets its own mesh
object built before the clock starts.
"""

from __future__ import annotations

import os
import tempfile
import tracemalloc

import numpy as np

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


def _peak_mib(fn) -> float:
    """The most memory ``fn`` holds at once beyond what was allocated before, in MiB."""
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


def run(table) -> None:
    v, fi, fo = torus_mesh()
    tris = fi.reshape(-1, 3)
    case = f"export {len(tris):,} triangles"
    with tempfile.TemporaryDirectory() as d:
        p = lambda name: os.path.join(d, name)  # noqa: E731

        table.time(
            f"{case}: binary STL", "formgraph", lambda: _write(p("a.stl"), stl_binary(v, fi, fo))
        )
        table.time(
            f"{case}: ASCII STL", "formgraph", lambda: _write(p("b.stl"), stl_ascii(v, fi, fo))
        )
        in_blocks = lambda: _write_pieces(p("b2.stl"), stl_ascii_chunks(v, fi, fo))  # noqa: E731
        whole_mib = _peak_mib(lambda: _write(p("b.stl"), stl_ascii(v, fi, fo)))
        table.time(
            f"{case}: ASCII STL",
            "formgraph, in blocks",
            in_blocks,
            note=f"peak memory +{_peak_mib(in_blocks):.1f} MiB over the mesh "
            f"(built whole: +{whole_mib:.0f} MiB)",
        )
        table.time(f"{case}: OBJ", "formgraph", lambda: _write(p("c.obj"), obj_bytes(v, fi, fo)))

        import meshio

        mm = meshio.Mesh(v, [("triangle", tris)])
        table.time(
            f"{case}: binary STL",
            "meshio",
            lambda: meshio.write(p("m.stl"), mm, file_format="stl", binary=True),
        )

        import stl

        sm = stl.mesh.Mesh(np.zeros(len(tris), dtype=stl.mesh.Mesh.dtype))
        sm.vectors[:] = v[tris]
        table.time(
            f"{case}: binary STL", "numpy-stl", lambda: sm.save(p("s.stl"), mode=stl.Mode.BINARY)
        )

        import trimesh

        tm = trimesh.Trimesh(v, tris, process=False)
        table.time(
            f"{case}: binary STL",
            "trimesh",
            lambda: tm.export(p("t.stl")),
            note="face normals cached after the first call",
        )

        import pyvista as pv

        pm = pv.PolyData.from_regular_faces(v, tris)
        table.time(f"{case}: binary STL", "pyvista (VTK)", lambda: pm.save(p("v.stl"), binary=True))

        table.time(
            f"{case}: ASCII STL",
            "pyvista (VTK)",
            lambda: pm.save(p("v2.stl"), binary=False),
            repeat=1,
        )
        table.time(
            f"{case}: ASCII STL",
            "trimesh",
            lambda: _write(p("t2.stl"), trimesh.exchange.stl.export_stl_ascii(tm).encode()),
            repeat=1,
        )
        table.time(
            f"{case}: ASCII STL",
            "numpy-stl",
            lambda: sm.save(p("s2.stl"), mode=stl.Mode.ASCII),
            repeat=1,
        )
        table.time(
            f"{case}: ASCII STL",
            "meshio",
            lambda: meshio.write(p("m2.stl"), mm, file_format="stl", binary=False),
            repeat=1,
        )

        table.time(f"{case}: OBJ", "pyvista (VTK)", lambda: pm.save(p("v.obj")))
        table.time(f"{case}: OBJ", "trimesh", lambda: tm.export(p("t.obj")), repeat=1)
        table.time(f"{case}: OBJ", "meshio", lambda: meshio.write(p("m.obj"), mm), repeat=1)
