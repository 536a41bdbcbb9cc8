"""Fabrication benchmark: nesting (time and utilisation) and pocket tool paths.

Cases:

* nesting 200 mixed parts (the fixed set of ``tests/fabrication_parts.py``: plates with
  holes, discs, rings, brackets, gears, slots, squares) on 600 x 400 sheets, 2 mm apart,
  quarter turns, effort 10: ``layout.nest`` through a graph (a new graph each call: no
  cache answers) beside the kernel alone;
* a pocket of a 1,000-vertex wiggly outline (radius 50 +- 8, a 6 mm tool, stepover 0.4,
  one depth) through ``cam.pocket`` and the kernel alone, against shapely's buffer written
  as its users write a contour-parallel pocket (buffer inward by r + k s until empty);
* utilisation, ours against spyrrow (sparrow, the state of the art in strip packing) on a
  strip 400 high, on the parts without holes (spyrrow has none), spyrrow given at least the
  time ours took (its budget is whole seconds);
* utilisation on sheets, ours (no-fit polygons, the search over the order) against a plain
  bottom-left fill of the parts' bounding rectangles, with the same number of evaluations
  (the rectangles' orders: decreasing area, then random restarts), and ours without the
  search (effort 1).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import shapely

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from fabrication_parts import KINDS, part  # noqa: E402

SHEET = (600.0, 400.0)
SPACING = 2.0
EFFORT = 10
TOLERANCE = 0.05  # mm, the nesting's simplification


def _parts(count: int, kinds=KINDS) -> list:  # noqa: ANN001
    out = []
    for i in range(count):
        out += part(kinds[i % len(kinds)], 150.0 * i)
    return out


def _arrays(curves) -> list[list[np.ndarray]]:  # noqa: ANN001
    """The parts as ``layout.nest`` reads them (the even-odd region's pieces, outer ring
    first), for the kernel's rows."""
    from formgraph.core.registry import Context
    from formgraph.nodes import _outlines

    loops, _, hole = _outlines.region_loops(curves, Context("bench", Path(".")))
    starts = list(np.flatnonzero(~hole)) + [len(loops)]
    return [loops[a:b] for a, b in zip(starts[:-1], starts[1:], strict=True)]


def run(table) -> None:  # noqa: ANN001 - the harness's Table
    _nest_time(table)
    _pocket_time(table)
    _strip_utilisation(table)
    _sheet_utilisation(table)


def _nest_time(table) -> None:  # noqa: ANN001
    import formgraph as fg
    from formgraph.kernels.layout import nest

    curves = _parts(200)
    parts = _arrays(curves)
    calls = iter(range(10**9))

    def api():
        g = fg.Graph()
        # a tolerance a hair different each call: the cache never answers
        tol = TOLERANCE * (1 + next(calls) * 1e-12)
        g.add(
            "n",
            "layout.nest",
            curves=curves,
            sheet=list(SHEET),
            spacing=SPACING,
            effort=EFFORT,
            tolerance=tol,
        )
        return g.evaluate("n")

    out = api()
    table.compare(
        "nest 200 mixed parts, 600 x 400, effort 10",
        api=api,
        kernel=lambda: nest.nest(parts, SHEET, SPACING, 4, 0, EFFORT, TOLERANCE),
        rounds=3,
        min_seconds=0.0,
        note=f"{out.sheets} sheets, utilisation {out.utilisation:.3f}",
    )


def _wiggly(n: int = 1000) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 50 + 8 * np.sin(7 * t)
    return np.c_[r * np.cos(t), r * np.sin(t)]


def _pocket_time(table) -> None:  # noqa: ANN001
    import formgraph as fg
    from formgraph.kernels.cam.paths import pocket_levels

    ring = _wiggly()
    curve = fg.NurbsCurve.polyline(np.c_[ring, np.zeros(len(ring))], closed=True)
    r, step = 3.0, 2.4
    calls = iter(range(10**9))

    def api():
        g = fg.Graph()
        # a new depth each call: the cache never answers
        g.add("p", "cam.pocket", curves=[curve], tool_diameter=6, depth=1 + next(calls) * 1e-9)
        return g.evaluate("p")

    def shapely_pocket():
        poly = shapely.Polygon(ring)
        levels, k = [], 0
        while True:
            level = poly.buffer(-(r + k * step))
            if level.is_empty:
                return levels
            levels.append(level)
            k += 1

    table.compare(
        "pocket of a 1,000-vertex outline, 6 mm tool",
        api=api,
        kernel=lambda: pocket_levels([ring], r, step, 0.01),
        references={"shapely buffer loop": shapely_pocket},
        note=f"{len(pocket_levels([ring], r, step, 0.01))} levels",
    )


def _strip_utilisation(table) -> None:  # noqa: ANN001
    from formgraph.kernels.layout import nest

    kinds = ("plate", "disc", "bracket", "gear", "slot", "small disc")
    parts = [p[:1] for p in _arrays(_parts(48, kinds))]  # outer rings only
    area = sum(shapely.Polygon(p[0]).area for p in parts)
    height = 400.0
    t0 = time.perf_counter()
    ours = nest.nest(parts, (20000.0, height), SPACING, 4, 0, EFFORT)
    took = time.perf_counter() - t0
    table.add(
        "utilisation, 48 parts on a strip 400 high",
        "formgraph",
        [took],
        f"utilisation {area / (height * ours.length):.3f} "
        f"(length {ours.length:.1f}, effort {EFFORT})",
    )
    try:
        import spyrrow
    except ImportError as exc:
        table.add(
            "utilisation, 48 parts on a strip 400 high",
            "spyrrow",
            None,
            f"not installed ({exc.name})",
        )
        return
    items = [
        spyrrow.Item(str(i), [tuple(map(float, q)) for q in p[0]], 1, [0.0, 90.0, 180.0, 270.0])
        for i, p in enumerate(parts)
    ]
    seconds = max(1, int(np.ceil(took)))
    config = spyrrow.StripPackingConfig(
        early_termination=True,
        total_computation_time=seconds,
        min_items_separation=SPACING,
        num_workers=1,
        seed=0,
    )
    t0 = time.perf_counter()
    sol = spyrrow.StripPackingInstance("bench", height, items).solve(config)
    took = time.perf_counter() - t0
    table.add(
        "utilisation, 48 parts on a strip 400 high",
        "spyrrow",
        [took],
        f"utilisation {area / (height * sol.width):.3f} "
        f"(length {sol.width:.1f}, {seconds} s budget)",
    )


def _sheet_utilisation(table) -> None:  # noqa: ANN001
    from formgraph.kernels.layout import nest

    parts = _arrays(_parts(80))
    area = sum(shapely.Polygon(p[0], p[1:]).area for p in parts)
    case = "utilisation, 80 mixed parts on 600 x 400 sheets"
    for effort, label in ((EFFORT, "formgraph"), (1, "formgraph, effort 1")):
        t0 = time.perf_counter()
        ours = nest.nest(parts, SHEET, SPACING, 4, 0, effort)
        table.add(
            case,
            label,
            [time.perf_counter() - t0],
            f"utilisation {ours.utilisation:.3f}, {ours.sheets} sheets, effort {effort}",
        )
    # plain bottom-left fill of the bounding rectangles: the same evaluations, as restarts
    sizes = np.array([np.ptp(p[0], axis=0) for p in parts])
    t0 = time.perf_counter()
    best = None
    for seed in range(EFFORT):  # decreasing area first, then random orders
        rng = np.random.default_rng(seed)
        order = np.argsort(-sizes.prod(axis=1)) if seed == 0 else rng.permutation(len(sizes))
        got = _box_fill(sizes[order], SHEET, SPACING)
        if best is None or got < best:
            best = got
    sheets, length = best
    used = (sheets - 1) * SHEET[0] * SHEET[1] + length * SHEET[1]
    table.add(
        case,
        "bottom-left fill of boxes",
        [time.perf_counter() - t0],
        f"utilisation {area / used:.3f}, {int(sheets)} sheets, {EFFORT} restarts",
    )


def _box_fill(sizes: np.ndarray, sheet: tuple[float, float], gap: float) -> tuple[int, float]:
    """Plain bottom-left fill of rectangles (Jakobs 1996's BL on the corners of the boxes
    placed: candidates right of and above each, the leftmost then lowest that fits, either
    way up), sheet after sheet: (sheets, the last one's used length)."""
    w, h = sheet
    sheets: list[np.ndarray] = [np.zeros((0, 4))]
    for size in sizes:
        for k, boxes in enumerate(sheets):
            best = None
            for dx, dy in (size, size[::-1]):
                xs = np.r_[0.0, boxes[:, 2] + gap]
                ys = np.r_[0.0, boxes[:, 3] + gap]
                cx, cy = (a.ravel() for a in np.meshgrid(xs, ys))
                ok = (cx + dx <= w) & (cy + dy <= h)
                if len(boxes):
                    clear = (
                        (cx[:, None] >= boxes[None, :, 2] + gap)
                        | (cx[:, None] + dx + gap <= boxes[None, :, 0])
                        | (cy[:, None] >= boxes[None, :, 3] + gap)
                        | (cy[:, None] + dy + gap <= boxes[None, :, 1])
                    )
                    ok &= clear.all(axis=1)
                if ok.any():
                    j = np.flatnonzero(ok)[np.lexsort((cy[ok], cx[ok]))[0]]
                    cand = (cx[j], cy[j], cx[j] + dx, cy[j] + dy)
                    if best is None or cand[:2] < best[:2]:
                        best = cand
            if best is not None:
                sheets[k] = np.vstack([boxes, best])
                break
        else:
            sheets.append(np.array([[0.0, 0.0, *size]]))
    return len(sheets), float(sheets[-1][:, 2].max())
