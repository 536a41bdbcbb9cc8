"""Every example graph in graphs/ loads, checks and evaluates all its sinks."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from tools import admesh

import formgraph as fg

GRAPHS = sorted((Path(__file__).resolve().parents[1] / "graphs").glob("*.yaml"))


def test_there_are_example_graphs():
    assert len(GRAPHS) >= 2


@pytest.mark.parametrize("path", GRAPHS, ids=[p.stem for p in GRAPHS])
def test_example_graph_evaluates(path, tmp_path):
    g = fg.load(path, out_dir=tmp_path)
    outs = g.evaluate_all()
    assert outs
    for name, value in outs.items():
        if fg.node_types()[g.nodes[name]].is_export:
            out = Path(value)
            assert out.is_file() and out.stat().st_size > 0, name
            assert tmp_path in out.parents
    # a second run is served from the cache and writes nothing new
    g.evaluate_all()
    assert all(s.status == "cached" for s in g.stats.values())


STL_GRAPHS = [p for p in GRAPHS if "export.stl" in p.read_text()]


@pytest.mark.parametrize("path", STL_GRAPHS, ids=[p.stem for p in STL_GRAPHS])
def test_example_stl_exports_are_watertight_and_outward(path, tmp_path):
    import trimesh

    g = fg.load(path, out_dir=tmp_path)
    g.evaluate_all()
    stls = [n for n, t in g.nodes.items() if t == "export.stl"]
    assert stls
    for name in stls:
        assert g.stats[name].warnings == [], name  # the exporter's own mesh report is clean
        mesh = trimesh.load(tmp_path / g.node_inputs(name)["path"], file_type="stl")
        assert mesh.is_watertight and mesh.is_winding_consistent, name
        assert mesh.volume > 0, name
        # one solid body: any other shell is a cavity inside it (a hollow, the inside of a
        # lattice's skin), which faces inward
        shells = mesh.split(only_watertight=False)
        assert sum(s.volume > 0 for s in shells) == 1, (name, [s.volume for s in shells])
        # admesh's own repair report finds nothing to do (its "Normals fixed" is left out: it
        # recomputes facet normals from float32 vertices, which differ from ours on the
        # 1e-9-wide slivers a boolean can leave, without any defect of the solid)
        if shutil.which("admesh"):
            report = admesh(tmp_path / g.node_inputs(name)["path"])
            for what in (
                "Facets with 1 disconnected edge",
                "Degenerate facets",
                "Edges fixed",
                "Facets removed",
                "Facets added",
                "Facets reversed",
                "Backwards edges",
            ):
                assert report[what] == 0, (name, what)
            assert report["Number of parts"] == len(shells), name
