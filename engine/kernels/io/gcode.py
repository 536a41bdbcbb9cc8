"""RS-274 G-code (NIST RS274/NGC, the dialect of LinuxCNC, grbl and most hobby controllers)
from tool-centre paths: millimetres (G21), absolute coordinates (G90), the XY plane (G17),
feed per minute (G94).

A router's path is reached by a rapid move (G0) at the safe height, entered by a plunge
at the plunge feed (G1 Z), cut at the feed (G1, or G2/G3 for circular arcs, the centre
given relative to the arc's start as I J), and left by a rapid move back up to the safe
height: rapid moves happen only at the safe height. A laser's path has no Z at all: the
beam is switched on (M4, dynamic power: grbl's laser mode scales it with the speed, so
corners do not burn) with its power as S at the path's start and off (M5) at its end.

Every line is laid out as text in bulk (:mod:`.numfmt`): a column per word, rows joined
at once, no Python step per move.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .numfmt import float_words, join_rows, squeeze

__all__ = ["ToolPath", "arc_moves", "gcode_bytes"]

DECIMALS = 4  # 0.1 micrometre
_COLUMNS = ("X", "Y", "Z", "I", "J", "F", "S")
_STRAIGHT = 1e-12  # relative: a chain piece this close to its chord is a straight move


@dataclass(frozen=True)
class ToolPath:
    """One path of the tool's centre.

    Attributes
    ----------
    points : (n, 3) float
        Where the moves go, the start first.
    centres : (n - 1, 2) float
        The centre of move j when it is a circular arc in XY, NaN when it is straight.
    clockwise : (n - 1,) bool
        Whether arc j turns clockwise seen from +z (G2; else G3).
    """

    points: np.ndarray
    centres: np.ndarray
    clockwise: np.ndarray

    @classmethod
    def polyline(cls, points: np.ndarray) -> ToolPath:
        p = np.asarray(points, dtype=np.float64)
        return cls(p, np.full((max(len(p) - 1, 0), 2), np.nan), np.zeros(max(len(p) - 1, 0), bool))


def arc_moves(chain: np.ndarray, z: float) -> ToolPath:
    """The moves of an arc chain (as :class:`formgraph.kernels.io.Path2D` holds it: ends
    and tangent intersections, ``[A0, T0, A1, T1, ..., Ak]``) at height z.

    An arc from A to B whose tangents meet at T has its centre on the line from T through
    the chord's middle M, at t^2 / h from T (t = |TA|, h = |TM|); a piece whose T lies on
    its chord is a straight move.
    """
    c = np.asarray(chain, dtype=np.float64)[:, :2]
    a, t, b = c[0:-1:2], c[1::2], c[2::2]
    m = 0.5 * (a + b)
    tm = m - t
    ta = a - t
    h2 = np.einsum("ij,ij->i", tm, tm)
    t2 = np.einsum("ij,ij->i", ta, ta)
    turn = (t[:, 0] - a[:, 0]) * (b[:, 1] - t[:, 1]) - (t[:, 1] - a[:, 1]) * (b[:, 0] - t[:, 0])
    scale = max(float(np.abs(c).max()), 1e-300)
    straight = np.abs(turn) <= _STRAIGHT * scale * scale
    centres = np.full((len(a), 2), np.nan)
    arc = ~straight
    centres[arc] = t[arc] + tm[arc] * (t2[arc] / h2[arc])[:, None]
    points = np.c_[np.r_[a[:1], b], np.full(len(b) + 1, float(z))]
    return ToolPath(points, centres, turn < 0)


def gcode_bytes(
    paths: Sequence[ToolPath],
    feed: float,
    plunge: float,
    safe_z: float,
    spindle: float | None = None,
    laser: bool = False,
) -> bytes:
    """The G-code program that runs the paths in order.

    Parameters
    ----------
    paths : sequence of ToolPath
    feed, plunge : float
        Cutting and plunging feeds, mm/min (> 0).
    safe_z : float
        Height of every rapid move (router); above every path.
    spindle : float, optional
        Router: spindle speed (M3 S...; without it the spindle is left to the operator).
        Laser: the power S (default 1000, grbl's full power).
    laser : bool
        Write a laser program (no Z; M4 S on, M5 off per path).

    Raises
    ------
    ValueError
        A feed that is not positive, coordinates that are not finite, a path above the
        safe height.
    """
    for name, v in (("feed", feed), ("plunge", plunge)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"the {name} must be positive (mm/min), got {v}")
    if not np.isfinite(safe_z):
        raise ValueError(f"the safe height must be finite, got {safe_z}")
    for i, p in enumerate(paths):  # one step per path: its checks
        if not np.isfinite(p.points).all():
            raise ValueError(f"path {i} has coordinates that are not finite")
        if not laser and p.points[:, 2].max() >= safe_z:
            raise ValueError(
                f"path {i} reaches z = {p.points[:, 2].max():g}, not below the safe height "
                f"{safe_z:g}: rapid moves there would cut"
            )
    power = 1000.0 if spindle is None and laser else spindle
    blocks = [_path_rows(p, feed, plunge, safe_z, power, laser) for p in paths if len(p.points)]
    head = [b"(formgraph tool paths: mm, absolute)\n", b"G21\nG90\nG17\nG94\n"]
    if laser:
        head.append(b"M5\n")
        tail = [b"M2\n"]
    else:
        head.append(_line("G0", Z=safe_z))
        if spindle is not None:
            head.append(_line("M3", S=spindle))
        tail = [b"M5\n" if spindle is not None else b"", b"M2\n"]
    if not blocks:
        return b"".join(head + tail)
    codes = np.concatenate([b[0] for b in blocks])
    values = {k: np.concatenate([b[1][k] for b in blocks]) for k in _COLUMNS}
    canvases: list[bytes | np.ndarray] = [codes.view(np.uint8).reshape(len(codes), -1)]
    for k in _COLUMNS:  # one column per word: the rows that have it, formatted at once
        v = values[k]
        has = ~np.isnan(v)
        canvas = np.zeros((len(v), 32), dtype=np.uint8)
        if has.any():
            words = float_words(v[has], decimals=DECIMALS, lead=b" " + k.encode()).view(np.uint8)
            canvas[has, : words.shape[1]] = words
        canvases.append(canvas)
    return b"".join(head) + join_rows(canvases, b"\n") + b"".join(tail)


def _line(code: str, **words: float) -> bytes:
    text = code + "".join(f" {k}{_number(v)}" for k, v in words.items())
    return (text + "\n").encode()


def _number(v: float) -> str:
    return squeeze(float_words(np.array([v]), decimals=DECIMALS).view(np.uint8)).decode()


def _path_rows(
    p: ToolPath, feed: float, plunge: float, safe_z: float, power: float | None, laser: bool
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The rows of one path: their codes (S2) and each word's value (NaN: not written)."""
    pts = p.points
    k = len(pts) - 1
    n = k + 3  # the approach, the entry (plunge or beam on), the moves, the exit
    codes = np.empty(n, dtype="S2")
    v = {c: np.full(n, np.nan) for c in _COLUMNS}
    # the approach: a rapid move to above the start (the tool is at the safe height)
    codes[0] = b"G0"
    v["X"][0], v["Y"][0] = pts[0, 0], pts[0, 1]
    if laser:
        codes[1] = b"M4"
        v["S"][1] = power
    else:
        codes[1] = b"G1"
        v["Z"][1] = pts[0, 2]
        v["F"][1] = plunge
    moves = slice(2, 2 + k)
    arc = ~np.isnan(p.centres[:, 0])
    codes[moves] = np.where(arc, np.where(p.clockwise, b"G2", b"G3"), b"G1")
    v["X"][moves], v["Y"][moves] = pts[1:, 0], pts[1:, 1]
    if not laser:
        dz = pts[1:, 2] != pts[:-1, 2]
        v["Z"][moves] = np.where(dz, pts[1:, 2], np.nan)
    v["I"][moves] = np.where(arc, p.centres[:, 0] - pts[:-1, 0], np.nan)
    v["J"][moves] = np.where(arc, p.centres[:, 1] - pts[:-1, 1], np.nan)
    if k:
        v["F"][2] = feed
    # the exit: back up to the safe height, or the beam off
    if laser:
        codes[-1] = b"M5"
    else:
        codes[-1] = b"G0"
        v["Z"][-1] = safe_z
    return codes, v
