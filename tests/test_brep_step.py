"""STEP solids out and in: export.step's solids read back by OpenCASCADE's own reader
(valid, the same volume, names and colours), read.step of files OCC wrote, solids beside
our curves in one file, and FreeCAD opening the bracket's STEP."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path

import pytest

import formgraph as fg

pytest.importorskip("OCP")

from formgraph.kernels.brep import occ  # noqa: E402

GRAPHS = Path(__file__).resolve().parents[1] / "graphs"


def _occ_read(path: Path) -> object:
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.STEPControl import STEPControl_Reader

    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_ReturnStatus.IFSelect_RetDone
    reader.TransferRoots()
    return reader.OneShape()


def _drilled(g: fg.Graph) -> None:
    g.add("b", "brep.box", size=[30, 20, 10])
    g.add("f", "brep.fillet", solid="@b", radius=2, edges="=kind == line and abs(z) < 1")
    g.add("c", "brep.cylinder", radius=4, height=30)
    g.add("d", "brep.boolean", a="@f", b=["@c"], operation="difference")


def test_solids_written_are_read_back_by_occ_valid_and_of_the_same_volume(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    _drilled(g)
    g.add("s", "export.step", path="d.step", solids=["@d"], names=["drilled"], colors=["#8fa3b8"])
    path = Path(g.evaluate("s"))
    shape = _occ_read(path)
    solids = occ.solids_of(shape)
    assert len(solids) == 1 and occ.is_valid(shape)
    expected = occ.volume(g.evaluate("d").shape)
    assert occ.volume(shape) == pytest.approx(expected, rel=1e-6)
    four_fillets = 4 * (1 - math.pi / 4) * 4 * 10
    assert expected == pytest.approx(30 * 20 * 10 - four_fillets - math.pi * 16 * 10, rel=1e-9)
    text = path.read_text()
    assert "MANIFOLD_SOLID_BREP" in text and "PRODUCT('drilled'" in text
    assert "COLOUR_RGB('',0.56078" in text.replace(" ", "")  # 0x8f / 255
    assert "AUTOMOTIVE_DESIGN" in text and "CYLINDRICAL_SURFACE" in text


def test_the_same_solids_give_the_same_bytes(tmp_path):
    def write(folder: Path) -> bytes:
        g = fg.Graph(out_dir=folder, cache_dir=folder / "cache")
        _drilled(g)
        g.add("s", "export.step", path="d.step", solids=["@d"])
        return Path(g.evaluate("s")).read_bytes()

    assert write(tmp_path / "a") == write(tmp_path / "b")


def test_solids_beside_curves_in_one_file(tmp_path):
    g = fg.Graph(out_dir=tmp_path)
    _drilled(g)
    g.add("circle", "nurbs.circle", radius=20)
    g.add("s", "export.step", path="m.step", solids=["@d"], curves=["@circle"])
    path = Path(g.evaluate("s"))
    text = path.read_text()
    assert "B_SPLINE_CURVE_WITH_KNOTS" in text and "MANIFOLD_SOLID_BREP" in text
    shape = _occ_read(path)
    (solid,) = occ.solids_of(shape)
    assert occ.volume(solid) == pytest.approx(occ.volume(g.evaluate("d").shape), rel=1e-6)


def test_a_sphere_s_seven_eighths_come_back_as_written():
    # a face on a closed surface is read back by OCC as the other side of its loop unless
    # cut along a seam first (stepwrite.unambiguous)
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Pnt

    from formgraph.kernels.brep import exchange, stepread, stepwrite

    box = BRepPrimAPI_MakeBox(10, 10, 10).Shape()
    ball = BRepPrimAPI_MakeSphere(gp_Pnt(10, 10, 10), 4).Shape()
    part = BRepAlgoAPI_Fuse(box, ball).Shape()
    (back,) = stepread.read(stepwrite.write([part], ["part"], [None]))
    fused = 1000 + 4 / 3 * math.pi * 64 * 7 / 8
    assert occ.volume(exchange.from_bytes(back)) == pytest.approx(fused, rel=1e-9)


def test_the_vase_solid_round_trips(tmp_path):
    g = fg.load(GRAPHS / "vase_solid.yaml", out_dir=tmp_path)
    shape = _occ_read(Path(g.evaluate("step")))
    assert occ.is_valid(shape)
    assert occ.volume(shape) == pytest.approx(g.evaluate("measures").volume, rel=1e-6)


def test_read_step_of_a_file_occ_wrote(tmp_path):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer

    box = BRepPrimAPI_MakeBox(10, 10, 10).Shape()
    boss = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(5, 5, 5), gp_Dir(0, 0, 1)), 3, 15).Shape()
    part = BRepAlgoAPI_Fuse(box, boss).Shape()
    far = BRepPrimAPI_MakeBox(gp_Pnt(50, 0, 0), 2, 3, 4).Shape()
    writer = STEPControl_Writer()
    writer.Transfer(part, STEPControl_StepModelType.STEPControl_AsIs)
    writer.Transfer(far, STEPControl_StepModelType.STEPControl_AsIs)
    writer.Write(str(tmp_path / "occ.step"))

    g = fg.Graph(out_dir=tmp_path / "out", inputs_dir=tmp_path)
    g.add("r", "read.step", path="occ.step")
    solids = g.evaluate("r")
    assert len(solids) == 2
    volumes = sorted(occ.volume(s.shape) for s in solids)
    assert volumes == pytest.approx([24, 1000 + math.pi * 9 * 10], rel=1e-9)
    assert all(occ.is_valid(s.shape) for s in solids)
    # and a solid read is a solid like any other
    g.add("pick", "brep.box", size=[200, 200, 200])
    g.add("cut", "brep.boolean", a="@pick", b=["@r"], operation="intersection")
    assert occ.volume(g.evaluate("cut").shape) == pytest.approx(sum(volumes), rel=1e-9)


def test_our_step_round_trips_through_read_step(tmp_path):
    g = fg.Graph(out_dir=tmp_path, inputs_dir=tmp_path)
    _drilled(g)
    g.add("s", "export.step", path="d.step", solids=["@d"])
    g.evaluate("s")
    g.add("r", "read.step", path="d.step")
    (back,) = g.evaluate("r")
    assert occ.volume(back.shape) == pytest.approx(occ.volume(g.evaluate("d").shape), rel=1e-9)


def test_freecad_opens_the_bracket_valid_with_planes_and_cylinders(tmp_path):
    freecad = shutil.which("freecadcmd")
    if freecad is None:
        pytest.skip("FreeCAD (freecadcmd) is not installed")
    g = fg.load(GRAPHS / "bracket.yaml", out_dir=tmp_path)
    path = Path(g.evaluate("step"))
    script = tmp_path / "read.py"
    script.write_text(
        "import json, Part\n"
        f"s = Part.read({str(path)!r})\n"
        "print('RESULT ' + json.dumps({'valid': s.isValid(), 'solids': len(s.Solids),\n"
        "    'volume': s.Volume, 'faces': sorted({type(f.Surface).__name__ for f in s.Faces})}))\n"
    )
    done = subprocess.run(
        [freecad, str(script)], capture_output=True, text=True, timeout=120, check=False
    )
    lines = [x for x in done.stdout.splitlines() if x.startswith("RESULT ")]
    assert lines, done.stdout + done.stderr
    got = json.loads(lines[-1][len("RESULT ") :])
    assert got["valid"] and got["solids"] == 1
    assert got["faces"] == ["Cylinder", "Plane"]
    ours = g.evaluate("measures").volume
    assert got["volume"] == pytest.approx(ours, rel=1e-6)
