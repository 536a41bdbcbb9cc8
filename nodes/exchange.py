"""Export for the next tool: 3MF for slicers, GLB for the web, STEP for CAD, .3dm for Rhino.

Each node builds the file's bytes with a kernel (:mod:`formgraph.kernels.io.threemf`,
``.gltf``, ``.step``, ``.rhino``) and hands them to ``ctx.write``: written atomically,
inside the output directory, left alone when the file already holds these bytes. Each
returns the written file's path.
"""

from __future__ import annotations

import re
from enum import Enum

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import OutputPath
from formgraph.geometry import Mesh
from formgraph.kernels.io import gltf, threemf
from formgraph.kernels.mesh import meshops


class Unit(str, Enum):
    micron = "micron"
    millimeter = "millimeter"
    centimeter = "centimeter"
    inch = "inch"
    foot = "foot"
    meter = "meter"


# the CSS basic colour keywords (CSS Color Module Level 4, section 6.1)
_NAMED = {
    "black": "000000", "silver": "c0c0c0", "gray": "808080", "grey": "808080",
    "white": "ffffff", "maroon": "800000", "red": "ff0000", "purple": "800080",
    "fuchsia": "ff00ff", "magenta": "ff00ff", "green": "008000", "lime": "00ff00",
    "olive": "808000", "yellow": "ffff00", "navy": "000080", "blue": "0000ff",
    "teal": "008080", "aqua": "00ffff", "cyan": "00ffff", "orange": "ffa500",
}  # fmt: skip


def css_rgba(text: str) -> tuple[float, float, float, float]:
    """A CSS colour (``#rgb``, ``#rrggbb``, ``#rrggbbaa`` or a basic keyword) as 0..1 RGBA.

    Raises
    ------
    ValueError
        For anything else.
    """
    t = str(text).strip().lower()
    t = "#" + _NAMED[t] if t in _NAMED else t
    if re.fullmatch(r"#[0-9a-f]{3}", t):
        t = "#" + "".join(c * 2 for c in t[1:])
    if not re.fullmatch(r"#[0-9a-f]{6}([0-9a-f]{2})?", t):
        raise ValueError(
            f"{text!r} is not a colour: write #rrggbb, #rgb or a name such as red or navy"
        )
    t = t + "ff" if len(t) == 7 else t
    r, g, b, a = (int(t[k : k + 2], 16) / 255 for k in (1, 3, 5, 7))
    return (r, g, b, a)


def _triangles(meshes: list[Mesh], ctx: Context) -> list[tuple[np.ndarray, np.ndarray]]:
    ctx.guard(sum(int(np.sum(m.face_sizes - 2)) for m in meshes), "triangles")
    out = []
    for m in meshes:
        v, fi, fo = meshops.triangulate(
            m.vertices, m.face_indices, m.face_offsets, max_tests=ctx.budget
        )
        out.append((v, fi.reshape(-1, 3)))
    return out


def _per_mesh(values: list | None, meshes: list[Mesh], port: str) -> list | None:
    if values is not None and len(values) != len(meshes):
        raise InputError(port, f"{len(values)} {port} for {len(meshes)} meshes: give one each")
    return values


@node("export.3mf", version=1)
def export_3mf(
    meshes: list[Mesh],
    path: OutputPath,
    names: list[str] | None = None,
    colors: list[str] | None = None,
    units: Unit = Unit.millimeter,
    *,
    ctx: Context,
) -> str:
    """Write meshes as a 3MF package, for slicers: one object and one build item each.

    A valid 3MF core package (content types, relationships, the model with its unit);
    polygons are triangulated (ear clipping for concave ones); each object carries its name
    and, given ``colors``, a base material of that colour. Slicers read the unit, so a part
    arrives at its size.

    Parameters
    ----------
    meshes : list[Mesh]
        The parts, one object each.
    path : OutputPath
        File path relative to the output directory, e.g. ``parts/plate.3mf``.
    names : list[str] | None
        One name per mesh (default ``mesh 1``, ``mesh 2``, ...).
    colors : list[str] | None
        One CSS colour per mesh (``red``, ``#ff8800``).
    units : Unit
        What one model unit is.
    """
    _per_mesh(names, meshes, "names")
    _per_mesh(colors, meshes, "colors")
    try:
        rgba = [css_rgba(c) for c in colors] if colors is not None else None
    except ValueError as exc:
        raise InputError("colors", str(exc)) from None
    data = threemf.write_3mf(_triangles(meshes, ctx), names=names, colors=rgba, unit=units.value)
    return str(ctx.write(path, data))


@node("export.gltf", version=1)
def export_gltf(
    meshes: list[Mesh],
    path: OutputPath,
    names: list[str] | None = None,
    units: Unit = Unit.millimeter,
    *,
    ctx: Context,
) -> str:
    """Write meshes as binary glTF 2.0 (``.glb``), for the web and AR viewers.

    One node and mesh each: float32 positions (with their bounds), smooth vertex normals
    (area-weighted) and uint32 triangle indices in one binary chunk. glTF's unit is the
    metre, so coordinates are scaled from ``units`` (a 100 mm vase is 0.1 m in the file).

    Parameters
    ----------
    meshes : list[Mesh]
        The meshes, one node each.
    path : OutputPath
        File path relative to the output directory, e.g. ``web/vase.glb``.
    names : list[str] | None
        One name per mesh.
    units : Unit
        What one model unit is.
    """
    _per_mesh(names, meshes, "names")
    scale = threemf.UNITS[units.value] / 1000.0
    data = gltf.write_glb(_triangles(meshes, ctx), names=names, scale=scale)
    return str(ctx.write(path, data))
