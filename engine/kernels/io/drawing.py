"""2-D drawings of the XY plane as SVG and PDF bytes, for laser cutters, plotters and print.

A drawing is a list of :class:`Path2D`: polylines, chains of cubic Beziers (exact, as
``C`` commands / ``c`` operators), or chains of circular arcs (exact ``A`` commands in SVG;
PDF has no arc operator, so there each arc becomes cubic Beziers within 1e-7 of the radius).

The PDF is written by these few lines of our own — a catalog, one page, one content stream
with ``m``/``l``/``c``/``h``/``S`` operators and an xref table of byte offsets — because a
drawing of strokes needs nothing more and no PDF library is then a dependency.
"""

from __future__ import annotations

import re
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .colors import PALETTE, css_color, rgb
from .numfmt import float_words, squeeze

__all__ = ["Path2D", "drawing_bounds", "layer_styles", "pdf_bytes", "svg_bytes"]

KINDS = ("polyline", "cubic", "arc")
UNITS_MM = {"mm": 1.0, "cm": 10.0, "in": 25.4, "pt": 25.4 / 72.0, "px": 25.4 / 96.0}
_ARC_TOL = 1e-9
_LAYER_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.-]*")  # an XML name: an SVG id, a PDF name


def layer_styles(layers: Sequence[str], colors: Mapping[str, str] | None = None) -> dict[str, str]:
    """Each layer's stroke colour (``#rrggbb``), in order of first use.

    ``colors`` gives some or all of them (CSS colours); the others take red, blue, green,
    magenta, cyan, yellow in turn by their position.

    Raises
    ------
    ValueError
        A layer name that is not an XML name (a letter or ``_``, then letters, digits,
        ``_ . -``: it becomes an SVG id), or a colour CSS does not know.
    """
    order = list(dict.fromkeys(layers))
    for name in order:
        if not isinstance(name, str) or not _LAYER_NAME.fullmatch(name):
            raise ValueError(
                f"layer {name!r}: a drawing layer's name starts with a letter or _ and has only "
                "letters, digits, _ . and - (it becomes the SVG group's id)"
            )
    given = {k: css_color(v) for k, v in (colors or {}).items()}
    return {n: given.get(n, PALETTE[i % len(PALETTE)]) for i, n in enumerate(order)}


@dataclass(frozen=True)
class Path2D:
    """One stroke of a drawing.

    Attributes
    ----------
    kind : {"polyline", "cubic", "arc"}
        ``polyline``: points (n >= 2, 2), straight segments. ``cubic``: points (3k+1, 2), the
        start then (control, control, end) per Bezier segment. ``arc``: points (2k+1, 2), the
        start then (corner, end) per circular arc of less than 180 degrees, the corner being
        where the tangents at its ends meet (the control polygon of a rational quadratic
        circular arc); collinear pieces are straight segments.
    points : (n, 2) float64
    closed : bool
        Close the path back to its first point.
    """

    kind: str
    points: np.ndarray
    closed: bool = False

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"path kind must be one of {', '.join(KINDS)}; got {self.kind!r}")
        p = np.array(self.points, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 2:
            raise ValueError(f"path points must be an (n, 2) array, got shape {p.shape}")
        if not np.all(np.isfinite(p)):
            raise ValueError("path points must be finite; found NaN or infinity")
        n = len(p)
        if self.kind == "polyline" and n < 2:
            raise ValueError(f"a polyline needs at least 2 points, got {n}")
        if self.kind == "cubic" and (n < 4 or (n - 1) % 3):
            raise ValueError(f"a cubic Bezier chain needs 3k+1 points (k >= 1), got {n}")
        if self.kind == "arc":
            if n < 3 or (n - 1) % 2:
                raise ValueError(f"an arc chain needs 2k+1 points (k >= 1), got {n}")
            t0 = np.linalg.norm(p[1:-1:2] - p[:-2:2], axis=1)
            t1 = np.linalg.norm(p[2::2] - p[1:-1:2], axis=1)
            scale = np.maximum(np.maximum(t0, t1), 1e-300)
            bad = np.abs(t0 - t1) > _ARC_TOL * scale
            if np.any(bad):
                k = int(np.argmax(bad))
                raise ValueError(
                    f"arc piece {k} is not circular: its corner is {t0[k]:.6g} from the start "
                    f"and {t1[k]:.6g} from the end (a circular arc's tangents are equal)"
                )
        p.flags.writeable = False
        object.__setattr__(self, "points", p)


def _arc_geometry(p: np.ndarray) -> tuple[np.ndarray, ...]:
    """Centre, radius, start angle and signed sweep of each arc piece of a chain ``p``.

    With tangent length t = |P1 - P0| and half chord c = |P2 - P0| / 2, the half sweep a has
    cos a = c / t, the radius is r = t / tan a, and the centre lies on the line from the
    corner P1 through the chord's midpoint M at C = P1 + (M - P1) / sin(a)**2.
    Straight (collinear) pieces get radius 0.
    """
    p0, p1, p2 = p[:-2:2], p[1:-1:2], p[2::2]
    t = np.linalg.norm(p1 - p0, axis=1)
    c = 0.5 * np.linalg.norm(p2 - p0, axis=1)
    d1, d2 = p1 - p0, p2 - p1
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    straight = np.abs(cross) <= 1e-12 * np.maximum(t * t, 1e-300)
    cos_a = np.clip(np.where(straight, 1.0, c / np.maximum(t, 1e-300)), -1.0, 1.0)
    sin_a = np.sqrt(1.0 - cos_a**2)
    safe_sin = np.where(straight, 1.0, sin_a)
    radius = np.where(straight, 0.0, t * cos_a / safe_sin)
    mid = 0.5 * (p0 + p2)
    centre = p1 + (mid - p1) / (safe_sin**2)[:, None]
    start = np.arctan2(p0[:, 1] - centre[:, 1], p0[:, 0] - centre[:, 0])
    sweep = np.where(straight, 0.0, np.sign(cross) * 2.0 * np.arccos(cos_a))
    return centre, radius, start, sweep, straight


def _cubic_extrema(q: np.ndarray) -> np.ndarray:
    """Points where a cubic chain's x or y is extreme inside a segment (for tight bounds).

    Per segment and axis, B'(t) / 3 = a t^2 + b t + c with a = -P0 + 3P1 - 3P2 + P3,
    b = 2(P0 - 2P1 + P2), c = P1 - P0; its roots in (0, 1) are the candidates.
    """
    p0, p1, p2, p3 = q[:-3:3], q[1:-2:3], q[2:-1:3], q[3::3]
    a = -p0 + 3 * p1 - 3 * p2 + p3
    b = 2 * (p0 - 2 * p1 + p2)
    c = p1 - p0
    disc = b * b - 4 * a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        quad = np.abs(a) > 1e-12 * (np.abs(b) + np.abs(c) + 1e-300)
        r1 = np.where(quad, (-b + sq) / (2 * a), -c / b)
        r2 = np.where(quad, (-b - sq) / (2 * a), -c / b)
    ts = np.concatenate([r1, r2], axis=1)  # (segments, 4): two roots per axis
    ok = np.isfinite(ts) & (ts > 0) & (ts < 1) & (np.concatenate([disc, disc], axis=1) >= 0)
    seg = np.repeat(np.arange(len(p0)), 4).reshape(-1, 4)[ok]
    t = ts[ok][:, None]
    s = 1 - t
    return s**3 * p0[seg] + 3 * s * s * t * p1[seg] + 3 * s * t * t * p2[seg] + t**3 * p3[seg]


def _arc_extrema(p: np.ndarray) -> np.ndarray:
    """Points where an arc chain reaches an axis direction (0, 90, 180, 270 degrees)."""
    centre, radius, start, sweep, straight = _arc_geometry(p)
    k = np.arange(-8, 9) * (np.pi / 2)  # axis angles around the start
    lo = np.minimum(start, start + sweep)[:, None]
    hi = np.maximum(start, start + sweep)[:, None]
    inside = (k[None, :] > lo) & (k[None, :] < hi) & ~straight[:, None]
    piece, which = np.nonzero(inside)
    ang = k[which]
    return centre[piece] + radius[piece, None] * np.stack([np.cos(ang), np.sin(ang)], axis=1)


def drawing_bounds(paths: Sequence[Path2D]) -> tuple[np.ndarray, np.ndarray]:
    """Tight axis-aligned bounds (min (2,), max (2,)) of what the paths draw."""
    if not paths:
        raise ValueError("a drawing needs at least one path, got none")
    pts = []
    for path in paths:  # one iteration per curve
        p = path.points
        if path.kind == "polyline":
            pts.append(p)
        elif path.kind == "cubic":
            pts += [p[::3], _cubic_extrema(p)]
        else:
            pts += [p[::2], _arc_extrema(p)]
    allp = np.concatenate(pts)
    return allp.min(axis=0), allp.max(axis=0)


def _numbers(values: np.ndarray, decimals: int, lead: bytes = b" ") -> np.ndarray:
    """Rows of words with each value's text (rounded to ``decimals``) after ``lead``."""
    return float_words(np.asarray(values, dtype=np.float64).ravel(), decimals=decimals, lead=lead)


# --------------------------------------------------------------------------------------------
# SVG


def svg_bytes(
    paths: Sequence[Path2D],
    units: str = "mm",
    margin: float = 1.0,
    stroke_width: float = 0.1,
    decimals: int = 6,
    layers: Sequence[str] | None = None,
    colors: Mapping[str, str] | None = None,
) -> bytes:
    """An SVG drawing of the paths: one ``<path>`` each, exact Beziers and arcs.

    Coordinates are in ``units`` (one SVG user unit is one ``units``), the ``viewBox`` fits
    the drawing's tight bounds plus ``margin``, and y is flipped so +y points up as in the
    model. Strokes are unfilled, ``stroke_width`` wide, black — or, with ``layers``, one
    ``<g id=NAME>`` group per layer (also an Inkscape layer) stroked in its colour, the
    paths of each layer in their order, the layers in order of first use.

    Parameters
    ----------
    paths : sequence of Path2D
    units : {"mm", "cm", "in", "pt", "px"}
    margin : float
        Space around the drawing, in ``units``; >= 0.
    stroke_width : float
        Line width in ``units``; > 0.
    decimals : int
        Decimal places of every coordinate (6 in mm is a nanometre).
    layers : sequence of str, optional
        The layer of each path (see :func:`layer_styles` for the names).
    colors : mapping of layer -> CSS colour, optional
        Stroke colours; layers not named take the default palette.

    Returns
    -------
    bytes
        UTF-8 XML.
    """
    if units not in UNITS_MM:
        raise ValueError(f"units must be one of {', '.join(UNITS_MM)}; got {units!r}")
    if not margin >= 0 or not stroke_width > 0:
        raise ValueError(
            f"margin must be >= 0 and stroke_width > 0, got {margin} and {stroke_width}"
        )
    lo, hi = drawing_bounds(paths)
    size = np.maximum(hi - lo + 2 * margin, stroke_width)
    x0, y0 = lo[0] - margin, -(hi[1] + margin)  # the viewBox's top left, y flipped

    def fmt(values: Sequence[float]) -> str:
        return squeeze(_numbers(np.array(values), decimals, b" ").view(np.uint8)).decode()[1:]

    if layers is not None and len(layers) != len(paths):
        raise ValueError(f"{len(paths)} paths but {len(layers)} layer names")
    styles = layer_styles(layers, colors) if layers is not None else None
    inkscape = ' xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"' if styles else ""
    head = (
        '<?xml version="1.0" encoding="UTF-8" standalone="no"?>\n'
        f'<svg xmlns="http://www.w3.org/2000/svg"{inkscape} version="1.1" '
        f'width="{fmt([size[0]])}{units}" height="{fmt([size[1]])}{units}" '
        f'viewBox="{fmt([x0, y0, size[0], size[1]])}">\n'
    ).encode()
    style = (
        f'fill="none" stroke-width="{fmt([stroke_width])}" '
        'stroke-linecap="round" stroke-linejoin="round"'
    )
    body = _svg_paths(paths, decimals)
    lines = [head]
    if styles is None:
        lines += [f'<g {style} stroke="#000000">\n'.encode(), *body, b"</g>\n"]
    else:
        assert layers is not None
        # one top-level group per layer: what Inkscape takes as a layer (a nested one would
        # be a sub-layer) and what readers list as the drawing's layers
        for name, color in styles.items():
            lines.append(
                f'<g id="{name}" inkscape:groupmode="layer" inkscape:label="{name}" '
                f'{style} stroke="{color}">\n'.encode()
            )
            lines += [b for b, layer in zip(body, layers, strict=True) if layer == name]
            lines.append(b"</g>\n")
    lines.append(b"</svg>\n")
    return b"".join(lines)


def _svg_items(path: Path2D) -> list[tuple[bytes, np.ndarray]]:
    """The path data of one path as (command, (k, m) numbers) in order."""
    q = path.points * np.array([1.0, -1.0])
    if path.kind == "polyline":
        items = [(b"M", q[:1]), (b" L", q[1:])]
    elif path.kind == "cubic":
        items = [(b"M", q[:1]), (b" C", q[1:])]
    else:
        _, radius, _, sweep, straight = _arc_geometry(path.points)
        # Flipping y mirrors every arc, so a counter-clockwise arc of the model runs the
        # negative-angle way in the page's coordinates: sweep-flag 0 (SVG 1.1, F.6.5, where
        # flag 1 means increasing angle in user space). Every piece is under 180 degrees.
        k = len(radius)
        cols = [radius, radius, np.zeros(k), np.zeros(k), (sweep < 0) * 1.0]
        args = np.column_stack(cols + [q[2::2, 0], q[2::2, 1]])
        items = [(b"M", q[:1])]
        # straight pieces (a rounded rectangle's sides) as L: an arc of radius 0 is a line in
        # the SVG spec (F.6.2) but not in every reader; runs of each kind share a command
        cuts = np.flatnonzero(np.diff(straight.astype(np.int8))) + 1
        for run in np.split(np.arange(k), cuts):  # alternating runs: a handful
            if straight[run[0]]:
                items.append((b" L", args[run, 5:]))
            else:
                items.append((b" A", args[run]))
    if path.closed:
        items.append((b" Z", np.zeros((0, 1))))
    return items


def _svg_paths(paths: Sequence[Path2D], decimals: int) -> list[bytes]:
    """Every ``<path d=...>`` element, one per path (each ends in a newline).

    The numbers of all paths are formatted in one call and all the elements squeezed out of
    one canvas of words, so a drawing of many small curves (text) costs what its numbers
    cost, not a fixed overhead per curve.
    """
    items = [_svg_items(path) for path in paths]
    flat = [v for its in items for _, v in its]
    values = np.concatenate([v.ravel() for v in flat]) if flat else np.zeros(0)
    rows = _numbers(values, decimals)
    width = max(rows.shape[1], 2)
    if rows.shape[1] < width:
        rows = np.pad(rows, ((0, 0), (0, width - rows.shape[1])))
    words: dict[bytes, np.ndarray] = {}

    def text(t: bytes) -> np.ndarray:  # a short text as one row of words
        if t not in words:
            row = np.zeros(width * 8, dtype=np.uint8)
            row[: len(t)] = np.frombuffer(t, dtype=np.uint8)
            words[t] = row.view(np.uint64)[None, :]
        return words[t]

    blocks: list[np.ndarray] = []
    at = 0
    for its in items:  # one step per path, a handful of commands each
        blocks.append(text(b'<path d="'))
        for letter, v in its:
            blocks.append(text(letter))
            blocks.append(rows[at : at + v.size])
            at += v.size
        blocks.append(text(b'"/>\n'))
    return [
        line + b"\n" for line in squeeze(np.concatenate(blocks).view(np.uint8)).split(b"\n")[:-1]
    ]


# --------------------------------------------------------------------------------------------
# PDF


def _arc_cubics(p: np.ndarray) -> np.ndarray:
    """An arc chain as a cubic Bezier chain (3k+1, 2), each cubic spanning at most 22.5 deg.

    Handle length (4/3) tan(phi / 4) r per cubic of angle phi; the radial error is below
    1e-7 r at 22.5 degrees. Straight pieces become straight cubics.
    """
    centre, radius, start, sweep, straight = _arc_geometry(p)
    n_sub = int(max(1, np.ceil(np.abs(sweep).max(initial=0.0) / np.radians(22.5))))
    j = np.arange(n_sub + 1) / n_sub
    ang = start[:, None] + sweep[:, None] * j[None, :]  # (pieces, n_sub + 1)
    ends = centre[:, None, :] + radius[:, None, None] * np.stack([np.cos(ang), np.sin(ang)], -1)
    # straight pieces: points along the chord instead
    p0, p2 = p[:-2:2], p[2::2]
    chord = p0[:, None, :] + (p2 - p0)[:, None, :] * j[None, :, None]
    ends = np.where(straight[:, None, None], chord, ends)
    ends[:, 0], ends[:, -1] = p0, p2  # exact end points
    h = (4.0 / 3.0) * np.tan(sweep / (4 * n_sub)) * radius  # signed handle length
    tangent = np.stack([-np.sin(ang), np.cos(ang)], -1) * h[:, None, None]
    tangent = np.where(straight[:, None, None], (p2 - p0)[:, None, :] / (3 * n_sub), tangent)
    c1 = ends[:, :-1] + tangent[:, :-1]
    c2 = ends[:, 1:] - tangent[:, 1:]
    seg = np.stack([c1, c2, ends[:, 1:]], axis=2).reshape(-1, 3, 2)
    return np.concatenate([p[:1], seg.reshape(-1, 2)])


def pdf_bytes(
    paths: Sequence[Path2D],
    units: str = "mm",
    margin: float = 1.0,
    stroke_width: float = 0.1,
    compress: bool = True,
    layers: Sequence[str] | None = None,
    colors: Mapping[str, str] | None = None,
) -> bytes:
    """A one-page PDF drawing of the paths, at true scale.

    The page (MediaBox, in points) fits the drawing's tight bounds plus ``margin``; one
    drawing unit is ``units`` on paper (1 mm = 72 / 25.4 pt). Polylines become ``m``/``l``,
    cubic chains ``c``, arcs cubic Beziers (PDF has no arc operator), closed paths ``h``, and
    each path is stroked with ``S``. Coordinates are written in points with 4 decimals.
    With ``layers``, each layer is an optional content group (PDF 1.5, section 8.11: the
    layers panel of a PDF viewer or Illustrator) whose paths are stroked in its colour
    (``RG``), the layers in order of first use.

    Parameters
    ----------
    paths : sequence of Path2D
    units : {"mm", "cm", "in", "pt", "px"}
    margin : float
        Space around the drawing, in ``units``; >= 0.
    stroke_width : float
        Line width in ``units``; > 0.
    compress : bool
        Deflate the content stream (zlib, deterministic).
    layers : sequence of str, optional
        The layer of each path (names as :func:`layer_styles` takes them).
    colors : mapping of layer -> CSS colour, optional
        Stroke colours; layers not named take the default palette.

    Returns
    -------
    bytes
    """
    if units not in UNITS_MM:
        raise ValueError(f"units must be one of {', '.join(UNITS_MM)}; got {units!r}")
    if not margin >= 0 or not stroke_width > 0:
        raise ValueError(
            f"margin must be >= 0 and stroke_width > 0, got {margin} and {stroke_width}"
        )
    lo, hi = drawing_bounds(paths)
    scale = UNITS_MM[units] * 72.0 / 25.4  # points per drawing unit
    size = np.maximum(hi - lo + 2 * margin, stroke_width) * scale
    origin = lo - margin

    def pts(q: np.ndarray) -> np.ndarray:
        return _numbers((q - origin) * scale, 4)

    if layers is not None and len(layers) != len(paths):
        raise ValueError(f"{len(paths)} paths but {len(layers)} layer names")
    styles = layer_styles(layers, colors) if layers is not None else None
    strokes = []
    for path in paths:  # one iteration per curve; its points are formatted in bulk
        p = path.points
        if path.kind == "arc":
            p, kind = _arc_cubics(p), "cubic"
        else:
            kind = path.kind
        first = pts(p[:1])
        if kind == "polyline":
            rest, op = pts(p[1:]).reshape(len(p) - 1, -1), b" l\n"
        else:
            rest, op = pts(p[1:]).reshape((len(p) - 1) // 3, -1), b" c\n"
        body = np.concatenate([rest, np.repeat(_word_row(op), len(rest), axis=0)], axis=1)
        start = np.concatenate([first.reshape(1, -1), _word_row(b" m\n")], axis=1)
        text = squeeze(start.view(np.uint8)) + squeeze(body.view(np.uint8))
        strokes.append(
            text.replace(b"\n ", b"\n").lstrip(b" ") + (b"h S\n" if path.closed else b"S\n")
        )
    ops = [f"{_fmt1(stroke_width * scale)} w 1 J 1 j\n".encode()]
    if styles is None:
        ops += strokes
    else:
        assert layers is not None
        for k, (name, color) in enumerate(styles.items()):  # one marked section per layer
            r, g, b = (_fmt1(c / 255) for c in rgb(color))
            ops.append(f"/OC /L{k} BDC\n{r} {g} {b} RG\n".encode())
            ops += [t for t, layer in zip(strokes, layers, strict=True) if layer == name]
            ops.append(b"EMC\n")
    content = b"".join(ops)
    stream_dict = f"<< /Length {{}}{' /Filter /FlateDecode' if compress else ''} >>"
    if compress:
        content = zlib.compress(content, 6)
    catalog, resources, groups = "", "", []
    if styles is not None:  # objects 6, 7, ...: one optional content group per layer
        refs = " ".join(f"{6 + k} 0 R" for k in range(len(styles)))
        catalog = f" /OCProperties << /OCGs [{refs}] /D << /Order [{refs}] /ON [{refs}] >> >>"
        props = " ".join(f"/L{k} {6 + k} 0 R" for k in range(len(styles)))
        resources = f"/Properties << {props} >> "
        groups = [f"<< /Type /OCG /Name ({name}) >>".encode() for name in styles]
    objects = [
        f"<< /Type /Catalog /Pages 2 0 R{catalog} >>".encode(),
        b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>",
        (
            f"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 {_fmt1(size[0])} {_fmt1(size[1])}] "
            f"/Contents 4 0 R /Resources << {resources}>> >>"
        ).encode(),
        stream_dict.format(len(content)).encode() + b"\nstream\n" + content + b"\nendstream",
        b"<< /Producer (formgraph) >>",
        *groups,
    ]
    version = b"1.4" if styles is None else b"1.5"  # optional content is PDF 1.5
    out = [b"%PDF-" + version + b"\n%\xe2\xe3\xcf\xd3\n"]
    offsets = []
    pos = len(out[0])
    for i, body in enumerate(objects, start=1):
        chunk = f"{i} 0 obj\n".encode() + body + b"\nendobj\n"
        offsets.append(pos)
        out.append(chunk)
        pos += len(chunk)
    xref = [f"xref\n0 {len(objects) + 1}\n".encode(), b"0000000000 65535 f\r\n"]
    xref += [f"{o:010d} 00000 n\r\n".encode() for o in offsets]
    trailer = (
        f"trailer\n<< /Size {len(objects) + 1} /Root 1 0 R /Info 5 0 R >>\n"
        f"startxref\n{pos}\n%%EOF\n"
    ).encode()
    return b"".join(out + xref + [trailer])


def _word_row(text: bytes) -> np.ndarray:
    """A (1, w) row of words holding ``text``, NUL-padded."""
    row = np.zeros((1, (len(text) + 7) // 8), dtype=np.uint64)
    row.view(np.uint8)[0, : len(text)] = np.frombuffer(text, dtype=np.uint8)
    return row


def _fmt1(x: float) -> str:
    return squeeze(float_words(np.array([x]), decimals=4).view(np.uint8)).decode()
