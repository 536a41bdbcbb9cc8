"""Memory and depth: what making a big output costs at its peak, and a field recipe
thousands of operations deep.

``points.grid`` of 5 million points (a 120 MB output) through the API, fresh values so the
cache does not answer, against numpy's meshgrid as its users write it: the peak traced
while each runs (ours holds the output and the one copy freezing it makes), then the time.
A chain of field nodes 2,000 deep (``field.offset`` on a sphere) is built, checked and
meshed through the API.
"""

from __future__ import annotations

import itertools

import numpy as np

import formgraph as fg

NX, NY, NZ = 1000, 1000, 5
_ORIGINS = itertools.count()


def _grid_api() -> object:
    # a new origin each call: a new key, so the node runs (never answered by the cache)
    g = fg.Graph(memory_bytes=0)
    g.add("g", "points.grid", nx=NX, ny=NY, nz=NZ, origin=[next(_ORIGINS), 0, 0])
    return g.evaluate("g")


def _grid_kernel() -> object:
    from formgraph.nodes.points.sources import grid

    class _Ctx:
        def guard(self, *args, **kwargs):
            pass

    return grid(NX, NY, NZ, 1.0, (0.0, 0.0, 0.0), ctx=_Ctx())  # type: ignore[arg-type]


def _grid_numpy() -> np.ndarray:
    k, j, i = np.meshgrid(np.arange(NZ), np.arange(NY), np.arange(NX), indexing="ij")
    return np.stack([i.ravel(), j.ravel(), k.ravel()], axis=-1) * 1.0 + np.zeros(3)


DEPTH = 2000


def _chain_text() -> str:
    lines = ["formgraph: 1", "nodes:", "  f0: {type: field.sphere, radius: 1}"]
    lines += [
        f"  f{i}: {{type: field.offset, field: '@f{i - 1}', distance: 0.0001}}"
        for i in range(1, DEPTH)
    ]
    lines.append(f"  m: {{type: field.mesh, field: '@f{DEPTH - 1}', cell: 0.1}}")
    return "\n".join(lines) + "\n"


def run(table) -> None:
    case = f"points.grid of {NX * NY * NZ:,} points ({NX * NY * NZ * 24 / 1e6:.0f} MB)"
    table.memory(
        f"{case}: peak memory",
        api=_grid_api,
        references={"numpy meshgrid": _grid_numpy},
        note="the output and one frozen copy",
    )
    table.compare(
        case,
        api=_grid_api,
        kernel=_grid_kernel,
        references={"numpy meshgrid": _grid_numpy},
        rounds=5,
    )
    text = _chain_text()
    table.compare(
        f"{DEPTH:,} field nodes deep: load, check, mesh (cell 0.1)",
        api=lambda: fg.Graph.from_text(text, file="chain.yaml").evaluate("m"),
        rounds=3,
    )
