"""Remeshing benchmark: ``mesh.remesh``'s kernel against pymeshlab's isotropic remeshing.

The issue asked to measure and choose between pyacvd's clustering (what ``mesh.remesh``
calls) and Botsch & Kobbelt's isotropic remeshing (split long edges, collapse short ones,
flip toward valence 6, tangential relaxation, projection back), as pymeshlab's
``meshing_isotropic_explicit_remeshing`` implements it (VCG). Each row times one input
at one target edge length; the note gives what the choice rests on:

- ``closed``: every edge on exactly two triangles (a closed input must stay closed);
- ``min``: the smallest triangle angle, and ``<30``: the share of triangles with an angle
  under 30 degrees (an equilateral mesh has none);
- ``cv``: the edge lengths' coefficient of variation (0 for even edges), and ``mean``: the
  mean edge over the target;
- ``H``: the Hausdorff distance to the input over the target edge (both ways, sampled at
  the vertices and triangle centres, exact distances to the other surface).

Inputs: a sphere, a torus, a boolean (a cube less a sphere: sharp creases) and a noisy
sphere decimated to 10 % (long thin triangles). Ours through ``mesh.remesh`` (the target
edge a param moved a hair each call), the kernel beside; each implementation one timed
call a row (no warm-up: seconds each), its quality measured on a call of its own.
"""

from __future__ import annotations

import itertools

import numpy as np

from formgraph.kernels.geometry import meshdist
from formgraph.kernels.mesh import remesh as krem
from formgraph.kernels.mesh import simplify as ksimp


def _inputs():
    import fast_simplification
    import manifold3d
    import trimesh

    sphere = trimesh.creation.icosphere(4)
    torus = trimesh.creation.torus(1.0, 0.4, major_sections=128, minor_sections=64)
    cut = manifold3d.Manifold.cube([2, 2, 2], center=True) - manifold3d.Manifold.sphere(
        1.3, circular_segments=96
    )
    m = cut.to_mesh()
    noisy = trimesh.creation.icosphere(5)
    rng = np.random.default_rng(3)
    nv = noisy.vertices * (1 + rng.normal(0, 0.004, (len(noisy.vertices), 1)))
    dv, dt = fast_simplification.simplify(nv, noisy.faces, target_reduction=0.9)
    return [
        ("sphere", sphere.vertices, sphere.faces, 0.05),
        ("torus", torus.vertices, torus.faces, 0.03),
        ("cube less sphere", np.asarray(m.vert_properties[:, :3], float), m.tri_verts, 0.08),
        ("noisy sphere decimated", dv, dt, 0.05),
    ]


def _pymeshlab(v, t, edge):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(v, t))
    ms.meshing_isotropic_explicit_remeshing(
        iterations=10, targetlen=pymeshlab.PureValue(edge), featuredeg=30.0
    )
    out = ms.current_mesh()
    return out.vertex_matrix(), out.face_matrix()


def _acvd(v, t, edge):
    """pyacvd's clustering as ``mesh.remesh`` called it before this comparison: the input
    subdivided to about three vertices a cluster, then clustered and its dual taken."""
    import warnings

    import pyacvd
    import pyvista as pv

    clusters = max(4, krem.vertex_estimate(v, t, edge))
    mesh = pv.PolyData(v, np.hstack([np.full((len(t), 1), 3), t]).ravel())
    with warnings.catch_warnings():  # pyacvd calls a pyvista API that pyvista deprecates
        warnings.simplefilter("ignore")
        clus = pyacvd.Clustering(mesh)
        levels = 0
        while len(v) * 4**levels < 3 * clusters and levels < 6:
            levels += 1
        if levels:
            clus.subdivide(levels)
        clus.cluster(clusters)
        out = clus.create_mesh()
    ot = np.asarray(out.faces, dtype=np.int64).reshape(-1, 4)[:, 1:]
    return np.asarray(out.points, dtype=np.float64), ot


def quality(v, t, v0, t0, edge) -> dict:
    """What the choice rests on (see the module docstring)."""
    v, t = np.asarray(v, float), np.asarray(t, np.int64)
    p = v[t]
    e = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 1], p[:, 0] - p[:, 2]], axis=1)
    le = np.linalg.norm(e, axis=2)
    ang = []
    for i in range(3):
        a, b = -e[:, i - 1], e[:, i]
        ang.append(
            np.degrees(
                np.arccos(
                    np.clip(
                        np.einsum("ij,ij->i", a, b) / np.maximum(le[:, i - 1] * le[:, i], 1e-300),
                        -1,
                        1,
                    )
                )
            )
        )
    least = np.min(ang, axis=0)
    ka, kb = t.reshape(-1), t[:, [1, 2, 0]].reshape(-1)
    key = np.unique(np.minimum(ka, kb) * len(v) + np.maximum(ka, kb), return_index=True)[1]
    lengths = le.reshape(-1)[key]

    def one_way(pa, ta, pb, tb):
        pts = np.concatenate([pa, pa[ta].mean(axis=1)])
        return float(meshdist.Nearest(pb[tb]).distance(pts).max())

    h = max(one_way(v, t, v0, t0), one_way(v0, t0, v, t))
    return {
        "closed": ksimp.is_closed(t),
        "min": float(least.min()),
        "<30": float((least < 30).mean()),
        "cv": float(lengths.std() / lengths.mean()),
        "mean": float(lengths.mean() / edge),
        "H": h / edge,
        "faces": len(t),
    }


def _note(q: dict) -> str:
    return (
        f"{q['faces']} tri, closed {'yes' if q['closed'] else 'NO'}, min {q['min']:.1f} deg, "
        f"<30 {100 * q['<30']:.1f} %, cv {q['cv']:.2f}, mean {q['mean']:.2f}, H {q['H']:.2f}"
    )


def run(table) -> None:
    import formgraph as fg
    from formgraph.geometry import Mesh

    for name, v0, t0, edge in _inputs():
        v0 = np.asarray(v0, float)
        t0 = np.asarray(t0, np.int64)
        mesh = Mesh(v0, t0.reshape(-1), np.arange(0, t0.size + 1, 3))
        g = fg.Graph()
        g.add_param("m", type="Mesh")
        g.add_param("edge", edge)
        g.add("r", "mesh.remesh", mesh="=m", edge_length="=edge")
        steps = itertools.count(1)

        def ours(g=g, mesh=mesh, edge=edge, steps=steps):
            return g.evaluate("r", m=mesh, edge=edge * (1 + next(steps) * 1e-12))

        out = ours()
        notes = {
            "pyacvd (clustering)": _note(quality(*_acvd(v0, t0, edge)[:2], v0, t0, edge)),
            "pymeshlab isotropic": _note(quality(*_pymeshlab(v0, t0, edge)[:2], v0, t0, edge)),
        }
        table.compare(
            f"mesh.remesh of a {name} ({len(t0):,} tri) to edge {edge:g}",
            api=ours,
            kernel=lambda v0=v0, t0=t0, edge=edge: krem.isotropic_remesh(v0, t0, edge),
            references={
                "pyacvd (clustering)": lambda v0=v0, t0=t0, edge=edge: _acvd(v0, t0, edge),
                "pymeshlab isotropic": lambda v0=v0, t0=t0, edge=edge: _pymeshlab(v0, t0, edge),
            },
            rounds=1,
            warmup=False,
            note=_note(quality(out.vertices, out.face_indices.reshape(-1, 3), v0, t0, edge)),
            notes=notes,
        )
