"""Selection and proximity through the public API: attr.distance and field.from_mesh against
pysdf and libigl, points.scatter against pymeshlab's Poisson-disk sampling, curves.voronoi
against shapely, geometry.filter against the numpy mask a user writes.

Every "formgraph" row builds a fresh graph (or changes a param) per call, so nothing comes
from the cache: the BVH of the mesh is built every time, as a user's first evaluation
builds it. ``BENCH_PROXIMITY_POINTS`` (default 1,000,000) sets the query count of the
distance rows.
"""

from __future__ import annotations

import itertools
import os

import numpy as np

import formgraph as fg
from formgraph.geometry import Mesh, Points

N_POINTS = int(os.environ.get("BENCH_PROXIMITY_POINTS", "1000000"))


def _torus():
    import trimesh

    return trimesh.creation.torus(1.0, 0.4, major_sections=320, minor_sections=160)


def _mesh(tm) -> Mesh:
    f = np.asarray(tm.faces)
    return Mesh(tm.vertices, f.reshape(-1), np.arange(0, f.size + 1, 3))


def _distance_rows(table) -> None:
    from formgraph.kernels.geometry import meshdist

    tor = _torus()
    mesh = _mesh(tor)
    v, t = np.asarray(tor.vertices), np.asarray(tor.faces)
    v32, t32 = v.astype(np.float32), t.astype(np.uint32)
    rng = np.random.default_rng(0)
    p = rng.uniform(-1.5, 1.5, (N_POINTS, 3)) * [1, 1, 0.4]
    pts = Points(p)

    def through_graph(signed: bool):
        g = fg.Graph()
        g.add_param("pts", type="Points")
        g.add_param("m", type="Mesh")
        g.add("d", "attr.distance", geometry="=pts", to="=m", signed=signed)
        return g.evaluate("d", pts=pts, m=mesh)

    def pysdf(robust: bool):
        from pysdf import SDF

        return SDF(v32, t32, robust=robust)(p)

    def igl_unsigned():
        import igl

        return igl.point_mesh_squared_distance(p, v, t)

    def igl_signed():
        import igl

        return igl.signed_distance(p, v, t, igl.SIGNED_DISTANCE_TYPE_PSEUDONORMAL)

    case = f"attr.distance, {N_POINTS:,} points to a {len(t):,}-triangle torus (in its box)"
    table.compare(
        case,
        api=lambda: through_graph(False),
        kernel=lambda: meshdist.Nearest(v[t]).locate(p),
        references={
            "pysdf (robust=False: nearest vertex's faces, approximate)": lambda: pysdf(False),
            "libigl point_mesh_squared_distance (AABB tree, exact)": igl_unsigned,
        },
        rounds=3,
        note="exact (every triangle that could be nearer is looked at), with the closest point",
    )
    table.compare(
        f"{case}, signed",
        api=lambda: through_graph(True),
        kernel=lambda: meshdist.SignedDistance(v, t).locate(p),
        references={
            "pysdf (robust: sign by ray casts)": lambda: pysdf(True),
            "libigl signed_distance (pseudonormal)": igl_signed,
        },
        rounds=3,
        note="pseudonormal sign on a closed mesh",
    )

    def from_mesh():
        g = fg.Graph()
        g.add_param("m", type="Mesh")
        g.add("f", "field.from_mesh", mesh="=m")
        return g.evaluate("f", m=mesh).evaluate(p)

    table.compare(
        f"field.from_mesh + evaluate, {N_POINTS:,} points, {len(t):,} triangles",
        api=from_mesh,
        kernel=lambda: meshdist.SignedDistance(v, t)(p),
        references={"pysdf (robust)": lambda: pysdf(True)},
        rounds=3,
    )


def _scatter_row(table) -> None:
    import trimesh

    from formgraph.kernels.mesh import scatter

    tor = trimesh.creation.torus(10.0, 4.0, major_sections=320, minor_sections=160)
    mesh = _mesh(tor)
    spacing = float(np.sqrt(tor.area * 0.62 / 100_000))  # about 100k points
    seeds = itertools.count()

    def ours():
        g = fg.Graph()
        g.add_param("m", type="Mesh")
        g.add("s", "points.scatter", geometry="=m", spacing=spacing, seed=next(seeds))
        return g.evaluate("s", m=mesh)

    def meshlab():
        import pymeshlab

        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(tor.vertices, tor.faces))
        ms.generate_sampling_poisson_disk(samplenum=100_000)
        return ms.current_mesh().vertex_matrix()

    n = len(ours())
    table.compare(
        f"points.scatter Poisson disk on a {len(tor.faces):,}-face torus ({n:,} points)",
        api=ours,
        kernel=lambda: scatter.poisson_disk(
            tor.vertices, tor.faces, spacing, np.random.default_rng(next(seeds))
        ),
        references={"pymeshlab generate_sampling_poisson_disk(samplenum=100000)": meshlab},
        rounds=5,
        note="no two closer than the spacing, maximal within 2x",
    )


def _voronoi_row(table) -> None:
    import shapely

    xy = np.random.default_rng(1).uniform(0, 100, (10_000, 2))
    pts = Points(xy)
    region = shapely.box(-5, -5, 105, 105)

    def ours():
        g = fg.Graph()
        g.add_param("p", type="Points")
        g.add("v", "curves.voronoi", points="=p")
        return g.evaluate("v", p=pts)

    def theirs():
        cells = shapely.voronoi_polygons(shapely.multipoints(xy), extend_to=region, ordered=True)
        return shapely.intersection(shapely.get_parts(cells), region)

    table.compare(
        "curves.voronoi of 10,000 points, clipped to their box",
        api=ours,
        references={"shapely voronoi_polygons(ordered) + intersection": theirs},
        note="one NurbsCurve per cell",
    )


def _filter_row(table) -> None:
    g = fg.Graph()
    g.add_param("t", 0.0)
    g.add("p", "points.random", count=1_000_000, seed=2, min=[-1, -1, -1], max=[1, 1, 1])
    g.add("f", "geometry.filter", geometry="@p", keep="=z > t")
    xyz = np.asarray(g.evaluate("p").xyz)
    ts = itertools.count()

    def ours():  # a new threshold each call: the points come from the cache, the filter runs
        return g.evaluate("f", t=(next(ts) % 1000) / 1000.0 - 0.5)

    def numpy_mask():
        t = (next(ts) % 1000) / 1000.0 - 0.5
        return xyz[xyz[:, 2] > t]

    table.compare(
        "geometry.filter of 1,000,000 points ('=z > t', t changed every call)",
        api=ours,
        references={"numpy xyz[xyz[:, 2] > t]": numpy_mask},
    )


def run(table) -> None:
    _filter_row(table)
    _voronoi_row(table)
    _scatter_row(table)
    _distance_rows(table)
