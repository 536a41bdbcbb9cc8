"""The README's examples stay true: its Python block runs, its YAML example loads."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

import formgraph as fg

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", README, flags=re.S)


def test_python_example_runs(tmp_path):
    (code,) = [b for b in blocks("python") if "import formgraph as fg" in b]
    shutil.copytree(ROOT / "graphs", tmp_path / "graphs")
    r = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "out" / "tube.stl").is_file()
    assert (tmp_path / "copy.yaml").is_file()


def test_yaml_example_is_the_spiral_tube_graph():
    (example,) = [b for b in blocks("yaml") if "Spiral tube" in b]
    g = fg.Graph.from_text(example)
    assert g.params == {"turns": 3, "radius": 2.0}
    assert set(g.nodes) == {"spiral", "section", "tube", "mesh", "closed", "solid", "print"}
    assert yaml.safe_load(example)["nodes"]["print"]["type"] == "export.stl"


def test_solids_example_runs_to_watertight_solids(tmp_path):
    (example,) = [b for b in blocks("yaml") if "A pot, as a capped solid" in b]
    g = fg.Graph.from_text(example, out_dir=tmp_path)
    for node in ("solid", "shell", "holes"):
        assert g.evaluate(node).is_watertight, node
    size = g.evaluate("size")
    assert size.watertight and size.volume == pytest.approx(g.evaluate("solid").volume)
    assert g.evaluate("holes").volume < g.evaluate("shell").volume
    g.evaluate_all()
    assert (tmp_path / "pot.stl").is_file()


def test_solids_from_outlines_example_runs():
    (example,) = [b for b in blocks("yaml") if "A tag with a hole" in b]
    g = fg.Graph.from_text(example)
    tag = g.evaluate("tag")
    assert tag.is_watertight and tag.volume > 0
    assert (g.evaluate("check.parts"), g.evaluate("check.cavities")) == (1, 0)
    assert len(g.evaluate("layers")) == 8  # four layers: an outline and the hole each
    assert len(g.evaluate("shadow")) == 2
    size = g.evaluate("box.size")
    assert size[0] <= 40 + 1e-9 and size[1] <= 10 + 1e-9 and max(size[0] - 40, size[1] - 10) > -1e-9
    for node in ("knob", "rounded"):
        assert g.evaluate(node).is_watertight, node
    assert g.evaluate("rounded").volume > g.evaluate("knob").volume
