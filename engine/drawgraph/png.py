"""Rasterize the shapes of a :class:`~formgraph.drawgraph.drawing.Drawing` to PNG with Pillow.

Pillow is already installed with pyvista (which needs it for its images); it draws the same
shapes the SVG holds, supersampled twice and averaged down for smooth edges. The text is
DejaVu Sans, taken from matplotlib's fonts when matplotlib is there (it comes with pyvista
too), else Pillow's own scalable default font.
"""

from __future__ import annotations

import io
from functools import lru_cache
from typing import Any

import numpy as np

from ..core.errors import BudgetError
from .shapes import Circle, Rect, Shape, Text, Wire

__all__ = ["MAX_PIXELS", "MAX_SIDE", "MIN_SCALE", "fitted_scale", "rasterize"]

SUPERSAMPLE = 2
MAX_PIXELS = 40_000_000  # of the PNG (the canvas is SUPERSAMPLE^2 times that): ~160 MB RGB
MAX_SIDE = 32_000  # pixels a side: what image viewers and browsers still open
MIN_SCALE = 0.5  # pixels per drawing unit below which the text (12 units) cannot be read


def fitted_scale(width: float, height: float, scale: float) -> float:
    """``scale``, lowered until a ``width`` x ``height`` page fits the canvas budget.

    Raises
    ------
    BudgetError
        When even :data:`MIN_SCALE` pixels per unit would not fit: the graph is too large
        for one picture (the SVG has no such limit).
    """
    w, h = max(width, 1e-9), max(height, 1e-9)
    fit = min(scale, MAX_SIDE / w, MAX_SIDE / h, float(np.sqrt(MAX_PIXELS / (w * h))))
    if fit < MIN_SCALE:
        raise BudgetError(
            f"the drawing is {w:,.0f} x {h:,.0f} units: as a PNG it would be "
            f"{w * scale:,.0f} x {h * scale:,.0f} pixels, over the budget of "
            f"{MAX_PIXELS:,} pixels ({MAX_SIDE:,} a side) even at {MIN_SCALE:g} pixels a "
            "unit; write it as .svg, or draw fewer nodes"
        )
    return fit


@lru_cache(maxsize=32)
def _font(size: int, bold: bool) -> Any:
    from PIL import ImageFont

    try:
        import matplotlib

        name = "DejaVuSans-Bold.ttf" if bold else "DejaVuSans.ttf"
        return ImageFont.truetype(f"{matplotlib.get_data_path()}/fonts/ttf/{name}", size)
    except (ImportError, OSError):
        return ImageFont.load_default(size)


def _dashes(points: np.ndarray, on: float, off: float) -> list[np.ndarray]:
    """The pieces of a polyline that a dash pattern ``on``, ``off`` draws."""
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return []
    starts = np.arange(0.0, s[-1], on + off)
    pieces = []
    for a in starts:
        b = min(a + on, s[-1])
        t = np.concatenate([[a], s[(s > a) & (s < b)], [b]])
        pieces.append(
            np.column_stack([np.interp(t, s, points[:, 0]), np.interp(t, s, points[:, 1])])
        )
    return pieces


def rasterize(shapes: list[Shape], width: float, height: float, scale: float = 2.0) -> bytes:
    """PNG bytes of ``shapes`` on a white ``width`` x ``height`` page, ``scale`` pixels per
    unit -- fewer when the page would not fit the canvas budget (:func:`fitted_scale`)."""
    from PIL import Image, ImageDraw

    k = fitted_scale(width, height, scale) * SUPERSAMPLE
    size = (max(1, int(np.ceil(width * k))), max(1, int(np.ceil(height * k))))
    img = Image.new("RGB", size, "white")
    draw = ImageDraw.Draw(img)
    anchors = {"start": "ls", "middle": "ms", "end": "rs"}
    for s in shapes:
        if isinstance(s, Rect):
            box = [s.x * k, s.y * k, (s.x + s.w) * k, (s.y + s.h) * k]
            fill = None if s.fill == "none" else s.fill
            outline = None if s.stroke == "none" else s.stroke
            if s.dash is None:
                draw.rounded_rectangle(
                    box, radius=s.radius * k, fill=fill, outline=outline, width=round(s.width * k)
                )
                continue
            draw.rounded_rectangle(box, radius=s.radius * k, fill=fill)
            x0, y0, x1, y1 = box
            edge = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]])
            for piece in _dashes(edge, s.dash[0] * k, s.dash[1] * k):
                draw.line([tuple(p) for p in piece], fill=outline, width=round(s.width * k))
        elif isinstance(s, Circle):
            draw.ellipse(
                [(s.x - s.r) * k, (s.y - s.r) * k, (s.x + s.r) * k, (s.y + s.r) * k],
                fill=None if s.fill == "none" else s.fill,
                outline=None if s.stroke == "none" else s.stroke,
            )
        elif isinstance(s, Text):
            font = _font(max(1, round(s.size * k)), s.bold)
            xy = (s.x * k, s.y * k)
            extra = dict(stroke_width=round(1.5 * k), stroke_fill="white") if s.halo else {}
            draw.text(xy, s.text, fill=s.fill, font=font, anchor=anchors[s.anchor], **extra)
        elif isinstance(s, Wire):
            line = s.polyline() * k
            width = max(1, round(s.width * k))
            pieces = [line] if s.dash is None else _dashes(line, s.dash[0] * k, s.dash[1] * k)
            for piece in pieces:
                draw.line([tuple(p) for p in piece], fill=s.stroke, width=width, joint="curve")
    if SUPERSAMPLE > 1:  # the mean of each block of samples: a box filter, exact here
        img = img.reduce(SUPERSAMPLE)
    buf = io.BytesIO()
    img.save(buf, format="PNG", compress_level=6)
    return buf.getvalue()
