"""How each kind of geometry is drawn: colours, materials, normals, edges, back faces.

The shading is meant to be honest about the geometry, as Rhino's and Blender's viewports
are: the back of a face (its vertices run clockwise as seen) is drawn in :data:`BACK_FACE`,
one colour for every layer, so a mesh that faces inward cannot pass for a correct one;
surfaces and fine meshes are smooth-shaded, but normals are split where faces meet at more
than :data:`FEATURE_ANGLE` (a box stays a box) and those feature edges and open boundaries
are drawn as lines; the edges of every face are drawn only on a coarse mesh (at most
:data:`COARSE_FACES` faces), where each face matters, or when asked for.

pyvista is imported inside the functions, so importing this module costs nothing.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = [
    "BACKGROUND",
    "BACK_FACE",
    "COARSE_FACES",
    "FEATURE_ANGLE",
    "PALETTE",
    "mix",
    "shaded",
    "style",
]

# matplotlib's tab10 without its red, which is kept for back faces (as Blender's face
# orientation overlay shows them); reads well on white and keeps neighbours apart
PALETTE = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#17becf",
    "#bcbd22",
    "#7f7f7f",
)
BACK_FACE = "#e0393e"
BACKGROUND = "white"
GRID_COLOR = "#8a8a8a"
ERROR_COLOR = "#b00020"
TEXT_COLOR = "#333333"

FEATURE_ANGLE = 30.0  # degrees between face normals above which an edge stays sharp
COARSE_FACES = 1000  # a mesh with at most this many faces is drawn with its edges

MATERIAL = dict(ambient=0.22, diffuse=0.78, specular=0.2, specular_power=24)


def mix(color: str, other: str, t: float) -> tuple[float, float, float]:
    """``color`` moved ``t`` of the way to ``other`` (RGB floats)."""
    import pyvista as pv

    a = np.array(pv.Color(color).float_rgb)
    b = np.array(pv.Color(other).float_rgb)
    return tuple(float(x) for x in (1 - t) * a + t * b)  # type: ignore[return-value]


def shaded(data: Any) -> tuple[Any, Any]:
    """A surface dataset ready for smooth shading, and its feature edges.

    Point normals are computed with the vertices split along edges sharper than
    :data:`FEATURE_ANGLE` (vtkPolyDataNormals). The faces are never reordered
    (``consistent_normals=False``): reordering would turn a face the right way round and so
    hide a wrong orientation, which the back-face colour is there to show. The lines are
    the feature edges, open boundaries and non-manifold edges of the unsplit mesh.
    """
    normals = data.compute_normals(
        cell_normals=False,
        point_normals=True,
        split_vertices=True,
        feature_angle=FEATURE_ANGLE,
        consistent_normals=False,
        auto_orient_normals=False,
        non_manifold_traversal=False,
    )
    lines = data.extract_feature_edges(
        feature_angle=FEATURE_ANGLE,
        boundary_edges=True,
        non_manifold_edges=True,
        feature_edges=True,
        manifold_edges=False,
    )
    return normals, lines


def style(kind: str, color: str, edges: bool = False) -> dict[str, Any]:
    """add_mesh keywords for one kind of geometry drawn in ``color``."""
    if kind == "points":
        return dict(color=color, render_points_as_spheres=True, point_size=12, style="points")
    if kind == "curves":
        return dict(color=color, line_width=3.5, render_lines_as_tubes=True)
    if kind in ("surfaces", "meshes"):
        # smooth_shading=False keeps pyvista from computing normals again (with faces
        # reordered); the actor's interpolation is set to Phong by apply_material
        return dict(
            color=color,
            smooth_shading=False,
            show_edges=edges,
            edge_color=mix(color, "black", 0.5),
            line_width=1.0,
            **MATERIAL,
        )
    if kind == "features":
        return dict(color=mix(color, "black", 0.55), line_width=1.6)
    # control polygon / net: thin lines in a darker shade, with their control points
    return dict(color=mix(color, "black", 0.35), line_width=1.2, style="wireframe")


def apply_material(actor: Any, kind: str) -> None:
    """Phong interpolation over the precomputed normals, and the back-face colour."""
    if kind not in ("surfaces", "meshes"):
        return
    import pyvista as pv
    from vtkmodules.vtkRenderingCore import vtkProperty

    prop = actor.GetProperty()
    prop.SetInterpolationToPhong()
    back = vtkProperty()
    back.DeepCopy(prop)
    back.SetColor(pv.Color(BACK_FACE).float_rgb)
    back.SetEdgeColor(mix(BACK_FACE, "black", 0.5))
    back.SetSpecular(0.0)
    actor.SetBackfaceProperty(back)


def set_edges(actor: Any, visible: bool) -> None:
    """Show or hide the edges of every face of a mesh or surface actor."""
    actor.GetProperty().SetEdgeVisibility(visible)
    back = actor.GetBackfaceProperty()
    if back is not None:
        back.SetEdgeVisibility(visible)
