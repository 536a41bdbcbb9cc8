"""Where a picture looks from: --camera, --azimuth and --elevation on view --screenshot,
watch --screenshot and sweep sheets; bad angles are a sentence (exit 2)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image
from scipy import ndimage

from formgraph import viewer
from formgraph.cli import main as cli
from formgraph.viewer.sheet import render_cell

BOX = "formgraph: 1\nnodes:\n  b: {type: mesh.box, size: [1, 2, 3]}\n"


def _footprint(png) -> float:
    """Width over height of the drawn solid (the largest blob of blue pixels: not the
    legend's text or swatch)."""
    a = np.asarray(Image.open(png).convert("RGB")).astype(int)
    label, _ = ndimage.label((a[..., 2] > a[..., 0] + 60) & (a[..., 0] < 80))
    ys, xs = np.nonzero(label == np.argmax(np.bincount(label.ravel())[1:]) + 1)
    return (np.ptp(xs) + 1) / (np.ptp(ys) + 1)


@pytest.mark.parametrize(
    ("camera", "aspect"), [("top", 1 / 2), ("bottom", 1 / 2), ("front", 1 / 3), ("side", 2 / 3)]
)
def test_view_screenshot_looks_from_the_named_side(tmp_path, camera, aspect, capsys):
    (tmp_path / "b.yaml").write_text(BOX)
    png = tmp_path / f"{camera}.png"
    args = ["view", str(tmp_path / "b.yaml"), "--screenshot", str(png), "--size", "320x320"]
    assert cli.main([*args, "--camera", camera]) == 0
    assert _footprint(png) == pytest.approx(aspect, rel=0.06)


def test_azimuth_and_elevation_turn_the_view(tmp_path):
    (tmp_path / "b.yaml").write_text(BOX)
    base = ["view", str(tmp_path / "b.yaml"), "--size", "320x320", "--screenshot"]
    assert cli.main([*base, str(tmp_path / "a.png"), "--azimuth", "0", "--elevation", "0"]) == 0
    assert cli.main([*base, str(tmp_path / "b.png"), "--azimuth", "90", "--elevation", "0"]) == 0
    # in perspective now, so only roughly the front's 1:3 and the side's 2:3
    assert _footprint(tmp_path / "a.png") < 0.45 < _footprint(tmp_path / "b.png")
    cam = viewer.Camera(azimuth=90, elevation=0)
    toward, up = cam.direction()
    np.testing.assert_allclose(toward, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(up, [0, 0, 1])
    toward, up = viewer.Camera("top").direction()
    np.testing.assert_allclose(toward, [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(up, [0, 1, 0], atol=1e-12)


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--elevation", "100"], "--elevation must be from -90 to 90 degrees, got 100"),
        (["--azimuth", "nan"], "--azimuth must be a finite number of degrees"),
    ],
)
def test_bad_angles_are_a_sentence(tmp_path, capsys, flags, message):
    (tmp_path / "b.yaml").write_text(BOX)
    png = tmp_path / "x.png"
    assert cli.main(["view", str(tmp_path / "b.yaml"), "--screenshot", str(png), *flags]) == 2
    assert message in capsys.readouterr().err and not png.exists()


def test_watch_screenshot_and_sheet_cells_take_the_camera(tmp_path):
    f = tmp_path / "b.yaml"
    f.write_text(BOX)
    png = tmp_path / "w.png"
    w = viewer.ScreenshotWatcher(
        f, png, size=(320, 320), camera=viewer.Camera("side"), out=io.StringIO()
    )
    assert w.reload() is True
    assert _footprint(png) == pytest.approx(2 / 3, rel=0.06)
    import formgraph as fg

    box = fg.load(f).evaluate("b")
    cell = tmp_path / "cell.png"
    cell.write_bytes(render_cell(box, (256, 256), ("front", None, None)))
    assert _footprint(cell) == pytest.approx(1 / 3, rel=0.08)
    parser = cli._parser()
    for command in (["watch"], ["sweep", "--vary", "s=1,2", "--render", "b"]):
        assert parser.parse_args([*command, "--camera", "top", "g.yaml"]).camera == "top"


def test_a_sweep_refuses_a_bad_camera_before_it_runs(tmp_path):
    import formgraph as fg
    from formgraph.sweeps.api import sweep

    f = tmp_path / "b.yaml"
    f.write_text("formgraph: 1\nparams:\n  s: 1.0\nnodes:\n  b: {type: mesh.box, size: '=s'}\n")
    with pytest.raises(ValueError, match="camera must be one of iso, top"):
        sweep(fg.load(f), {"s": "1,2"}, render="b", out=tmp_path, camera=("up", None, None))
