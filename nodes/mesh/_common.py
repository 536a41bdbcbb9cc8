"""Helpers shared by the ``mesh`` nodes: a mesh's arrays, its half-edges, and the errors of
kernels that need an oriented manifold or clip to floats, said against the input they are about.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context
from formgraph.geometry import Mesh
from formgraph.kernels.mesh import (
    HalfEdges,
    MeshTopologyError,
    meshops,
)


def halfedges(mesh: Mesh, port: str = "mesh") -> HalfEdges:
    try:
        return mesh.halfedges
    except MeshTopologyError as exc:
        raise InputError(port, str(exc)) from None


def guard_counts(ctx: Context, counts: list[tuple[int, int, int]]) -> None:
    if counts:
        n_vertices, _, n_faces = counts[-1]
        ctx.guard(n_faces, "faces")
        ctx.guard(n_vertices, "vertices")


def mesh_arrays(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return mesh.vertices, mesh.face_indices, mesh.face_offsets


def topology(port: str, fn: Callable[..., Any], *args: Any) -> Any:
    """Call a kernel that needs an oriented manifold; say which node fixes what it lacks."""
    try:
        return fn(*args)
    except MeshTopologyError as exc:
        hint = (
            "mesh.orient makes the faces agree"
            if "orientation" in str(exc)
            else "mesh.weld or a cleaner source may help"
        )
        raise InputError(port, f"{exc}; {hint}") from None


def clipping(ctx: Context, fn: Callable[..., Any], *args: Any) -> Any:
    """Call a kernel that may ear-clip faces, with the budget as its work limit."""
    try:
        return fn(*args, max_tests=ctx.budget)
    except meshops.WorkLimitError as exc:
        ctx.guard(exc.work, "triangle-corner tests of ear clipping")
        raise


def within_floats(arrays: Any, port: str, inputs: str) -> Any:
    """Kernel output arrays, or an error naming the scalar input that overflowed them.

    The inputs are finite, so a non-finite vertex means a size (or thickness) large enough
    that a coordinate passed the largest float: that input is to blame, not the mesh.
    """
    v = arrays[0]
    ok = np.isfinite(v).all(axis=1)
    if not ok.all():
        i = int(np.argmin(ok))
        raise InputError(
            port,
            f"{inputs} put vertex {i} at [{', '.join(f'{c:g}' for c in v[i])}], beyond the "
            f"largest float (about {np.finfo(np.float64).max:.3g}); use smaller values",
        )
    return arrays


def fmt(x: Any) -> str:
    a = np.atleast_1d(np.asarray(x, dtype=float))
    return f"{a[0]:g}" if a.size == 1 else f"[{', '.join(f'{c:g}' for c in a)}]"
