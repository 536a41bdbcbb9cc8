"""``export.gcode``: tool paths written as RS-274 G-code (:mod:`formgraph.kernels.io.gcode`),
by ``ctx.write`` as every export is: atomic, inside the output directory."""

from __future__ import annotations

import math
from enum import Enum
from pathlib import PurePosixPath
from typing import Annotated

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import OutputPath
from formgraph.geometry import Curve, NurbsCurve
from formgraph.kernels.curves import sampling as ksampling
from formgraph.kernels.io.gcode import ToolPath, arc_moves, gcode_bytes
from formgraph.nodes.export.drawing import curve_path

EXTENSIONS = (".nc", ".ngc", ".gcode", ".gc", ".tap", ".cnc")  # what senders open as G-code


class Mode(str, Enum):
    """The machine."""

    router = "router"  # a spindle: Z moves, plunges, rapid moves at the safe height
    laser = "laser"  # a beam: no Z, M4 S power on and M5 off per path


@node("export.gcode", version=1)
def gcode(
    paths: list[Curve],
    path: OutputPath,
    feed: float = 1000.0,
    plunge: float = 300.0,
    safe_z: float = 5.0,
    spindle: Annotated[float | None, Range(min=0)] = None,
    mode: Mode = Mode.router,
    tolerance: Annotated[float, Range(min=1e-6)] = 0.01,
    *,
    ctx: Context,
) -> str:
    """Write tool paths as RS-274 G-code in millimetres (G21, G90), for a router or a laser.

    Each path is reached by a rapid move (G0) at ``safe_z``, entered by a plunge at the
    ``plunge`` feed to its first point, cut at ``feed`` and left by a rapid move back up
    to ``safe_z``. Polylines become G1 moves through their points; curves made of exact
    circular arcs (``nurbs.circle``, ``curves.rectangle``, the exact offsets of
    ``cam.profile`` and ``cam.pocket``) become G2/G3 arcs (I J the centre from the arc's
    start), not chords; any other curve is G1 moves within ``tolerance`` of it. With
    ``mode: laser`` there is no Z: the beam goes on (M4, grbl's dynamic power, S =
    ``spindle``, default 1000) at each path's start and off (M5) at its end.

    Refused: a file name without a G-code extension, a safe height at or below the work's
    top (z = 0). Warned: no paths (the program does nothing), a router's path above the
    work (z > 0: it cuts air).

    Parameters
    ----------
    paths : list[Curve]
        The tool-centre paths, in the order to run them (``cam.profile``, ``cam.pocket``).
    path : OutputPath
        File path relative to the output directory, e.g. ``part.nc``; its extension one
        of .nc, .ngc, .gcode, .gc, .tap, .cnc.
    feed : float
        Cutting feed, mm/min.
    plunge : float
        Plunging feed, mm/min.
    safe_z : float
        Height of rapid moves: above the work (z > 0; its top is z = 0) and its clamps.
    spindle : float
        Router: spindle speed, rpm (M3 S...); without it no spindle command is written.
        Laser: the beam's power S.
    mode : Mode
        router or laser.
    tolerance : float
        Largest distance between a curve that is not a polyline nor arcs and its moves.

    Example
    -------
    ``nc: {type: export.gcode, paths: ["@pocket", "@profile"], path: part.nc, feed: 1200}``
    """
    if isinstance(paths, Curve):
        paths = [paths]
    suffix = PurePosixPath(str(path)).suffix.lower()
    if suffix not in EXTENSIONS:
        raise InputError(
            "path",
            f"{str(path)!r} is not a G-code file name: end it with one of "
            f"{', '.join(EXTENSIONS)} (controllers and senders go by the extension)",
        )
    for port, value in (("feed", feed), ("plunge", plunge)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(port, f"the {port} must be positive (mm/min), got {value}")
    laser = mode == Mode.laser
    if not laser and not (math.isfinite(safe_z) and safe_z > 0):
        raise InputError(
            "safe_z",
            f"the safe height must be above the work (z > 0: the work's top is z = 0), "
            f"got {safe_z}",
        )
    moves = [_moves(c, i, tolerance, ctx) for i, c in enumerate(paths)]
    ctx.guard(sum(len(m.points) for m in moves), "G-code moves")
    if not any(len(m.points) for m in moves):
        ctx.warn("no paths to cut: the program only sets the machine up and ends")
    above = [i for i, m in enumerate(moves) if len(m.points) and m.points[:, 2].max() > 0]
    if above and not laser:
        top = max(float(moves[i].points[:, 2].max()) for i in above)
        listed = ", ".join(map(str, above[:5])) + (" ..." if len(above) > 5 else "")
        ctx.warn(
            f"{len(above)} path(s) ({listed}) run above the work, up to z = {top:g} (tool "
            "paths go down from its top at z = 0): they cut nothing there"
        )
    try:
        data = gcode_bytes(moves, feed, plunge, safe_z, spindle, laser)
    except ValueError as exc:
        port = "safe_z" if "safe height" in str(exc) else "paths"
        raise InputError(port, str(exc)) from None
    return str(ctx.write(path, data))


def _moves(c: Curve, i: int, tol: float, ctx: Context) -> ToolPath:
    """A curve's moves: its points (a polyline's own), exact arcs, or chords within ``tol``."""
    if isinstance(c, NurbsCurve):
        cp = np.asarray(c.control_points)
        if c.degree == 1:
            return ToolPath.polyline(cp)
        z = cp[:, 2]
        if c.degree == 2 and c.rational and np.all(z == z[0]):
            drawn = curve_path(c)
            if drawn.kind == "arc":
                return arc_moves(drawn.points, float(z[0]))
        w = np.asarray(c.weights) if c.rational else None
        _, t = InputError.call(
            "paths",
            ksampling.sample_nurbs,
            cp,
            c.degree,
            c.knots,
            w,
            tol,
            closed=False,
            guard=lambda n: ctx.guard(n, "G-code moves"),
            params=True,
        )
        t = np.r_[t, c.knots[-1]] if t[-1] < c.knots[-1] else t
        return ToolPath.polyline(np.asarray(c.evaluate(t)))
    pts = np.asarray(c.sample(max(65, getattr(c, "samples", 256) + 1)))
    if not np.isfinite(pts).all():
        raise InputError("paths", f"curve {i} has points that are not finite")
    return ToolPath.polyline(pts)
