"""Framing: the camera that makes the geometry fill the free part of a view, the scale bar
and the size line in model units, and the round ranges of the bounds grid.

:func:`fit` frames the drawn points themselves, not their bounding box or sphere (a torus
seen from a corner would otherwise fill half the frame): it projects them with the
camera's own matrix (vectorized), centres them in the free rectangle (the view less what
the legend, status line, sliders and scale bar take) and zooms until they fill it.

pyvista and VTK are imported inside the functions, so importing this module costs nothing.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .style import TEXT_COLOR

__all__ = [
    "CAMERAS",
    "Camera",
    "ScaleBar",
    "fit",
    "fit_scenes",
    "nice_range",
    "nice_step",
    "project",
    "size_text",
    "view_axis",
]

SAMPLE = 6000  # points projected to frame a view (a strided sample of larger meshes)

#: named views as (azimuth, elevation) in degrees: azimuth about +z from the front (the
#: camera on -y, 0) toward the right side (+x, 90), elevation up from the XY plane
CAMERAS = {
    "iso": (135.0, float(np.degrees(np.arctan(1 / np.sqrt(2))))),  # from (1, 1, 1)
    "top": (0.0, 90.0),
    "front": (0.0, 0.0),
    "side": (90.0, 0.0),
    "bottom": (0.0, -90.0),
}
_STRAIGHT = {"top": 2, "bottom": 2, "front": 1, "side": 0}  # the axis a straight view drops


class Camera:
    """Where a view looks from: a named view, turned by an azimuth and an elevation.

    ``Camera()`` is the automatic choice (straight on for flat geometry, else isometric).
    A named view alone is straight on without perspective for ``top``, ``front``, ``side``
    and ``bottom`` (with the scale bar, as a drawing), in perspective for ``iso``. Giving
    ``azimuth`` or ``elevation`` replaces that angle of the view (``iso`` when none is
    named) and looks in perspective.

    Raises
    ------
    ValueError
        An unknown view, an angle that is not a finite number, an elevation outside
        -90..90.
    """

    def __init__(
        self, view: str | None = None, azimuth: float | None = None, elevation: float | None = None
    ):
        if view is not None and view not in CAMERAS:
            raise ValueError(f"camera must be one of {', '.join(CAMERAS)}, got {view!r}")
        for name, angle in (("azimuth", azimuth), ("elevation", elevation)):
            if angle is not None and (
                isinstance(angle, bool)
                or not isinstance(angle, (int, float))
                or not np.isfinite(angle)
            ):
                raise ValueError(f"{name} must be a finite number of degrees, got {angle!r}")
        if elevation is not None and not -90 <= elevation <= 90:
            raise ValueError(f"elevation must be from -90 to 90 degrees, got {elevation:g}")
        self.view, self.azimuth, self.elevation = view, azimuth, elevation

    @property
    def automatic(self) -> bool:
        return self.view is None and self.azimuth is None and self.elevation is None

    def straight_axis(self) -> int | None:
        """The axis a straight (parallel) view looks along, or None in perspective."""
        if self.azimuth is not None or self.elevation is not None:
            return None
        return _STRAIGHT.get(self.view or "")

    def direction(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit vectors from the focal point to the camera, and the view's up."""
        az0, el0 = CAMERAS[self.view or "iso"]
        az = np.radians(az0 if self.azimuth is None else self.azimuth)
        el = np.radians(el0 if self.elevation is None else self.elevation)
        toward = np.array([np.cos(el) * np.sin(az), -np.cos(el) * np.cos(az), np.sin(el)])
        # up is +z, except looking straight down or up, where it is the screen's +y
        up = np.array([0.0, 0.0, 1.0])
        if abs(np.cos(el)) < 1e-9:
            up = np.array([-np.sin(az), np.cos(az), 0.0])
        return toward, up

    def __repr__(self) -> str:
        return f"Camera({self.view!r}, azimuth={self.azimuth!r}, elevation={self.elevation!r})"


def view_axis(bounds: Sequence[float], rel: float = 1e-9) -> int | None:
    """The axis (0, 1, 2) along which ``bounds`` are flat, or None for a 3-D extent.

    A flat z is preferred (a top view), then y, then x.
    """
    b = np.asarray(bounds, dtype=np.float64).reshape(3, 2)
    extent = b[:, 1] - b[:, 0]
    size = float(extent.max())
    if size <= 0.0:
        return None
    for axis in (2, 1, 0):
        if extent[axis] <= rel * size:
            return axis
    return None


def nice_step(x: float) -> float:
    """The largest 1, 2 or 5 times a power of ten that is at most ``x`` (``x`` > 0)."""
    power = 10.0 ** np.floor(np.log10(x))
    for m in (5.0, 2.0, 1.0):
        if m * power <= x * (1 + 1e-9):
            return float(m * power)
    return float(power)


def nice_range(lo: float, hi: float, size: float, max_ticks: int = 9) -> tuple[float, float, int]:
    """``[lo, hi]`` widened to the nearest multiples of a round step, and the tick count.

    The step is 1, 2, 2.5 or 5 times a power of ten, at least ``size / 12`` (so labels on a
    short axis do not crowd), with at most ``max_ticks`` ticks; of those, the one that widens
    the range least (then the one with nearer five ticks). A thin axis (under ``size / 12``)
    keeps its ends and gets no labels (0: they would overlap); a flat one (``hi - lo`` tiny
    next to ``size``) gets one tick.
    """
    if size <= 0 or hi - lo <= 1e-9 * size:
        return lo, hi, 1
    if hi - lo < size / 12:  # a thin axis: widening it to a round step would swamp it
        return lo, hi, 0
    best: tuple[tuple[float, int], float, float, int] | None = None
    for power in range(int(np.floor(np.log10(hi - lo))) - 1, int(np.floor(np.log10(size))) + 2):
        for m in (1.0, 2.0, 2.5, 5.0):
            step = m * 10.0**power
            if step < size / 12:
                continue
            lo2 = step * np.floor(lo / step + 1e-9)
            hi2 = step * np.ceil(hi / step - 1e-9)
            n = int(round((hi2 - lo2) / step)) + 1
            key = (round(float(hi2 - lo2) / size, 9), abs(n - 5))
            if n <= max_ticks and (best is None or key < best[0]):
                best = (key, float(lo2), float(hi2), n)
    assert best is not None  # the largest step always fits in two or three ticks
    return best[1], best[2], best[3]


def size_text(bounds: Sequence[float], axis: int | None) -> str:
    """The size of the bounding box in model units: ``'5.2 x 5.2 x 3.7'`` (a drawing: two)."""
    b = np.asarray(bounds, dtype=np.float64).reshape(3, 2)
    extent = b[:, 1] - b[:, 0]
    names = [a for a in range(3) if a != axis] if axis is not None else [0, 1, 2]
    parts = [f"{'xyz'[a]} {extent[a]:.3g}" for a in names]
    return "size  " + "  ".join(parts)


# ---------------------------------------------------------------------------- camera


def _matrix(m: Any) -> np.ndarray:
    return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])


def project(renderer: Any, points: np.ndarray) -> np.ndarray:
    """Normalized view coordinates (-1 to 1 across the viewport) of (m, 3) world points."""
    cam = renderer.GetActiveCamera()
    aspect = renderer.GetTiledAspectRatio()
    m = _matrix(cam.GetCompositeProjectionTransformMatrix(aspect, -1.0, 1.0))
    h = np.column_stack([points, np.ones(len(points))]) @ m.T
    return h[:, :2] / h[:, 3:4]


def sample(points: np.ndarray, limit: int = SAMPLE) -> np.ndarray:
    """At most ``limit`` of the points, evenly strided, plus each axis's extremes."""
    points = np.asarray(points, dtype=np.float64)
    if len(points) <= limit:
        return points
    picked = points[:: int(np.ceil(len(points) / limit))]
    ends = points[np.concatenate([points.argmin(axis=0), points.argmax(axis=0)])]
    return np.concatenate([picked, ends])


def fit(
    renderer: Any,
    points: np.ndarray,
    free: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 1.0),
    fill: float = 0.92,
) -> None:
    """Move and zoom the camera (its direction kept) until ``points`` fill ``fill`` of the
    ``free`` rectangle (``x0, y0, x1, y1`` as fractions of the viewport), centred in it.

    The camera is moved sideways to centre the projected points and zoomed (the view angle,
    or the parallel scale) to fit; under perspective each move changes the projection a
    little, so three rounds are made.
    """
    cam = renderer.GetActiveCamera()
    cam.SetWindowCenter(0.0, 0.0)
    x0, y0, x1, y1 = free
    free_w, free_h = 2.0 * (x1 - x0), 2.0 * (y1 - y0)
    for _ in range(3 if not cam.GetParallelProjection() else 1):
        xy = project(renderer, points)
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        centre, extent = 0.5 * (lo + hi), hi - lo
        direction = np.array(cam.GetDirectionOfProjection())
        up = np.array(cam.GetViewUp())
        right = np.cross(direction, up)
        right /= np.linalg.norm(right)
        up = np.cross(right, direction)
        if cam.GetParallelProjection():
            half_h = cam.GetParallelScale()
        else:
            half_h = cam.GetDistance() * np.tan(np.radians(cam.GetViewAngle()) / 2)
        half_w = half_h * renderer.GetTiledAspectRatio()
        delta = right * centre[0] * half_w + up * centre[1] * half_h
        cam.SetPosition(*(np.array(cam.GetPosition()) + delta))
        cam.SetFocalPoint(*(np.array(cam.GetFocalPoint()) + delta))
        if extent.max() > 1e-12:
            factor = fill * min(free_w / max(extent[0], 1e-12), free_h / max(extent[1], 1e-12))
            cam.Zoom(float(factor))
    cam.SetWindowCenter(1.0 - (x0 + x1), 1.0 - (y0 + y1))
    renderer.ResetCameraClippingRange()
    if hasattr(cam, "is_set"):  # pyvista resets an unset camera on the first render
        cam.is_set = True


def fit_scenes(scenes: Sequence[Any]) -> None:
    """Frame what ``scenes`` draw with the camera they share (one scene, or linked views).

    Flat geometry (a drawing) is seen straight on without perspective, a top view when it
    lies in XY; anything else isometric. Everything drawn fills the views less their
    margins (legend, title, texts, scale bar, the sliders' column).
    """
    scene = scenes[0]
    boxes = [
        b
        for b in (
            s.grid_bounds()[0] if s.show_grid and s.grid_bounds() else s.bounds() for s in scenes
        )
        if b is not None
    ]
    if not boxes:
        return
    b = np.asarray(boxes).reshape(-1, 3, 2)
    bounds = np.column_stack([b[:, :, 0].min(axis=0), b[:, :, 1].max(axis=0)]).ravel()
    axis = view_axis(bounds)
    points = np.concatenate([s.points() for s in scenes])
    if scene.show_grid:  # the grid box's corners, so that its labels fit too
        corners = np.array(np.meshgrid(*bounds.reshape(3, 2), indexing="ij")).reshape(3, -1).T
        points = np.concatenate([points, corners])
    scene.activate()
    p = scene.plotter
    camera: Camera = getattr(scene, "camera", None) or Camera()
    if camera.automatic:
        views = {None: p.view_isometric, 2: p.view_xy, 1: p.view_xz, 0: p.view_yz}
        views[axis](render=False)
    else:
        axis = camera.straight_axis()
        toward, up = camera.direction()
        centre = bounds.reshape(3, 2).mean(axis=1)
        reach = max(float(np.ptp(bounds.reshape(3, 2), axis=1).max()), 1e-9)
        p.camera_position = [tuple(centre + 4 * reach * toward), tuple(centre), tuple(up)]
    p.camera.parallel_projection = axis is not None  # a drawing: no perspective
    p.reset_camera(render=False, bounds=tuple(bounds))
    w, h = scene.size()
    if len(scenes) == 1:
        options = scene.margin_options(axis)
    else:
        options = [tuple(np.max([s.margins(axis) for s in scenes], axis=0))]
    frees = [
        (left / w, bottom / h, 1.0 - scene.view_shift - right / w, 1.0 - top / h)
        for left, bottom, right, top in options
    ]
    free = frees[0]
    if len(frees) > 1:  # the one that lets the picture be largest
        fit(scene.renderer, points, (0.0, 0.0, 1.0, 1.0), fill=1.0)
        xy = project(scene.renderer, points)
        ex, ey = np.maximum(np.ptp(xy, axis=0), 1e-12)
        sizes = [min((f[2] - f[0]) / ex, (f[3] - f[1]) / ey) for f in frees]
        # off centre only for a clear gain (a long legend over a tall drawing)
        if max(sizes[1:]) > 1.1 * sizes[0]:
            free = frees[1 + int(np.argmax(sizes[1:]))]
    if len(scenes) > 1:
        for s in scenes:
            s.set_frame(bounds)
    for s in scenes:
        s.free = free
    fit(scene.renderer, points, free)
    for s in scenes:
        s.scale_bar.update()


# ------------------------------------------------------------------------- scale bar


class ScaleBar:
    """A bar of a round length in model units at the bottom left of a parallel view.

    It is recomputed at the start of every render of its renderer (so it stays true as the
    user zooms) and hidden under perspective, where no one length holds across the view.
    """

    HEIGHT = 46  # pixels the bar and its label take above the bottom of the view

    def __init__(self, renderer: Any):
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
        from vtkmodules.vtkRenderingCore import vtkActor2D, vtkPolyDataMapper2D, vtkTextActor

        self.renderer = renderer
        self.points = vtkPoints()
        self.points.SetNumberOfPoints(6)
        lines = vtkCellArray()
        for a, b in ((0, 1), (2, 3), (4, 5)):  # the bar and its two end ticks
            lines.InsertNextCell(2)
            lines.InsertCellPoint(a)
            lines.InsertCellPoint(b)
        poly = vtkPolyData()
        poly.SetPoints(self.points)
        poly.SetLines(lines)
        mapper = vtkPolyDataMapper2D()
        mapper.SetInputData(poly)
        self.poly = poly
        self.bar = vtkActor2D()
        self.bar.SetMapper(mapper)
        prop = self.bar.GetProperty()
        prop.SetColor(_rgb(TEXT_COLOR))
        prop.SetLineWidth(2.0)
        self.label = vtkTextActor()
        tp = self.label.GetTextProperty()
        tp.SetFontSize(13)
        tp.SetColor(_rgb(TEXT_COLOR))
        tp.SetJustificationToCentered()
        renderer.AddViewProp(self.bar)
        renderer.AddViewProp(self.label)
        self.length: float | None = None
        self._observer = renderer.AddObserver("StartEvent", lambda *_: self.update())

    def update(self) -> None:
        cam = self.renderer.GetActiveCamera()
        width, height = self.renderer.GetSize()
        visible = bool(cam.GetParallelProjection()) and width > 0 and height > 0
        self.bar.SetVisibility(visible)
        self.label.SetVisibility(visible)
        if not visible:
            self.length = None
            return
        per_unit = height / (2.0 * cam.GetParallelScale())
        self.length = nice_step(min(0.25 * width, 160.0) / per_unit)
        px = self.length * per_unit
        x, y = 14.0, 28.0
        for i, (px_, py_) in enumerate(
            [(x, y), (x + px, y), (x, y - 4), (x, y + 4), (x + px, y - 4), (x + px, y + 4)]
        ):
            self.points.SetPoint(i, px_, py_, 0.0)
        self.points.Modified()
        self.poly.Modified()
        self.label.SetInput(f"{self.length:g}")
        self.label.SetPosition(x + px / 2, y + 5)

    def remove(self) -> None:
        self.renderer.RemoveObserver(self._observer)
        self.renderer.RemoveViewProp(self.bar)
        self.renderer.RemoveViewProp(self.label)


def _rgb(color: str) -> tuple[float, float, float]:
    import pyvista as pv

    return pv.Color(color).float_rgb
