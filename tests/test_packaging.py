"""The package as users install it: every module in the wheel, rooms without import circles,
modules of a readable size.

The wheel test builds a wheel from this tree (no network: no build isolation, no deps) and
compares its contents with the tree, so a package that is missing from the wheel fails here
before a user's ``pip install .`` finds it. ``.ci/run`` also installs that wheel into a fresh
venv and runs the quick start and ``formgraph check`` of every example from there.
"""

from __future__ import annotations

import ast
import subprocess
import sys
import zipfile
from pathlib import Path

import networkx as nx
import pytest

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = {
    "formgraph": ROOT / "engine",
    "formgraph.nodes": ROOT / "nodes",
    "formgraph.viewer": ROOT / "viewer",
}


def tree_modules() -> dict[str, Path]:
    """Import name -> source file of every module in the tree."""
    out: dict[str, Path] = {}
    for name, folder in FOLDERS.items():
        for py in folder.rglob("*.py"):
            if "__pycache__" in py.parts:
                continue
            rel = py.relative_to(folder).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            out[".".join([name, *parts])] = py
    return out


def test_wheel_holds_every_module(tmp_path):
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            "-w",
            str(tmp_path),
            str(ROOT),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    (wheel,) = tmp_path.glob("formgraph-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    missing = []
    for mod, py in tree_modules().items():
        path = mod.replace(".", "/") + ("/__init__.py" if py.name == "__init__.py" else ".py")
        if path not in names:
            missing.append(path)
    assert not missing, f"the wheel lacks {missing}"
    assert "formgraph/studio/canvas.js" in names  # the studio's canvas, served with the page
    entry = [n for n in names if n.endswith("entry_points.txt")]
    assert entry, "no console script"
    text = zipfile.ZipFile(wheel).read(entry[0]).decode()
    assert "formgraph = formgraph.cli.main:main" in text


def _imports(mod: str, py: Path) -> set[str]:
    """The formgraph modules ``mod`` imports, anywhere in it (lazy imports count too)."""
    tree = ast.parse(py.read_text(), str(py))
    package = mod if py.name == "__init__.py" else mod.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("formgraph")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("formgraph"):
                continue
            found.add(target)
            found |= {f"{target}.{a.name}" for a in node.names}
    return found


def import_graph() -> nx.DiGraph:
    mods = tree_modules()
    g = nx.DiGraph()
    g.add_nodes_from(mods)
    for mod, py in mods.items():
        for target in _imports(mod, py):
            # importing a package's name means its __init__; a name from a module, the module
            while target and target not in mods:
                target = target.rpartition(".")[0]
            if target and target != mod and not mod.startswith(target + "."):
                g.add_edge(mod, target)
    return g


def test_no_import_circles_between_modules():
    g = import_graph()
    # a package's __init__ re-exporting its own modules is not a circle of rooms
    g.remove_edges_from([(a, b) for a, b in list(g.edges) if b.startswith(a + ".")])
    cycles = list(nx.simple_cycles(g))
    assert not cycles, "import circles: " + "; ".join(" -> ".join(c + c[:1]) for c in cycles[:5])


ROOMS = [
    "kernels",
    "geometry",
    "core",
    "language",
    "evaluation",
    "drawgraph",
    "sweeps",
    "studio",
    "cli",
]


@pytest.mark.parametrize("low", range(len(ROOMS)), ids=ROOMS)
def test_lower_rooms_do_not_import_higher_ones(low):
    g = import_graph()
    room = f"formgraph.{ROOMS[low]}"
    higher = [f"formgraph.{r}" for r in ROOMS[low + 1 :]]
    bad = [
        (a, b)
        for a, b in g.edges
        if (a == room or a.startswith(room + "."))
        and any(b == h or b.startswith(h + ".") for h in higher)
    ]
    assert not bad, f"{ROOMS[low]} imports a higher room: {bad[:5]}"


def test_no_module_past_650_lines():
    long = {
        m: n for m, py in tree_modules().items() if (n := len(py.read_text().splitlines())) > 650
    }
    assert not long, f"split these modules (STYLE.md: ~600 lines at most): {long}"
