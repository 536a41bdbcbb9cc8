"""The primitives of a small vector drawing: rectangles, circles, smooth wires and text, and
each one's SVG element (the page that holds them is :class:`~formgraph.drawgraph.drawing.Drawing`).

The graph drawing (:mod:`formgraph.drawgraph.layout`) is built from these few primitives so that
its SVG and PNG show exactly the same thing. Text widths come from DejaVu Sans' advance
widths (the font the PNG uses, and the first the SVG asks for), so boxes fit their text.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from xml.sax.saxutils import escape, quoteattr

import numpy as np

__all__ = ["Circle", "Rect", "Shape", "Text", "Wire", "text_width"]

FONT_FAMILY = "DejaVu Sans, Verdana, Arial, sans-serif"

# advance widths of ASCII 32..126 in DejaVu Sans (regular, bold), in 1/100 em
_REGULAR = (
    "32 40 46 84 64 95 78 27 39 39 50 84 32 36 32 34 64 64 64 64 64 64 64 64 64 64 34 34 84 84 "
    "84 53 100 68 69 70 77 63 58 77 75 29 29 66 56 86 75 79 60 79 69 63 61 73 68 99 69 61 69 39 "
    "34 39 84 50 50 61 63 55 63 62 35 63 63 28 28 58 28 97 63 61 63 63 41 52 39 63 59 82 59 59 "
    "52 64 34 64 84"
)
_BOLD = (
    "35 46 52 84 70 100 87 31 46 46 52 84 38 42 38 37 70 70 70 70 70 70 70 70 70 70 40 40 84 84 "
    "84 58 100 77 76 73 83 68 68 82 84 37 37 77 64 100 84 85 73 85 77 72 68 81 77 110 77 72 73 "
    "46 37 46 84 50 50 67 72 59 72 68 44 72 71 34 34 67 34 104 71 69 72 72 49 60 48 71 65 92 65 "
    "65 58 71 37 71 84"
)
_WIDTHS = {False: [int(w) for w in _REGULAR.split()], True: [int(w) for w in _BOLD.split()]}


@functools.lru_cache(maxsize=8192)  # the same port and type names, box after box
def text_width(text: str, size: float, bold: bool = False) -> float:
    """The width of ``text`` set in DejaVu Sans at ``size`` pixels (others as an 'M')."""
    table = _WIDTHS[bold]
    return size / 100.0 * sum(table[ord(c) - 32] if 32 <= ord(c) < 127 else 100 for c in text)


@dataclass(frozen=True)
class Rect:
    x: float
    y: float
    w: float
    h: float
    fill: str = "white"
    stroke: str = "#444444"
    width: float = 1.0
    radius: float = 0.0
    cls: str = ""
    dash: tuple[float, float] | None = None
    title: str = ""  # a tooltip in the SVG


@dataclass(frozen=True)
class Circle:
    x: float
    y: float
    r: float
    fill: str = "#444444"
    stroke: str = "none"
    cls: str = ""


@dataclass(frozen=True)
class Text:
    x: float
    y: float  # the baseline
    text: str
    size: float = 12.0
    fill: str = "#222222"
    bold: bool = False
    anchor: str = "start"  # start | middle | end
    cls: str = ""
    halo: bool = False  # a white outline behind, to read over wires


@dataclass(frozen=True)
class Wire:
    """A smooth wire through ``points``: cubic segments leaving and entering horizontally."""

    points: tuple[tuple[float, float], ...]
    stroke: str = "#777777"
    width: float = 1.4
    cls: str = "wire"
    dash: tuple[float, float] | None = None
    data: tuple[tuple[str, str], ...] = ()  # data-* attributes in the SVG

    def segments(self) -> list[tuple[tuple[float, float], ...]]:
        """Each cubic Bezier segment as its four control points."""
        out = []
        for (x0, y0), (x1, y1) in zip(self.points[:-1], self.points[1:], strict=True):
            dx = max(abs(x1 - x0) / 2.0, 8.0)
            out.append(((x0, y0), (x0 + dx, y0), (x1 - dx, y1), (x1, y1)))
        return out

    def path_data(self) -> str:
        x, y = self.points[0]
        parts = [f"M{x:.1f},{y:.1f}"]
        for _, a, b, c in self.segments():
            parts.append(f"C{a[0]:.1f},{a[1]:.1f} {b[0]:.1f},{b[1]:.1f} {c[0]:.1f},{c[1]:.1f}")
        return " ".join(parts)

    def polyline(self, per_segment: int = 32) -> np.ndarray:
        """The wire flattened to (m, 2) points (Bernstein form, vectorized per segment)."""
        t = np.linspace(0.0, 1.0, per_segment)[:, None]
        basis = np.hstack([(1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t**2 * (1 - t), t**3])
        pieces = [basis @ np.asarray(seg) for seg in self.segments()]
        return np.concatenate(pieces) if pieces else np.asarray(self.points, dtype=float)


Shape = Rect | Circle | Text | Wire


def _num(v: float) -> str:
    return f"{v:.1f}".rstrip("0").rstrip(".")


def _svg(s: Shape) -> str:
    cls = f' class="{s.cls}"' if s.cls else ""
    if isinstance(s, Rect):
        dash = f' stroke-dasharray="{_num(s.dash[0])} {_num(s.dash[1])}"' if s.dash else ""
        r = f' rx="{_num(s.radius)}"' if s.radius else ""
        body = (
            f'<rect{cls} x="{_num(s.x)}" y="{_num(s.y)}" width="{_num(s.w)}" '
            f'height="{_num(s.h)}"{r} fill="{s.fill}" stroke="{s.stroke}" '
            f'stroke-width="{_num(s.width)}"{dash}'
        )
        return body + (f"><title>{escape(s.title)}</title></rect>" if s.title else "/>")
    if isinstance(s, Circle):
        return (
            f'<circle{cls} cx="{_num(s.x)}" cy="{_num(s.y)}" r="{_num(s.r)}" '
            f'fill="{s.fill}" stroke="{s.stroke}"/>'
        )
    if isinstance(s, Text):
        weight = ' font-weight="bold"' if s.bold else ""
        halo = ' stroke="white" stroke-width="3" paint-order="stroke"' if s.halo else ""
        return (
            f'<text{cls} x="{_num(s.x)}" y="{_num(s.y)}" font-size="{_num(s.size)}" '
            f'fill="{s.fill}" text-anchor="{s.anchor}"{weight}{halo}>{escape(s.text)}</text>'
        )
    dash = f' stroke-dasharray="{_num(s.dash[0])} {_num(s.dash[1])}"' if s.dash else ""
    data = "".join(f" data-{k}={quoteattr(v)}" for k, v in s.data)
    return (
        f'<path{cls} d="{s.path_data()}" fill="none" stroke="{s.stroke}" '
        f'stroke-width="{_num(s.width)}"{dash}{data}/>'
    )
