"""The README's examples stay true: its Python block runs, its YAML example loads."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

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
