"""``curves.text``: the outlines of a line of text in a TrueType or OpenType font, exact
quadratic and cubic pieces (:mod:`formgraph.kernels.curves.text`).
"""

from __future__ import annotations

from enum import Enum
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import InputPath, Vec3
from formgraph.geometry import Curve, NurbsCurve, frozen_array
from formgraph.kernels.curves import text as ktext
from formgraph.kernels.geometry import MAX_COORDINATE


class Align(str, Enum):
    """Where a line of text sits on its position."""

    left = "left"  # starts there
    center = "center"  # its middle there
    right = "right"  # ends there


def _font(font: str, font_file: str | None, ctx: Context) -> ktext.Font:
    """The parsed font: the file the graph names (its bytes key the node), else a bundled
    one."""
    if font_file is not None:
        if not font_file.lower().endswith((".ttf", ".otf")):
            raise InputError("font_file", f"{font_file!r}: a font file is a .ttf or .otf")
        _, data = ctx.read(font_file)
        try:
            return ktext.load_font(data)
        except ValueError as exc:
            raise InputError("font_file", f"{font_file!r}: {exc}") from None
    path = InputError.call("font", ktext.bundled_font_path, font)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError("font", f"cannot read the bundled font {font!r}: {exc}") from None
    return InputError.call("font", ktext.load_font, data)


@node("curves.text", version=1)
def text(
    text: str,
    size: Annotated[float, Range(min=0)] = 10.0,
    font: str = "DejaVu Sans",
    align: Align = Align.left,
    position: Vec3 = (0.0, 0.0, 0.0),
    font_file: InputPath | None = None,
    *,
    ctx: Context,
) -> list[Curve]:
    """Text as closed outlines: each glyph's contours as exact NURBS, holes included.

    The font's own Bezier outlines become NURBS without approximation: TrueType's
    quadratic contours (implied on-curve points restored) as closed degree-2 curves, CFF's
    cubic ones as degree 3. Outer contours run counter-clockwise and holes (the counter of
    an ``o``) clockwise, so the list is a region by the even-odd rule as the region nodes
    and ``offset.marching_squares`` read it. Glyphs advance by the font's widths and
    kerning (GPOS pair adjustments, else the ``kern`` table); lines (split at newlines)
    are the font's line height apart, the first baseline through ``position``.

    Parameters
    ----------
    text : str
        The text; ``\\n`` starts a new line.
    size : float
        The em size in model units (a capital of DejaVu Sans is 0.73 of it).
    font : str
        A bundled font (they ship with matplotlib): DejaVu Sans, DejaVu Sans Bold, DejaVu
        Sans Oblique, DejaVu Sans Bold Oblique, DejaVu Sans Mono, DejaVu Sans Mono Bold,
        DejaVu Serif, DejaVu Serif Bold, DejaVu Serif Italic.
    align : Align
        left, center or right: each line starts at, is centred on or ends at ``position``.
    position : Vec3
        Where the first line's baseline meets the alignment point.
    font_file : InputPath | None
        A TrueType or OpenType font (``.ttf``, ``.otf``) in the graph's folder (or the
        inputs folder), e.g. ``fonts/Inter.otf``: used instead of ``font``. Confined as
        every input path (no absolute path, no ``..``, no symlink out); its bytes are part
        of the node's key, so editing the font recomputes the text.

    Example
    -------
    ``label: {type: curves.text, text: "FORMGRAPH", size: 8, align: center}``
    """
    if not size > 0:
        raise InputError("size", f"size must be positive, got {size}")
    ctx.guard(len(text) * 64, "glyph control points")  # a glyph has tens of points
    f = _font(font, font_file, ctx)
    degree, pts, offsets, missing = InputError.call(
        "text", ktext.layout, f, text, size, align.value
    )
    if missing:
        chars = "".join(missing[:20])
        ctx.warn(
            f"the font {font_file or font!r} has no glyph for {chars!r}: drawn as its "
            "missing-glyph box"
        )
    ctx.guard(len(pts), "glyph control points")
    with np.errstate(all="ignore"):
        extent = np.abs(np.asarray(pts, dtype=float)).max(initial=0) + np.abs(position).max()
    if not extent <= MAX_COORDINATE:
        raise InputError(
            "size",
            f"size {size:g} (at position {[float(x) for x in position]}) puts the text's outline "
            f"{'past any finite number' if not np.isfinite(extent) else f'at {extent:.3g}'}, "
            f"beyond {MAX_COORDINATE:g} mm where a double no longer holds a tenth of a "
            "millimetre",
        )
    # one frozen array for all the control points: each curve's are a view of it (shared,
    # not copied), and the knots of each piece count are made once
    xyz = frozen_array(np.c_[pts, np.zeros(len(pts))] + np.asarray(position))
    knots: dict[int, np.ndarray] = {}
    out: list[Curve] = []
    for i in range(len(offsets) - 1):  # one curve per contour
        cp = xyz[offsets[i] : offsets[i + 1]]
        pieces = (len(cp) - 1) // degree
        if pieces not in knots:
            inner = np.repeat(np.arange(1, pieces), degree)
            ends = [0.0] * (degree + 1), [float(pieces)] * (degree + 1)
            knots[pieces] = frozen_array(np.concatenate([ends[0], inner, ends[1]]))
        out.append(NurbsCurve(cp, degree, knots[pieces]))
    return out
