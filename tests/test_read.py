"""The read.* nodes: files in the cache key, confinement, formats against independent writers."""

from __future__ import annotations

import io
from pathlib import Path

import meshio
import numpy as np
import pytest
import trimesh

import formgraph as fg
from formgraph.kernels.io.exporters import obj_bytes, ply_binary, stl_ascii, stl_binary

HEAD = "formgraph: 1\nnodes:\n"


pytestmark = pytest.mark.usefixtures("keep_locale")  # lib3mf writes: see conftest.py


def _graph(folder: Path, body: str, name: str = "g.yaml") -> Path:
    path = folder / name
    path.write_text(HEAD + body)
    return path


def _read(folder: Path, file: str, **kw) -> fg.Mesh:
    extra = "".join(f", {k}: {str(v).lower()}" for k, v in kw.items())
    g = fg.load(_graph(folder, f"  m: {{type: read.mesh, path: {file}{extra}}}\n"))
    return g.evaluate("m")


def _same_triangles(mesh: fg.Mesh, tm: trimesh.Trimesh, atol: float = 0.0) -> None:
    """The same triangles (as coordinate triples, in order) as ``tm``."""
    tris = mesh.face_indices.reshape(-1, 3)
    np.testing.assert_allclose(mesh.vertices[tris], tm.vertices[tm.faces], atol=atol, rtol=0)


# ------------------------------------------------------------------------- the cache key


def test_an_edited_file_recomputes_an_unchanged_one_is_not_parsed(tmp_path):
    trimesh.creation.box().export(tmp_path / "part.stl")
    g = fg.load(
        _graph(
            tmp_path,
            "  m: {type: read.mesh, path: part.stl, weld: true}\n"
            "  t: {type: mesh.triangulate, mesh: '@m'}\n",
        )
    )
    assert g.evaluate("t").n_faces == 12
    assert g.stats["m"].status == "computed"
    g.evaluate("t")
    assert g.stats["m"].status == "cached" and g.stats["t"].status == "cached"
    (tmp_path / "part.stl").touch()  # a new stamp, the same bytes: still cached
    g.evaluate("t")
    assert g.stats["m"].status == "cached"
    trimesh.creation.icosphere(1).export(tmp_path / "part.stl")
    assert g.evaluate("t").n_faces == 80
    assert g.stats["m"].status == "computed" and g.stats["t"].status == "computed"


def test_an_unchanged_file_is_not_even_read_again(tmp_path, monkeypatch):
    from formgraph.core import safety

    trimesh.creation.box().export(tmp_path / "part.stl")
    g = fg.load(_graph(tmp_path, "  m: {type: read.mesh, path: part.stl}\n"))
    reads = []
    real = safety.read_input
    monkeypatch.setattr(safety, "read_input", lambda p, *a: reads.append(p) or real(p, *a))
    g.evaluate("m")
    for _ in range(3):  # keyed again (as a sweep plans each variant): the stamp says unchanged
        g.plan("m")
        g.evaluate("m")
    assert len(reads) == 1 and g.stats["m"].status == "cached"


def test_the_disk_cache_keys_by_content_across_processes(tmp_path):
    trimesh.creation.box().export(tmp_path / "part.stl")
    path = _graph(tmp_path, "  m: {type: read.mesh, path: part.stl}\n")
    fg.load(path, cache_dir=tmp_path / "cache").evaluate("m")
    g = fg.load(path, cache_dir=tmp_path / "cache")
    g.evaluate("m")
    assert g.stats["m"].source == "disk"


def test_watch_files_include_the_inputs(tmp_path):
    trimesh.creation.box().export(tmp_path / "part.stl")
    g = fg.load(_graph(tmp_path, "  m: {type: read.mesh, path: part.stl}\n"))
    assert (tmp_path / "part.stl").resolve() in g.input_files
    assert g.files == [tmp_path / "g.yaml"]  # what a sweep sends along: the graph's own text


def test_an_inputs_folder_is_where_paths_start_and_stop(tmp_path):
    (tmp_path / "data").mkdir()
    trimesh.creation.box().export(tmp_path / "data" / "part.stl")
    path = _graph(tmp_path, "  m: {type: read.mesh, path: part.stl}\n")
    with pytest.raises(fg.GraphError, match="does not exist"):
        fg.load(path).evaluate("m")
    assert fg.load(path, inputs_dir=tmp_path / "data").evaluate("m").n_faces == 12


def test_the_cli_takes_an_inputs_folder_and_a_file_for_a_mesh_param(tmp_path):
    from tools import cli

    (tmp_path / "data").mkdir()
    trimesh.creation.box().export(tmp_path / "data" / "part.stl")
    graph = _graph(tmp_path, "  m: {type: read.mesh, path: part.stl, weld: true}\n")
    r = cli("run", str(graph), "--inputs", str(tmp_path / "data"), "--no-cache")
    assert r.returncode == 0, r.stderr
    assert "12 faces" in r.stdout or "12" in r.stdout


# --------------------------------------------------------------------------- the formats


@pytest.fixture(scope="module")
def ball() -> trimesh.Trimesh:
    return trimesh.creation.icosphere(2)


def test_stl_binary_and_ascii_from_trimesh(tmp_path, ball):
    (tmp_path / "b.stl").write_bytes(ball.export(file_type="stl"))
    (tmp_path / "a.stl").write_bytes(ball.export(file_type="stl_ascii").encode())
    _same_triangles(_read(tmp_path, "b.stl"), ball, atol=1e-6)  # binary STL holds float32
    _same_triangles(_read(tmp_path, "a.stl"), ball, atol=1e-6)


def test_stl_round_trips_with_our_exporters_and_welds_closed(tmp_path, ball):
    v, f = ball.vertices, ball.faces.ravel()
    fo = np.arange(0, f.size + 1, 3)
    (tmp_path / "b.stl").write_bytes(stl_binary(v, f, fo))
    (tmp_path / "a.stl").write_bytes(stl_ascii(v, f, fo))
    for name in ("a.stl", "b.stl"):
        m = _read(tmp_path, name, weld=True)
        assert m.n_vertices == len(v) and m.n_faces == len(ball.faces)
        assert trimesh.Trimesh(m.vertices, m.face_indices.reshape(-1, 3)).is_watertight


def test_obj_ply_off_keep_polygons_exactly(tmp_path):
    rng = np.random.default_rng(3)
    v = rng.normal(size=(7, 3))
    fi = np.array([0, 1, 2, 1, 2, 3, 4, 2, 4, 5, 6, 0])
    fo = np.array([0, 3, 7, 12])
    (tmp_path / "m.obj").write_bytes(obj_bytes(v, fi, fo))
    (tmp_path / "m.ply").write_bytes(ply_binary(v, fi, fo))
    cells = [("triangle", [[0, 1, 2]]), ("quad", [[1, 2, 3, 4]]), ("polygon", [[2, 4, 5, 6, 0]])]
    meshio.write(tmp_path / "m.off", meshio.Mesh(v, cells[:1]))
    for name in ("m.obj", "m.ply"):
        m = _read(tmp_path, name)
        assert np.array_equal(m.vertices, v)  # shortest round-trip text / doubles: exact
        assert m.face_indices.tolist() == fi.tolist() and m.face_offsets.tolist() == fo.tolist()
    off = _read(tmp_path, "m.off")
    np.testing.assert_allclose(off.vertices, v, rtol=1e-12)
    assert off.face_indices.tolist() == [0, 1, 2]


@pytest.mark.parametrize("binary", [True, False])
def test_ply_from_meshio_mixed_faces(tmp_path, binary):
    v = np.random.default_rng(1).random((6, 3))
    mm = meshio.Mesh(v, [("triangle", [[0, 1, 2]]), ("quad", [[1, 2, 3, 4]])])
    meshio.write(tmp_path / "m.ply", mm, binary=binary)
    m = _read(tmp_path, "m.ply")
    np.testing.assert_allclose(m.vertices, v, rtol=1e-7)
    assert m.face_offsets.tolist() == [0, 3, 7]
    assert m.face_indices.tolist() == [0, 1, 2, 1, 2, 3, 4]


def test_obj_negative_indices_texture_refs_and_crlf(tmp_path):
    text = (
        "# made by hand\r\no thing\r\nv 0 0 0\r\nv 1 0 0\r\nv 1 1 0 0.5 0.5 0.5\r\n"
        "vt 0 0\r\nvn 0 0 1\r\nf -3/1/1 -2/1/1 -1/1/1\r\nv 0 1 0\r\nf 1//1 3//1 4//1"
    )
    (tmp_path / "m.obj").write_text(text, newline="")
    m = _read(tmp_path, "m.obj")
    assert m.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    assert m.face_indices.tolist() == [0, 1, 2, 0, 2, 3]


def test_3mf_from_lib3mf_with_a_build_transform(tmp_path, ball):
    lib3mf = pytest.importorskip("lib3mf")
    w = lib3mf.get_wrapper()
    model = w.CreateModel()
    obj = model.AddMeshObject()
    obj.SetName("ball")
    pos = [lib3mf.Position(ctypes_floats(p)) for p in ball.vertices]
    tris = [lib3mf.Triangle(tuple(int(i) for i in t)) for t in ball.faces]
    obj.SetGeometry(pos, tris)
    t = lib3mf.Transform()
    m = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [10, 20, 30]]
    for r in range(4):
        for c in range(3):
            t.Fields[r][c] = m[r][c]
    model.AddBuildItem(obj, t)
    model.QueryWriter("3mf").WriteToFile(str(tmp_path / "m.3mf"))
    got = _read(tmp_path, "m.3mf")
    _same_triangles(got, ball.copy().apply_translation([10, 20, 30]), atol=1e-5)


def ctypes_floats(p) -> tuple[float, float, float]:
    return tuple(float(x) for x in p)


def test_glb_from_trimesh_every_mesh_with_its_transform(tmp_path, ball):
    box = trimesh.creation.box()
    rot = trimesh.transformations.rotation_matrix(0.7, [0, 0, 1], [1, 2, 3])
    scene = trimesh.Scene()
    scene.add_geometry(box, transform=rot)
    scene.add_geometry(ball, transform=trimesh.transformations.scale_matrix(2))
    (tmp_path / "s.glb").write_bytes(scene.export(file_type="glb"))
    got = _read(tmp_path, "s.glb")
    want = np.concatenate([g.vertices for g in scene.dump(concatenate=False)])
    # metres in the file, millimetres here
    assert got.n_faces == len(box.faces) + len(ball.faces)
    np.testing.assert_allclose(
        np.sort(got.vertices, axis=0), np.sort(want * 1000, axis=0), atol=1e-3
    )


# ------------------------------------------------------------------------- bad files


@pytest.mark.parametrize(
    "name, data, match",
    [
        ("t.stl", b"\0" * 80 + (10**8).to_bytes(4, "little") + b"\0" * 100, "claims 100,000,000"),
        ("t.stl", b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n", "three per facet"),
        ("t.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "does not exist"),
        ("t.obj", b"v 0 zero 0\n", "not a number"),
        ("t.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000\n"
         b"property float x\nproperty float y\nproperty float z\nend_header\n\0\0", "truncated"),
        ("t.off", b"OFF\n1000 1 0\n0 0 0\n", "truncated"),
        ("t.3mf", b"PK\x03\x04 not really", "not a 3MF"),
        ("t.glb", b"glTF\x02\0\0\0\xff\xff\0\0" + b"\0" * 12, "claims"),
        ("t.xyz", b"1 2 3\n", "unknown format"),
    ],
)  # fmt: skip
def test_garbage_names_the_node_the_input_and_the_file(tmp_path, name, data, match):
    (tmp_path / name).write_bytes(data)
    with pytest.raises(fg.NodeError, match=match) as info:
        _read(tmp_path, name)
    text = str(info.value)
    assert "node 'm'" in text and "input 'path'" in text and name in text


def test_a_3mf_zip_bomb_is_refused_by_its_budget(tmp_path):
    import zipfile

    from formgraph.kernels.io.threemf_read import read_3mf

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("3D/3dmodel.model", b"<model>" + b" " * (1 << 24))
    with pytest.raises(ValueError, match="zip bomb"):
        read_3mf(buf.getvalue(), max_bytes=1 << 20)


# ------------------------------------------------------------------------------- points


def _points(folder: Path, name: str, data: bytes) -> np.ndarray:
    (folder / name).write_bytes(data)
    g = fg.load(_graph(folder, f"  p: {{type: read.points, path: {name}}}\n"))
    return g.evaluate("p").xyz


def test_points_csv_header_names_the_columns(tmp_path):
    data = b"id,z,x,y\n0,3,1,2\n1,6,4,5\n# done\n"
    assert _points(tmp_path, "p.csv", data).tolist() == [[1, 2, 3], [4, 5, 6]]


def test_points_xyz_without_header_and_two_columns(tmp_path):
    assert _points(tmp_path, "p.xyz", b"1 2 3 255 0 0\n4 5 6 0 255 0\n").tolist() == [
        [1, 2, 3],
        [4, 5, 6],
    ]
    assert _points(tmp_path, "p.txt", b"x y\n1.5 2\n\n3 4e1\n").tolist() == [
        [1.5, 2, 0],
        [3, 40, 0],
    ]


def test_points_from_a_ply_written_by_trimesh(tmp_path):
    cloud = trimesh.PointCloud(np.random.default_rng(2).random((50, 3)))
    (tmp_path / "c.ply").write_bytes(cloud.export(file_type="ply"))
    np.testing.assert_allclose(_points(tmp_path, "c.ply", (tmp_path / "c.ply").read_bytes()),
                               cloud.vertices, rtol=1e-6)  # fmt: skip


def test_points_ragged_lines_are_refused(tmp_path):
    with pytest.raises(fg.NodeError, match="line 2 has 2 values but line 1 has 3"):
        _points(tmp_path, "p.xyz", b"1 2 3\n4 5\n")


# ------------------------------------------------------------------------ --set FILE


PARAMS = """\
formgraph: 1
params:
  part: {type: Mesh}
  outline: {type: "list[Curve]"}
  cloud: {type: Points}
nodes:
  m: {type: mesh.triangulate, mesh: "=part"}
"""


def test_set_fills_geometry_params_from_files(tmp_path):
    from formgraph.language.params import parse_sets

    trimesh.creation.box().export(tmp_path / "scan.stl")
    (tmp_path / "o.svg").write_bytes(
        b'<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="10mm" viewBox="0 0 10 10">'
        b'<circle cx="5" cy="5" r="2"/><rect width="1" height="1"/></svg>'
    )
    (tmp_path / "c.csv").write_bytes(b"1,2,3\n")
    (tmp_path / "g.yaml").write_text(PARAMS)
    g = fg.load(tmp_path / "g.yaml")
    got = parse_sets(
        g,
        [
            f"part={tmp_path / 'scan.stl'}",
            f"outline={tmp_path / 'o.svg'}",
            f"cloud={tmp_path / 'c.csv'}",
        ],
    )
    assert got["part"].n_faces == 12 and got["part"].n_vertices == 36  # as read.mesh reads it
    assert len(got["outline"]) == 2 and got["outline"][0].rational
    assert got["cloud"].xyz.tolist() == [[1, 2, 3]]
    assert g.evaluate("m", **got).n_faces == 12


def test_set_a_missing_or_bad_file_says_which_param(tmp_path):
    from formgraph.language.params import parse_sets

    (tmp_path / "g.yaml").write_text(PARAMS)
    g = fg.load(tmp_path / "g.yaml")
    with pytest.raises(fg.GraphError, match="--set part: .*does not exist"):
        parse_sets(g, [f"part={tmp_path / 'none.stl'}"])
    (tmp_path / "bad.stl").write_bytes(b"nonsense" * 20)
    with pytest.raises(fg.GraphError, match="--set part: cannot read .*claims"):
        parse_sets(g, [f"part={tmp_path / 'bad.stl'}"])


def test_run_with_set_file_from_the_command_line(tmp_path):
    from tools import cli

    trimesh.creation.icosphere(1).export(tmp_path / "scan.stl")
    (tmp_path / "g.yaml").write_text(
        "formgraph: 1\nparams:\n  part: {type: Mesh}\nnodes:\n"
        '  w: {type: mesh.weld, mesh: "=part"}\n'
    )
    r = cli("run", str(tmp_path / "g.yaml"), "--set", "part=scan.stl", "--no-cache", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "80" in r.stdout


def test_watch_watches_the_input_files(tmp_path):
    pytest.importorskip("pyvista")
    import os
    import time

    from formgraph import viewer

    (tmp_path / "data").mkdir()
    part = tmp_path / "data" / "part.stl"
    trimesh.creation.box().export(part)
    graph = _graph(tmp_path, "  m: {type: read.mesh, path: part.stl, weld: true}\n")
    w = viewer.ScreenshotWatcher(
        graph, tmp_path / "m.png", "m", out=io.StringIO(), err=io.StringIO(),
        out_dir=tmp_path / "o", inputs_dir=tmp_path / "data",
    )  # fmt: skip
    g, _ = w._load(None)  # what a reload loads, without drawing it
    assert part.resolve() in w.files and g.evaluate("m").n_faces == 12
    before = w._stamp()
    trimesh.creation.icosphere(1).export(part)
    later = time.time() + 5
    os.utime(part, (later, later))  # a new stamp, even on a coarse clock
    assert w._stamp() != before  # the next poll reloads


def test_a_sweep_worker_reads_inputs_from_the_same_folder(tmp_path):
    from formgraph.sweeps import cluster, tasks

    (tmp_path / "data").mkdir()
    trimesh.creation.box().export(tmp_path / "data" / "part.stl")
    graph = _graph(tmp_path, "  m: {type: read.mesh, path: part.stl, weld: true}\n")
    g = fg.load(graph, inputs_dir=tmp_path / "data")
    bp = cluster.blueprint(g, None, False)  # what travels to a worker
    assert bp.inputs == str((tmp_path / "data").resolve())
    assert tasks._graph(bp).evaluate("m").n_faces == 12


def test_ply_attributes_written_by_export_ply_come_back(tmp_path):
    (tmp_path / "w.yaml").write_text(
        HEAD + "  ball: {type: mesh.sphere, radius: 2}\n"
        "  paint: {type: attr.set, geometry: '@ball', name: color,"
        " value: ['=clip(0.5 + x / 4, 0, 1)', 0.5, 0.25]}\n"
        "  heat: {type: attr.set, geometry: '@paint', name: heat, value: '=z * z'}\n"
        "  x: {type: export.ply, mesh: '@heat', path: c.ply}\n"
    )
    g = fg.load(tmp_path / "w.yaml", out_dir=tmp_path)
    g.evaluate("x")
    back = _read(tmp_path, "c.ply")
    want = g.evaluate("heat")
    np.testing.assert_allclose(back.point_data["color"], want.point_data["color"], atol=0.5 / 255)
    np.testing.assert_array_equal(back.point_data["heat"], want.point_data["heat"])
    pts = _points(tmp_path, "c.ply", (tmp_path / "c.ply").read_bytes())
    assert len(pts) == want.n_vertices
