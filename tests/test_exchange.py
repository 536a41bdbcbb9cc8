"""export.3mf, export.gltf, export.step and export.rhino, each read back by an independent
reader (lib3mf, trimesh and pygltflib, OpenCASCADE, rhino3dm) and by our own read nodes."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
import trimesh

import formgraph as fg

HEAD = "formgraph: 1\nnodes:\n"
TWO = (
    "  ball: {type: mesh.sphere, radius: 2}\n"
    "  box: {type: mesh.box, size: [1, 2, 3], center: [5, 0, 0]}\n"
)


def _run(folder: Path, body: str, node: str):
    (folder / "g.yaml").write_text(HEAD + body)
    g = fg.load(folder / "g.yaml", out_dir=folder / "out")
    return g, g.evaluate(node)


def _meshes(g) -> list[fg.Mesh]:
    return [g.evaluate("ball"), g.evaluate("box")]


# ---------------------------------------------------------------------------------- 3MF


def test_3mf_opens_in_lib3mf_with_names_colours_and_exact_vertices(tmp_path):
    lib3mf = pytest.importorskip("lib3mf")
    g, out = _run(
        tmp_path,
        TWO + "  x: {type: export.3mf, meshes: ['@ball', '@box'], path: p.3mf,"
        " names: [ball, box], colors: [red, '#0080ff']}\n",
        "x",
    )
    w = lib3mf.get_wrapper()
    model = w.CreateModel()
    reader = model.QueryReader("3mf")
    reader.SetStrictModeActive(True)
    reader.ReadFromFile(out)
    assert reader.GetWarningCount() == 0
    assert model.GetUnit() == lib3mf.ModelUnit.MilliMeter
    objects = model.GetMeshObjects()
    found = {}
    while objects.MoveNext():
        o = objects.GetCurrentMeshObject()
        verts = np.array([list(p.Coordinates) for p in o.GetVertices()])
        found[o.GetName()] = (verts, o.GetTriangleCount(), o.GetObjectLevelProperty())
    items = model.GetBuildItems()
    count = 0
    while items.MoveNext():
        count += 1
    assert count == 2 and set(found) == {"ball", "box"}
    for name, mesh in zip(("ball", "box"), _meshes(g), strict=True):
        verts, tris, _ = found[name]
        np.testing.assert_allclose(verts, mesh.vertices, rtol=1e-6, atol=1e-6)  # float32
        assert tris == int(np.sum(mesh.face_sizes - 2))
    resource, prop, has = found["box"][2]
    assert has
    colour = model.GetBaseMaterialGroupByID(resource).GetDisplayColor(prop)
    assert (colour.Red, colour.Green, colour.Blue) == (0, 128, 255)


def test_3mf_reads_back_exactly_through_read_mesh(tmp_path):
    g, out = _run(tmp_path, TWO + "  x: {type: export.3mf, meshes: ['@ball'], path: p.3mf}\n", "x")
    (tmp_path / "in.yaml").write_text(HEAD + "  m: {type: read.mesh, path: out/p.3mf}\n")
    back = fg.load(tmp_path / "in.yaml").evaluate("m")
    assert np.array_equal(back.vertices, g.evaluate("ball").vertices)  # shortest round trip


def test_3mf_units_scale_on_reading(tmp_path):
    g, out = _run(
        tmp_path, TWO + "  x: {type: export.3mf, meshes: ['@box'], path: p.3mf, units: inch}\n", "x"
    )
    from formgraph.kernels.io.threemf import read_3mf

    ((_, v, _),) = read_3mf(Path(out).read_bytes())
    np.testing.assert_allclose(v, g.evaluate("box").vertices * 25.4)


def test_3mf_refuses_a_colour_it_cannot_read(tmp_path):
    with pytest.raises(fg.NodeError, match="not a colour"):
        _run(
            tmp_path,
            TWO + "  x: {type: export.3mf, meshes: ['@box'], path: p.3mf, colors: [reddish]}\n",
            "x",
        )


# ---------------------------------------------------------------------------------- GLB


def test_glb_loads_in_trimesh_and_pygltflib_in_metres(tmp_path):
    pygltflib = pytest.importorskip("pygltflib")
    g, out = _run(
        tmp_path, TWO + "  x: {type: export.gltf, meshes: ['@ball', '@box'], path: p.glb}\n", "x"
    )
    data = Path(out).read_bytes()
    doc = pygltflib.GLTF2.load_from_bytes(data)
    assert doc.asset.version == "2.0" and len(doc.meshes) == 2
    scene = trimesh.load(io.BytesIO(data), file_type="glb", process=False)
    meshes = list(scene.geometry.values())
    for got, want in zip(meshes, _meshes(g), strict=True):
        tris = want.face_indices.reshape(-1, 3) if np.all(want.face_sizes == 3) else None
        np.testing.assert_allclose(got.vertices * 1000, want.vertices, rtol=1e-6, atol=1e-5)
        if tris is not None:
            assert np.array_equal(got.faces, tris)
        normals = got.vertex_normals
        np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-5)
    ball = meshes[0]
    # a sphere's vertex normals point out along the radius
    radial = ball.vertices / np.linalg.norm(ball.vertices, axis=1, keepdims=True)
    assert np.min(np.sum(radial * ball.vertex_normals, axis=1)) > 0.95


def test_glb_reads_back_through_read_mesh(tmp_path):
    g, out = _run(tmp_path, TWO + "  x: {type: export.gltf, meshes: ['@box'], path: p.glb}\n", "x")
    (tmp_path / "in.yaml").write_text(HEAD + "  m: {type: read.mesh, path: out/p.glb}\n")
    back = fg.load(tmp_path / "in.yaml").evaluate("m")
    box = g.evaluate("box")
    assert back.n_faces == int(np.sum(box.face_sizes - 2))
    np.testing.assert_allclose(back.vertices, box.vertices, rtol=1e-6, atol=1e-5)
