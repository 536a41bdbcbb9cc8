"""The README stays a true quick start: its commands are CI's, its examples run, its links
lead somewhere, and every dependency it installs is explained. (The manual's pages under
docs/ are checked by tests/test_docs.py.)"""

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


def section(title: str) -> str:
    start = README.index(f"\n## {title}\n")
    end = README.find("\n## ", start + 1)
    return README[start : end if end > 0 else None]


def test_the_two_setup_commands_open_the_readme_and_ci_runs_the_second():
    head = README[: README.index("## A graph, by example")]
    commands = re.findall(r"^    (python3 -m venv .*)$", head, flags=re.M)
    assert len(commands) == 2, commands
    run, test = commands
    assert "formgraph run graphs/spiral_tube.yaml" in run
    assert "pytest -n 2" in test
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    assert test in ci, ".ci/run must run the README's test command verbatim"


def test_the_readme_is_a_quick_start_and_a_tour():
    titles = re.findall(r"^## (.+)$", README, flags=re.M)
    for title in (
        "Quick start",
        "A graph, by example",
        "A tour",
        "Command line",
        "Documentation",
        "Dependencies",
        "Development",
    ):
        assert title in titles, title
    # new capabilities' sections go at the end of the tour, where this comment stands
    tour = section("A tour")
    assert "<!-- A new capability's short section goes above this line" in tour
    # the manual is on the site: a README that grows back into it fails here
    assert len(README.splitlines()) < 600, "move the details to a page under docs/"


def test_yaml_example_is_the_spiral_tube_graph():
    (example,) = [b for b in blocks("yaml") if "Spiral tube" in b]
    g = fg.Graph.from_text(example)
    assert g.params == {"turns": 3, "radius": 2.0}
    assert set(g.nodes) == {"spiral", "section", "tube", "mesh", "closed", "solid", "print"}
    assert yaml.safe_load(example)["nodes"]["print"]["type"] == "export.stl"


def test_python_example_runs_as_it_says(tmp_path):
    (code,) = [b for b in blocks("python") if "import formgraph as fg" in b]
    shutil.copytree(ROOT / "graphs", tmp_path / "graphs")
    r = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert r.returncode == 0, r.stderr
    said = re.search(r"# (\d+ \w+)$", code, flags=re.M).group(1)  # the comment's output
    assert r.stdout.strip() == said
    assert (tmp_path / "out" / "tube.stl").is_file()


def test_every_link_of_the_readme_leads_to_a_file_or_a_heading():
    anchors = {
        re.sub(r"[^\w\- ]", "", h.lower()).replace(" ", "-")
        for h in re.findall(r"^#+ (.+)$", README, flags=re.M)
    }
    for link in re.findall(r"\]\(([^)\s]+)\)", README):
        if re.match(r"^[a-z]+:", link):
            continue
        path, _, anchor = link.partition("#")
        if not path:
            assert anchor in anchors, link
        else:
            assert (ROOT / path).exists(), link


def test_every_dependency_is_explained():
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    deps = section("Dependencies").lower()
    names = list(project["dependencies"])
    for extra in ("test", "bench", "docs"):
        assert f"(the `{extra}` extra)" in deps, extra
        names += project["optional-dependencies"][extra]
    for requirement in names:
        name = re.split(r"[<>=\[ ;]", requirement, maxsplit=1)[0].lower()
        assert name in deps, f"{name} is installed but the README does not say why"


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
