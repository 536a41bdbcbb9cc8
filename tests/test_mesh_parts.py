"""mesh.split and the parts and cavities of mesh.measure (nodes/mesh/parts.py,
kernels/mesh/parts.py): against trimesh's split, closed forms of nested shells, and the
attributes each part keeps."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import formgraph as fg
from formgraph.kernels.mesh import parts as kparts


def run(node_type: str, **inputs):
    g = fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n"), g.stats["n"].warnings


def sphere(radius: float, center=(0.0, 0.0, 0.0), segments: int = 16, inward=False) -> fg.Mesh:
    g = fg.Graph()
    g.add("s", "mesh.sphere", radius=radius, center=list(center), segments=segments)
    g.add("f", "mesh.flip", mesh="@s")
    return g.evaluate("f" if inward else "s")


def soup(mesh: fg.Mesh, seed: int = 0) -> fg.Mesh:
    """The mesh's triangles, each with its own three vertices, in a shuffled order."""
    from formgraph.kernels.mesh.meshops import triangulate

    v, fi, _ = triangulate(mesh.vertices, mesh.face_indices, mesh.face_offsets)
    tri = fi.reshape(-1, 3)[np.random.default_rng(seed).permutation(len(fi) // 3)]
    pts = v[tri.reshape(-1)]
    return fg.Mesh(pts, np.arange(len(pts)), np.arange(0, len(pts) + 1, 3))


def merged(meshes: list[fg.Mesh]) -> fg.Mesh:
    g = fg.Graph()
    g.add("m", "mesh.merge", meshes=meshes)
    return g.evaluate("m")


def test_split_of_a_soup_agrees_with_trimesh():
    rng = np.random.default_rng(3)
    radii, centres = rng.uniform(0.5, 2, 6), rng.uniform(-20, 20, (6, 3))
    balls = [sphere(r, c) for r, c in zip(radii, centres, strict=True)]
    box = fg.Mesh([[0, 0, 50], [1, 0, 50], [0, 1, 50]], [[0, 1, 2]])  # an open part
    m = soup(merged([*balls, box]))
    parts, warnings = run("mesh.split", mesh=m)
    assert warnings == []
    ref = trimesh.Trimesh(m.vertices, m.face_indices.reshape(-1, 3)).split(only_watertight=False)
    assert len(parts) == len(ref) == 7
    ours = sorted(round(p.volume if p.is_watertight else -p.area, 9) for p in parts)
    theirs = sorted(round(r.volume if r.is_watertight else -r.area, 9) for r in ref)
    assert ours == pytest.approx(theirs, rel=1e-12)
    # closed ones first, largest volume first; then the open one
    assert [p.is_watertight for p in parts] == [True] * 6 + [False]
    vols = [p.volume for p in parts[:6]]
    assert vols == sorted(vols, reverse=True)
    for p in parts[:6]:  # each part welded: a closed sphere again
        t = trimesh.Trimesh(p.vertices, p.face_indices.reshape(-1, 3), process=False)
        assert t.is_watertight and t.is_winding_consistent and p.euler_characteristic == 2


def test_parts_touching_at_a_point_stay_two_and_keep_their_attributes():
    tet = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    second = tet * -1.0  # shares the vertex at the origin, mirrored: faces reversed
    v = np.concatenate([tet, second])
    f = faces + [[a + 4, c + 4, b + 4] for a, b, c in faces]
    m = fg.Mesh(
        v,
        f,
        point_data={"h": np.arange(8.0)},
        face_data={"id": np.arange(8.0)},
    )
    parts, _ = run("mesh.split", mesh=m)
    assert len(parts) == 2
    for p in parts:
        assert p.n_vertices == 4 and p.is_watertight
        assert p.volume == pytest.approx(1 / 6, rel=1e-12)
    # the shared point came from the first of the coincident vertices: h = 0 in both
    assert sorted(parts[0].point_data["h"].tolist()) in ([0, 1, 2, 3], [0, 5, 6, 7])
    ids = sorted(parts[0].face_data["id"].tolist() + parts[1].face_data["id"].tolist())
    assert ids == list(range(8))
    for p in parts:
        for k in range(p.n_vertices):  # every attribute is its vertex's
            src = np.flatnonzero((v == p.vertices[k]).all(axis=1))[0]
            assert p.point_data["h"][k] == src


def test_split_of_an_empty_mesh_is_an_empty_list_with_a_warning():
    parts, warnings = run("mesh.split", mesh=fg.Mesh(np.zeros((0, 3)), np.zeros(0), [0]))
    assert parts == [] and "no faces" in warnings[0]


def test_measure_counts_parts_and_the_sealed_voids_among_them():
    outer = sphere(3.0)
    void = sphere(2.0, inward=True)  # a hollow ball's inner wall
    island = sphere(1.0)  # a ball inside the void: a part, not a void
    beside = sphere(1.0, (10, 0, 0))
    m = soup(merged([outer, void, island, beside]))
    g = fg.Graph()
    g.add("x", "mesh.measure", mesh=m)
    assert g.evaluate("x.parts") == 4
    assert g.evaluate("x.cavities") == 1
    tm = trimesh.Trimesh(m.vertices, m.face_indices.reshape(-1, 3))
    assert len(tm.split(only_watertight=False)) == 4


def test_a_void_whose_wall_faces_outward_is_still_a_cavity():
    m = merged([sphere(3.0), sphere(1.0, (0.5, 0.2, 0.1))])  # inner wall the wrong way round
    g = fg.Graph()
    g.add("x", "mesh.measure", mesh=m)
    assert (g.evaluate("x.parts"), g.evaluate("x.cavities")) == (2, 1)


def test_inside_counts_survive_rays_through_edges_and_vertices():
    """The ray from the point of a part runs exactly through the edges and vertices of an
    axis-aligned box around it (same y, z as the box's vertices): simulation of simplicity
    counts each crossing once."""
    g = fg.Graph()
    g.add("b", "mesh.box", size=[4, 4, 4])
    g.add("t", "mesh.triangulate", mesh="@b")
    box = g.evaluate("t")
    inner = fg.Mesh(
        np.array([[-1, -2, -2], [1, -2, -2], [-1, 2, -2], [-1, -2, 2]], float) * 0.25,
        [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    m = merged([box, inner])
    parts = kparts.face_parts(*m.arrays)
    counts = kparts.inside_counts(*m.arrays, parts, np.arange(parts.count))
    assert sorted(counts.tolist()) == [0, 1]


def test_face_parts_orders_closed_parts_by_volume_then_open_ones_by_area():
    small, big = sphere(1.0, (5, 0, 0)), sphere(2.0)
    sheet = fg.Mesh([[0, 0, 9], [9, 0, 9], [0, 9, 9]], [[0, 1, 2]])
    m = merged([sheet, small, big])
    parts = kparts.face_parts(*m.arrays)
    assert parts.count == 3
    assert parts.closed.tolist() == [True, True, False]
    assert parts.volume[0] > parts.volume[1] > 0
    assert parts.area[2] == pytest.approx(40.5)
