"""The drawing of a graph itself: one box per node and param, one path per wire, sources
left of sinks, no overlapping boxes, run colours and seconds, marks, SVG and PNG, the CLI."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.cli.main import main
from formgraph.drawgraph.layout import MARKS, draw_graph, node_marks
from formgraph.drawgraph.shapes import Text, text_width
from formgraph.language.model import Literal, wires_of

ROOT = Path(__file__).resolve().parents[1]
GRAPHS = sorted((ROOT / "graphs").glob("*.yaml"))
SVG = "{http://www.w3.org/2000/svg}"


def parse(svg: str) -> ET.Element:
    return ET.fromstring(svg.encode("utf-8"))


def by_class(root: ET.Element, tag: str, cls: str) -> list[ET.Element]:
    return [e for e in root.iter(f"{SVG}{tag}") if e.get("class") == cls]


def wire_count(g: fg.Graph) -> int:
    """Wires as authored: every @node reference in every input, repeat: source and
    simulate: from (a simulation's state input is drawn as its 'from')."""
    count = 0
    for n in g.nodes:
        nd = g._nodes[n]  # noqa: SLF001
        count += sum(len(wires_of(v)) for v in nd.inputs.values())
        if nd.repeat is not None:
            count += len(wires_of(nd.repeat.source))
        if nd.simulate is not None:
            count += len(wires_of(nd.simulate.source)) + len(wires_of(nd.simulate.steps))
            count -= len(wires_of(nd.inputs.get(nd.simulate.state, None) or Literal(0)))
    return count


def path_ends(d: str) -> tuple[tuple[float, float], tuple[float, float]]:
    nums = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?", d)]
    return (nums[0], nums[1]), (nums[-2], nums[-1])


def fills_of(root: ET.Element) -> dict[str, str]:
    return {
        r.find(f"{SVG}title").text.split(" (")[0]: r.get("fill")
        for r in by_class(root, "rect", "node")
    }


def ring_graph() -> fg.Graph:
    g = fg.Graph()
    g.add_param("n", 6, min=3, max=24, doc="corners")
    g.add_param("r", 2.0)
    g.add("pts", "points.circle", count="=n", radius="=r")
    g.add("outline", "curves.polyline", points="@pts", closed=True)
    g.add("wave", "curves.parametric", x="r * cos(t)", y="sin(t)", t=[0, 6.283])
    g.add("both", "offset.marching_squares", curves=["@outline", "@wave"], distance=0.2)
    return g


# ---------------------------------------------------------------------------- structure


@pytest.mark.parametrize("path", GRAPHS, ids=[p.stem for p in GRAPHS])
def test_every_example_graph_draws_one_box_per_node_and_one_path_per_wire(path):
    g = fg.load(path)
    root = parse(draw_graph(g).svg)
    nodes = by_class(root, "rect", "node")
    assert len(nodes) == len(g.nodes)
    assert {r.find(f"{SVG}title").text.split(" (")[0] for r in nodes} == set(g.nodes)
    assert len(by_class(root, "rect", "param")) == len(g.params)
    assert len(by_class(root, "path", "wire")) == wire_count(g)
    names = {t.text for t in by_class(root, "text", "name")}
    assert names == set(g.nodes) | set(g.params)
    types = {t.text for t in by_class(root, "text", "type")}
    assert set(g.nodes.values()) <= types


def test_boxes_show_type_ports_and_output_types_and_wires_their_types():
    g = ring_graph()
    root = parse(draw_graph(g).svg)
    outputs = [t.text for t in by_class(root, "text", "output-type")]
    assert outputs.count("-> Points") == 1 and "-> list[Curve]" in outputs
    ports = [t.text for t in by_class(root, "text", "port-name")]
    assert sorted(ports) == ["count", "curves", "points", "radius", "x"]
    labels = {t.text for t in by_class(root, "text", "wire-label")}
    # the list port joins the types of the wires that reach it
    assert labels == {"Points", "NurbsCurve, ParametricCurve", "int", "float"}
    # params: 'n' feeds count, 'r' feeds radius and the expression text of wave.x
    params = by_class(root, "path", "param-wire")
    assert sorted(p.get("data-from") + ">" + p.get("data-to") for p in params) == [
        "n>pts.count",
        "r>pts.radius",
        "r>wave.x",
    ]
    both = [p for p in by_class(root, "path", "wire") if p.get("data-to") == "both.curves"]
    assert sorted(p.get("data-from") for p in both) == ["outline", "wave"]


def test_a_repeated_transform_is_drawn_with_the_type_it_carries():
    g = fg.Graph()
    g.add("box", "mesh.box", size=[1, 1, 1])
    g.add("turned", "geometry.transform", geometry="@box", rotate=[0, 0, "=i * 10"])
    g.set_input("turned", "repeat", {"i": 4})
    g.add("pts", "points.grid", nx=2, ny=2)
    g.add("placed", "geometry.transform", geometry="@box", translate="=p")
    g.set_input("placed", "repeat", {"p": "@pts"})
    g.add("circles", "nurbs.circle", radius="=k + 1")
    g.set_input("circles", "repeat", {"k": 3})
    g.add("scaled", "geometry.transform", geometry="=c", scale=2)
    g.set_input("scaled", "repeat", {"c": "@circles"})
    g.add("all", "mesh.merge", meshes="@turned")
    root = parse(draw_graph(g).svg)
    texts = [t.text for t in by_class(root, "text", "output-type")]
    assert not any("Geometry" in t for t in texts), texts  # not the port's declared type
    assert texts.count("-> list[Mesh]") == 2 and "-> list[NurbsCurve]" in texts
    wire_labels = [t.text for t in by_class(root, "text", "wire-label")]
    assert "list[Mesh]" in wire_labels and not any("Geometry" in t for t in wire_labels)


def _box_rects(root: ET.Element) -> list[tuple[float, float, float, float]]:
    rects = by_class(root, "rect", "node") + by_class(root, "rect", "param")
    return [tuple(float(r.get(k)) for k in ("x", "y", "width", "height")) for r in rects]


@settings(max_examples=25, deadline=None)
@given(st.lists(st.lists(st.integers(0, 30), min_size=1, max_size=3), min_size=1, max_size=12))
def test_random_dags_flow_left_to_right_without_overlapping_boxes(parents):
    g = fg.Graph()
    g.add_param("size", 1.0)
    g.add("m0", "mesh.box", size=["=size", 1, 1])
    for i, ps in enumerate(parents, start=1):
        ups = sorted({f"@m{p % i}" for p in ps})
        g.add(f"m{i}", "mesh.merge", meshes=ups)
    root = parse(draw_graph(g).svg)
    assert len(by_class(root, "path", "wire")) == wire_count(g)
    x_of = {}
    for r in by_class(root, "rect", "node"):
        x_of[r.find(f"{SVG}title").text.split(" (")[0]] = float(r.get("x"))
    for p in by_class(root, "path", "wire"):
        (x0, _), (x1, _) = path_ends(p.get("d"))
        assert x0 < x1, "a wire runs right to left"
        assert x_of[p.get("data-from")] < x_of[p.get("data-to").split(".")[0]]
    boxes = _box_rects(root)
    for i, (x, y, w, h) in enumerate(boxes):
        for x2, y2, w2, h2 in boxes[i + 1 :]:
            overlap = x < x2 + w2 and x2 < x + w and y < y2 + h2 and y2 < y + h
            assert not overlap, "two boxes overlap"
    width, height = float(root.get("width")), float(root.get("height"))
    assert all(x >= 0 and y >= 0 and x + w <= width and y + h <= height for x, y, w, h in boxes)


def test_text_fits_its_box():
    g = ring_graph()
    d = draw_graph(g)
    root = parse(d.svg)
    for r in by_class(root, "rect", "node"):
        name = r.find(f"{SVG}title").text.split(" (")[0]
        assert text_width(name, 13, True) < float(r.get("width"))
    assert text_width("m", 10) == pytest.approx(0.97 * 10)
    assert any(isinstance(s, Text) and s.text == "both" for s in d.shapes)


# ------------------------------------------------------------------------- after a run


def test_after_a_run_boxes_are_coloured_computed_or_cached_with_seconds():
    g = ring_graph()
    assert "computed" not in draw_graph(g).svg  # before any run: no status
    g.evaluate("both")
    root = parse(draw_graph(g).svg)
    status = {t.text.split()[0] for t in by_class(root, "text", "status")}
    assert status == {"computed"}
    assert all(re.search(r"\d ms$|\d s$", t.text) for t in by_class(root, "text", "status"))
    g.evaluate("both", n=8)  # what n reaches recomputes; wave (r only) is cached
    root = parse(draw_graph(g).svg)
    fills = {
        r.find(f"{SVG}title").text.split(" (")[0]: r.get("fill")
        for r in by_class(root, "rect", "node")
    }
    assert fills["pts"] == fills["wave"] != fills["outline"] or fills["outline"] == fills["pts"]
    statuses = {n: s.status for n, s in g.stats.items()}
    colour = {"computed": "#fde2c4", "cached": "#d9e9f7"}
    assert {n: fills[n] for n in statuses} == {n: colour[s] for n, s in statuses.items()}
    assert set(colour[s] for s in statuses.values()) == set(colour.values())  # both kinds
    summary = by_class(root, "text", "run")[0].text
    computed = sum(1 for s in statuses.values() if s == "computed")
    assert summary.startswith(f"last run: {computed} computed, {len(statuses) - computed} cached")


def test_nodes_left_out_of_a_run_are_greyed():
    g = ring_graph()
    g.evaluate("outline")
    root = parse(draw_graph(g).svg)
    fills = {
        r.find(f"{SVG}title").text.split(" (")[0]: r.get("fill")
        for r in by_class(root, "rect", "node")
    }
    assert fills["wave"] == fills["both"] == "#f1f1f1"


# ------------------------------------------------------------------------------- marks


def test_marks_come_from_a_hook_exports_subgraphs_and_repeats(tmp_path):
    g = ring_graph()
    g.add("save", "export.svg", curves="@both", path="x.svg")
    g.add("sub", "parts/ring.yaml", radius="=r")  # a subgraph node (not checked here)
    g.add("wave", "curves.parametric", repeat={"i": "=n"}, x="r * cos(t) + i", y="sin(t)")
    assert node_marks(g, "save") == ["export"]
    assert node_marks(g, "sub") == ["subgraph"]
    assert node_marks(g, "wave") == ["repeat i"]
    root = parse(draw_graph(g).svg)
    marks = sorted(t.text for t in by_class(root, "text", "mark-text"))
    assert marks == ["export", "repeat i", "subgraph"]
    assert len(by_class(root, "rect", "stack")) == 2  # the repeated node is a stack
    assert len(by_class(root, "rect", "inner")) == 1  # the subgraph a double border
    outputs = [t.text for t in by_class(root, "text", "output-type")]
    assert "-> list[Curve]" in outputs  # the repeated parametric curve: one per item
    repeat_wire = [
        p for p in by_class(root, "path", "param-wire") if p.get("data-to") == "wave.repeat i"
    ]
    assert [p.get("data-from") for p in repeat_wire] == ["n"]

    def heavy(graph, name):
        return ["heavy"] if name == "both" else []

    root = parse(draw_graph(g, marks=[*MARKS, heavy]).svg)
    assert "heavy" in {t.text for t in by_class(root, "text", "mark-text")}


# -------------------------------------------------------------------------- SVG and PNG


def test_save_writes_svg_and_a_non_blank_png(tmp_path):
    from matplotlib.image import imread

    g = fg.load(ROOT / "graphs" / "box_sculpture.yaml")
    d = draw_graph(g, tmp_path / "g.svg")
    assert parse((tmp_path / "g.svg").read_text()).tag == f"{SVG}svg"
    out = d.save(tmp_path / "deep" / "g.png")
    img = imread(str(out))[..., :3]
    assert img.shape[:2] == (int(np.ceil(d.height)) * 2, int(np.ceil(d.width)) * 2)
    ink = np.abs(img - 1.0).max(axis=-1) > 0.1
    assert 0.03 < ink.mean() < 0.6  # boxes, text and wires, on a white page
    orange = (img[..., 0] > 0.9) & (img[..., 1] > 0.4) & (img[..., 1] < 0.6) & (img[..., 2] < 0.2)
    assert orange.sum() > 100  # the mesh family's bands
    with pytest.raises(ValueError, match=r"\.svg or \.png"):
        d.save(tmp_path / "g.pdf")


def test_jupyter_shows_the_svg():
    assert fg.draw_graph(ring_graph())._repr_svg_().lstrip().startswith("<?xml")


# --------------------------------------------------------------------------------- CLI


def test_cli_graph_svg_png_and_run(tmp_path, capsys, monkeypatch):
    f = ROOT / "graphs" / "vase.yaml"
    svg, png = tmp_path / "v.svg", tmp_path / "v.png"
    assert main(["graph", str(f), "-o", str(svg)]) == 0
    assert f"wrote {svg} (6 nodes, 4 params)" in capsys.readouterr().out
    assert len(by_class(parse(svg.read_text()), "rect", "node")) == 6
    args = ["graph", str(f), "-o", str(png), "--run", "--no-cache", "--out", str(tmp_path / "o")]
    assert main(args) == 0
    assert "after a run of 6 nodes" in capsys.readouterr().out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["graph", str(f), "-o", "-"]) == 0
    assert parse(capsys.readouterr().out).tag == f"{SVG}svg"
    assert main(["graph", str(f), "-o", str(tmp_path / "v.pdf")]) == 2
    assert ".svg or .png" in capsys.readouterr().err
    monkeypatch.chdir(tmp_path)
    assert main(["graph", str(f)]) == 0 and (tmp_path / "vase.svg").is_file()


def test_a_node_with_several_outputs_gets_a_row_and_an_anchor_per_output():
    g = fg.Graph()
    g.add("s", "stub.split", x=3.0)
    g.add("c", "points.circle", count=4, radius="@s.hi")
    root = parse(draw_graph(g).svg)
    outputs = [t.text for t in by_class(root, "text", "output-type")]
    assert outputs[:2] == ["lo: float", "hi: float"]
    anchors = [float(c.get("cy")) for c in by_class(root, "circle", "output")]
    (wire,) = by_class(root, "path", "wire")
    (_, y0), _ = path_ends(wire.get("d"))
    assert y0 == pytest.approx(anchors[1], abs=0.1)  # leaves from the 'hi' row
    assert {t.text for t in by_class(root, "text", "wire-label")} == {"float"}
    assert g.evaluate("c") is not None


def test_cli_graph_run_that_fails_draws_how_far_it_got(tmp_path, capsys):
    f = tmp_path / "big.yaml"
    f.write_text(
        "formgraph: 1\nnodes:\n  box: {type: mesh.box}\n"
        "  smooth: {type: mesh.catmull_clark, mesh: '@box', levels: 6}\n"
    )
    svg = tmp_path / "big.svg"
    args = ["graph", str(f), "--run", "--no-cache", "--budget", "1000", "-o", str(svg)]
    assert main(args) == 1
    captured = capsys.readouterr()
    assert "smooth failed" in captured.out and "node 'smooth'" in captured.err
    fills = fills_of(parse(svg.read_text()))
    assert fills == {"box": "#fde2c4", "smooth": "#f4b6b6"}  # computed, failed
    legend = {t.text for t in by_class(parse(svg.read_text()), "text", "legend")}
    assert "failed" in legend


def test_the_svg_needs_neither_pyvista_nor_pillow():
    import subprocess
    import sys

    code = (
        "import sys, formgraph as fg\n"
        "g = fg.load(sys.argv[1])\n"
        "assert '<svg' in fg.draw_graph(g).svg\n"
        "print(sorted(m for m in ('pyvista', 'vtk', 'PIL') if m in sys.modules))\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", code, str(ROOT / "graphs" / "lamp.yaml")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


def test_cli_graph_shows_the_param_values_of_set(tmp_path):
    svg = tmp_path / "v.svg"
    f = ROOT / "graphs" / "spiral_tube.yaml"
    assert main(["graph", str(f), "--set", "turns=7", "-o", str(svg)]) == 0
    types = {t.text for t in by_class(parse(svg.read_text()), "text", "type")}
    assert "= 7 [1..12]" in types
