"""Entry points: a window on a graph or on geometry values, and PNGs rendered off screen.

``show`` and ``screenshot`` make the plotter a :class:`~.app.Session` needs (one view, or
a subplot per node for the side by side layout) and hand it over.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from formgraph.evaluation.graph import Graph, load

from .app import Session, shown_nodes
from .frame import Camera

__all__ = ["make_plotter", "screenshot", "show", "view_count"]


def view_count(source: Any, node: str | Iterable[str] | None = None) -> int:
    """How many views the side by side layout of ``source`` needs (one per shown node)."""
    if isinstance(source, (str, os.PathLike)):
        source = load(source)
    if isinstance(source, Graph):
        return len(shown_nodes(source, node))
    return len(source) if isinstance(source, (list, tuple)) else 1


def make_plotter(
    views: int = 1,
    layout: str = "overlay",
    size: tuple[int, int] = (1024, 768),
    *,
    off_screen: bool | None = None,
    controls: bool = False,
    title: str | None = None,
) -> Any:
    """A plotter for a :class:`Session`: one view, or ``views`` side by side (``layout
    "side"``), with a narrower last column for the sliders when ``controls``."""
    import pyvista as pv

    kwargs: dict[str, Any] = {"window_size": list(size)}
    if off_screen is not None:
        kwargs["off_screen"] = off_screen
    if title is not None:
        kwargs["title"] = title
    if layout == "side":
        n = max(1, views)
        kwargs["shape"] = (1, n + 1) if controls else (1, n)
        kwargs["border"] = False
        if controls:
            kwargs["col_weights"] = [1.0] * n + [0.32 * min(n, 3)]
    return pv.Plotter(**kwargs)


def show(
    source: Any,
    node: str | Iterable[str] | None = None,
    size: tuple[int, int] = (1024, 768),
    *,
    layout: str = "overlay",
    edges: bool | None = None,
    jupyter_backend: str | None = None,
    camera: Camera | None = None,
    color: str | None = None,
    **params: Any,
) -> Session:
    """Open an interactive window on a graph's results (or ``node``) or on geometry values.

    Every numeric graph param with a min and a max gets a slider; moving it re-evaluates
    through the cache and redraws in place. Keys: ``c`` control polygons, ``n`` control
    nets, ``e`` mesh edges, ``g`` grid, ``f`` fit, ``v`` isometric, ``q`` quit. In Jupyter,
    pass ``jupyter_backend`` (``"static"``, or ``"trame"`` where trame is installed).

    Parameters
    ----------
    source : Graph, str, path, geometry or list of geometries
    node : str or list of str, optional
        Nodes to show (``name`` or ``name.output``); default: the graph's results.
    size : (int, int)
        Window size in pixels.
    layout : {"overlay", "side"}
        All nodes in one view, or one view per node side by side (linked cameras).
    edges : bool, optional
        Mesh face edges always (True), never (False), on coarse meshes (None).
    camera : Camera, optional
        Where to look from first (``Camera("top")``); automatic if None.
    color : str, optional
        Colour points and meshes by this attribute, with a colour bar.
    **params
        Graph param values.

    Example
    -------
    >>> import formgraph as fg
    >>> fg.show("graphs/box_sculpture.yaml", ["faceted", "smooth_blocks"], layout="side")
    ... # doctest: +SKIP
    """
    if isinstance(source, (str, os.PathLike)):
        source = load(source)
    views = view_count(source, node) if layout == "side" else 1
    plotter = make_plotter(
        views, layout, size, controls=_has_controls(source), title=_window_title(source)
    )
    session = Session(
        source,
        node,
        plotter=plotter,
        params=params,
        layout=layout,
        edges=edges,
        camera=camera,
        color=color,
    )
    session.add_sliders()
    session.add_keys()
    plotter.show(jupyter_backend=jupyter_backend)
    return session


def screenshot(
    source: Any,
    path: str | os.PathLike[str],
    node: str | Iterable[str] | None = None,
    size: tuple[int, int] = (1024, 768),
    *,
    layout: str = "overlay",
    edges: bool | None = None,
    camera: Camera | None = None,
    color: str | None = None,
    **params: Any,
) -> Path:
    """Render a graph's results (or ``node``, or geometry values) off screen to a PNG.

    The parent folder of ``path`` is created. Returns the path written. ``camera`` (a
    :class:`~.frame.Camera`: ``Camera("top")``, ``Camera(azimuth=30, elevation=20)``) says
    where to look from; by default straight on for flat geometry, else isometric. ``color``
    names an attribute to colour points and meshes by, with a colour bar.

    Example
    -------
    >>> viewer.screenshot("graphs/spiral_tube.yaml", "out/tube.png", turns=5)  # doctest: +SKIP
    PosixPath('out/tube.png')
    """
    path = Path(path)
    if isinstance(source, (str, os.PathLike)):
        source = load(source)
    views = view_count(source, node) if layout == "side" else 1
    plotter = make_plotter(views, layout, size, off_screen=True)
    try:
        Session(
            source,
            node,
            plotter=plotter,
            params=params,
            timing=False,
            layout=layout,
            edges=edges,
            camera=camera,
            color=color,
        )
        path.parent.mkdir(parents=True, exist_ok=True)
        plotter.screenshot(str(path))
    finally:
        plotter.close()
    return path


def _has_controls(source: Any) -> bool:
    """Whether a window on ``source`` gets sliders or check boxes."""
    if not isinstance(source, Graph):
        return False
    values = source.params
    return any(
        isinstance(values.get(n), bool)
        or (p.min is not None and p.max is not None and isinstance(values.get(n), (int, float)))
        for n, p in source.param_defs.items()
    )


def _window_title(source: Any) -> str:
    if isinstance(source, Graph) and source.file:
        return f"formgraph - {Path(source.file).name}"
    if isinstance(source, (str, os.PathLike)):
        return f"formgraph - {Path(source).name}"
    return "formgraph"
