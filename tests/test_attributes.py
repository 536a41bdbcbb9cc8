"""attr.set, per-element expressions, and attributes through every node that carries them
(nodes/attributes.py, kernels/attributes/propagate.py, language/elements.py)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import formgraph as fg
from formgraph.geometry import Mesh, Points
from formgraph.kernels.attributes.noise import noise
from formgraph.kernels.attributes.random import rand
from formgraph.kernels.geometry.meshdist import point_triangle_distance
from formgraph.kernels.mesh import meshops
from formgraph.kernels.mesh.meshops import rotation_matrix


def run(node_type: str, geometry, port: str = "mesh", /, **inputs):
    """``node_type`` applied to ``geometry`` (a Mesh, Points or a list of meshes)."""
    g = fg.Graph()
    kind = "Mesh" if isinstance(geometry, Mesh) else "Points"
    kind = kind if isinstance(geometry, (Mesh, Points)) else "list[Mesh]"
    g.add_param("input_", type=kind)
    g.add("n", node_type, **{port: "=input_"}, **inputs)
    return g.evaluate("n", input_=geometry)


def load_text(tmp_path, text: str, **kw) -> fg.Graph:
    path = tmp_path / "g.yaml"
    path.write_text(text)
    return fg.load(path, **kw)


def box(size=(1.0, 2.0, 3.0), center=(0.0, 0.0, 0.0)) -> Mesh:
    return Mesh(*meshops.box(size, center))


def linear(m: Mesh, name: str = "h") -> Mesh:
    """``m`` with point attribute ``h = 2x - 3y + z/2 + 1``, linear in space."""
    v = m.vertices
    return m.with_data({name: 2 * v[:, 0] - 3 * v[:, 1] + 0.5 * v[:, 2] + 1}, m.face_data)


def linear_error(m: Mesh, name: str = "h") -> float:
    v = m.vertices
    return float(np.abs(m.point_data[name] - (2 * v[:, 0] - 3 * v[:, 1] + 0.5 * v[:, 2] + 1)).max())


# ------------------------------------------------------------------------------ attr.set


def test_attr_set_evaluates_once_over_every_element():
    pts = Points(np.random.default_rng(0).uniform(-5, 5, (500, 3)))
    out = run("attr.set", pts, "geometry", name="h", value="=x * 2 + rand(i, 3) + noise(x, y, z)")
    x, y, z = pts.xyz.T
    expect = x * 2 + rand(np.arange(500.0), 3) + noise(x, y, z)
    np.testing.assert_array_equal(out.point_data["h"], expect)
    np.testing.assert_array_equal(out.xyz, pts.xyz)  # the same points
    vec = run("attr.set", out, "geometry", name="color", value=["=h / 10", 0.5, "=i / count"])
    assert vec.point_data["color"].shape == (500, 3)
    np.testing.assert_array_equal(vec.point_data["color"][:, 0], out.point_data["h"] / 10)
    np.testing.assert_array_equal(vec.point_data["color"][:, 2], np.arange(500) / 500)
    const = run("attr.set", pts, "geometry", name="c", value=[0.1, 0.2, 0.3])
    assert (
        const.point_data["c"].shape == (500, 3)
        and (const.point_data["c"][7] == [0.1, 0.2, 0.3]).all()
    )


def test_attr_set_on_faces_and_params(tmp_path):
    g = load_text(
        tmp_path,
        """
formgraph: 1
params: {k: {default: 3.0}}
nodes:
  b: {type: mesh.box, size: [2, 2, 2]}
  up: {type: attr.set, geometry: "@b", name: up, value: "=k * nz", domain: face}
  cz: {type: attr.set, geometry: "@b", name: cz, value: "=z", domain: face}
""",
    )
    up = g.evaluate("up").face_data["up"]
    assert sorted(up.tolist()) == [-3, 0, 0, 0, 0, 3]
    assert sorted(g.evaluate("cz").face_data["cz"].tolist()) == [-1, 0, 0, 0, 0, 1]
    assert g.evaluate("up", k=1.0).face_data["up"].max() == 1.0


def test_unknown_name_is_an_error_naming_node_input_and_attributes(tmp_path):
    g = load_text(
        tmp_path,
        """
formgraph: 1
nodes:
  p: {type: points.grid, nx: 3, ny: 3}
  t: {type: attr.set, geometry: "@p", name: tag, value: 1}
  bad: {type: attr.set, geometry: "@t", name: h, value: "=heigth * 2"}
""",
    )
    with pytest.raises(fg.NodeError, match=r"node 'bad', input 'value'") as info:
        g.evaluate("bad")
    assert "names 'heigth'" in str(info.value) and "(attributes: tag)" in str(info.value)
    with pytest.raises(fg.NodeError, match="'name'"):
        run("attr.set", Points([[0, 0]]), "geometry", name="2x", value=1)
    with pytest.raises(fg.NodeError, match="no faces"):
        run("attr.set", Points([[0, 0]]), "geometry", name="a", value=1, domain="face")


def test_attributes_reach_the_disk_cache_and_come_back(tmp_path):
    text = """
formgraph: 1
nodes:
  b: {type: mesh.box}
  s: {type: attr.set, geometry: "@b", name: h, value: "=rand(i) + z"}
  c: {type: mesh.catmull_clark, mesh: "@s", levels: 1}
"""
    first = load_text(tmp_path, text, cache_dir=tmp_path / "cache").evaluate("c")
    g = load_text(tmp_path, text, cache_dir=tmp_path / "cache")
    again = g.evaluate("c")
    assert g.stats["c"].status != "computed"
    assert again == first and again.point_data["h"].tolist() == first.point_data["h"].tolist()


def test_a_new_rand_hash_leaves_results_cached_with_the_old_one_unused(tmp_path, monkeypatch):
    from formgraph.evaluation import run as run_mod

    text = """
formgraph: 1
nodes:
  b: {type: mesh.box}
  s: {type: attr.set, geometry: "@b", name: h, value: "=rand(i)"}
"""
    load_text(tmp_path, text, cache_dir=tmp_path / "cache").evaluate("s")
    g = load_text(tmp_path, text, cache_dir=tmp_path / "cache")
    g.evaluate("s")
    assert g.stats["s"].status != "computed"
    monkeypatch.setattr(run_mod, "FUNCTIONS_VERSION", run_mod.FUNCTIONS_VERSION + "-next")
    g = load_text(tmp_path, text, cache_dir=tmp_path / "cache")
    g.evaluate("s")
    assert g.stats["s"].status == "computed"


# ---------------------------------------------------------------------- propagation


@pytest.mark.parametrize("node_type", ["mesh.catmull_clark", "mesh.doo_sabin"])
def test_a_linear_attribute_stays_exactly_linear_through_subdivision(node_type):
    m = linear(box())
    m = m.with_data(m.point_data, {"f": np.arange(6.0)})
    out = run(node_type, m, levels=2)
    assert linear_error(out) < 1e-12
    f = out.face_data["f"]
    assert f.shape == (out.n_faces,) and f.min() >= 0 and f.max() <= 5
    if node_type == "mesh.doo_sabin":  # F-faces first: the shrunken faces keep their value
        assert f[:6].tolist() == list(range(6))
    if node_type == "mesh.catmull_clark":  # every child face has its parent's value
        assert np.bincount(f.astype(int)).tolist() == [16] * 6
        centres = np.add.reduceat(out.vertices[out.face_indices], out.face_offsets[:-1]) / 4
        parent_normal = meshops.face_normals(*m.arrays)[f.astype(int)]
        assert (np.einsum("ij,ij->i", centres, parent_normal) > 0).all()


def test_transform_turns_a_normal_attribute():
    m = box()
    normals = meshops.face_normals(*m.arrays)
    m = m.with_data(None, {"normal": normals})
    out = run("geometry.transform", m, "geometry", rotate=[30, 40, 50], scale=[1, 2, -3])
    expect = meshops.face_normals(*out.arrays)  # the faces' real normals after the map
    np.testing.assert_allclose(out.face_data["normal"], expect, atol=1e-12)


def test_copy_to_points_carries_part_point_and_copy_index():
    part = linear(box((0.2, 0.2, 0.2)))
    pts = Points([[0, 0, 0], [5, 0, 0], [0, 5, 0]], {"w": [1.0, 2.0, 3.0]})
    g = fg.Graph()
    g.add_param("part", type="Mesh")
    g.add_param("pts", type="Points")
    g.add("c", "mesh.copy_to_points", mesh="=part", points="=pts", scale="=w")
    out = g.evaluate("c", part=part, pts=pts)
    assert out.point_data["copy"].tolist() == np.repeat([0, 1, 2], 8).tolist()
    assert out.point_data["w"].tolist() == np.repeat([1, 2, 3], 8).tolist()
    np.testing.assert_array_equal(out.point_data["h"], np.tile(part.point_data["h"], 3))
    size = np.ptp(out.vertices.reshape(3, 8, 3), axis=1)[:, 0]
    np.testing.assert_allclose(size, [0.2, 0.4, 0.6])


def test_per_point_expressions_match_a_loop_of_transforms():
    pts = Points(np.random.default_rng(2).uniform(-3, 3, (20, 3)))
    pts = pts.with_point_data({"normal": np.random.default_rng(3).normal(size=(20, 3))})
    part = box((0.3, 0.2, 0.1))
    g = fg.Graph()
    g.add_param("part", type="Mesh")
    g.add_param("pts", type="Points")
    g.add_param("k", default=0.5)
    g.add(
        "c",
        "mesh.copy_to_points",
        mesh="=part",
        points="=pts",
        scale="=k + rand(i)",
        rotate=[0, 0, "=360 * rand(i, 1)"],
        align="=normal",
    )
    out = g.evaluate("c", part=part, pts=pts)
    i = np.arange(20.0)
    scale, angle = 0.5 + rand(i), 360 * rand(i, 1)
    from formgraph.kernels.geometry import affine

    for k in range(20):
        n = pts.point_data["normal"][k]
        frame = affine.align_z(n[None])[0] @ rotation_matrix([0, 0, angle[k]]) * scale[k]
        expect = part.vertices @ frame.T + pts.xyz[k]
        np.testing.assert_allclose(out.vertices[8 * k : 8 * k + 8], expect, atol=1e-12)


def test_triangulate_merge_flip_orient_keep_attributes():
    m = linear(box())
    m = m.with_data(m.point_data, {"f": np.arange(6.0)})
    tri = run("mesh.triangulate", m)
    assert tri.face_data["f"].tolist() == np.repeat(np.arange(6.0), 2).tolist()
    assert linear_error(tri) == 0
    other = box(center=(5, 0, 0)).with_data({"g": np.ones(8)})
    merged = run("mesh.merge", [m, other], "meshes")
    assert merged.point_data["h"][8:].tolist() == [0] * 8  # absent on the second: 0
    assert merged.point_data["g"].tolist() == [0] * 8 + [1] * 8
    for node_type in ("mesh.flip", "mesh.orient"):
        out = run(node_type, m)
        assert out.point_data == m.point_data and out.face_data == m.face_data


def test_weld_cap_and_solidify_carry_attributes():
    soup = trimesh.creation.icosphere(1)
    tris = soup.vertices[soup.faces.reshape(-1)]
    m = Mesh(tris, np.arange(len(tris)), np.arange(0, len(tris) + 1, 3))
    m = linear(m)
    welded = run("mesh.weld", m)
    assert welded.n_vertices == len(soup.vertices) and linear_error(welded) == 0
    # an open tube: the fan centres of its (non-planar) loops get the mean of the loop
    plane = fg.Graph()
    plane.add("t", "nurbs.tessellate", surface="@c", u=4, v=12)
    plane.add("c", "nurbs.revolve", curve="@l", angle=360)
    plane.add("l", "nurbs.curve", points=[[1, 0, 0], [1.5, 0, 1], [1, 0, 2]], degree=2)
    tube = linear(plane.evaluate("t"))
    capped = run("mesh.cap", tube)
    assert capped.is_watertight and linear_error(capped) < 1e-12
    shell = run("mesh.solidify", linear(run("mesh.triangulate", box())), thickness=0.1)
    assert shell.point_data["h"].shape == (shell.n_vertices,)
    np.testing.assert_array_equal(shell.point_data["h"][:8], shell.point_data["h"][8:])


def test_booleans_interpolate_point_attributes_and_keep_face_sources():
    a = linear(box((2, 2, 2)))
    a = a.with_data(a.point_data, {"src": np.zeros(6)})
    b = linear(box((2, 2, 2), (1, 1, 1)))
    b = b.with_data(b.point_data, {"src": np.ones(6)})
    g = fg.Graph()
    g.add_param("a", type="Mesh")
    g.add_param("b", type="Mesh")
    g.add("d", "mesh.boolean", a="=a", b="=b", operation="difference")
    g.add("u", "mesh.union", meshes=["=a", "=b"])
    for name in ("d", "u"):
        out = g.evaluate(name, a=a, b=b)
        assert out.is_watertight and linear_error(out) < 1e-12
        # faces from b's box lie in b's planes, a's in a's
        centres = np.add.reduceat(out.vertices[out.face_indices], out.face_offsets[:-1]) / 3
        from_b = out.face_data["src"] == 1
        on_b = np.isclose(np.abs(centres - 1), 1).any(axis=1)
        on_a = np.isclose(np.abs(centres), 1).any(axis=1)
        assert from_b.any() and (~from_b).any()
        assert on_b[from_b].all() and on_a[~from_b].all()


def _sphere_with_attributes() -> tuple[trimesh.Trimesh, Mesh]:
    tm = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    m = linear(Mesh(tm.vertices, tm.faces.reshape(-1), np.arange(0, tm.faces.size + 1, 3)))
    v = m.vertices
    point = {**m.point_data, "k": np.full(len(v), 0.37), "color": (v + 1) / 2}
    return tm, m.with_data(point, {"id": np.arange(m.n_faces, dtype=float)})


@pytest.mark.parametrize(
    ("node_type", "inputs"),
    [
        ("mesh.decimate", {"ratio": 0.3}),
        ("mesh.remesh", {"edge_length": 0.25}),
        ("mesh.offset", {"distance": 0.1, "cell": 0.15}),
        ("mesh.offset", {"distance": -0.2, "cell": 0.15}),
    ],
)
def test_remade_surfaces_take_attributes_from_the_closest_point_of_the_input(node_type, inputs):
    tm, m = _sphere_with_attributes()
    out = run(node_type, m, **inputs)
    assert set(out.point_data) == {"h", "k", "color"} and set(out.face_data) == {"id"}
    assert out.point_data["color"].shape == (out.n_vertices, 3)
    assert np.all(out.point_data["k"] == 0.37)  # a constant stays exact
    # a linear attribute: its value at each new vertex's closest point of the input, by
    # trimesh's own closest-point query
    q, dist, _ = trimesh.proximity.closest_point(tm, out.vertices)
    h_at_q = 2 * q[:, 0] - 3 * q[:, 1] + 0.5 * q[:, 2] + 1
    np.testing.assert_allclose(out.point_data["h"], h_at_q, rtol=0, atol=1e-9)
    # so within |grad h| * distance of the linear function at the vertex itself
    assert linear_error(out) <= np.sqrt(2**2 + 3**2 + 0.5**2) * dist.max() + 1e-9
    np.testing.assert_allclose(out.point_data["color"], (q + 1) / 2, rtol=0, atol=1e-9)
    # each new face: the input face nearest its centroid (any of a tie)
    c = np.add.reduceat(out.vertices[out.face_indices], out.face_offsets[:-1]) / 3
    ids = out.face_data["id"].astype(int)
    assert np.array_equal(ids, out.face_data["id"])
    got = np.linalg.norm(trimesh.triangles.closest_point(tm.triangles[ids], c) - c, axis=1)
    # the exact nearest by brute force over every face (trimesh's closest_point picks its
    # candidates by a radius heuristic and can miss the nearest by ~1e-7 on a tie)
    tri = tm.triangles
    best = point_triangle_distance(c[:, None], tri[None, :, 0], tri[None, :, 1], tri[None, :, 2])
    np.testing.assert_allclose(got, best.min(axis=1), rtol=0, atol=1e-12)


def test_remade_surfaces_of_polygons_take_the_nearest_polygon_and_nothing_without():
    m = linear(box((2, 2, 2)))  # six quads
    m = m.with_data(m.point_data, {"side": np.arange(6.0)})
    out = run("mesh.offset", m, distance=0.3, cell=0.2)
    tri = meshops.triangulate(m.vertices, m.face_indices, m.face_offsets)[1].reshape(-1, 3)
    corners = m.vertices[tri]  # two triangles per side, in face order
    q = trimesh.proximity.closest_point(trimesh.Trimesh(m.vertices, tri), out.vertices)[0]
    np.testing.assert_allclose(
        out.point_data["h"], 2 * q[:, 0] - 3 * q[:, 1] + 0.5 * q[:, 2] + 1, rtol=0, atol=1e-9
    )
    c = np.add.reduceat(out.vertices[out.face_indices], out.face_offsets[:-1]) / 3
    near = [  # from every centroid to each triangle, then to each side (two triangles)
        trimesh.triangles.closest_point(np.repeat(corners[[j]], len(c), axis=0), c)
        for j in range(len(tri))
    ]
    to_side = np.linalg.norm(np.stack(near, axis=1) - c[:, None], axis=2)
    to_side = to_side.reshape(len(c), 6, 2).min(axis=2)
    side = out.face_data["side"].astype(int)
    np.testing.assert_allclose(to_side[np.arange(len(c)), side], to_side.min(axis=1), atol=1e-12)
    assert len(np.unique(side)) == 6
    plain = run("mesh.decimate", box((2, 2, 2)), ratio=0.5)
    assert not plain.point_data and not plain.face_data


def test_tessellation_and_grid_carry_u_v():
    g = fg.Graph()
    g.add("l", "nurbs.curve", points=[[1, 0, 0], [2, 0, 1], [1, 0, 2]], degree=2)
    g.add("s", "nurbs.revolve", curve="@l", angle=180)
    g.add("t", "nurbs.tessellate", surface="@s", u=6, v=5)
    s, m = g.evaluate("s"), g.evaluate("t")
    u, v = m.point_data["u"], m.point_data["v"]
    np.testing.assert_allclose(s.evaluate(u, v), m.vertices, atol=1e-12)
    rows = [Points([[i, j, 0] for j in range(4)], {"r": [i] * 4}) for i in range(3)]
    gg = fg.Graph()
    gg.add_param("rows", type="list[Points]")
    gg.add("m", "surfaces.grid", points="=rows")
    grid = gg.evaluate("m", rows=rows)
    np.testing.assert_allclose(grid.point_data["u"], grid.vertices[:, 0] / 2)
    np.testing.assert_allclose(grid.point_data["v"], grid.vertices[:, 1] / 3)
    assert grid.point_data["r"].tolist() == grid.vertices[:, 0].tolist()


# --------------------------------------------------------------------------------- export


def test_ply_writes_colours_and_attributes_that_trimesh_and_meshio_read(tmp_path):
    import io
    import struct

    import meshio

    from formgraph.kernels.io.exporters import ply_binary

    sphere = trimesh.creation.icosphere(2)
    m = Mesh(sphere.vertices, sphere.faces.reshape(-1), np.arange(0, sphere.faces.size + 1, 3))
    z = m.vertices[:, 2]
    colour = np.column_stack([(z + 1) / 2, np.full_like(z, 0.25), 1 - (z + 1) / 2])
    face_colour = np.tile([0.0, 1.0, 0.5], (m.n_faces, 1))
    m = m.with_data({"color": colour, "h": z}, {"color": face_colour, "id": np.arange(m.n_faces)})
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("w", "export.ply", mesh="=m", path="colours.ply")
    g.out_dir = tmp_path
    path = g.evaluate("w", m=m)
    back = trimesh.load(path, process=False)
    np.testing.assert_array_equal(back.vertices, m.vertices)
    np.testing.assert_array_equal(back.visual.vertex_colors[:, :3], np.rint(colour * 255))
    faces = back.metadata["_ply_raw"]["face"]["data"]
    np.testing.assert_array_equal(faces["id"], np.arange(m.n_faces))
    assert (faces["green"] == 255).all() and (faces["blue"] == 128).all()
    # meshio reads the vertex properties (it refuses face lists with more properties)
    only_points = tmp_path / "points.ply"
    only_points.write_bytes(ply_binary(*m.arrays, m.point_data))
    raw = meshio.read(only_points)
    np.testing.assert_array_equal(raw.point_data["h"], z)
    red = raw.point_data["red"].view(np.uint8)  # meshio reads uchar as int8
    np.testing.assert_array_equal(red, np.rint(colour[:, 0] * 255))
    # mixed face sizes with a face attribute: records of different lengths, parsed by hand
    v, fi, fo = meshops.box(1.0)
    fi, fo = np.r_[fi, [0, 1, 2]], np.r_[fo, fo[-1] + 3]
    data = ply_binary(v, fi, fo, None, {"k": np.arange(7.0)})
    body = data[data.index(b"end_header\n") + 11 + 8 * 3 * 8 :]
    pos, faces = 0, []
    for _ in range(7):
        c = body[pos]
        idx = struct.unpack(f"<{c}i", body[pos + 1 : pos + 1 + 4 * c])
        (k,) = struct.unpack("<d", body[pos + 1 + 4 * c : pos + 9 + 4 * c])
        faces.append((list(idx), k))
        pos += 9 + 4 * c
    assert pos == len(body) and [k for _, k in faces] == list(range(7))
    assert [f for f, _ in faces] == [list(f) for f in Mesh(v, fi, fo).faces]
    plain = trimesh.load(io.BytesIO(ply_binary(*box().arrays)), file_type="ply", process=False)
    assert len(plain.vertices) == 8


def test_curves_copy_to_points_per_point_and_sample_surface_attributes():
    g = fg.Graph()
    g.add("wall", "surfaces.parametric", x="v", y="0.5 * sin(v)", z="u", u=[0, 2], v=[0, 6])
    g.add("spots", "geometry.sample_surface", surface="@wall", u=2, v=5)
    g.add("ring", "nurbs.circle", radius=0.2)
    g.add(
        "rings",
        "curves.copy_to_points",
        curve="@ring",
        points="@spots.points",
        align="=normal",
        scale="=1 + i",
    )
    spots = g.evaluate("spots")
    pts = spots.points
    np.testing.assert_array_equal(pts.point_data["normal"], np.asarray(spots.normals))
    assert pts.point_data["u"].shape == (10,) and pts.point_data["v"].max() < 6
    rings = g.evaluate("rings")
    for k, ring in enumerate(rings):
        p = ring.sample(64)
        r = np.linalg.norm(p - pts.xyz[k], axis=1)
        np.testing.assert_allclose(r, 0.2 * (1 + k), rtol=1e-9)
        # the ring's plane is normal to the surface normal there
        np.testing.assert_allclose((p - pts.xyz[k]) @ pts.point_data["normal"][k], 0, atol=1e-9)


def test_per_element_values_are_checked(tmp_path):
    g = load_text(
        tmp_path,
        """
formgraph: 1
nodes:
  p: {type: points.grid, nx: 2, ny: 2}
  inf: {type: attr.set, geometry: "@p", name: h, value: "=1 / (x * 0)"}
  deep: {type: mesh.copy_to_points, mesh: "@b", points: "@p", rotate: "=x"}
  b: {type: mesh.box}
""",
    )
    with pytest.raises(fg.NodeError, match="not finite at element 0"):
        g.evaluate("inf")
    with pytest.raises(fg.NodeError, match="input 'rotate'"):
        g.evaluate("deep")  # one number per point where a vector per point is needed
    with pytest.raises(fg.NodeError, match=r"rotate needs \[rx, ry, rz\] per point"):
        g.evaluate("deep")


def test_from_faces_takes_the_points_attributes():
    pts = Points([[0, 0], [1, 0], [1, 1], [0, 1]], {"w": [1.0, 2.0, 3.0, 4.0]})
    out = run("mesh.from_faces", pts, "vertices", faces=[[0, 1, 2, 3]])
    assert out.point_data["w"].tolist() == [1, 2, 3, 4]


def test_per_element_expressions_in_a_repeat_read_the_loop_name(tmp_path):
    text = """
formgraph: 1
nodes:
  p: {type: points.grid, nx: 3, ny: 1}
  s: {type: attr.set, repeat: {k: 3}, geometry: "@p", name: h, value: "=x * k + rand(i, k)"}
"""
    out = load_text(tmp_path, text).evaluate("s")
    x, i = np.asarray(out[0].xyz)[:, 0], np.arange(3.0)
    for k, value in enumerate(out):
        np.testing.assert_array_equal(value.point_data["h"], x * k + rand(i, k))


def test_glb_writes_the_color_attribute_as_color_0(tmp_path):
    sphere = trimesh.creation.icosphere(2)
    m = Mesh(sphere.vertices, sphere.faces.reshape(-1), np.arange(0, sphere.faces.size + 1, 3))
    z = m.vertices[:, 2]
    colour = np.column_stack([(z + 1) / 2, np.full_like(z, 0.25), 1 - (z + 1) / 2])
    g = fg.Graph()
    g.add_param("m", type="Mesh")
    g.add("w", "export.gltf", meshes=["=m"], path="colours.glb")
    g.out_dir = tmp_path
    path = g.evaluate("w", m=m.with_data({"color": colour}))
    scene = trimesh.load(path, process=False)
    back = next(iter(scene.geometry.values()))
    assert len(back.vertices) == m.n_vertices
    np.testing.assert_allclose(back.visual.vertex_colors[:, :3] / 255.0, colour, atol=1 / 255)


def test_onto_triangles_without_area():
    from formgraph.kernels.attributes import propagate as carry

    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [7, 0, 0]] + [[9, 9, 9]] * 3
    m = Mesh(np.array(v, float), np.arange(9), [0, 3, 6, 9])
    m = m.with_data({"h": np.arange(9.0)}, {"f": [1.0, 2, 3]})
    p = np.array([[0.25, 0.25, 1.0], [5.1, 0.5, 0.0], [6.8, -0.2, 0.3], [9, 9, 9.5]])
    data = carry.onto(m, p, (np.array([0, 1, 2, 3]), np.array([0, 4])))
    # a face: barycentric; collinear corners: along the nearest edge; one point: its value
    np.testing.assert_allclose(data["point_data"]["h"], [0.75, 3.1, 4.8, 6], atol=1e-12)
    assert data["face_data"]["f"].tolist() == [2.0]  # centroid (5.3, 2.4, 2.7): the segment


def test_onto_finds_the_closest_triangle_exactly():
    from formgraph.kernels.geometry.meshdist import Nearest

    tm = trimesh.creation.torus(2.0, 0.6, 40, 12)
    rng = np.random.default_rng(9)
    p = np.concatenate(
        [
            tm.vertices[rng.integers(0, len(tm.vertices), 300)] + rng.normal(size=(300, 3)) * s
            for s in (0.01, 0.2, 3.0)
        ]
    )
    _, tri, v, w = Nearest(tm.vertices[tm.faces]).locate(p)
    a, b, c = (tm.vertices[tm.faces[tri, j]] for j in range(3))
    assert np.all((v >= -1e-12) & (w >= -1e-12) & (v + w <= 1 + 1e-12))
    q = a + v[:, None] * (b - a) + w[:, None] * (c - a)
    # brute force: every point against every triangle (Ericson's exact distance)

    t = tm.vertices[tm.faces]
    ref = point_triangle_distance(p[:, None], t[None, :, 0], t[None, :, 1], t[None, :, 2])
    np.testing.assert_allclose(np.linalg.norm(p - q, axis=1), ref.min(axis=1), atol=1e-12)
    # never farther than trimesh's closest points (its candidates by box are approximate)
    assert np.all(
        np.linalg.norm(p - q, axis=1) <= trimesh.proximity.closest_point(tm, p)[1] + 1e-12
    )
