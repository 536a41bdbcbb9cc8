"""Text as exact outlines: a font's glyphs as NURBS, laid out by its advances and kerning.

A TrueType glyph is a list of contours of on- and off-curve points; between two off-curve
points lies an implied on-curve point halfway (the TrueType Reference Manual, "Digitizing
letterform designs"). With the implied points inserted and every straight segment given a
middle point halfway, a contour is a chain of quadratic Beziers, written exactly as one
closed degree-2 NURBS (the pieces joined by double knots, knots at the integers). CFF
(PostScript) outlines are cubic: their charstrings are a small program only an interpreter
runs, so they come through fontTools' pen protocol, lines raised to cubics exactly, as one
closed degree-3 NURBS per contour.

Holes: fonts fill by the nonzero rule with outer contours one way round (clockwise in
TrueType, counter-clockwise in CFF) and holes the other; each glyph is turned so its
largest contour (by the exact area of its Bezier chain) runs counter-clockwise, so outer
boundaries are counter-clockwise and holes clockwise, as the region nodes give them.

Layout: each glyph advances by its ``hmtx`` width plus the kerning of the pair (the GPOS
``kern`` feature's pair adjustments, formats 1 and 2, else the legacy ``kern`` table);
lines are ``ascender - descender + lineGap`` apart (``hhea``); a line is aligned left,
centre or right on the origin. fontTools parses the binary tables; everything after the
parse is numpy, each distinct glyph converted once per font.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import io
import math
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["ALIGNS", "BUNDLED", "Font", "GlyphOutline", "bundled_font_path", "layout", "load_font"]

ALIGNS = ("left", "center", "right")

# Fonts that ship inside matplotlib (a dependency of pyvista): DejaVu, free to embed and use
BUNDLED = {
    "DejaVu Sans": "DejaVuSans.ttf",
    "DejaVu Sans Bold": "DejaVuSans-Bold.ttf",
    "DejaVu Sans Oblique": "DejaVuSans-Oblique.ttf",
    "DejaVu Sans Bold Oblique": "DejaVuSans-BoldOblique.ttf",
    "DejaVu Sans Mono": "DejaVuSansMono.ttf",
    "DejaVu Sans Mono Bold": "DejaVuSansMono-Bold.ttf",
    "DejaVu Serif": "DejaVuSerif.ttf",
    "DejaVu Serif Bold": "DejaVuSerif-Bold.ttf",
    "DejaVu Serif Italic": "DejaVuSerif-Italic.ttf",
}


def bundled_font_path(name: str) -> Path:
    """The file of a font that ships with matplotlib, found without importing matplotlib."""
    if name not in BUNDLED:
        raise ValueError(
            f"no bundled font {name!r}: the bundled fonts are {', '.join(BUNDLED)}; or give "
            "the path of a .ttf or .otf file in the graph's folder"
        )
    spec = importlib.util.find_spec("matplotlib")
    if spec is None or not spec.submodule_search_locations:
        raise ValueError("the bundled fonts come with matplotlib, which is not installed")
    root = Path(list(spec.submodule_search_locations)[0])
    return root / "mpl-data" / "fonts" / "ttf" / BUNDLED[name]


@dataclass(frozen=True)
class GlyphOutline:
    """A glyph's contours in font units: contour i is the closed Bezier chain
    ``points[offsets[i]:offsets[i + 1]]`` (start, then ``degree`` points per piece, back to
    the start)."""

    degree: int
    points: np.ndarray  # (m, 2) float
    offsets: np.ndarray  # (c + 1,) int


@dataclass
class Font:
    """A parsed font: metrics, character map, kerning and a cache of converted glyphs."""

    ttfont: object
    units_per_em: int
    line_height: int
    cubic: bool
    cmap: dict[int, str]
    advances: dict[str, int]
    pairs: dict[tuple[str, str], int]
    classes: list[tuple[dict[str, int], dict[str, int], np.ndarray, set[str]]]
    glyphs: dict[str, GlyphOutline] = field(default_factory=dict)

    def kerning(self, left: list[str], right: list[str]) -> np.ndarray:
        """The kerning (font units) of each pair (left[i], right[i])."""
        out = np.zeros(len(left))
        for i, pair in enumerate(zip(left, right, strict=True)):  # one step per character
            if pair in self.pairs:
                out[i] = self.pairs[pair]
                continue
            for class1, class2, values, coverage in self.classes:
                if pair[0] in coverage:
                    out[i] = values[class1.get(pair[0], 0), class2.get(pair[1], 0)]
                    break
        return out

    def outline(self, name: str) -> GlyphOutline:
        if name not in self.glyphs:
            self.glyphs[name] = _cff_outline(self, name) if self.cubic else _tt_outline(self, name)
        return self.glyphs[name]


@functools.lru_cache(maxsize=8)
def _parse(digest: str, data: bytes) -> Font:
    from fontTools.ttLib import TTFont, TTLibError

    try:
        tt = TTFont(io.BytesIO(data), lazy=True)
        cubic = "CFF " in tt or "CFF2" in tt
        if not cubic and "glyf" not in tt:
            raise ValueError("the font has neither TrueType (glyf) nor CFF outlines")
        hhea = tt["hhea"]
        cmap = tt.getBestCmap() or {}
        advances = {g: int(m[0]) for g, m in tt["hmtx"].metrics.items()}
        pairs, classes = _gpos_kerning(tt)
        if not pairs and not classes and "kern" in tt:
            for table in tt["kern"].kernTables:
                if getattr(table, "format", None) == 0:
                    pairs.update({k: int(v) for k, v in table.kernTable.items()})
        return Font(
            tt,
            int(tt["head"].unitsPerEm),
            int(hhea.ascent - hhea.descent + hhea.lineGap),
            cubic,
            dict(cmap),
            advances,
            pairs,
            classes,
        )
    except (TTLibError, KeyError, AssertionError, IndexError, TypeError, struct.error) as exc:
        raise ValueError(f"cannot read the font: {exc}") from None


def load_font(data: bytes) -> Font:
    """A parsed font from the bytes of a TTF or OTF file (cached by content)."""
    return _parse(hashlib.sha256(data).hexdigest(), data)


def _gpos_kerning(tt) -> tuple[dict, list]:
    """Pair adjustments (x advance of the first glyph) of the GPOS ``kern`` feature."""
    pairs: dict[tuple[str, str], int] = {}
    classes: list = []
    if "GPOS" not in tt:
        return pairs, classes
    table = tt["GPOS"].table
    if table.FeatureList is None or table.LookupList is None:
        return pairs, classes
    indices = sorted(
        {
            i
            for rec in table.FeatureList.FeatureRecord
            if rec.FeatureTag == "kern"
            for i in rec.Feature.LookupListIndex
        }
    )
    for li in indices:  # a few lookups, a few subtables each
        lookup = table.LookupList.Lookup[li]
        for sub in lookup.SubTable:
            if lookup.LookupType == 9:
                sub = sub.ExtSubTable
            if getattr(sub, "LookupType", 2) != 2 and lookup.LookupType != 9:
                continue
            if not hasattr(sub, "Format") or not hasattr(sub, "Coverage"):
                continue
            first = sub.Coverage.glyphs
            if sub.Format == 1:
                for g1, pset in zip(first, sub.PairSet, strict=False):
                    for rec in pset.PairValueRecord:
                        x = getattr(rec.Value1, "XAdvance", 0) if rec.Value1 else 0
                        if x:
                            pairs.setdefault((g1, rec.SecondGlyph), int(x))
            elif sub.Format == 2:
                values = np.array(
                    [
                        [
                            getattr(c2.Value1, "XAdvance", 0) if c2.Value1 else 0
                            for c2 in c1.Class2Record
                        ]
                        for c1 in sub.Class1Record
                    ],
                    dtype=np.float64,
                )
                classes.append(
                    (
                        dict(sub.ClassDef1.classDefs),
                        dict(sub.ClassDef2.classDefs),
                        values,
                        set(first),
                    )
                )
    return pairs, classes


def _chain_area(points: np.ndarray, offsets: np.ndarray, degree: int) -> np.ndarray:
    """Exact signed area of each closed Bezier chain (Green's theorem on the power form:
    for x = sum a_i t^i, y = sum b_j t^j, 1/2 int x y' - y x' = 1/2 sum a_i b_j (j - i)/(i + j))."""
    from .sampling import _power_matrix

    p = degree
    starts = offsets[:-1]
    pieces = (np.diff(offsets) - 1) // p
    seg_start = np.repeat(starts, pieces) + p * (
        np.arange(pieces.sum()) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    )
    idx = seg_start[:, None] + np.arange(p + 1)
    bez = points[idx]  # (s, p + 1, 2)
    coef = np.einsum("ij,sic->sjc", _power_matrix(p), bez)
    i = np.arange(p + 1)
    ii, jj = np.meshgrid(i, i, indexing="ij")
    w = np.where(ii + jj > 0, (jj - ii) / np.maximum(ii + jj, 1), 0.0)
    seg_area = 0.5 * np.einsum("si,ij,sj->s", coef[:, :, 0], w, coef[:, :, 1])
    return np.bincount(np.repeat(np.arange(len(pieces)), pieces), seg_area, len(pieces))


def _oriented(degree: int, points: np.ndarray, offsets: np.ndarray) -> GlyphOutline:
    """The outline turned so that its largest contour runs counter-clockwise."""
    if len(offsets) > 1:
        area = _chain_area(points, offsets, degree)
        if area[np.argmax(np.abs(area))] < 0:
            ring = np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))
            # reverse every contour in place: index from each contour's end backwards
            local = np.arange(len(points)) - offsets[ring]
            points = points[offsets[ring + 1] - 1 - local]
    points.flags.writeable = False
    return GlyphOutline(degree, points, np.asarray(offsets))


def _tt_outline(font: Font, name: str) -> GlyphOutline:
    """A TrueType glyph's contours as closed quadratic Bezier chains (vectorized)."""
    glyf = font.ttfont["glyf"]  # type: ignore[index]
    coords, ends, flags = glyf[name].getCoordinates(glyf)
    xy = np.asarray(coords, dtype=np.float64).reshape(-1, 2)
    if len(xy) == 0:
        return GlyphOutline(2, np.zeros((0, 2)), np.zeros(1, dtype=np.int64))
    on = (np.frombuffer(bytes(flags), dtype=np.uint8) & 1).astype(bool)
    ends = np.asarray(ends, dtype=np.int64)
    starts = np.concatenate([[0], ends[:-1] + 1])
    sizes = ends - starts + 1
    contour = np.repeat(np.arange(len(ends)), sizes)
    nxt = np.arange(len(xy)) + 1
    nxt[ends] = starts  # cyclic successor within the contour
    # between two points of the same kind goes a point halfway, of the other kind: between
    # two off-curve points the implied on-curve point, between two on-curve points the
    # middle control point of a straight piece
    mid_needed = on == on[nxt]
    mids = 0.5 * (xy + xy[nxt])
    # sequence per contour: each point, then its midpoint when needed
    count = 1 + mid_needed.astype(np.int64)
    seq = np.repeat(np.arange(len(xy)), count)
    is_mid = np.zeros(len(seq), dtype=bool)
    first_of = np.cumsum(count) - count
    is_mid[first_of[mid_needed] + 1] = True
    pts = np.where(is_mid[:, None], mids[seq], xy[seq])
    kind_on = np.where(is_mid, ~on[seq], on[seq])
    seq_contour = contour[seq]
    keep = sizes[seq_contour] > 1  # a contour of one point draws nothing
    pts, kind_on, seq_contour = pts[keep], kind_on[keep], seq_contour[keep]
    # rotate each contour to start on an on-curve point, then close it with that point
    out_sizes = np.bincount(seq_contour, minlength=len(ends))
    present = np.flatnonzero(out_sizes)
    out_start = np.concatenate([[0], np.cumsum(out_sizes)[:-1]])
    local = np.arange(len(pts)) - out_start[seq_contour]
    on_idx = np.flatnonzero(kind_on)  # every contour has one now
    first_on = out_sizes.copy()  # larger than any index in its contour
    np.minimum.at(first_on, seq_contour[on_idx], local[on_idx])
    shift = first_on[seq_contour]
    rolled = out_start[seq_contour] + (local + shift) % out_sizes[seq_contour]
    pts = pts[rolled]
    # close: append each contour's first point after its last
    sizes2 = out_sizes[present]
    starts2 = out_start[present]
    total = sizes2 + 1
    idx = np.repeat(starts2, total) + (
        np.arange(total.sum()) - np.repeat(np.cumsum(total) - total, total)
    ) % np.repeat(sizes2, total)
    offsets = np.concatenate([[0], np.cumsum(total)])
    return _oriented(2, pts[idx], offsets)


def _cff_outline(font: Font, name: str) -> GlyphOutline:
    """A CFF glyph's contours as closed cubic Bezier chains, through fontTools' pens."""
    from fontTools.pens.basePen import BasePen

    class Chains(BasePen):
        def __init__(self, glyphset):
            super().__init__(glyphset)
            self.contours: list[list[tuple[float, float]]] = []

        def _moveTo(self, p):
            self.contours.append([p])

        def _lineTo(self, p):
            a = self.contours[-1][-1]
            self.contours[-1] += [
                (a[0] + (p[0] - a[0]) / 3, a[1] + (p[1] - a[1]) / 3),
                (a[0] + 2 * (p[0] - a[0]) / 3, a[1] + 2 * (p[1] - a[1]) / 3),
                p,
            ]

        def _curveToOne(self, p1, p2, p3):
            self.contours[-1] += [p1, p2, p3]

        def _closePath(self):
            c = self.contours[-1]
            if c[-1] != c[0]:
                self._lineTo(c[0])

        _endPath = _closePath

    glyphset = font.ttfont.getGlyphSet()  # type: ignore[attr-defined]
    pen = Chains(glyphset)
    glyphset[name].draw(pen)
    contours = [c for c in pen.contours if len(c) >= 4]
    if not contours:
        return GlyphOutline(3, np.zeros((0, 2)), np.zeros(1, dtype=np.int64))
    pts = np.concatenate([np.asarray(c, dtype=np.float64) for c in contours])
    offsets = np.concatenate([[0], np.cumsum([len(c) for c in contours])])
    return _oriented(3, pts, offsets)


def layout(
    font: Font, text: str, size: float, align: str = "left"
) -> tuple[int, np.ndarray, np.ndarray, list[str]]:
    """The outlines of ``text`` set in ``font`` at em size ``size``, the first baseline at y=0.

    Parameters
    ----------
    font : Font
    text : str
        Lines separated by newlines.
    size : float
        The em size in model units (> 0).
    align : {"left", "center", "right"}
        Where each line sits on x = 0: its start, its middle or its end (by advances).

    Returns
    -------
    degree : int
        2 (TrueType) or 3 (CFF).
    points : (m, 2) float
        Every contour's closed Bezier chain, contour after contour.
    offsets : (c + 1,) int
        Contour i is ``points[offsets[i]:offsets[i + 1]]``.
    missing : list of str
        Characters the font has no glyph for (drawn as its .notdef box).
    """
    if align not in ALIGNS:
        raise ValueError(f"align must be one of {', '.join(ALIGNS)}; got {align!r}")
    if not (math.isfinite(size) and size > 0):
        raise ValueError(f"size must be a positive number, got {size!r}")
    scale = size / font.units_per_em
    missing: list[str] = []
    chunks_p: list[np.ndarray] = []
    chunks_o: list[np.ndarray] = []
    base = 0
    degree = 3 if font.cubic else 2
    for row, line in enumerate(text.split("\n")):  # one step per line
        names = []
        for ch in line:  # one step per character: a dictionary look-up
            g = font.cmap.get(ord(ch))
            if g is None:
                if not ch.isspace() and ch not in missing:
                    missing.append(ch)
                g = ".notdef"
            names.append(g)
        if not names:
            continue
        adv = np.array([font.advances.get(g, 0) for g in names], dtype=np.float64)
        adv[:-1] += font.kerning(names[:-1], names[1:])
        x = np.concatenate([[0.0], np.cumsum(adv)[:-1]])
        width = float(adv.sum())
        x0 = {"left": 0.0, "center": -width / 2, "right": -width}[align]
        y = -row * font.line_height
        outlines = {g: font.outline(g) for g in dict.fromkeys(names)}
        for g, gx in zip(names, x, strict=True):  # one step per character: array copies
            o = outlines[g]
            if len(o.offsets) < 2:
                continue
            chunks_p.append(o.points + (gx + x0, y))
            chunks_o.append(o.offsets[1:] + base)
            base += len(o.points)
    if not chunks_p:
        return degree, np.zeros((0, 2)), np.zeros(1, dtype=np.int64), missing
    points = np.concatenate(chunks_p) * scale
    offsets = np.concatenate([[0], *chunks_o])
    return degree, points, offsets, missing
