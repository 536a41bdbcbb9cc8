"""A drawing: shapes on a white page, written as SVG by our own code or rasterized to PNG
with Pillow (:mod:`formgraph.drawgraph.png`), so both show exactly the same thing."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from .png import rasterize
from .shapes import FONT_FAMILY, Shape, _svg

__all__ = ["Drawing"]


@dataclass
class Drawing:
    """Shapes in drawing order on a ``width`` x ``height`` white page (pixels)."""

    width: float
    height: float
    shapes: list[Shape] = field(default_factory=list)
    title: str = ""
    #: what a program drawing on top needs: for a graph, each box's place and its ports'
    #: (see :func:`formgraph.drawgraph.layout.draw_graph`)
    meta: dict = field(default_factory=dict)

    def add(self, shape: Shape) -> None:
        self.shapes.append(shape)

    # ----------------------------------------------------------------------------- SVG

    @property
    def svg(self) -> str:
        """The drawing as a standalone SVG document."""
        w, h = int(np.ceil(self.width)), int(np.ceil(self.height))
        out = [
            '<?xml version="1.0" encoding="UTF-8"?>',
            f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
            f'viewBox="0 0 {w} {h}" font-family={quoteattr(FONT_FAMILY)}>',
        ]
        if self.title:
            out.append(f"<title>{escape(self.title)}</title>")
        out.append(f'<rect class="page" x="0" y="0" width="{w}" height="{h}" fill="white"/>')
        for s in self.shapes:
            out.append(_svg(s))
        out.append("</svg>")
        return "\n".join(out) + "\n"

    def _repr_svg_(self) -> str:  # Jupyter shows the drawing
        return self.svg

    # ----------------------------------------------------------------------------- PNG

    def png(self, scale: float = 2.0) -> bytes:
        """The drawing as PNG bytes, ``scale`` pixels per drawing unit (Pillow)."""
        return rasterize(self.shapes, self.width, self.height, scale)

    def save(self, path: str | os.PathLike[str], scale: float = 2.0) -> Path:
        """Write ``path`` as SVG or PNG (by its suffix), atomically; returns the path."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".svg", ".png"):
            raise ValueError(f"{path}: a drawing is saved as .svg or .png")
        data = self.svg.encode("utf-8") if suffix == ".svg" else self.png(scale)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_bytes(data)
        os.replace(tmp, path)
        return path
