"""Offset benchmark: the node's two paths vs shapely's buffer, and our contouring vs scikit-image.

Cases:

* the offset of a 1,000- and a 10,000-vertex wiggly closed polyline (a circle with two sine
  wiggles, extent 2.3), outward and inward by 0.05, at the default 0.1 %-of-extent accuracy,
  through a graph read from a file's text as a user writes one (the loop's points a
  literal list, the distance a param moved a hair each call): the node's default path
  (GEOS's buffer, chords chosen from the tolerance) and its marching path (the distance
  field and marching squares, as an explicit ``cell`` -- the one the default would
  choose -- asks for), against shapely's round-join buffer of the prebuilt polygon (GEOS,
  compiled; its default 8 chords a quarter circle). The notes give the Hausdorff distance
  between each result and shapely's, as a fraction of the extent;
* the contouring step alone: ``marching_squares`` on a 2000 x 2000 field with one contour
  (a cone) and on a busy field of about 120 contours, against
  ``skimage.measure.find_contours`` on the same array (scikit-image returns (row, col) and
  leaves contours that reach the border open; ours closes them along the border, so the
  busy field is padded low to keep all contours inside).
"""

from __future__ import annotations

import itertools

import numpy as np

from formgraph.kernels.offset import default_cell, marching_squares

N_VERTICES = 10_000
GRID = 2000


def wiggly(n: int = N_VERTICES) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 1 + 0.1 * np.sin(20 * t) + 0.05 * np.sin(7 * t)
    return np.c_[r * np.cos(t), r * np.sin(t)]


def busy_field(n: int = GRID) -> np.ndarray:
    y, x = np.mgrid[-1 : 1 : n * 1j, -1 : 1 : n * 1j]
    f = np.sin(22 * x) * np.cos(22 * y) + 0.3 * np.sin(50.6 * x + 1)
    # Fade to low values near the border so every contour closes inside the field.
    fade = np.clip((1 - np.maximum(np.abs(x), np.abs(y))) / 0.05, 0, 1)
    return f * fade - 2 * (1 - fade)


def _hausdorff(loops: list[np.ndarray], shape) -> float:
    import shapely

    ours = shapely.segmentize(shapely.MultiLineString([np.r_[lp, lp[:1]] for lp in loops]), 0.005)
    theirs = shapely.segmentize(shape.boundary, 0.005)
    a = shapely.distance(shapely.points(shapely.get_coordinates(ours)), shape.boundary)
    b = shapely.distance(shapely.points(shapely.get_coordinates(theirs)), ours)
    return float(max(a.max(), b.max()))


def run(table) -> None:  # noqa: ANN001 - the harness's Table
    for n in (1_000, N_VERTICES):
        _offset_rows(table, n)
    _contour_rows(table)


def graph_text(pts: np.ndarray, cell: float | None = None) -> str:
    """A graph file as a user writes one: the loop's points a literal list, the distance
    a param."""
    rows = ", ".join(f"[{float(x)!r}, {float(y)!r}]" for x, y in pts)
    extra = f", cell: {cell!r}" if cell is not None else ""
    return (
        "formgraph: 1\nparams:\n  d: 0.05\nnodes:\n"
        f"  pts: {{type: points.list, points: [{rows}]}}\n"
        "  loop: {type: curves.polyline, points: '@pts', closed: true}\n"
        f"  off: {{type: offset.marching_squares, curves: ['@loop'], distance: '=d'{extra}}}\n"
    )


def _offset_rows(table, n: int) -> None:  # noqa: ANN001
    import formgraph as fg

    pts = wiggly(n)
    extent = float(np.ptp(pts, axis=0).max())
    for d in (0.05, -0.05):
        side = "outward" if d > 0 else "inward"
        cell = default_cell(extent, d)
        default = fg.Graph.from_text(graph_text(pts))
        marching = fg.Graph.from_text(graph_text(pts, cell))

        def call(g, d=d):
            steps = itertools.count(1)
            return lambda: g.evaluate("off", d=d * (1 + next(steps) * 1e-9))

        import shapely

        polygon = shapely.Polygon(pts)
        reference = polygon.buffer(d)
        table.compare(
            f"offset.marching_squares of a {n:,}-vertex wiggly loop {side} {abs(d)}",
            api=call(default),
            references={
                "shapely buffer": lambda d=d, p=polygon: p.buffer(d),
                "formgraph, marching path (an explicit cell)": call(marching),
            },
            rounds=7,
            note="a graph file's literal loop, the distance a param; "
            + _hausdorff_note(default.evaluate("off", d=d), reference, extent),
            notes={
                "shapely buffer": "8 chords a quarter circle",
                "formgraph, marching path (an explicit cell)": _hausdorff_note(
                    marching.evaluate("off", d=d), reference, extent
                ),
            },
        )


def _hausdorff_note(curves, reference, extent: float) -> str:
    loops = [np.asarray(c.control_points)[:-1, :2] for c in curves]
    return f"Hausdorff to shapely {_hausdorff(loops, reference) / extent:.3%} of extent"


def _contour_rows(table) -> None:  # noqa: ANN001
    y, x = np.mgrid[-1 : 1 : GRID * 1j, -1 : 1 : GRID * 1j]
    cone = np.hypot(x, y)
    busy = busy_field()
    for name, field, level in (("one contour", 1 - cone, 0.5), ("busy", busy, 0.5)):
        count = len(marching_squares(field, level))

        def skimage_contours(f=field, lv=level):
            from skimage import measure

            return lambda: measure.find_contours(f, lv)

        table.compare(
            f"contour {GRID}x{GRID} {name}",
            api=lambda f=field, lv=level: marching_squares(f, lv),
            references={"skimage find_contours": _lazy(skimage_contours)},
            rounds=5,
            note=f"the kernel (formgraph.kernels.offset.marching_squares); {count} loops",
        )


def _lazy(make):
    """Import the reference inside the timed callable's first call (ImportError is noted)."""
    state = {}

    def call():
        if "fn" not in state:
            state["fn"] = make()
        return state["fn"]()

    return call
