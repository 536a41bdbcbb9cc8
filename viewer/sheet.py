"""Contact sheets of a sweep: one off-screen picture per variant, labelled, tiled.

``render_cell`` draws one value (on a Dask worker, in parallel); ``contact_sheet`` tiles the
cells on the client. A sheet holds at most ``per_sheet`` cells (100 by default, a 10 x 10
grid); more variants page onto ``sheet-2.png``, ``sheet-3.png``, ... so each cell stays big
enough to read however many variants there are.
"""

from __future__ import annotations

import io
import math
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["CELL", "LABEL_HEIGHT", "contact_sheet", "grid_shape", "render_cell"]

CELL = (256, 192)  # width, height of a rendered cell, in pixels
LABEL_HEIGHT = 34  # the strip under each cell holding its variant number and params
BACKGROUND = (255, 255, 255)
FAILED = (236, 226, 226)


def render_cell(
    value: Any, size: tuple[int, int] = CELL, camera: tuple[Any, Any, Any] | None = None
) -> bytes:
    """A PNG (bytes) of ``value`` drawn off screen as ``formgraph view`` draws it, without
    the bounds grid (its labels do not survive a cell's size); the camera fits the value,
    looking from ``camera`` = (view, azimuth, elevation) as :class:`~.frame.Camera` takes
    them (automatic if None)."""
    import pyvista as pv

    from .app import Session
    from .frame import Camera

    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    try:
        session = Session(
            value, plotter=plotter, timing=False, camera=Camera(*camera) if camera else None
        )
        if session.scene.show_grid:
            session.scene.toggle_grid()
            session.scene.fit_camera()
        with tempfile.TemporaryDirectory(prefix="formgraph-cell-") as tmp:
            path = Path(tmp) / "cell.png"
            plotter.screenshot(str(path))
            return path.read_bytes()
    finally:
        plotter.close()


def grid_shape(count: int) -> tuple[int, int]:
    """(columns, rows) of a sheet of ``count`` cells: as square as it gets, wider first."""
    cols = max(1, math.ceil(math.sqrt(count)))
    return cols, max(1, math.ceil(count / cols))


def contact_sheet(
    cells: Sequence[tuple[str, bytes | str | os.PathLike[str] | None]],
    path: str | os.PathLike[str],
    *,
    size: tuple[int, int] = CELL,
    per_sheet: int = 100,
) -> list[Path]:
    """Tile ``cells`` (label, PNG bytes or file, or None for a failed variant) into sheets.

    The first sheet is ``path``; further pages add ``-2``, ``-3``, ... before the suffix.
    Each file is written whole or not at all. Returns the paths written.
    """
    from PIL import Image, ImageDraw, ImageFont

    if per_sheet < 1:
        raise ValueError(f"per_sheet must be at least 1, got {per_sheet}")
    path = Path(path)
    font = ImageFont.load_default(size=12)
    w, h = size
    pages = [cells[i : i + per_sheet] for i in range(0, len(cells), per_sheet)] or [[]]
    written = []
    for number, page in enumerate(pages, start=1):
        cols, rows = grid_shape(len(page))
        sheet = Image.new("RGB", (cols * w, rows * (h + LABEL_HEIGHT)), BACKGROUND)
        draw = ImageDraw.Draw(sheet)
        for i, (label, image) in enumerate(page):
            x, y = (i % cols) * w, (i // cols) * (h + LABEL_HEIGHT)
            if image is None:
                draw.rectangle([x, y, x + w - 1, y + h - 1], fill=FAILED)
                draw.text(
                    (x + w // 2, y + h // 2), "failed", fill=(150, 40, 40), font=font, anchor="mm"
                )
            else:
                src = io.BytesIO(image) if isinstance(image, bytes) else image
                with Image.open(src) as im:
                    sheet.paste(im.convert("RGB").resize((w, h)), (x, y))
            for j, text in enumerate(_wrap(label, font, w - 8, 2)):
                draw.text((x + 4, y + h + 3 + 15 * j), text, fill=(30, 30, 30), font=font)
            draw.rectangle([x, y, x + w - 1, y + h + LABEL_HEIGHT - 1], outline=(200, 200, 200))
        target = path if number == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
        sheet.save(tmp, format="PNG")
        os.replace(tmp, target)
        written.append(target)
    return written


def _wrap(text: str, font: Any, width: int, lines: int) -> list[str]:
    """``text`` broken at spaces into at most ``lines`` lines that fit ``width`` pixels."""
    out: list[str] = []
    current = ""
    for word in text.split():
        trial = f"{current} {word}".strip()
        if font.getlength(trial) <= width or not current:
            current = trial
            continue
        out.append(current)
        current = word
    out.append(current)
    if len(out) > lines:
        out = out[:lines]
        while out[-1] and font.getlength(out[-1] + "...") > width:
            out[-1] = out[-1][:-1]
        out[-1] += "..."
    return out
