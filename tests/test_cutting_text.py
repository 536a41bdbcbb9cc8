"""curves.text (nodes/curves/text.py, kernels/curves/text.py): glyph outlines as exact NURBS.

References: fontTools' own pen decomposition of the same glyphs (the implied on-curve
points), the font's hmtx and legacy kern tables read directly, shapely areas of densely
flattened outlines, and a CFF font built in the test with fontTools' FontBuilder.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from fontTools.pens.basePen import BasePen
from fontTools.ttLib import TTFont

import formgraph as fg
from formgraph.kernels.curves import regions
from formgraph.kernels.curves import text as ktext

SANS = ktext.bundled_font_path("DejaVu Sans")


def run(**inputs):
    g = fg.Graph()
    g.add("t", "curves.text", **inputs)
    return g.evaluate("t")


def dense(c: fg.NurbsCurve, n: int = 400) -> np.ndarray:
    return np.asarray(c.evaluate(np.linspace(*c.domain, n + 1)))[:-1, :2]


def signed(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def test_o_has_a_clockwise_hole_inside_a_counter_clockwise_outline():
    curves = run(text="o", size=10)
    assert len(curves) == 2
    assert all(c.closed and c.degree == 2 and not c.rational for c in curves)
    areas = sorted(signed(dense(c)) for c in curves)
    assert areas[0] < 0 < areas[1] and abs(areas[0]) < areas[1]
    hole = shapely.Polygon(dense(curves[int(np.argmin([signed(dense(c)) for c in curves]))]))
    outer = shapely.Polygon(dense(curves[int(np.argmax([signed(dense(c)) for c in curves]))]))
    assert outer.contains(hole)


@pytest.mark.parametrize("word", ["Bag", "8%", "formgraph", "ÆØé"])
def test_areas_match_shapely_on_the_flattened_outline(word):
    curves = run(text=word, size=20)
    rings = [dense(c, 2000) for c in curves]
    region = regions.even_odd_region(rings)
    # exact areas of the quadratic chains (Green's theorem) against shapely's flattening
    font = ktext.load_font(SANS.read_bytes())
    deg, pts, off, _ = ktext.layout(font, word, 20)
    exact = ktext._chain_area(pts, off, deg).sum()
    assert region.area == pytest.approx(exact, rel=2e-5)
    # and as outer CCW / holes CW: the signed areas add up to the region's area
    assert sum(signed(r) for r in rings) == pytest.approx(region.area, rel=1e-9)


class Segments(BasePen):
    """fontTools' decomposition of a TrueType glyph into quadratic pieces and lines."""

    def __init__(self, glyphset):
        super().__init__(glyphset)
        self.pieces: list[tuple] = []

    def _moveTo(self, p):
        self.start = self.last = p

    def _lineTo(self, p):
        self.pieces.append((self.last, p))
        self.last = p

    def _qCurveToOne(self, p1, p2):
        self.pieces.append((self.last, p1, p2))
        self.last = p2

    def _closePath(self):
        if self.last != self.start:  # the closing line is implied
            self._lineTo(self.start)


@pytest.mark.parametrize("char", ["o", "S", "%", "&", "é", "Q"])
def test_glyph_pieces_are_exactly_fonttools_quadratic_pieces(char):
    tt = TTFont(SANS)
    gs = tt.getGlyphSet()
    pen = Segments(gs)
    gs[tt.getBestCmap()[ord(char)]].draw(pen)
    upem = tt["head"].unitsPerEm
    curves = run(text=char, size=upem)  # one model unit per font unit
    ours = set()
    for c in curves:
        cp = np.asarray(c.control_points)[:, :2]
        for k in range(0, len(cp) - 1, 2):
            a, m, b = cp[k], cp[k + 1], cp[k + 2]
            ends = frozenset([tuple(np.round(a, 9)), tuple(np.round(b, 9))])
            straight = np.allclose(m, (a + b) / 2)
            ours.add((ends, None if straight else tuple(np.round(m, 9))))
    theirs = set()
    for piece in pen.pieces:
        ends = frozenset([tuple(np.round(piece[0], 9)), tuple(np.round(piece[-1], 9))])
        if len(piece) == 2 or np.allclose(piece[1], np.add(piece[0], piece[2]) / 2):
            theirs.add((ends, None))
        else:
            theirs.add((ends, tuple(np.round(piece[1], 9))))
    assert ours == theirs


def test_advances_and_kerning_follow_the_font_tables():
    tt = TTFont(SANS)
    upem = tt["head"].unitsPerEm
    cmap = tt.getBestCmap()
    a, v = cmap[ord("A")], cmap[ord("V")]
    legacy = {k: v for t in tt["kern"].kernTables for k, v in t.kernTable.items()}
    assert legacy[(a, v)] < 0  # DejaVu kerns AV: the test means something

    def min_x(curves):
        return min(float(np.asarray(c.control_points)[:, 0].min()) for c in curves)

    alone = run(text="V", size=upem)
    pair = run(text="AV", size=upem)
    n_a = len(run(text="A", size=upem))
    shift = min_x(pair[n_a:]) - min_x(alone)
    assert shift == pytest.approx(tt["hmtx"][a][0] + legacy[(a, v)], abs=1e-9)
    # without kerning between them, a space advances by its width alone
    spaced = run(text="A V", size=upem)
    space = tt["hmtx"][cmap[ord(" ")]][0]
    expect = tt["hmtx"][a][0] + space
    assert min_x(spaced[n_a:]) - min_x(alone) == pytest.approx(expect, abs=1e-9)


def test_alignment_lines_and_position():
    tt = TTFont(SANS)
    upem = tt["head"].unitsPerEm
    width = sum(tt["hmtx"][tt.getBestCmap()[ord(ch)]][0] for ch in "HI") / upem * 10
    left = run(text="HI", size=10)
    right = run(text="HI", size=10, align="right", position=[5, 1, 2])
    centre = run(text="HI", size=10, align="center")
    lx = np.concatenate([c.control_points for c in left])
    rx = np.concatenate([c.control_points for c in right])
    cx = np.concatenate([c.control_points for c in centre])
    np.testing.assert_allclose(rx - lx, np.broadcast_to([5 - width, 1, 2], lx.shape), atol=1e-9)
    np.testing.assert_allclose(cx[:, 0] - lx[:, 0], -width / 2, atol=1e-9)
    two = run(text="H\nH", size=10)
    h = tt["hhea"]
    drop = (h.ascent - h.descent + h.lineGap) / upem * 10
    y = [float(np.asarray(c.control_points)[:, 1].min()) for c in two]
    assert y[0] - y[1] == pytest.approx(drop)


def test_text_is_a_region_the_booleans_take():
    label = run(text="Ab", size=10)
    g = fg.Graph()
    g.add("u", "curves.boolean", a=label, b=[], operation="union")
    out = g.evaluate("u")
    holes = sum(signed(np.asarray(c.control_points)[:-1, :2]) < 0 for c in out)
    assert holes == 2  # the counters of A and b


def test_missing_glyphs_warn_and_bad_inputs_are_located():
    g = fg.Graph()
    g.add("t", "curves.text", text="a\u4e00")
    with pytest.warns(fg.FormgraphWarning, match="no glyph for '\u4e00'"):
        assert len(g.evaluate("t")) >= 2
    with pytest.raises(fg.NodeError, match=r"input 'font'.*bundled fonts are DejaVu Sans"):
        run(text="a", font="Comic Sans")
    with pytest.raises(fg.FormgraphError, match=r"'align'.*must be one of"):
        run(text="a", align="middle")
    assert run(text=" \n ") == []


def cff_font() -> bytes:
    """A one-glyph CFF font: a square ring (outer CCW and inner CW, cubic sides)."""
    from io import BytesIO

    from fontTools.fontBuilder import FontBuilder
    from fontTools.pens.t2CharStringPen import T2CharStringPen

    fb = FontBuilder(1000, isTTF=False)
    fb.setupGlyphOrder([".notdef", "o"])
    fb.setupCharacterMap({ord("o"): "o"})
    pen = T2CharStringPen(600, None)
    pen.moveTo((0, 0))
    pen.lineTo((500, 0))
    pen.curveTo((600, 250), (600, 450), (500, 700))
    pen.lineTo((0, 700))
    pen.closePath()
    pen.moveTo((100, 100))
    pen.lineTo((100, 600))
    pen.lineTo((400, 600))
    pen.lineTo((400, 100))
    pen.closePath()
    empty = T2CharStringPen(600, None)
    fb.setupCFF(
        "Test",
        {"FullName": "Test"},
        {"o": pen.getCharString(), ".notdef": empty.getCharString()},
        {},
    )
    fb.setupHorizontalMetrics({"o": (600, 0), ".notdef": (600, 0)})
    fb.setupHorizontalHeader(ascent=800, descent=-200)
    fb.setupNameTable({"familyName": "Test", "styleName": "Regular"})
    fb.setupOS2()
    fb.setupPost()
    out = BytesIO()
    fb.save(out)
    return out.getvalue()


def test_cff_outlines_are_exact_cubics_with_a_clockwise_hole():
    font = ktext.load_font(cff_font())
    deg, pts, off, missing = ktext.layout(font, "oo", 1000)
    assert deg == 3 and not missing and len(off) == 5
    area = ktext._chain_area(pts, off, 3)
    # outer: the 500 x 700 box plus the cubic's bulge past x = 500, int (x - 500) y' dt with
    # x - 500 = 300 t (1 - t) and y' = 3 (250 (1-t)^2 + 400 t (1-t) + 250 t^2): Beta integrals
    bulge = 900 * (250 / 20 + 400 / 30 + 250 / 20)
    assert area[0] == pytest.approx(500 * 700 + bulge)
    assert area[1] == pytest.approx(-300 * 500)
    assert pts[off[2], 0] - pts[off[0], 0] == pytest.approx(600)  # the advance
    curve = fg.NurbsCurve(
        np.c_[pts[off[0] : off[1]], np.zeros(off[1] - off[0])],
        3,
        np.concatenate([[0] * 4, np.repeat(np.arange(1, 4), 3), [4] * 4]),
    )
    assert curve.closed
    np.testing.assert_allclose(curve.evaluate(1.5)[:2], [575, 350])


def test_a_font_file_in_the_graphs_folder_is_read_confined_and_keyed(tmp_path):
    import shutil

    (tmp_path / "fonts").mkdir()
    shutil.copy(ktext.bundled_font_path("DejaVu Sans Bold"), tmp_path / "fonts" / "f.ttf")
    (tmp_path / "g.yaml").write_text(
        "formgraph: 1\n"
        "nodes:\n"
        "  bold: {type: curves.text, text: 'Wide', size: 10, font_file: fonts/f.ttf}\n"
        "  plain: {type: curves.text, text: 'Wide', size: 10}\n"
    )
    g = fg.load(tmp_path / "g.yaml", out_dir=tmp_path / "out")

    def width(curves):
        x = np.concatenate([np.asarray(c.control_points)[:, 0] for c in curves])
        return x.max() - x.min()

    bold, plain = g.evaluate("bold"), g.evaluate("plain")
    assert width(bold) > width(plain) * 1.05  # DejaVu Sans Bold is wider
    # the file's bytes key the node: another font under the same name recomputes it
    (tmp_path / "fonts" / "f.ttf").write_bytes(cff_font())
    g2 = fg.load(tmp_path / "g.yaml", out_dir=tmp_path / "out")
    assert g2.evaluate("bold") != bold
    cubic = g2.evaluate("bold")
    assert all(c.degree == 3 for c in cubic)  # the CFF font's cubics (its .notdef for "Wide")
    # a path out of the graph's folder is refused when the graph is loaded
    (tmp_path / "out.yaml").write_text(
        "formgraph: 1\nnodes:\n  t: {type: curves.text, text: a, font_file: ../f.ttf}\n"
    )
    with pytest.raises(fg.GraphError, match=r"input 'font_file'.*leaves the inputs folder"):
        fg.load(tmp_path / "out.yaml")


def test_a_font_file_must_be_a_font(tmp_path):
    (tmp_path / "bad.ttf").write_bytes(b"not a font")
    (tmp_path / "notes.txt").write_text("x")
    (tmp_path / "g.yaml").write_text(
        "formgraph: 1\n"
        "nodes:\n"
        "  a: {type: curves.text, text: 'a', font_file: bad.ttf}\n"
        "  b: {type: curves.text, text: 'a', font_file: notes.txt}\n"
    )
    g = fg.load(tmp_path / "g.yaml")
    with pytest.raises(fg.NodeError, match=r"input 'font_file'.*'bad.ttf': cannot read the font"):
        g.evaluate("a")
    with pytest.raises(fg.NodeError, match=r"input 'font_file'.*a \.ttf or \.otf"):
        g.evaluate("b")


@pytest.mark.parametrize("name", ["DejaVu Sans", "DejaVu Serif"])
def test_gpos_kerning_agrees_with_the_legacy_kern_table_on_every_pair(name):
    path = ktext.bundled_font_path(name)
    tt = TTFont(path)
    legacy = {k: v for t in tt["kern"].kernTables for k, v in t.kernTable.items()}
    assert len(legacy) > 100
    font = ktext.load_font(path.read_bytes())
    pairs = list(legacy)
    ours = font.kerning([p[0] for p in pairs], [p[1] for p in pairs])
    np.testing.assert_array_equal(ours, [legacy[p] for p in pairs])
