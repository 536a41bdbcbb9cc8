"""Exact solids attacked: STEP files truncated, not STEP, garbled, of surfaces only, of
more entities than the budget, too slow to read; NaN, infinite and zero sizes; a section
crossing itself; selectors that select nothing or read nonsense; meshes finer than the
budget; empty tool lists; names and colours that do not fit. Each a located sentence."""

from __future__ import annotations

from pathlib import Path

import pytest

import formgraph as fg

pytest.importorskip("OCP")

from formgraph.kernels.brep import stepread  # noqa: E402

ERRORS = (fg.GraphError, fg.NodeError)


def _solid_step(folder: Path) -> bytes:
    g = fg.Graph(out_dir=folder)
    g.add("b", "brep.box", size=[10, 20, 30])
    g.add("f", "brep.fillet", solid="@b", radius=1)
    g.add("s", "export.step", path="part.step", solids=["@f"])
    return Path(g.evaluate("s")).read_bytes()


def _read(folder: Path, data: bytes, budget: int | None = None) -> object:
    (folder / "in.step").write_bytes(data)
    kw = {} if budget is None else {"budget": budget}
    g = fg.Graph(out_dir=folder / "out", inputs_dir=folder, **kw)
    g.add("r", "read.step", path="in.step")
    return g.evaluate("r")


def test_a_truncated_step_file(tmp_path):
    data = _solid_step(tmp_path)
    with pytest.raises(ERRORS, match=r"node 'r', input 'path'.*'in.step'.*truncated"):
        _read(tmp_path, data[: len(data) // 2])


def test_a_file_that_is_not_step(tmp_path):
    with pytest.raises(ERRORS, match=r"not a STEP file"):
        _read(tmp_path, b"solid cube\nendsolid cube\n")


def test_garbled_entities_are_said_in_words(tmp_path):
    data = _solid_step(tmp_path)
    head, rest = data.split(b"DATA;", 1)
    garbled = (
        head
        + b"DATA;\n#1=CLOSED_SHELL('',(#2,#3));\n#2=NONSENSE((((;\n"
        + b"ENDSEC;\nEND-ISO-10303-21;\n"
    )
    with pytest.raises(ERRORS, match=r"cannot read it as STEP: (it holds no|OpenCASCADE)") as err:
        _read(tmp_path, garbled)
    assert "Standard_" not in str(err.value)


def test_surfaces_only_are_not_solids(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("s", "nurbs.surface", points=[[[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 1]]],
          degree_u=1, degree_v=1)  # fmt: skip
    g.add("w", "export.step", path="surf.step", surfaces=["@s"])
    data = Path(g.evaluate("w")).read_bytes()
    with pytest.raises(ERRORS, match=r"it holds no solid \(1 faces in open shells"):
        _read(tmp_path, data)


def test_more_entities_than_the_budget_are_refused_before_parsing(tmp_path):
    data = _solid_step(tmp_path)
    n = stepread.count_entities(data)
    with pytest.raises(ERRORS, match=rf"{n:,}|{n}.*STEP entities|STEP entities"):
        _read(tmp_path, data, budget=n // 2)


def test_a_read_that_takes_too_long_is_stopped(tmp_path, monkeypatch):
    data = _solid_step(tmp_path)
    monkeypatch.setattr(stepread, "TIMEOUT", 0.01)
    with pytest.raises(ERRORS, match=r"took longer than 0.01 s and was stopped"):
        _read(tmp_path, data)


@pytest.mark.parametrize(
    "kind,inputs,port",
    [
        ("brep.box", {"size": [1, float("nan"), 1]}, "size"),
        ("brep.box", {"size": [1, float("inf"), 1]}, "size"),
        ("brep.box", {"size": [1, 0, 1]}, "size"),
        ("brep.box", {"size": 1, "center": [0, float("inf"), 0]}, "center"),
        ("brep.cylinder", {"radius": float("inf"), "height": 1}, "radius"),
        ("brep.cylinder", {"radius": 1, "height": 0}, "height"),
    ],
)
def test_sizes_that_make_no_solid(kind, inputs, port):
    g = fg.Graph()
    g.add("s", kind, **inputs)
    with pytest.raises(ERRORS, match=rf"input '{port}'"):
        g.evaluate("s")


@pytest.mark.parametrize("radius", [float("nan"), float("inf"), 0.0, -1.0])
def test_fillet_radii_that_are_not_a_radius(radius):
    g = fg.Graph()
    g.add("b", "brep.box", size=10)
    g.add("f", "brep.fillet", solid="@b", radius=radius)
    with pytest.raises(ERRORS, match=r"input 'radius'"):
        g.evaluate("f")


def test_extrusion_of_nan_height_and_of_open_curves():
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=2)
    g.add("e", "brep.extrude", curves=["@c"], height=float("nan"))
    with pytest.raises(ERRORS, match=r"input 'height'"):
        g.evaluate("e")
    g = fg.Graph()
    g.add("l", "curves.polyline", points=[[0, 0, 0], [5, 0, 0], [5, 5, 0]])
    g.add("e", "brep.extrude", curves=["@l"], height=1)
    with pytest.raises(ERRORS, match=r"input 'curves'"):
        g.evaluate("e")


def test_a_loft_section_crossing_itself():
    g = fg.Graph()
    g.add("bow", "curves.polyline", points=[[0, 0, 0], [10, 10, 0], [10, 0, 0], [0, 10, 0]],
          closed=True)  # fmt: skip
    g.add("top", "nurbs.circle", radius=5, center=[5, 5, 10])
    g.add("l", "brep.loft", curves=["@bow", "@top"])
    with pytest.raises(ERRORS, match=r"section 0 crosses itself"):
        g.evaluate("l")


def test_a_self_crossing_profile_extrudes_as_its_even_odd_region():
    # the region reader's rule, as curves.boolean reads it: a bow tie is two triangles
    g = fg.Graph()
    g.add("bow", "curves.polyline", points=[[0, 0, 0], [10, 10, 0], [10, 0, 0], [0, 10, 0]],
          closed=True)  # fmt: skip
    g.add("e", "brep.extrude", curves=["@bow"], height=2)
    g.add("m", "brep.measure", solid="@e")
    m = g.evaluate("m")
    assert m.volume == pytest.approx(2 * 25 * 2, rel=1e-9) and m.solids == 2


def test_revolving_across_the_axis():
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=3, center=[1, 0, 0])
    g.add("v", "brep.revolve", curves=["@c"])
    with pytest.raises(ERRORS, match=r"reaches x = -2.*x >= 0"):
        g.evaluate("v")


def test_a_mesh_finer_than_the_budget_is_refused_before_meshing():
    g = fg.Graph(budget=100_000)
    g.add("b", "brep.cylinder", radius=100, height=100)
    g.add("m", "brep.mesh", solid="@b", tolerance=1e-6)
    with pytest.raises(ERRORS, match=r"triangles"):
        g.evaluate("m")


def test_selectors_of_the_wrong_kind():
    g = fg.Graph()
    g.add("b", "brep.box", size=10)
    g.add("f", "brep.fillet", solid="@b", radius=1, edges="=z + 1")
    with pytest.raises(ERRORS, match=r"input 'edges'.*gives numbers, not true or false"):
        g.evaluate("f")


def test_a_boolean_with_no_tools_warns():
    g = fg.Graph()
    g.add("b", "brep.box", size=10)
    g.add("u", "brep.boolean", a="@b", b=[], operation="difference")
    with pytest.warns(fg.FormgraphWarning, match="b holds no solids"):
        g.evaluate("u")


def test_step_names_and_colours_that_do_not_fit(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    g.add("b", "brep.box", size=10)
    g.add("s", "export.step", path="a.step", solids=["@b"], names=["a", "b"])
    with pytest.raises(ERRORS, match=r"input 'names'.*2 names for 1 solids"):
        g.evaluate("s")
    g.add("t", "export.step", path="b.step", solids=["@b"], colors=["not a colour"])
    with pytest.raises(ERRORS, match=r"input 'colors'"):
        g.evaluate("t")
    g.add("u", "export.step", path="../c.step", solids=["@b"])
    with pytest.raises(ERRORS, match=r"input 'path'"):
        g.evaluate("u")
    assert not (tmp_path.parent / "c.step").exists()


def test_a_damaged_cache_entry_for_a_solid_is_a_miss(tmp_path):
    def graph():
        g = fg.Graph(cache_dir=tmp_path / "cache")
        g.add("b", "brep.box", size=10)
        g.add("f", "brep.fillet", solid="@b", radius=1)
        return g

    graph().evaluate("f")
    for entry in (tmp_path / "cache").rglob("*"):
        if entry.is_file() and entry.stat().st_size > 1000:
            raw = bytearray(entry.read_bytes())
            raw[len(raw) // 2] ^= 0xFF
            entry.write_bytes(bytes(raw))
    again = graph()
    out = again.evaluate("f")
    assert again.stats["f"].source != "disk"
    from formgraph.kernels.brep import occ

    assert occ.is_valid(out.shape)
