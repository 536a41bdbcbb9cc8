"""Mesh processing: smoothing, decimation, isotropic remeshing.

Thin adapters over :mod:`formgraph.kernels.mesh.smooth` (sparse Laplacian and Taubin
smoothing, boundaries held), :mod:`formgraph.kernels.mesh.simplify` (quadric decimation
through fast-simplification) and :mod:`formgraph.kernels.mesh.remesh` (Botsch & Kobbelt's
isotropic remeshing, batched). A closed input stays closed in every one: smoothing keeps
the connectivity, and the other two check their result and say so if a closed mesh came
out open. Smoothing keeps every attribute with its element; the other two take them from
the input's closest point (``propagate.onto``).
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.geometry import Mesh
from formgraph.kernels.attributes import propagate as carry
from formgraph.kernels.attributes.propagate import SAME
from formgraph.kernels.mesh import meshops
from formgraph.kernels.mesh import remesh as krem
from formgraph.kernels.mesh import simplify as ksimp
from formgraph.kernels.mesh import smooth as ksm


class SmoothMethod(str, Enum):
    """How mesh.smooth moves vertices."""

    taubin = "taubin"  # lambda|mu: a low-pass filter (a closed part's volume kept)
    laplacian = "laplacian"  # toward the neighbours' mean: shrinks


def _triangles(mesh: Mesh, ctx: Context) -> tuple[np.ndarray, np.ndarray]:
    v, fi, _ = meshops.triangulate(
        mesh.vertices, mesh.face_indices, mesh.face_offsets, max_tests=ctx.budget
    )
    return v, fi.reshape(-1, 3)


def _remade(source: Mesh, t: np.ndarray, v: np.ndarray, out: np.ndarray) -> Mesh:
    """Triangles ``out`` over ``v``, carrying ``source``'s attributes (``t``: its own
    triangles): from the closest point of the input, by ``propagate.onto``."""
    fi, fo = out.reshape(-1), np.arange(0, out.size + 1, 3)
    return Mesh(v, fi, fo, **carry.onto(source, v, (fi, fo), t))


#: Taubin's largest stable strength: a pass pair scales the umbrella operator's eigenmode of
#: eigenvalue k (0 <= k <= 2; 2 on a bipartite mesh, such as a grid of quads) by
#: (1 - s k)(1 + (s + 0.03) k), whose size at k = 2 passes 1 from s = 0.7028: above it the
#: finest zig-zag grows every step (a 32 x 16 torus at 0.72 reached 1e78 in 2,000 steps)
TAUBIN_MAX_STRENGTH = 0.7


@node("mesh.smooth", version=3)
def smooth(
    mesh: Mesh,
    iterations: Annotated[int, Range(min=0, max=100_000)] = 10,
    method: SmoothMethod = SmoothMethod.taubin,
    strength: Annotated[float, Range(min=0, max=1)] = 0.5,
    keep_volume: bool = True,
    *,
    ctx: Context,
) -> Mesh:
    """Smooth a mesh: Taubin's lambda|mu (each closed part's volume kept) or Laplacian
    (shrinks).

    Each step moves every vertex toward the mean of its edge neighbours (one sparse
    matrix product over all vertices); Taubin follows each step with a slightly larger one
    back (mu = -(strength + 0.03)), a low-pass filter that removes noise without shrinking
    (Taubin, SIGGRAPH 1995). The filter alone grows a closed surface a little (a clean
    icosphere by 0.25 % in 10 steps, 2.5 % in 100), so with ``keep_volume`` every closed
    part is scaled about its vertex mean back to its starting volume (Desbrun et al. 1999;
    once at the end, which is the same as after every step since a pass commutes with a
    uniform scale): its volume stays the input's to rounding. Vertices on boundary or
    non-manifold edges are held, so open outlines stay put (an open part has no volume to
    keep and is left as the filter makes it); faces are unchanged, so a closed mesh stays
    closed.

    Parameters
    ----------
    mesh : Mesh
        Any polygon mesh.
    iterations : int
        Steps (a Taubin step is a lambda and a mu pass).
    method : SmoothMethod
        ``taubin`` or ``laplacian``.
    strength : float
        Lambda, the fraction of the way to the neighbours' mean per pass, 0 .. 1 (Taubin:
        at most 0.7, beyond which its filter is unstable).
    keep_volume : bool
        Taubin only: scale each closed part back to its starting volume (false: the
        filter alone, as trimesh's ``filter_taubin``).

    Example
    -------
    ``tidy: {type: mesh.smooth, mesh: "@scan", iterations: 20}``
    """
    taubin = SmoothMethod(method) is SmoothMethod.taubin
    if taubin and strength > TAUBIN_MAX_STRENGTH:
        raise InputError(
            "strength",
            f"Taubin smoothing is stable up to strength {TAUBIN_MAX_STRENGTH}; at {strength:g}"
            " its mu pass amplifies the finest ripples every step until the mesh blows up"
            " (use a smaller strength and more iterations, or method: laplacian)",
        )
    ctx.guard(mesh.n_vertices * max(iterations, 1), "vertex updates")
    mu = -(strength + 0.03)
    v = ksm.smooth(
        mesh.vertices,
        mesh.face_indices,
        mesh.face_offsets,
        iterations,
        SmoothMethod(method).value,
        strength,
        mu,
        keep_volume and taubin,
    )
    # the same vertices and faces, moved: every attribute stays with its element
    return Mesh(v, mesh.face_indices, mesh.face_offsets, **carry.carried(mesh, SAME, SAME))


@node("mesh.decimate", version=2)
def decimate(
    mesh: Mesh,
    ratio: Annotated[float | None, Range(min=0, max=1)] = None,
    faces: Annotated[int | None, Range(min=4)] = None,
    *,
    ctx: Context,
) -> Mesh:
    """Fewer triangles, the shape kept: quadric error edge collapse (Garland & Heckbert).

    Through fast-simplification (Fast-Quadric-Mesh-Simplification). Polygons are
    triangulated first. A closed mesh stays closed, or the node says it could not. Point
    attributes are interpolated at each new vertex's closest point of the input (its
    triangle's barycentric weights); face attributes come from the input face nearest
    each new face's centroid.

    Parameters
    ----------
    mesh : Mesh
        The mesh to simplify.
    ratio : float | None
        The fraction of triangles kept, 0 .. 1 (default 0.5 when ``faces`` is not given).
    faces : int | None
        The number of triangles wanted instead.
    """
    if ratio is not None and faces is not None:
        raise InputError("faces", "give ratio or faces, not both")
    if mesh.n_faces == 0:
        raise InputError("mesh", "the mesh has no faces")
    v, t = _triangles(mesh, ctx)
    target = faces if faces is not None else int(round(len(t) * (0.5 if ratio is None else ratio)))
    if target < 4:
        raise InputError("ratio", f"that keeps {target} triangles; a solid needs at least 4")
    try:
        ov, ot = ksimp.decimate(v, t, target)
    except ksimp.OpenedError as exc:
        raise InputError("faces" if faces is not None else "ratio", str(exc)) from None
    return _remade(mesh, t, ov, ot)


@node("mesh.remesh", version=2)
def remesh(
    mesh: Mesh,
    edge_length: Annotated[float, Range(min=0)],
    iterations: Annotated[int, Range(min=1, max=100)] = 10,
    feature_angle: Annotated[float, Range(min=0, max=180)] = 30.0,
    *,
    ctx: Context,
) -> Mesh:
    """Even triangles of about ``edge_length``: isotropic remeshing (Botsch & Kobbelt).

    Each round splits the edges longer than 4/3 ``edge_length``, collapses those shorter
    than 4/5 of it, flips edges toward valence 6, moves every vertex toward its
    neighbours' centroid in its tangent plane and projects it back onto the input
    (Botsch & Kobbelt, "A remeshing approach to multiresolution modeling", 2004), every
    step batched over the whole mesh. Creases (a dihedral angle over ``feature_angle``)
    and boundaries are kept: their vertices move only along them, their corners not at
    all. A closed input stays closed and keeps its orientation. Chosen over pyacvd's
    clustering by measurement (bench/bench_remesh.py): the clustering rounded off the
    creases of a boolean, opened a decimated mesh and was slower. Attributes as in
    ``mesh.decimate``: a point's from the input's closest point, a face's from the input
    face nearest its centroid.

    Parameters
    ----------
    mesh : Mesh
        A triangle or polygon mesh (each edge on one or two faces).
    edge_length : float
        The target edge length, > 0.
    iterations : int
        Rounds of split, collapse, flip, relax and project.
    feature_angle : float
        Edges whose faces meet at more than this many degrees are creases, kept sharp.

    Example
    -------
    ``even: {type: mesh.remesh, mesh: "@part", edge_length: 1.5}``
    """
    if not edge_length > 0:
        raise InputError("edge_length", f"edge_length must be > 0, got {edge_length:g}")
    if mesh.n_faces == 0:
        raise InputError("mesh", "the mesh has no faces")
    v, t = _triangles(mesh, ctx)
    estimate = krem.vertex_estimate(v, t, edge_length)
    ctx.guard(estimate, "vertices")
    ctx.guard(iterations * 4 * max(estimate, len(v)), "vertex updates")
    try:
        ov, ot = krem.isotropic_remesh(v, t, edge_length, iterations, feature_angle)
    except ksimp.OpenedError as exc:
        raise InputError("edge_length", str(exc)) from None
    except ValueError as exc:
        raise InputError("mesh", str(exc)) from None
    return _remade(mesh, t, ov, ot)
