"""DXF drawings to exact NURBS curves, in millimetres, through ezdxf.

``ezdxf.recover`` reads the file (ASCII or binary, any code page, damaged files repaired
where it can). Each entity becomes exact NURBS arrays: LINE degree 1; LWPOLYLINE and 2-D
POLYLINE one curve each, a bulge an exact arc (:func:`.chains.bulge_arc`), straight runs
degree-raised to match; CIRCLE, ARC and ELLIPSE rational quadratics; SPLINE its own degree,
knots and weights (fit-point splines through ezdxf's construction of their control points).
Entities in an object coordinate system (an extrusion other than +z) are mapped to world
coordinates. Blocks are expanded (INSERT and MINSERT, nested, with their transforms); an
entity on layer ``0`` inside a block takes the layer of the INSERT, as CAD programs draw it.

``$INSUNITS`` scales the drawing to millimetres (unitless drawings are taken as they are).
Expansion is budgeted: at most ``max_entities`` entities and :data:`MAX_DEPTH` nested
inserts, so a block inserting itself ten times at ten levels is refused, not expanded.
"""

from __future__ import annotations

import io
import math
from collections import Counter
from dataclasses import dataclass

import numpy as np

from .chains import Chain, CurveArrays, arc_pieces, bulge_arc, line_piece

__all__ = ["DxfCurve", "MAX_DEPTH", "MAX_ENTITIES", "read_dxf"]

MAX_DEPTH = 16
MAX_ENTITIES = 1_000_000  # entities expanded one by one in Python: about 30 s of them
UNITS_MM = {1: 25.4, 2: 304.8, 4: 1.0, 5: 10.0, 6: 1000.0, 8: 25.4e-6, 9: 0.0254,
            10: 914.4, 13: 1e-3, 14: 100.0}  # fmt: skip


@dataclass(frozen=True)
class DxfCurve:
    curve: CurveArrays
    layer: str


def read_dxf(data: bytes, max_entities: int = MAX_ENTITIES) -> tuple[list[DxfCurve], Counter]:
    """Every curve entity of a DXF file's model space (blocks expanded) as NURBS arrays,
    and a count of the entity types passed over (text, hatches, points, ...).

    Raises
    ------
    ValueError
        For a file ezdxf cannot read, an expansion over the budget, or an INSERT scaled by
        zero (or a non-finite number).
    """
    import ezdxf
    from ezdxf import recover
    from ezdxf.audit import AuditError

    try:
        doc, auditor = recover.read(io.BytesIO(data))
    except (ezdxf.DXFError, ValueError, TypeError, IndexError, KeyError, UnicodeError) as exc:
        reason = str(exc).strip()[:100] or "it stops without saying why"
        raise ValueError(f"not a DXF drawing ezdxf can read: {reason}") from None
    scale = UNITS_MM.get(int(doc.header.get("$INSUNITS", 0) or 0), 1.0)
    out: list[DxfCurve] = []
    skipped: Counter = Counter()
    # the recovery deletes an INSERT whose block the file does not define: counted, so the
    # reader says so rather than drawing less without a word
    geometric = {AuditError.INVALID_MAJOR_AXIS, AuditError.INVALID_ELLIPSE_RATIO,
                 AuditError.REMOVED_INVALID_GRAPHIC_ENTITY, AuditError.INVALID_VERTEX_COUNT,
                 AuditError.INVALID_SPLINE_DEFINITION,
                 AuditError.INVALID_SPLINE_CONTROL_POINT_COUNT,
                 AuditError.INVALID_SPLINE_FIT_POINT_COUNT,
                 AuditError.INVALID_SPLINE_KNOT_VALUE_COUNT,
                 AuditError.INVALID_SPLINE_WEIGHT_COUNT}  # fmt: skip
    for fix in auditor.fixes:
        if fix.code == AuditError.UNDEFINED_BLOCK:
            skipped["INSERT of a block the file does not define"] += 1
        elif fix.code in geometric and str(fix.message).startswith("Removed"):
            # an entity the repair deleted as degenerate (an ELLIPSE of zero major axis)
            skipped[f"{str(fix.message).removeprefix('Removed ').rstrip('.')}"] += 1
    _counted(doc, max_entities)
    count = 0
    dropped: dict[tuple[str, str], list[str]] = {}
    stack = [(iter(doc.modelspace()), None, 0)]
    while stack:
        entities, layer, depth = stack[-1]
        e = next(entities, None)
        if e is None:
            stack.pop()
            continue
        count += 1
        if count > max_entities:
            raise ValueError(
                f"the drawing expands to more than {max_entities:,} entities (blocks inside "
                f"blocks?), over the budget"
            )
        own = e.dxf.get("layer", "0")
        here = layer if (layer is not None and own == "0") else own
        kind = e.dxftype()
        if kind == "INSERT":
            if depth >= MAX_DEPTH:
                raise ValueError(f"blocks nest deeper than {MAX_DEPTH} levels")
            name = e.dxf.get("name", "")
            scales = [e.dxf.get(f"{axis}scale", 1.0) for axis in "xyz"]
            if not all(math.isfinite(f) and f != 0 for f in scales):
                raise ValueError(
                    f"INSERT {e.dxf.get('handle', '?')} of block {name!r}: a scale of "
                    f"{', '.join(f'{f:g}' for f in scales)} (x, y, z) flattens or overflows it; "
                    "every scale must be a non-zero finite number"
                )
            stack.append((_expand(e), here, depth + 1))
            continue
        try:
            curves = _curves(e, kind)
        except _Nothing as why:  # degenerate: said in the warning, with its handle
            dropped.setdefault((kind, str(why)), []).append(e.dxf.get("handle", "?"))
            continue
        except (ValueError, ZeroDivisionError, IndexError) as exc:
            raise ValueError(f"{kind} {e.dxf.get('handle', '?')}: {exc}") from None
        if curves is None:
            skipped[kind] += 1
            continue
        for cp, p, k, w in curves:
            out.append(DxfCurve((cp * scale, p, k, w), here))
    for (kind, why), handles in dropped.items():
        shown = ", ".join(handles[:3]) + (", ..." if len(handles) > 3 else "")
        skipped[f"{kind} that draws nothing ({why}; handle {shown})"] += len(handles)
    return out, skipped


class _Nothing(ValueError):
    """An entity that draws nothing (a radius of zero or less, a zero axis): passed over
    with a warning naming it, as an INSERT of a missing block is."""


def _copies(e) -> int:
    """How many times an INSERT places its block: rows x columns of a MINSERT, else 1."""
    return max(1, int(e.dxf.get("row_count", 1))) * max(1, int(e.dxf.get("column_count", 1)))


def _counted(doc, max_entities: int) -> None:
    """Refuse, before anything is expanded, a drawing whose blocks expand past the budget:
    the entities of each block definition are counted once, an INSERT counting its copies
    times its block's count, multiplied down the block tree (an 11-level fan-out of 10
    inserts a level is 10^11 entities, refused here in the time it takes to count the
    file's own entities). A block that inserts itself is refused too."""
    size: dict[str, int] = {}
    on_path: set[str] = set()

    def block_size(name: str) -> int:
        # iterative post-order over the blocks a block inserts (no recursion: a chain of
        # thousands of nested blocks is fine)
        stack = [(name, None)]
        while stack:
            key, inserts = stack.pop()
            if key in size:
                continue
            block = doc.blocks.get(key)
            if block is None:
                size[key] = 0
                continue
            if inserts is None:
                if key in on_path:
                    raise ValueError(f"block {key!r} inserts itself (through its inserts)")
                on_path.add(key)
                inserts = [(e.dxf.get("name", ""), _copies(e)) for e in block.query("INSERT")]
                stack.append((key, inserts))
                stack.extend((child, None) for child, _ in inserts if child not in size)
                continue
            on_path.discard(key)
            size[key] = len(block) + sum(n * size.get(child, 0) for child, n in inserts)
        return size[name]

    total = 0
    biggest = (0, None)
    for e in doc.modelspace().query("INSERT"):
        n = _copies(e) * block_size(e.dxf.get("name", ""))
        total += n
        biggest = max(biggest, (n, e), key=lambda x: x[0])
    total += len(doc.modelspace())
    if total > max_entities:
        n, e = biggest
        copies = _copies(e)
        grid = f" ({copies:,} copies, a MINSERT's rows x columns)" if copies > 1 else ""
        raise ValueError(
            f"the drawing's blocks expand to {total:,} entities, over the budget of "
            f"{max_entities:,}: INSERT {e.dxf.get('handle', '?')} of block "
            f"{e.dxf.get('name', '')!r}{grid} alone makes {n:,} (blocks inside blocks); "
            "refused before expanding"
        )


def _expand(insert):
    for ins in insert.multi_insert():  # one for an INSERT, rows x columns for a MINSERT
        yield from ins.virtual_entities()


def _to_wcs(e, curve: CurveArrays) -> CurveArrays:
    cp, p, k, w = curve
    ocs = e.ocs()
    if not ocs.transform:
        return curve
    return np.array([list(v) for v in ocs.points_to_wcs(cp.tolist())]), p, k, w


def _v(x) -> np.ndarray:
    return np.array([float(x[0]), float(x[1]), float(x[2]) if len(x) > 2 else 0.0])


def _curves(e, kind: str) -> list[CurveArrays] | None:
    if kind == "LINE":
        c = Chain()
        a, b = _v(e.dxf.start), _v(e.dxf.end)
        if np.array_equal(a, b):
            raise _Nothing("its two ends are one point")
        c.add(line_piece(a, b))
        return [c.curve()]
    if kind == "LWPOLYLINE":
        z = float(e.dxf.get("elevation", 0.0))
        pts = [(_v((x, y, z)), b) for x, y, b in e.get_points("xyb")]
        return _bulged(e, pts, bool(e.closed))
    if kind == "POLYLINE":
        if e.is_2d_polyline:
            z = float(e.dxf.get("elevation", (0, 0, 0))[2])
            pts = [
                (_v((v.dxf.location[0], v.dxf.location[1], z)), float(v.dxf.get("bulge", 0)))
                for v in e.vertices
            ]
            return _bulged(e, pts, bool(e.is_closed))
        if e.is_3d_polyline:
            pts = [(_v(v.dxf.location), 0.0) for v in e.vertices]
            return _bulged(None, pts, bool(e.is_closed))
        return None  # polyface and polygon meshes are not curves
    if kind in ("CIRCLE", "ARC"):
        c0, r = _v(e.dxf.center), float(e.dxf.radius)
        if not r > 0:
            raise _Nothing(f"a radius of {r:g}")
        if kind == "CIRCLE":
            t0, t1 = 0.0, 2 * math.pi
        else:
            t0, t1 = math.radians(e.dxf.start_angle), math.radians(e.dxf.end_angle)
            t1 = t1 + 2 * math.pi if t1 <= t0 else t1
        chain = Chain()
        chain.add(arc_pieces(c0, np.array([r, 0, 0]), np.array([0, r, 0]), t0, t1))
        return [_to_wcs(e, chain.curve())]
    if kind == "ELLIPSE":
        major, ratio = _v(e.dxf.major_axis), float(e.dxf.get("ratio", 1.0))
        if not np.linalg.norm(major) > 0:
            raise _Nothing("a major axis of zero length")
        if not ratio > 0:
            raise _Nothing(f"an axis ratio of {ratio:g}")
        t0, t1 = float(e.dxf.start_param), float(e.dxf.end_param)
        t1 = t1 + 2 * math.pi if t1 <= t0 else t1
        chain = Chain()
        chain.add(arc_pieces(_v(e.dxf.center), _v(e.dxf.major_axis), _v(e.minor_axis), t0, t1))
        return [chain.curve()]
    if kind == "SPLINE":
        tool = e.construction_tool()
        cp = np.array([list(p) for p in tool.control_points], dtype=np.float64)
        knots = np.array(tool.knots(), dtype=np.float64)
        weights = np.array(tool.weights(), dtype=np.float64) if tool.is_rational else None
        return [(cp, int(tool.degree), knots, weights)]
    return None


def _bulged(e, pts: list, closed: bool) -> list[CurveArrays]:
    if closed and len(pts) > 1:
        pts = [*pts, (pts[0][0], 0.0)]
    chain = Chain()
    for (p0, b), (p1, _) in zip(pts[:-1], pts[1:], strict=True):
        if np.array_equal(p0, p1):
            continue
        chain.add(bulge_arc(p0, p1, float(b)) if b else line_piece(p0, p1))
    if not len(chain):
        return []
    curve = chain.curve()
    return [_to_wcs(e, curve) if e is not None else curve]
