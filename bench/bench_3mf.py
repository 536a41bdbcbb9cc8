"""Reading a 1M-triangle 3MF: ``read.mesh`` (expat, streaming) against the regular-expression
reader it replaced, trimesh and lib3mf, as their users call them.

- ours through the public API: a graph with a ``read.mesh`` node loaded afresh each call
  (its own cache: the file is read and parsed every time), and the kernel
  (``threemf_read.read_3mf`` on the file's bytes);
- the reader this replaced (regular expressions over the whole vertex and triangle
  blocks), taken from the commit before it (``git show``): noted as not installed where
  git or the history is not there;
- ``trimesh.load(path, force="mesh")`` (trimesh parses 3MF with lxml);
- lib3mf: ``ReadFromFile`` then every mesh object's vertices and triangle indices, what a
  lib3mf user does to get at the geometry.

Peak memory (tracemalloc, which numpy and lib3mf's Python objects report to) of the same
reads, ours against trimesh: the streaming parse keeps near the output's size.
"""

from __future__ import annotations

import importlib.util
import subprocess
import tempfile
from pathlib import Path

import numpy as np

import formgraph as fg
from formgraph.kernels.io.threemf import write_3mf
from formgraph.kernels.io.threemf_read import read_3mf

BASELINE = "4787063"  # the last commit with the regular-expression reader


def _sphere(n_theta: int = 1000, n_phi: int = 501) -> tuple[np.ndarray, np.ndarray]:
    """A UV sphere of 2 * n_theta * (n_phi - 1) triangles (1,000,000 by default)."""
    theta = np.linspace(0, 2 * np.pi, n_theta, endpoint=False)
    phi = np.linspace(0, np.pi, n_phi + 1)[1:-1]
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.stack([np.cos(t) * np.sin(p), np.sin(t) * np.sin(p), np.cos(p)], -1)
    v = np.concatenate([[[0, 0, 1]], ring.reshape(-1, 3), [[0, 0, -1]]]) * 50
    rows = n_phi - 1
    idx = 1 + np.arange(n_theta * rows).reshape(n_theta, rows)
    nxt = np.roll(idx, -1, axis=0)
    quads_a = np.stack([idx[:, :-1], nxt[:, :-1], nxt[:, 1:]], -1).reshape(-1, 3)
    quads_b = np.stack([idx[:, :-1], nxt[:, 1:], idx[:, 1:]], -1).reshape(-1, 3)
    top = np.stack([np.zeros(n_theta, int), nxt[:, 0], idx[:, 0]], -1)
    bottom = np.stack([np.full(n_theta, len(v) - 1), idx[:, -1], nxt[:, -1]], -1)
    return v, np.concatenate([top, quads_a, quads_b, bottom])


def _baseline():
    """The replaced reader's module, from git (ImportError when it cannot be had)."""
    root = Path(__file__).resolve().parent.parent
    try:
        source = subprocess.run(
            ["git", "show", f"{BASELINE}:engine/kernels/io/threemf.py"],
            cwd=root,
            capture_output=True,
            check=True,
            text=True,
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        raise ImportError("the regular-expression reader", name="git history") from None
    name = "formgraph.kernels.io._threemf_regex_baseline"
    spec = importlib.util.spec_from_loader(name, loader=None)
    module = importlib.util.module_from_spec(spec)
    module.__package__ = "formgraph.kernels.io"
    exec(compile(source, "threemf.py@" + BASELINE, "exec"), module.__dict__)  # noqa: S102
    return module


def _lib3mf(path: str):
    import lib3mf

    model = lib3mf.get_wrapper().CreateModel()
    model.QueryReader("3mf").ReadFromFile(path)
    out = []
    objects = model.GetMeshObjects()
    while objects.MoveNext():
        o = objects.GetCurrentMeshObject()
        out.append((o.GetVertices(), o.GetTriangleIndices()))
    return out


def run(table) -> None:
    v, t = _sphere()
    folder = Path(tempfile.mkdtemp(prefix="bench3mf-"))
    path = folder / "sphere.3mf"
    path.write_bytes(write_3mf([(v, t)]))
    (folder / "g.yaml").write_text(
        "formgraph: 1\nnodes:\n  m: {type: read.mesh, path: sphere.3mf}\n"
    )

    def api():
        return fg.load(folder / "g.yaml").evaluate("m")

    def trimesh_load():
        import trimesh

        return trimesh.load(str(path), force="mesh", process=False)

    refs = {
        "regex reader (replaced)": lambda: _baseline().read_3mf(path.read_bytes()),
        "trimesh": trimesh_load,
        "lib3mf": lambda: _lib3mf(str(path)),
    }
    try:  # load it once, outside the clock
        old = _baseline()
        refs["regex reader (replaced)"] = lambda: old.read_3mf(path.read_bytes())
    except ImportError:
        pass
    case = f"read a {len(t):,}-triangle 3MF ({path.stat().st_size / 1e6:.0f} MB zip)"
    table.compare(
        case,
        api=api,
        kernel=lambda: read_3mf(path.read_bytes()),
        references=refs,
        rounds=3,
        note="expat, streamed a megabyte at a time",
    )
    table.memory(
        f"peak memory: {case}",
        api=api,
        references={
            "regex reader (replaced)": refs["regex reader (replaced)"],
            "trimesh": trimesh_load,
        },
        note=f"the mesh itself: {(v.nbytes + t.size * 8 + (len(t) + 1) * 8) / 1e6:.0f} MB",
    )
