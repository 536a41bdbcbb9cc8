"""SVG drawings to exact NURBS curves, in millimetres with y up.

The SVG itself — paths and their commands, basic shapes (``rect`` with rounded corners,
``circle``, ``ellipse``, ``line``, ``polyline``, ``polygon``), nested transforms, CSS and
``use`` — is read by ``svgelements``, which knows the specification's rules; every segment
it reports, transforms applied, is then made exact here: lines degree 1, quadratic and cubic
Béziers as they are, elliptical arcs as rational quadratics (:mod:`.chains`). Each subpath is
one curve. Segments are taken in their element's own coordinates and its full transform is
applied to the control points (an affine map keeps a rational Bézier exact; a skewed arc
stays an exact ellipse), arcs converted from the endpoint form by the specification's own
formulas rather than through a transformed ellipse's rounded axes.

Units: svgelements resolves ``width="100mm"`` with a ``viewBox`` (and every other length) to
CSS pixels at 96 per inch; a pixel is 25.4/96 mm. The y axis is flipped to point up, about
the document's bottom edge when it has a height (so the page's lower-left corner is the
origin), else about y = 0.

A hostile file is bounded before svgelements sees it: at most :data:`MAX_ELEMENTS` tags and
:data:`MAX_DEPTH` levels of nesting, :data:`MAX_NUMBERS` numbers, ``use`` references
neither cyclic nor expanding past the tag budget, no external entities (expat never fetches
them, and its billion-laughs guard bounds internal ones).
"""

from __future__ import annotations

import io
import math
import re
from collections import Counter
from dataclasses import dataclass

import numpy as np

from ..geometry import MAX_COORDINATE
from .chains import Chain, CurveArrays, arc_pieces, bezier_piece, line_piece

__all__ = ["MAX_DEPTH", "MAX_ELEMENTS", "MAX_NUMBERS", "SvgCurve", "read_svg"]

MAX_ELEMENTS = 250_000
MAX_DEPTH = 512
MAX_NUMBERS = 2_000_000  # svgelements parses a path's numbers in Python: about 20 s of them
_NUMBER = re.compile(rb"[0-9]+(?:\.[0-9]*)?|\.[0-9]+")
PX_MM = 25.4 / 96.0


@dataclass(frozen=True)
class SvgCurve:
    curve: CurveArrays
    layer: str  # its Inkscape layer's label (or id), else its outermost named group's id


def _bounded(data: bytes, max_elements: int) -> None:
    tags = data.count(b"<")
    if tags > max_elements:
        raise ValueError(f"the file has {tags:,} tags, over the budget of {max_elements:,}")
    deepest = _depth(data)
    if deepest > MAX_DEPTH:
        raise ValueError(f"elements nest {deepest:,} deep, over the budget of {MAX_DEPTH}")
    numbers = len(_NUMBER.findall(data))
    if numbers > MAX_NUMBERS:
        raise ValueError(
            f"the file holds {numbers:,} numbers (path coordinates), over the budget of "
            f"{MAX_NUMBERS:,}"
        )
    if b"<use" in data or b":use" in data:
        _bounded_uses(data, max_elements)


def _depth(data: bytes) -> int:
    """How deep the elements nest, in one linear pass over the positions of ``<`` and ``>``
    (a regular expression per tag rescanned the rest of the file for every ``<`` left
    without its ``>``: 58 KiB of them took 20 s).

    A tag runs from a ``<`` to the next ``>``; a ``<`` inside it starts no tag. An end tag
    (``</``) closes one level, an empty-element tag (``/>``) none, declarations, comments
    and processing instructions (``<!``, ``<?``) none; a ``<`` with no ``>`` after it is not
    a tag (the XML parser reports it).
    """
    buf = np.frombuffer(data, np.uint8)
    lt, gt = np.flatnonzero(buf == 60), np.flatnonzero(buf == 62)
    close = np.searchsorted(gt, lt)  # each '<''s next '>' (its index in gt)
    ok = close < gt.size
    lt, close = lt[ok], gt[close[ok]]
    if lt.size == 0:
        return 0
    starts = np.ones(lt.size, dtype=bool)
    starts[1:] = lt[1:] > close[:-1]  # not inside the tag a '<' before it opened
    lt, close = lt[starts], close[starts]
    after = buf[np.minimum(lt + 1, buf.size - 1)]
    ending = after == 47  # '</'
    empty = (buf[close - 1] == 47) & (close - 1 > lt)  # '/>'
    name = np.where(ending, buf[np.minimum(lt + 2, buf.size - 1)], after)
    other = ((name == 33) | (name == 63)) & (close > lt + 1 + ending)  # '<!', '<?'
    step = np.where(other, 0, np.where(ending, -1, np.where(empty, 0, 1)))
    return int(max(np.cumsum(step).max(initial=0), 0))


def _bounded_uses(data: bytes, max_elements: int) -> None:
    """Refuse ``use`` references that form a cycle or expand past the tag budget (a use of
    a group of two uses of ... doubles per level), before svgelements expands them."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(data)
    except ET.ParseError:
        return  # svgelements reports it
    ids: dict[str, ET.Element] = {}
    for el in root.iter():
        if el.get("id"):
            ids.setdefault(el.get("id"), el)

    def ref(el: ET.Element) -> ET.Element | None:
        if not el.tag.endswith("use"):
            return None
        href = el.get("href") or el.get("{http://www.w3.org/1999/xlink}href") or ""
        return ids.get(href[1:]) if href.startswith("#") else None

    size: dict[int, int] = {}  # expanded element count, by id(element)
    on_path: set[int] = set()
    stack: list[tuple[ET.Element, bool]] = [(root, False)]
    while stack:  # post-order, without recursion
        el, done = stack.pop()
        key = id(el)
        if done:
            on_path.discard(key)
            n = 1 + sum(size[id(c)] for c in el)
            target = ref(el)
            if target is not None:
                n += size[id(target)]
            if n > max_elements:
                raise ValueError(
                    f"'use' references expand to more than {max_elements:,} elements, over "
                    f"the budget"
                )
            size[key] = n
            continue
        if key in size:
            continue
        if key in on_path:
            raise ValueError(f"a 'use' refers to an element that contains it (id {el.get('id')!r})")
        on_path.add(key)
        stack.append((el, True))
        target = ref(el)
        for c in (*el, *(() if target is None else (target,))):
            if id(c) in on_path:
                raise ValueError(
                    f"a 'use' refers to an element that contains it (id {c.get('id')!r})"
                )
            if id(c) not in size:
                stack.append((c, False))


def read_svg(data: bytes, max_elements: int = MAX_ELEMENTS) -> tuple[list[SvgCurve], Counter]:
    """Every drawn shape of an SVG file as exact NURBS arrays, one per subpath, and a count
    of what was passed over (``text`` not converted to paths, ``image``).

    Raises
    ------
    ValueError
        For a file over the budgets, or one svgelements cannot parse as SVG.
    """
    import svgelements as se

    _bounded(data, max_elements)
    _finite_values(data)
    _drawable_size(data)
    try:
        doc = se.SVG.parse(io.BytesIO(data), reify=False, ppi=96.0, on_error="raise")
    except Exception as exc:  # svgelements raises what its XML parser raises
        raise ValueError(_why_not(data, exc, se)) from None
    _drawable_view_box(data)
    mm, declared = _mm_per_px(data, doc)
    height = _length(getattr(doc, "height", None)) if declared else 0.0
    flip = np.array([mm, -mm, 1.0])
    shift = np.array([0.0, height * mm if height else 0.0, 0.0])
    out: list[SvgCurve] = []
    passed: Counter = Counter()
    # (element, its layer, whether that layer is an Inkscape layer rather than a named group)
    stack: list[tuple[object, str, bool]] = [(doc, "", False)]
    while stack:  # depth-first, without recursion
        node, layer, marked = stack.pop()
        if isinstance(node, (se.Group, se.Use)) or node is doc:  # a use holds its copy
            for child in reversed(list(node)):
                name, mark = layer, marked
                if isinstance(child, se.Group):
                    is_layer = _is_layer(child)
                    if is_layer or (not marked and not layer):  # innermost layer, else outermost id
                        name, mark = (_layer_name(child) or layer), is_layer or marked
                stack.append((child, name, mark))
            continue
        if not isinstance(node, se.Shape):
            if isinstance(node, se.Text | se.Image):
                passed[type(node).__name__.lower()] += 1
            continue
        if node.values.get("visibility") == "hidden":
            continue
        m = node.transform  # local to document pixels: applied to the control points (exact)
        lin = np.array([[m.a, m.c, 0.0], [m.b, m.d, 0.0], [0.0, 0.0, 1.0]], dtype=np.float64)
        move = np.array([m.e, m.f, 0.0], dtype=np.float64)
        tag = type(node).__name__.lower()
        name = f"a {tag}" + (f" id {node.id!r}" if getattr(node, "id", None) else "")
        if (
            not (np.isfinite(lin).all() and np.isfinite(move).all())
            or lin[0, 0] * lin[1, 1] == lin[0, 1] * lin[1, 0]
        ):
            raise ValueError(
                f"{name}: its transform {_shown_matrix(m)} flattens it to a line or a point, "
                "or is not finite numbers"
            )
        try:
            chains = _chains(se.Path(node), se)
        except ValueError as exc:
            raise ValueError(f"{name}: {exc}") from None
        if not chains:  # a zero size, which the SVG specification draws as nothing
            passed[f"{tag} of zero size"] += 1
        for chain in chains:
            cp, p, k, w = chain.curve()
            with np.errstate(all="ignore"):
                cp = (cp @ lin.T + move) * flip + shift
            _in_range(cp, name)
            out.append(SvgCurve((cp, p, k, w), layer))
    return out, passed


def _in_range(cp: np.ndarray, name: str) -> None:
    """Refuse control points that are not finite or lie past :data:`MAX_COORDINATE`
    (a ``skewX(90)``, a huge scale), naming the element."""
    xyz = cp[:, :3] / cp[:, 3:] if cp.shape[1] == 4 else cp
    with np.errstate(all="ignore"):
        big = float(np.max(np.abs(xyz))) if xyz.size else 0.0
    if not np.isfinite(xyz).all() or big > MAX_COORDINATE:
        shown = "not a finite number" if not np.isfinite(xyz).all() else f"{big:.3g} mm"
        raise ValueError(
            f"{name}: a coordinate comes out {shown} after its transforms and units, past "
            f"{MAX_COORDINATE:g} mm (where a double no longer holds a tenth of a millimetre): "
            "a skew of 90 degrees, or a scale or number far too large?"
        )


def _shown_matrix(m: object) -> str:
    values = [getattr(m, k) for k in "abcdef"]
    return "matrix(" + " ".join(f"{float(v):g}" for v in values) + ")"


def _why_not(data: bytes, exc: Exception, se: object) -> str:
    """What is wrong with a file svgelements failed on, in a reader's words: the XML
    parser's own sentence, else the first path data or transform that fails alone."""
    import xml.etree.ElementTree as ET

    if isinstance(exc, ET.ParseError):
        return f"not an SVG document: the XML is not well formed ({exc})"
    for m in re.finditer(rb"\s(d|transform)\s*=\s*(\"[^\"<]*\"|'[^'<]*')", data):
        text = m.group(2)[1:-1].decode("utf-8", "replace")
        try:
            if m.group(1) == b"d":
                list(se.Path(text))  # type: ignore[attr-defined]
            else:
                se.Matrix(text)  # type: ignore[attr-defined]
        except Exception as bad:  # noqa: BLE001  (which one fails is what we want)
            line = data.count(b"\n", 0, m.start()) + 1
            what = "path data" if m.group(1) == b"d" else "transform"
            if isinstance(bad, ZeroDivisionError | OverflowError) or "domain" in str(bad):
                reason = "holds a number too small or too large to compute with"
            else:
                reason = "is not valid SVG syntax (a command without its numbers, or a stray "
                reason += "character?)"
            return f"line {line}: the {what} {_clip(text)!r} {reason}"
    reason = str(exc).strip() or "it stops without saying why"
    return f"not an SVG drawing svgelements can read: {reason[:100]}"


def _clip(text: str, n: int = 40) -> str:
    return text if len(text) <= n else text[: n - 3] + "..."


_ROOT_LENGTH = re.compile(
    rb"\s*([+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)\s*([a-z%]*)\s*"
)


def _drawable_size(data: bytes) -> None:
    """Refuse a root ``width`` or ``height`` that is zero, negative, not finite or not a
    length at all (``nanmm``, ``1e400mm``): the SVG specification draws nothing for zero,
    and svgelements then gave no curves without a word."""
    root = re.search(rb"<(?:\w+:)?svg\b([^<>]*)>", data[: 1 << 16])
    if root is None:
        return
    for m in re.finditer(rb"\s(width|height)\s*=\s*[\"']([^\"'<>]*)[\"']", root.group(1)):
        text = m.group(2)
        length = _ROOT_LENGTH.fullmatch(text)
        value = float(length.group(1)) if length else float("nan")
        if not (math.isfinite(value) and value > 0):
            raise ValueError(
                f"the root's {m.group(1).decode()} {text.decode('latin-1')[:30]!r} is not a "
                "positive finite length: an SVG viewer draws nothing of it"
            )


# the attributes that hold coordinates and lengths, and a NaN or infinity written in one
_GEOMETRIC = rb"d|points|x|y|x1|y1|x2|y2|cx|cy|r|rx|ry|width|height|viewBox|transform"
_ATTRIBUTE = re.compile(rb"\s(" + _GEOMETRIC + rb")\s*=\s*(\"[^\"]*\"|'[^']*')")
_NOT_FINITE = re.compile(
    rb"(?<![A-Za-z0-9_#.-])[+-]?(nan|inf(inity)?)(mm|cm|in|pt|pc|px|em|ex|%)?(?![A-Za-z0-9_-])",
    re.I,
)


_HUGE = re.compile(rb"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)[eE]\+?[0-9]{3,}")


def _finite_values(data: bytes) -> None:
    """Refuse a NaN or an infinity (or a number past the largest double) in a coordinate,
    length or transform, naming its line and attribute (svgelements parses them as numbers
    and then draws nothing, or fails without a word)."""
    if not re.search(rb"(?i)nan|inf|e\+?[0-9]{3}", data):
        return
    for m in _ATTRIBUTE.finditer(data):  # the rare file that spells one: attribute by attribute
        bad = _NOT_FINITE.search(m.group(2))
        if bad is None:  # a number past the largest double (1e400) reads as an infinity
            bad = next(
                (h for h in _HUGE.finditer(m.group(2)) if math.isinf(float(h.group()))), None
            )
        if bad:
            line = data.count(b"\n", 0, m.start()) + 1
            raise ValueError(
                f"line {line}: the {m.group(1).decode()} attribute holds "
                f"{bad.group().decode('latin-1')!r}; coordinates and lengths must be finite "
                "numbers"
            )


def _drawable_view_box(data: bytes) -> None:
    """Refuse a root ``viewBox`` of zero (or negative) width or height: the SVG
    specification draws nothing for it (zero disables rendering; negative is an error)."""
    root = re.search(rb"<(?:\w+:)?svg\b([^<>]*)>", data[: 1 << 16])
    box = root and re.search(rb"\sviewBox\s*=\s*[\"']([^\"']*)[\"']", root.group(1))
    if not box:
        return
    numbers = re.split(rb"[\s,]+", box.group(1).strip())
    try:
        w, h = float(numbers[2]), float(numbers[3])
    except (IndexError, ValueError):
        raise ValueError(
            f"the root's viewBox {box.group(1).decode('latin-1')[:40]!r} is not four numbers "
            "(min-x min-y width height)"
        ) from None
    if not (w > 0 and h > 0):
        raise ValueError(
            f"the root's viewBox {box.group(1).decode('latin-1')[:40]!r} has a width or height "
            "of zero or less: an SVG viewer draws nothing of it"
        )


_UNIT_MM = {
    "mm": 1.0,
    "cm": 10.0,
    "in": 25.4,
    "pt": 25.4 / 72,
    "pc": 25.4 / 6,
    "px": PX_MM,
    "": PX_MM,
}


def _mm_per_px(data: bytes, doc: object) -> tuple[float, bool]:
    """Millimetres per svgelements pixel, from the root's own width (or height) and unit;
    and whether the root declares a height (or a view box) to flip about.

    svgelements turns millimetres into pixels with a rounded inch (0.0393701 in/mm, 5e-7
    off); a document ``width="100mm"`` must measure 100 mm, so the root's length is read
    here and divided by the pixels svgelements made of it.
    """
    root = re.search(rb"<(?:\w+:)?svg\b([^<>]*)>", data[: 1 << 16])
    if root is None:
        return PX_MM, False
    attrs = dict(re.findall(rb'([\w:-]+)\s*=\s*["\']([^"\']*)["\']', root.group(1)))
    declared = b"height" in attrs or b"viewBox" in attrs
    for name in (b"width", b"height"):
        m = re.fullmatch(rb"\s*([0-9.eE+-]+)\s*(mm|cm|in|pt|pc|px|)\s*", attrs.get(name, b""))
        px = _length(getattr(doc, name.decode(), None))
        if m and px:
            try:
                amount = float(m.group(1))
            except ValueError:
                continue
            if amount > 0:
                return amount * _UNIT_MM[m.group(2).decode()] / px, declared
    return PX_MM, declared


def _length(value: object) -> float:
    try:
        f = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return 0.0
    return f if np.isfinite(f) and f > 0 else 0.0


def _is_layer(group: object) -> bool:
    values = getattr(group, "values", {}) or {}
    return any(str(k).endswith("groupmode") and v == "layer" for k, v in values.items())


def _layer_name(group: object) -> str:
    values = getattr(group, "values", {}) or {}
    for key, v in values.items():
        if str(key).endswith("}label") or str(key) == "inkscape:label":
            return str(v)
    return str(getattr(group, "id", None) or values.get("id") or "")


def _xyz(pt: object) -> np.ndarray:
    return np.array([float(pt.x), float(pt.y), 0.0])  # type: ignore[attr-defined]


def _chains(path: object, se: object) -> list[Chain]:
    chains: list[Chain] = []
    current = Chain()
    start = None
    for seg in path:  # type: ignore[attr-defined]
        if isinstance(seg, se.Move):
            if len(current):
                chains.append(current)
            current, start = Chain(), seg.end
            continue
        if isinstance(seg, se.Close):
            if start is not None and seg.start is not None and len(current):
                a, b = _xyz(seg.start), _xyz(start)
                if np.linalg.norm(a - b) > 1e-9 * (1.0 + np.abs(b).max()):
                    current.add(line_piece(a, b))
                else:  # closed already, up to rounding: end exactly where it began
                    current.pieces[-1][-1, :3] = b * current.pieces[-1][-1, 3]
            if len(current):
                chains.append(current)
            current = Chain()
            continue
        if seg.start is None or seg.end is None:
            continue
        p0, p1 = _xyz(seg.start), _xyz(seg.end)
        if isinstance(seg, se.Line):
            if p0.tolist() != p1.tolist():
                current.add(line_piece(p0, p1))
        elif isinstance(seg, se.QuadraticBezier):
            current.add(bezier_piece(np.array([p0, _xyz(seg.control), p1])))
        elif isinstance(seg, se.CubicBezier):
            current.add(bezier_piece(np.array([p0, _xyz(seg.control1), _xyz(seg.control2), p1])))
        elif isinstance(seg, se.Arc):
            current.add(_arc(seg, p0, p1))
    if len(current):
        chains.append(current)
    return chains


def _arc(seg: object, p0: np.ndarray, p1: np.ndarray) -> list[np.ndarray]:
    """An SVG elliptical arc, from its endpoint form (radii, rotation, large-arc and sweep
    flags) to centre form by the SVG specification's appendix (F.6.5, radii scaled up as
    F.6.6 says when they cannot span the chord), then exact pieces."""
    rx, ry = abs(float(seg.rx)), abs(float(seg.ry))  # type: ignore[attr-defined]
    sweep = float(seg.sweep)  # type: ignore[attr-defined]
    if rx == 0 or ry == 0 or sweep == 0 or p0.tolist() == p1.tolist():
        return [line_piece(p0, p1)] if p0.tolist() != p1.tolist() else []
    phi = float(seg.get_rotation())  # type: ignore[attr-defined]
    large, positive = abs(sweep) > math.pi, sweep > 0
    cos_p, sin_p = math.cos(phi), math.sin(phi)
    dx, dy = (p0[0] - p1[0]) / 2, (p0[1] - p1[1]) / 2
    x1, y1 = cos_p * dx + sin_p * dy, -sin_p * dx + cos_p * dy
    scale = (x1 / rx) ** 2 + (y1 / ry) ** 2
    if scale > 1:
        rx, ry = rx * math.sqrt(scale), ry * math.sqrt(scale)
    num = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1
    den = rx * rx * y1 * y1 + ry * ry * x1 * x1
    root = math.sqrt(max(num / den, 0.0)) * (-1 if large == positive else 1)
    cx1, cy1 = root * rx * y1 / ry, -root * ry * x1 / rx
    center = np.array(
        [
            cos_p * cx1 - sin_p * cy1 + (p0[0] + p1[0]) / 2,
            sin_p * cx1 + cos_p * cy1 + (p0[1] + p1[1]) / 2,
            0.0,
        ]
    )
    t0 = math.atan2((y1 - cy1) / ry, (x1 - cx1) / rx)
    t1 = math.atan2((-y1 - cy1) / ry, (-x1 - cx1) / rx)
    delta = (t1 - t0) % (2 * math.pi)
    if not positive:
        delta -= 2 * math.pi
    a = rx * np.array([cos_p, sin_p, 0.0])
    b = ry * np.array([-sin_p, cos_p, 0.0])
    if not (np.isfinite(center).all() and math.isfinite(delta) and np.isfinite(a + b).all()):
        raise ValueError(
            "an arc is too large for double precision: its radii or its centre overflow (the "
            "centre is found through squares of the radii)"
        )
    pieces = arc_pieces(center, a, b, t0, t0 + delta)
    pieces[0][0, :3], pieces[-1][-1, :3] = p0, p1  # the joints exactly where the path has them
    return pieces
