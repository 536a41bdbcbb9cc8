"""formgraph graph -o big.png: the canvas is budgeted (scaled down to fit, else refused with a
sentence before anything is allocated); the SVG has no such limit."""

from __future__ import annotations

from PIL import Image

from formgraph.cli import main as cli
from formgraph.drawgraph import png


def _chain(path, n: int) -> None:
    lines = ["formgraph: 1", "nodes:", "  n0: {type: points.circle, count: 3}"]
    lines += [f"  n{i}: {{type: geometry.transform, geometry: '@n{i - 1}'}}" for i in range(1, n)]
    path.write_text("\n".join(lines) + "\n")


def test_a_long_graph_is_scaled_down_to_the_canvas_budget(tmp_path, capsys):
    _chain(tmp_path / "g.yaml", 90)
    out = tmp_path / "g.png"
    assert cli.main(["graph", str(tmp_path / "g.yaml"), "-o", str(out)]) == 0
    with Image.open(out) as im:
        w, h = im.size
    assert w <= png.MAX_SIDE and h <= png.MAX_SIDE and w * h <= png.MAX_PIXELS
    assert w > 2000  # still a picture of the graph, not a thumbnail


def test_a_graph_too_large_for_a_png_is_a_sentence(tmp_path, capsys):
    _chain(tmp_path / "g.yaml", 400)
    out = tmp_path / "g.png"
    assert cli.main(["graph", str(tmp_path / "g.yaml"), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "as a PNG it would be" in err and "over the budget of" in err and ".svg" in err
    assert "internal error" not in err and not out.exists()
    assert cli.main(["graph", str(tmp_path / "g.yaml"), "-o", str(tmp_path / "g.svg")]) == 0
