"""mesh.* nodes: graphs built in code and the box_sculpture example."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import formgraph as fg
from formgraph.kernels.mesh.meshops import triangulate

GRAPHS = Path(__file__).resolve().parents[1] / "graphs"


def run(node_type: str, graph: fg.Graph | None = None, **inputs):
    g = graph or fg.Graph()
    g.add("n", node_type, **inputs)
    return g.evaluate("n")


def volume(m: fg.Mesh) -> float:
    _, tf, _ = triangulate(m.vertices, m.face_indices, m.face_offsets)
    t = m.vertices[tf.reshape(-1, 3)]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6)


def test_box():
    m = run("mesh.box", size=[1, 2, 3], center=[1, 0, 0])
    assert isinstance(m, fg.Mesh) and (m.n_vertices, m.n_faces) == (8, 6)
    assert m.halfedges.is_closed
    assert volume(m) == pytest.approx(6.0)
    np.testing.assert_allclose(m.vertices.min(axis=0), [0.5, -1, -1.5])
    assert volume(run("mesh.box", size=2)) == pytest.approx(8.0)
    assert volume(run("mesh.box")) == pytest.approx(1.0)


def test_box_rejects_a_flat_size():
    with pytest.raises(fg.NodeError, match=r"input 'size'.*box size must be > 0 along every axis"):
        run("mesh.box", size=[1, 0, 1])


def test_from_faces_mixed_sizes():
    pts = [[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [0, 1], [1, 2]]
    m = run("mesh.from_faces", vertices=pts, faces=[[0, 1, 4, 5], [1, 2, 3, 4], [5, 4, 6]])
    assert m.face_sizes.tolist() == [4, 4, 3]
    assert m.vertices.shape == (7, 3) and m.halfedges.euler_characteristic == 1


def test_a_faces_array_of_one_size_is_taken_whole():
    # fg.Mesh(v, (n, k) int array): flat as it is, the same mesh as from its rows
    v = np.random.default_rng(1).random((6, 3))
    quads = np.array([[0, 1, 2, 3], [2, 3, 4, 5]], dtype=np.int32)
    whole, rows = fg.Mesh(v, quads), fg.Mesh(v, [list(r) for r in quads])
    assert whole.face_indices.tolist() == rows.face_indices.tolist() == quads.ravel().tolist()
    assert whole.face_offsets.tolist() == rows.face_offsets.tolist() == [0, 4, 8]
    assert fg.Mesh(v, np.zeros((0, 3), dtype=np.int64)).n_faces == 0
    with pytest.raises(ValueError, match="face 1 refers to vertex 6, but there are 6"):
        fg.Mesh(v, np.array([[0, 1, 2], [3, 4, 6]]))
    with pytest.raises(ValueError, match="face 0 has 2 vertices"):
        fg.Mesh(v, np.array([[0, 1], [2, 3]]))


@pytest.mark.parametrize(
    "faces, message",
    [
        ([[0, 1, 2], [0, 1, 3]], r"faces 0 and 1 both run edge 0 -> 1 the same way"),
        ([[0, 1, 2], [1, 0, 3], [0, 1, 2]], r"edge \(0, 1\) is shared by 3 faces"),
        ([[0, 1, 9]], r"face 0 refers to vertex 9, but the mesh has 4 vertices"),
        ([[0, 1]], r"face 0 has 2 vertices; a face needs at least 3"),
    ],
)
def test_from_faces_rejects_bad_faces(faces, message):
    pts = [[0, 0], [1, 0], [1, 1], [0, 1]]
    with pytest.raises(fg.NodeError, match=r"node 'n', input 'faces'.*" + message):
        run("mesh.from_faces", vertices=pts, faces=faces)


@pytest.mark.parametrize(
    "faces, message",
    [
        ([[0, 1, "a"]], r"face 0 must be a list of vertex indices"),
        ("0 1 2", r"expected a list of faces"),
    ],
)
def test_from_faces_checks_the_faces_before_running(faces, message):
    g = fg.Graph()
    g.add("n", "mesh.from_faces", vertices=[[0, 0], [1, 0], [1, 1]], faces=faces)
    with pytest.raises(fg.GraphError, match=r"node 'n', input 'faces': " + message):
        g.check()


def test_catmull_clark_node():
    g = fg.Graph()
    g.add("b", "mesh.box", size=2)
    m = run("mesh.catmull_clark", g, mesh="@b")
    assert (m.n_vertices, m.n_faces) == (26, 24)
    np.testing.assert_allclose(np.abs(m.vertices[:8]), 5 / 9)
    m2 = run("mesh.catmull_clark", mesh=run("mesh.box"), levels=2)
    assert (m2.n_vertices, m2.n_faces) == (98, 96)
    same = run("mesh.catmull_clark", mesh=run("mesh.box"), levels=0)
    np.testing.assert_array_equal(same.vertices, run("mesh.box").vertices)


def test_catmull_clark_crease_angle_keeps_a_box():
    box = run("mesh.box", size=2)
    m = run("mesh.catmull_clark", mesh=box, levels=3, crease_angle=45)
    np.testing.assert_allclose(np.abs(m.vertices).max(axis=1), 1.0)
    soft = run("mesh.catmull_clark", mesh=box, levels=3, crease_angle=45, sharpness=1)
    assert np.abs(soft.vertices).max(axis=1).min() < 0.99
    assert volume(m) > volume(soft) > volume(run("mesh.catmull_clark", mesh=box, levels=3))


def test_sharpness_without_creases_warns():
    g = fg.Graph()
    g.add("b", "mesh.box")
    g.add("n", "mesh.catmull_clark", mesh="@b", sharpness=2)
    g.evaluate("n")
    assert any("sharpness has no effect" in w for w in g.stats["n"].warnings)


@pytest.mark.parametrize("node_type", ["mesh.catmull_clark", "mesh.doo_sabin"])
def test_subdivision_budget_is_checked_before_allocating(node_type):
    g = fg.Graph()
    g.add("b", "mesh.box")
    # 6 * 4**20 faces could never be allocated: the refusal must come first
    g.add("n", node_type, mesh="@b", levels=20)
    with pytest.raises(fg.BudgetError, match=r"would make [\d,]+ faces, over the budget"):
        g.evaluate("n")
    small = fg.Graph(budget=1000)
    small.add("b", "mesh.box")
    small.add("n", node_type, mesh="@b", levels=3)  # 384 faces: fine
    small.evaluate("n")
    small.add("m", node_type, mesh="@b", levels=4)  # 1,536 faces: refused
    with pytest.raises(fg.BudgetError, match="1,53[0-9] faces, over the budget of 1,000"):
        small.evaluate("m")


def test_subdivision_rejects_a_nonmanifold_mesh():
    g = fg.Graph()
    g.add_param("bad", type="Mesh")
    g.add("n", "mesh.catmull_clark", mesh="=bad")
    bad = fg.Mesh(np.zeros((5, 3)), [[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    with pytest.raises(fg.NodeError, match=r"input 'mesh'.*edge \(0, 1\) is shared by 3 faces"):
        g.evaluate("n", bad=bad)


def test_doo_sabin_node():
    m = run("mesh.doo_sabin", mesh=run("mesh.box", size=2))
    assert (m.n_vertices, m.n_faces) == (24, 26)
    assert sorted(m.face_sizes.tolist()) == [3] * 8 + [4] * 18
    m2 = run("mesh.doo_sabin", mesh=run("mesh.box"), levels=2)
    assert (m2.n_vertices, m2.n_faces) == (96, 98)


def test_triangulate_node():
    pts = [[0, 0], [2, 0], [2, 2], [1, 1], [0, 2]]  # a concave pentagon (an arrow)
    m = run("mesh.triangulate", mesh=run("mesh.from_faces", vertices=pts, faces=[[0, 1, 2, 3, 4]]))
    assert m.n_faces == 3 and (m.face_sizes == 3).all()
    t = m.vertices[m.face_indices.reshape(-1, 3)]
    area = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 2] / 2
    assert (area > 0).all() and area.sum() == pytest.approx(3.0)
    box = run("mesh.triangulate", mesh=run("mesh.box"))
    assert box.n_faces == 12 and volume(box) == pytest.approx(1.0)


def test_triangulate_node_tiles_a_large_concave_face_in_space_and_carries_face_data():
    """A 300-corner star face on a tilted plane with a second, square face, through the
    public API (a Mesh param): the star's triangles tile it (shapely's area, each inside),
    face normal kept, and each triangle carries its face's attribute."""
    shapely = pytest.importorskip("shapely")
    k = 300
    t = 2 * np.pi * np.arange(k) / k
    r = np.where(np.arange(k) % 2 == 0, 1.0, 0.3 + 0.2 * np.sin(7 * t))
    xy = np.column_stack([r * np.cos(t), r * np.sin(t)])
    rot = Rotation.from_euler("xyz", [30, -50, 10], degrees=True).as_matrix()
    square = np.array([[3.0, 0], [4, 0], [4, 1], [3, 1]])
    v = np.column_stack([np.r_[xy, square], np.zeros(k + 4)]) @ rot.T
    faces = [np.arange(k), np.arange(k, k + 4)]
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("t", "mesh.triangulate", mesh="=m")
    m = g.evaluate("t", m=fg.Mesh(v, faces, face_data={"id": np.array([5.0, 7.0])}))
    assert m.n_faces == (k - 2) + 2 and (m.face_sizes == 3).all()
    assert np.array_equal(m.face_data["id"], np.r_[np.full(k - 2, 5.0), 7.0, 7.0])
    tri = m.face_indices.reshape(-1, 3)[: k - 2]
    flat = (m.vertices @ rot)[:, :2]  # back in the plane
    a, b, c = flat[tri[:, 0]], flat[tri[:, 1]], flat[tri[:, 2]]
    area = ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]) / 2
    star = shapely.Polygon(xy)
    assert (area > 0).all() and area.sum() == pytest.approx(star.area, rel=1e-9)
    assert shapely.covers(star.buffer(1e-9), shapely.polygons(flat[tri])).all()


def test_merge_node():
    g = fg.Graph()
    g.add("a", "mesh.box")
    g.add("b", "mesh.box", center=[3, 0, 0])
    g.add("m", "mesh.merge", meshes=["@a", "@b"])
    g.add("one", "mesh.merge", meshes="@a")  # a single mesh where a list is asked
    m, one = g.evaluate("m"), g.evaluate("one")
    assert (m.n_vertices, m.n_faces) == (16, 12)
    assert m.halfedges.euler_characteristic == 4 and volume(m) == pytest.approx(2.0)
    assert one.n_faces == 6


def test_transform_node_matches_scipy():
    box = run("mesh.box", size=[1, 2, 3])
    angles = [30.0, -45.0, 120.0]
    m = run("mesh.transform", mesh=box, translate=[1, 2, 3], rotate=angles, scale=[2, 1, 0.5])
    expect = Rotation.from_euler("xyz", angles, degrees=True).apply(box.vertices * [2, 1, 0.5])
    np.testing.assert_allclose(m.vertices, expect + [1, 2, 3], atol=1e-12)
    assert volume(m) == pytest.approx(6.0)


def test_mirroring_transform_keeps_faces_outward():
    box = run("mesh.box")
    m = run("mesh.transform", mesh=box, scale=[-1, 1, 1])
    assert volume(m) == pytest.approx(1.0)  # faces reversed with the mirror
    assert volume(run("mesh.transform", mesh=box, scale=-2)) == pytest.approx(8.0)
    with pytest.raises(fg.NodeError, match=r"input 'scale'.*scale factors must be non-zero"):
        run("mesh.transform", mesh=box, scale=0)


def test_only_the_changed_branch_recomputes():
    g = fg.load(GRAPHS / "box_sculpture.yaml")
    g.evaluate("sculpture")
    g.evaluate("sculpture", crease=45)
    assert g.stats["hard_slab"].status == "computed"
    assert g.stats["smooth_blocks"].status == "cached"


def test_box_sculpture_example(tmp_path):
    g = fg.load(GRAPHS / "box_sculpture.yaml", out_dir=tmp_path)
    m = g.evaluate("sculpture")
    he = m.halfedges
    assert he.is_closed and he.euler_characteristic == 2 * 4  # four closed blobs
    assert (m.face_sizes == 4).all()
    tri = g.evaluate("printable")
    assert (tri.face_sizes == 3).all() and volume(tri) > 0
