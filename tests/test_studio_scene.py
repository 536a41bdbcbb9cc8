"""The studio's serialization of the scene (formgraph.studio.scene): what trame-vtk sends
of a step, with its polydata serializer keeping each cell array's legacy export."""

from __future__ import annotations

import shutil
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("trame_vtk")
pv = pytest.importorskip("pyvista")

from formgraph.studio.session import StudioSession  # noqa: E402

TUBE = Path(__file__).resolve().parents[1] / "graphs" / "spiral_tube.yaml"


def _serializers():
    from trame_vtk.modules.vtk.serializers import initialize_serializers, registry

    initialize_serializers()  # trame-vtk's own, as its protocol does when it starts
    return registry


@contextmanager
def _tube_scene(tmp_path):
    """The spiral tube opened in a studio session and shown in a fresh off-screen scene."""
    from formgraph.studio.scene import StudioScene, make_plotter

    path = tmp_path / "tube.yaml"
    shutil.copy(TUBE, path)
    session = StudioSession(path, out_dir=tmp_path / "out")
    plotter = make_plotter()
    try:
        scene = StudioScene(plotter)
        scene.update(session.open().shown)
        yield session, plotter, scene
    finally:
        plotter.close()


def _describe(serializer, data):
    from trame_vtk.modules.vtk.serializers import SynchronizationContext

    return serializer(None, data, "data", SynchronizationContext(), 1)


def test_cells_once_describes_polydata_as_trame_vtk_does():
    from formgraph.studio.scene import send_cells_once

    registry = _serializers()
    theirs = registry.SERIALIZERS["vtkPolyData"]
    send_cells_once()
    mine = registry.SERIALIZERS["vtkPolyData"]
    assert mine is not theirs and getattr(mine, "sends_cells_once", False)
    send_cells_once()  # once in place, nothing more
    assert registry.SERIALIZERS["vtkPolyData"] is mine
    verts = pv.PolyData(np.random.default_rng(0).random((5, 3)))
    for data in (pv.Sphere(), pv.Cube().extract_all_edges(), verts, pv.Cube().triangulate()):
        data.point_data["w"] = np.arange(data.n_points, dtype=float)
        assert _describe(mine, data) == _describe(theirs, data)


def test_unchanged_cells_keep_their_array_and_hash(tmp_path):
    from trame_vtk.modules.vtk.serializers import SynchronizationContext

    from formgraph.studio.scene import send_cells_once

    registry = _serializers()
    send_cells_once()
    serializer = registry.SERIALIZERS["vtkPolyData"]
    with _tube_scene(tmp_path) as (s, _plotter, scene):
        data = scene.parts[("solid", "meshes")].data
        context = SynchronizationContext()
        first = serializer(None, data, "d", context, 1)["properties"]
        scene.update(s.set_params(thickness=0.4).shown)
        second = serializer(None, data, "d", context, 1)["properties"]
        assert second["polys"]["hash"] == first["polys"]["hash"]
        assert second["points"]["hash"] != first["points"]["hash"]
        # the array behind the hash is the one exported the first time
        kept = context.data_array_cache[second["polys"]["hash"]]["array"]
        assert kept.GetMTime() == context.data_array_cache[first["polys"]["hash"]]["mTime"]
        # the faces changed (here: triangulated): exported again, a new hash
        data.faces = data.triangulate().faces
        third = serializer(None, data, "d", context, 1)["properties"]
        assert third["polys"]["hash"] != first["polys"]["hash"]
        legacy = context.data_array_cache[third["polys"]["hash"]]["array"]
        assert np.array_equal(np.asarray(legacy), data.faces)


def test_a_step_sends_only_its_new_arrays(tmp_path):
    """SentArrays picks, from trame-vtk's own descriptions of the scene, the arrays a page
    has not been sent: all of a first scene, only the moved points of a step."""
    from trame_vtk.modules.vtk.serializers import SynchronizationContext, serialize
    from trame_vtk.modules.vtk.serializers.utils import reference_id

    from formgraph.studio.scene import SentArrays, send_back_faces, send_cells_once

    _serializers()
    send_back_faces()
    send_cells_once()
    with _tube_scene(tmp_path) as (s, plotter, scene):
        window = plotter.render_window
        context = SynchronizationContext()

        def describe():
            return serialize(None, window, reference_id(window), context, 1)

        sent = SentArrays()
        first = sent.fresh(describe())
        mesh = scene.parts[("solid", "meshes")].data
        lines = scene.parts[("solid", "features")].data
        assert len(first) == len(set(first)) >= 4  # points, normals, faces, lines' points...
        assert sent.fresh(describe()) == []  # the same scene: nothing new
        scene.update(s.set_params(thickness=0.4).shown)
        step = sent.fresh(describe())
        # the tube's points and its feature lines' points moved; its faces, its normals
        # (a thicker tube's normals are the same) and the lines' cells did not
        assert len(step) == 2
        moved = {context.get_cached_data_array(h, True) for h in step}
        assert moved == {
            np.ascontiguousarray(mesh.points, dtype=np.float32).tobytes(),
            np.ascontiguousarray(lines.points, dtype=np.float32).tobytes(),
        }
        assert sent.fresh(describe()) == []


def test_sent_arrays_forget_the_oldest():
    from formgraph.studio.scene import SentArrays

    def scene(*hashes):  # the shape of trame-vtk's descriptions, one array per dependency
        deps = [{"properties": {"p": {"vtkClass": "vtkPoints", "hash": h}}} for h in hashes]
        return {"dependencies": deps, "properties": {"n": {"vtkClass": "x"}}}

    sent = SentArrays()
    assert sent.fresh(scene("a", "b", "a")) == ["a", "b"]  # each once, in order
    assert sent.fresh(scene("b", "c")) == ["c"]
    sent.fresh(scene(*(f"h{i}" for i in range(SentArrays.KEPT - 1))))  # "a" the oldest
    assert sent.fresh(scene("a", "c")) == ["a"]
