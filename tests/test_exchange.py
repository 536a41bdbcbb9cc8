"""export.3mf, export.gltf, export.step and export.rhino, each read back by an independent
reader (lib3mf, trimesh and pygltflib, OpenCASCADE, rhino3dm) and by our own read nodes."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np
import pytest
import trimesh

import formgraph as fg

HEAD = "formgraph: 1\nnodes:\n"


pytestmark = pytest.mark.usefixtures("keep_locale")  # lib3mf writes: see conftest.py


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
    from formgraph.kernels.io.threemf_read import read_3mf

    v = read_3mf(Path(out).read_bytes()).vertices
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


# --------------------------------------------------------------------------------- STEP

VASE = """\
  pts: {type: points.list, points: [[1.3, 0, 6], [0.8, 0, 4.5], [2.2, 0, 2.1], [0.7, 0, 0],
    [0, 0, 0]]}
  profile: {type: nurbs.interpolate, points: "@pts", degree: 3}
  vase: {type: nurbs.revolve, curve: "@profile"}
  sheet: {type: nurbs.surface, points: [[[0, 0, 0], [1, 0, 1], [2, 0, 0]],
    [[0, 1, 1], [1, 1, 2], [2, 1, 1]], [[0, 2, 0], [1, 2, 1], [2, 2, 0]]], degree_u: 2,
    degree_v: 2}
  box: {type: mesh.box, size: [2, 3, 4]}
  plane: {type: mesh.plane, size: [2, 2]}
"""


def _occ(path: str):
    pytest.importorskip("OCP")
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    reader = STEPControl_Reader()
    assert reader.ReadFile(path) == IFSelect_RetDone
    reader.TransferRoots()
    return reader.OneShape()


def _occ_items(shape, kind):
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    cast = {"FACE": TopoDS.Face, "EDGE": TopoDS.Edge, "SOLID": TopoDS.Solid, "SHELL": TopoDS.Shell}
    from OCP import TopAbs

    e = TopExp_Explorer(shape, getattr(TopAbs, f"TopAbs_{kind}"))
    out = []
    while e.More():
        out.append(cast[kind](e.Current()))
        e.Next()
    return out


def test_step_surfaces_read_by_opencascade_evaluate_the_same(tmp_path):
    from OCP.BRep import BRep_Tool
    from OCP.BRepCheck import BRepCheck_Analyzer

    g, out = _run(
        tmp_path,
        VASE + "  x: {type: export.step, surfaces: ['@vase', '@sheet'], path: s.step}\n",
        "x",
    )
    shape = _occ(out)
    assert BRepCheck_Analyzer(shape).IsValid()
    faces = _occ_items(shape, "FACE")
    assert len(faces) == 2
    for face, name in zip(faces, ("vase", "sheet"), strict=True):
        ours = g.evaluate(name)
        surf = BRep_Tool.Surface_s(face)
        assert surf.DynamicType().Name() == "Geom_BSplineSurface"
        assert surf.UDegree() == ours.degree_u and surf.VDegree() == ours.degree_v
        assert surf.IsURational() or surf.IsVRational() or not ours.rational
        u = np.linspace(ours.knots_u[0], ours.knots_u[-1], 9)
        v = np.linspace(ours.knots_v[0], ours.knots_v[-1], 7)
        uu, vv = np.meshgrid(u, v, indexing="ij")
        want = ours.evaluate(uu.ravel(), vv.ravel()).reshape(9, 7, 3)
        for i in range(9):
            for j in range(7):
                p = surf.Value(float(u[i]), float(v[j]))
                np.testing.assert_allclose([p.X(), p.Y(), p.Z()], want[i, j], atol=1e-12)


def test_step_curves_and_a_faceted_solid(tmp_path):
    from OCP.BRep import BRep_Tool
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    g, out = _run(
        tmp_path,
        VASE + "  x: {type: export.step, curves: ['@profile'], meshes: ['@box', '@plane'],"
        " path: m.step}\n",
        "x",
    )
    shape = _occ(out)
    (solid,) = _occ_items(shape, "SOLID")
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(solid, props)
    assert props.Mass() == pytest.approx(2 * 3 * 4, rel=1e-9)
    assert len(_occ_items(shape, "SHELL")) == 2  # the box's closed shell and the plane's
    profile = g.evaluate("profile")
    curves = [BRep_Tool.Curve_s(e, 0, 1) for e in _occ_items(shape, "EDGE")]
    splines = [c for c in curves if c is not None and c.DynamicType().Name() == "Geom_BSplineCurve"]
    assert splines, "the profile curve is not in the file"
    t = np.linspace(profile.knots[0], profile.knots[-1], 11)
    want = profile.evaluate(t)
    got = np.array([[p.X(), p.Y(), p.Z()] for p in (splines[0].Value(float(x)) for x in t)])
    np.testing.assert_allclose(got, want, atol=1e-12)


def test_step_refuses_a_parametric_surface(tmp_path):
    with pytest.raises(fg.NodeError, match="surface 0 is a ParametricSurface"):
        _run(
            tmp_path,
            "  s: {type: surfaces.parametric, x: u, y: v, z: u * v}\n"
            "  x: {type: export.step, surfaces: ['@s'], path: s.step}\n",
            "x",
        )


# --------------------------------------------------------------------------------- .3dm


def test_rhino_file_evaluates_the_same_in_rhino3dm(tmp_path):
    rhino3dm = pytest.importorskip("rhino3dm")
    g, out = _run(
        tmp_path,
        VASE + "  x: {type: export.rhino, curves: ['@profile'], surfaces: ['@vase'],"
        " meshes: ['@box'], layers: [profile, body, block], path: v.3dm}\n",
        "x",
    )
    model = rhino3dm.File3dm.Read(out)
    layers = [model.Layers[k].Name for k in range(len(model.Layers))]
    assert layers == ["profile", "body", "block"]
    kinds = [type(o.Geometry).__name__ for o in model.Objects]
    assert kinds == ["NurbsCurve", "NurbsSurface", "Mesh"]
    curve, surface, mesh = (o.Geometry for o in model.Objects)
    ours_c, ours_s = g.evaluate("profile"), g.evaluate("vase")
    for t in np.linspace(ours_c.knots[0], ours_c.knots[-1], 9):
        p = curve.PointAt(float(t))
        np.testing.assert_allclose([p.X, p.Y, p.Z], ours_c.evaluate([t])[0], atol=1e-12)
    for u in np.linspace(0, 1, 5):
        for v in np.linspace(0, 1, 5):
            p = surface.PointAt(float(u), float(v))
            np.testing.assert_allclose([p.X, p.Y, p.Z], ours_s.evaluate([u], [v])[0], atol=1e-12)
    assert surface.IsRational and len(mesh.Vertices) == g.evaluate("box").n_vertices


def test_rhino_round_trips_through_read_rhino_exactly(tmp_path):
    g, out = _run(
        tmp_path,
        VASE + "  x: {type: export.rhino, curves: ['@profile'], surfaces: ['@vase', '@sheet'],"
        " meshes: ['@box'], path: v.3dm}\n",
        "x",
    )
    (tmp_path / "in.yaml").write_text(HEAD + "  m: {type: read.rhino, path: out/v.3dm}\n")
    back = fg.load(tmp_path / "in.yaml").evaluate("m")
    (c,), (s1, s2), (m,) = back.curves, back.surfaces, back.meshes
    for got, want in ((c, g.evaluate("profile")),):
        assert np.array_equal(got.control_points, want.control_points)
        assert np.array_equal(got.knots, want.knots) and got.degree == want.degree
    for got, want in ((s1, g.evaluate("vase")), (s2, g.evaluate("sheet"))):
        np.testing.assert_allclose(got.control_points, want.control_points, rtol=0, atol=1e-14)
        assert np.array_equal(got.knots_u, want.knots_u) and np.array_equal(
            got.knots_v, want.knots_v
        )
        np.testing.assert_allclose(got.weights, want.weights, rtol=0, atol=1e-15)
    box = g.evaluate("box")
    assert np.array_equal(m.vertices, box.vertices) and np.array_equal(
        m.face_indices, box.face_indices
    )
    assert len(back.points) == 0


# ------------------------------------------------------------------------ vertex colours

COLOURED = """\
  ball: {type: mesh.sphere, radius: 2}
  paint: {type: attr.set, geometry: "@ball", name: color,
    value: ["=clip(0.5 + x / 4, 0, 1)", "=clip(0.5 + y / 4, 0, 1)", 0.25]}
"""


def test_glb_carries_a_color_attribute_as_color_0(tmp_path):
    g, out = _run(
        tmp_path, COLOURED + "  x: {type: export.gltf, meshes: ['@paint'], path: c.glb}\n", "x"
    )
    scene = trimesh.load(io.BytesIO(Path(out).read_bytes()), file_type="glb", process=False)
    (mesh,) = scene.geometry.values()
    want = np.asarray(g.evaluate("paint").point_data["color"])
    got = np.asarray(mesh.visual.vertex_colors)[:, :3] / 255.0
    np.testing.assert_allclose(got, want, atol=1 / 255 + 1e-9)
    (tmp_path / "in.yaml").write_text(HEAD + "  m: {type: read.mesh, path: out/c.glb}\n")
    back = fg.load(tmp_path / "in.yaml").evaluate("m")  # and our reader takes COLOR_0 back
    np.testing.assert_allclose(back.point_data["color"], want, atol=1e-7)


def _strict_lib3mf(lib3mf, path):
    """The file read by lib3mf in strict mode, which must raise no warning."""
    model = lib3mf.get_wrapper().CreateModel()
    reader = model.QueryReader("3mf")
    reader.SetStrictModeActive(True)
    reader.ReadFromFile(path)
    assert reader.GetWarningCount() == 0
    return model


def test_3mf_carries_a_color_attribute_as_a_colour_group(tmp_path):
    lib3mf = pytest.importorskip("lib3mf")
    g, out = _run(
        tmp_path, COLOURED + "  x: {type: export.3mf, meshes: ['@paint'], path: c.3mf}\n", "x"
    )
    model = _strict_lib3mf(lib3mf, out)
    groups = model.GetColorGroups()
    assert groups.MoveNext()
    group = groups.GetCurrentColorGroup()
    ids = group.GetAllPropertyIDs()
    want = np.round(np.asarray(g.evaluate("paint").point_data["color"]) * 255)
    assert len(ids) == len(want)
    got = [(c.Red, c.Green, c.Blue) for c in (group.GetColor(i) for i in ids[:50])]
    np.testing.assert_array_equal(got, want[:50])
    objects = model.GetMeshObjects()
    objects.MoveNext()
    obj = objects.GetCurrentMeshObject()
    for t in range(0, obj.GetTriangleCount(), 37):  # each corner's colour is its vertex's
        prop, tri = obj.GetTriangleProperties(t), obj.GetTriangle(t).Indices
        assert prop.ResourceID == group.GetResourceID()
        assert [prop.PropertyIDs[j] for j in range(3)] == [ids[i] for i in tri]
    (tmp_path / "in.yaml").write_text(HEAD + "  m: {type: read.mesh, path: out/c.3mf}\n")
    back = fg.load(tmp_path / "in.yaml").evaluate("m")  # our reader takes the group back
    np.testing.assert_allclose(back.point_data["color"][:, :3], want / 255, atol=1e-12)


def test_read_rhino_takes_what_rhino3dm_writes(tmp_path):
    r = pytest.importorskip("rhino3dm")
    model = r.File3dm()
    model.Objects.AddCurve(r.LineCurve(r.Point3d(0, 0, 0), r.Point3d(3, 4, 0)))
    model.Objects.AddCircle(r.Circle(r.Point3d(1, 2, 0), 5.0))
    model.Objects.AddSphere(r.Sphere(r.Point3d(0, 0, 0), 2.0))
    model.Objects.AddPoint(r.Point3d(7, 8, 9))
    mesh = r.Mesh()
    for p in ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)):
        mesh.Vertices.Add(*p)
    mesh.Faces.AddFace(0, 1, 2, 3)
    model.Objects.AddMesh(mesh)
    model.Write(str(tmp_path / "m.3dm"), 8)
    (tmp_path / "in.yaml").write_text(HEAD + "  m: {type: read.rhino, path: m.3dm}\n")
    got = fg.load(tmp_path / "in.yaml").evaluate("m")
    line, circle = got.curves
    np.testing.assert_allclose(
        line.evaluate([line.knots[0], line.knots[-1]]), [[0, 0, 0], [3, 4, 0]]
    )
    assert circle.rational
    p = circle.evaluate(np.linspace(circle.knots[0], circle.knots[-1], 50))
    np.testing.assert_allclose(np.linalg.norm(p - [1, 2, 0], axis=1), 5, atol=1e-12)
    (sphere,) = got.surfaces
    u, v = np.meshgrid(np.linspace(*sphere.domain_u, 7), np.linspace(*sphere.domain_v, 7))
    s = sphere.evaluate(u.ravel(), v.ravel())
    np.testing.assert_allclose(np.linalg.norm(s, axis=1), 2, atol=1e-12)
    (m,) = got.meshes
    assert m.face_offsets.tolist() == [0, 4] and got.points.xyz.tolist() == [[7, 8, 9]]


def test_step_rational_curve_stays_a_circle_in_opencascade(tmp_path):
    from OCP.BRep import BRep_Tool

    g, out = _run(
        tmp_path,
        "  c: {type: nurbs.circle, radius: 3}\n"
        "  x: {type: export.step, curves: ['@c'], path: c.step}\n",
        "x",
    )
    (edge,) = _occ_items(_occ(out), "EDGE")
    curve = BRep_Tool.Curve_s(edge, 0, 1)
    assert curve.IsRational()
    c = g.evaluate("c")
    for t in np.linspace(c.knots[0], c.knots[-1], 17):
        p = curve.Value(float(t))
        np.testing.assert_allclose([p.X(), p.Y(), p.Z()], c.evaluate([t])[0], atol=1e-12)


def test_3mf_writes_a_base_material_only_for_a_mesh_without_vertex_colours(tmp_path):
    """#33 item 19: the ``colors`` entry of a vertex-coloured mesh was written as a base
    material nothing referenced."""
    lib3mf = pytest.importorskip("lib3mf")
    g, out = _run(
        tmp_path,
        COLOURED + "  box: {type: mesh.box, size: [1, 1, 1]}\n"
        "  x: {type: export.3mf, meshes: ['@paint', '@box'], path: c.3mf,"
        " colors: [red, '#0080ff']}\n",
        "x",
    )
    with zipfile.ZipFile(out) as z:
        text = z.read("3D/3dmodel.model").decode()
    assert text.count("<base ") == 1 and 'displaycolor="#0080FFFF"' in text
    model = _strict_lib3mf(lib3mf, out)
    objects = model.GetMeshObjects()
    props = []
    while objects.MoveNext():
        props.append(objects.GetCurrentMeshObject().GetObjectLevelProperty())
    bases = model.GetBaseMaterialGroups()
    assert bases.MoveNext()
    base = bases.GetCurrentBaseMaterialGroup()
    assert base.GetCount() == 1 and props[1][:2] == (
        base.GetResourceID(),
        base.GetAllPropertyIDs()[0],
    )
    colour = base.GetDisplayColor(base.GetAllPropertyIDs()[0])
    assert (colour.Red, colour.Green, colour.Blue) == (0, 128, 255)
    with zipfile.ZipFile(
        _run(
            tmp_path,
            COLOURED + "  y: {type: export.3mf, meshes: ['@paint'], path: d.3mf, colors: [red]}\n",
            "y",
        )[1]
    ) as z:
        assert "basematerials" not in z.read("3D/3dmodel.model").decode()
