"""The pyvista viewer of formgraph: see any node, tune params with sliders, watch a file.

    import formgraph as fg
    from formgraph import viewer

    g = fg.load("graphs/spiral_tube.yaml")
    viewer.show(g, turns=5)                            # a window, a slider per ranged param
    viewer.screenshot(g, "out/tube.png", node="mesh")  # a PNG, off screen

pyvista is imported only when something is drawn, so importing this package is cheap.
"""

from __future__ import annotations

import os
import sys

# With no X display (CI, a server, a container) VTK would first try X, print a warning and
# only then fall back; EGL renders off screen directly.
if sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

from .app import LAYOUTS, Session, shown_nodes
from .entry import make_plotter, screenshot, show
from .frame import CAMERAS, Camera
from .scene import Scene
from .watch import ScreenshotWatcher, Watcher, display_problem, watch

__all__ = [
    "CAMERAS",
    "LAYOUTS",
    "Camera",
    "Scene",
    "ScreenshotWatcher",
    "Session",
    "Watcher",
    "display_problem",
    "make_plotter",
    "screenshot",
    "show",
    "shown_nodes",
    "watch",
]
