"""Nesting: parts put on rectangular sheets by bottom-left fill over no-fit polygons, the
order they go in searched by a genetic algorithm.

One evaluation places the parts in a given order (Burke et al. 2006's bottom-left fill,
as SVGnest does it): each part, at each allowed turn, may go anywhere in its sheet's
inner-fit rectangle (the translations that keep it on the sheet) outside the no-fit
polygons of the parts already there (:mod:`.nfp`). The free region is a polygon whose
corners are the candidate positions; every corner is scored at once (numpy), and the part
goes to the lowest, then leftmost, of those that keep the sheet's used length (its
rightmost edge) within 1 % of the sheet's width of the shortest; to the first sheet with
room, else to a new sheet. The free region of each part shape and turn on each sheet is
kept and only the no-fit polygons of parts placed since are taken from it, so a sheet's
work grows with the parts on it, not with their square.

The search (SVGnest's, after Burke et al.) is over the order: it starts from the parts by
decreasing area, and breeds orders by one-cut order crossover and swaps of neighbours,
keeping the best ``population``; ``effort`` evaluations in all. An evaluation is scored
by its sheet count, then the used length of its last sheet. Everything is seeded: the
same parts, seed and effort give the same layout, so a graph's result can be cached.

The spacing is kept by growing every part by half of it (mitred, which contains the round
offset: never closer than asked) plus the nesting tolerance: the part's outline is first
simplified within that tolerance (Douglas-Peucker), which the growth then covers, so the
parts placed never come closer than ``spacing`` whatever the simplification dropped.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely

from . import nfp as knfp

__all__ = ["Nesting", "PartTooLarge", "nest"]

_POPULATION = 10
_MUTATION = 0.1  # chance that a part swaps places with the next in a child's order
_FINEST = 8  # grid steps the tolerance spans at least
_SLACK = 0.01  # of the sheet's width: used lengths this close count as equal
_GROW_MITRE = 2.0  # mitre limit of the growth by half the spacing (>= 1: contains the round)
_FIT = 1e-9  # relative: a part this close to the sheet's size fits it


class PartTooLarge(ValueError):
    """A part that fits the sheet at none of the allowed turns; ``part`` is its index."""

    def __init__(self, part: int, size: tuple[float, float], sheet: tuple[float, float]):
        super().__init__(
            f"part {part} ({size[0]:.6g} x {size[1]:.6g}) does not fit on "
            f"the {sheet[0]:.6g} x {sheet[1]:.6g} sheet at any allowed turn"
        )
        self.part = part


@dataclass(frozen=True)
class Nesting:
    """Where each part went: part i's point x goes to ``R(angle[i]) @ x + offset[i]`` on
    sheet ``sheet[i]`` (in the sheet's own frame, its corner at the origin).

    Attributes
    ----------
    sheet : (n,) int
    angle : (n,) float
        Radians, counter-clockwise.
    offset : (n, 2) float
    sheets : int
        Sheets used.
    length : float
        How far the parts reach along x on the last sheet.
    utilisation : float
        The parts' area over the sheets' area used: every sheet full but the last, and of
        the last the strip up to ``length`` (what is right of it is an offcut to keep).
    evaluations : int
        Layouts tried.
    """

    sheet: np.ndarray
    angle: np.ndarray
    offset: np.ndarray
    sheets: int
    length: float
    utilisation: float
    evaluations: int


@dataclass
class _Shape:
    """One part shape (congruent parts share it) at one turn, on the grid."""

    outer: np.ndarray  # (m, 2) int64: the grown outline
    holes: list[np.ndarray]
    low: np.ndarray  # (2,) int64: the inner-fit rectangle of its translations
    high: np.ndarray
    right: int  # its containment box's right edge, from its reference point
    area: float
    fits: bool  # whether the sheet holds it at this turn


class _Problem:
    """The parts on the grid, and the no-fit polygons between their shapes (made once
    each, when first asked for)."""

    def __init__(
        self,
        polygons: list[shapely.Polygon],
        sheet: tuple[float, float],
        spacing: float,
        rotations: int,
        tolerance: float,
    ) -> None:
        self.n = len(polygons)
        self.angles = 2 * np.pi * np.arange(rotations) / rotations
        bounds = shapely.bounds(np.array(polygons, dtype=object))
        self.centre = 0.5 * (bounds[:, :2] + bounds[:, 2:])
        diag = float(np.hypot(*(bounds[:, 2:] - bounds[:, :2]).T).max()) + spacing + 2 * tolerance
        self.scale = knfp.grid_scale(max(sheet) + 2 * diag)
        self.sheet = sheet
        self.tolerance = tolerance
        self.area = shapely.area(np.array(polygons, dtype=object))
        # congruent parts (the same outline up to a translation) share their no-fit polygons
        keys: dict[bytes, int] = {}
        self.kind = np.empty(self.n, dtype=np.int64)
        firsts: list[int] = []
        step = tolerance * 1e-3
        for i, poly in enumerate(polygons):  # one step per part: its key
            rel = shapely.get_coordinates(poly) - self.centre[i]
            key = np.round(rel / step).astype(np.int64).tobytes()
            self.kind[i] = keys.setdefault(key, len(firsts))
            if self.kind[i] == len(firsts):
                firsts.append(i)
        self.shapes: list[list[_Shape]] = []
        for i in firsts:  # one step per distinct shape
            rel = shapely.transform(polygons[i], lambda xy, c=self.centre[i]: xy - c)
            grown = shapely.buffer(
                shapely.simplify(rel, tolerance),
                tolerance + spacing / 2,
                join_style="mitre",
                mitre_limit=_GROW_MITRE,
            )
            if shapely.get_type_id(grown) != 3:  # a growth joins no parts: take the hull
                grown = shapely.convex_hull(grown)
            ring = shapely.get_coordinates(rel.exterior)
            turns = []
            for k, a in enumerate(self.angles):  # one step per turn
                turns.append(self._shape(grown, ring, a, tolerance, i, k))
            self.shapes.append(turns)
        self._nfp: dict[tuple[int, int, int, int], tuple[list[np.ndarray], np.ndarray]] = {}
        self._base: dict[tuple[int, int, int], list[np.ndarray]] = {}

    def _shape(
        self, grown: shapely.Polygon, ring: np.ndarray, a: float, tol: float, i: int, k: int
    ) -> _Shape:
        c, s = math.cos(a), math.sin(a)
        rot = np.array([[c, -s], [s, c]])

        def grid(points: np.ndarray) -> np.ndarray:
            return np.round(points @ rot.T * self.scale).astype(np.int64)

        outer = grid(shapely.get_coordinates(grown.exterior)[:-1])
        holes = [grid(shapely.get_coordinates(h)[:-1]) for h in grown.interiors]
        turned = ring @ rot.T
        bare_lo, bare_hi = turned.min(axis=0), turned.max(axis=0)
        lo, hi = bare_lo - tol, bare_hi + tol  # the margin covers the outline's sampling
        size = np.array(self.sheet)
        low = np.ceil(-lo * self.scale).astype(np.int64)
        high = np.floor((size - hi) * self.scale).astype(np.int64)
        # a part as large as the sheet (within a relative _FIT) fits without the margin: it
        # goes to the middle of what is left, on the grid
        tight = (low > high) & (bare_hi - bare_lo <= size * (1 + _FIT))
        middle = np.round(0.5 * (size - bare_hi - bare_lo) * self.scale).astype(np.int64)
        low, high = np.where(tight, middle, low), np.where(tight, middle, high)
        right = int(math.ceil(bare_hi[0] * self.scale))
        return _Shape(outer, holes, low, high, right, self.area[i], bool(np.all(low <= high)))

    def nfp(self, a: int, ka: int, b: int, kb: int) -> tuple[list[np.ndarray], np.ndarray]:
        """The no-fit polygon of shape a at turn ka (placed at the origin) and shape b at
        turn kb, with its box (xmin, ymin, xmax, ymax). Made once per relative turn: the
        polygon of (a, 0, b, kb - ka) turned by ka (exactly, on the grid, for quarter turns)."""
        key = (a, ka, b, kb)
        got = self._nfp.get(key)
        if got is None:
            rel = (kb - ka) % len(self.angles)
            base = self._base.get((a, b, rel))
            if base is None:
                fixed, moving = self.shapes[a][0], self.shapes[b][rel]
                base = knfp.no_fit(fixed.outer, fixed.holes, moving.outer)
                self._base[(a, b, rel)] = base
            paths = [_turn(r, self.angles[ka]) for r in base]
            pts = np.concatenate(paths)
            got = (paths, np.r_[pts.min(axis=0), pts.max(axis=0)])
            self._nfp[key] = got
        return got


def _turn(ring: np.ndarray, angle: float) -> np.ndarray:
    """Integer points turned by ``angle`` about the origin: exact for quarter turns."""
    quarter = angle / (np.pi / 2)
    if abs(quarter - round(quarter)) < 1e-12:
        x, y = ring[:, 0], ring[:, 1]
        k = round(quarter) % 4
        return [ring, np.c_[-y, x], -ring, np.c_[y, -x]][k]
    c, s = math.cos(angle), math.sin(angle)
    return np.round(ring @ np.array([[c, s], [-s, c]])).astype(np.int64)


class _Sheet:
    """The parts on one sheet, and the free region of each shape and turn on it."""

    def __init__(self, area: float) -> None:
        self.placed: list[tuple[int, int, np.ndarray]] = []
        self.free: dict[tuple[int, int], tuple[list[np.ndarray], int]] = {}
        self.room = area
        self.right = 0

    def positions(self, problem: _Problem, t: int, k: int) -> np.ndarray | None:
        """The corners of the free region of shape t at turn k: (c, 2) int64, or None."""
        shape = problem.shapes[t][k]
        if not shape.fits:
            return None
        paths, done = self.free.get((t, k), (None, 0))
        if paths is None:
            lo, hi = shape.low, shape.high
            paths = [np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])]
        if done < len(self.placed) and paths:
            pts = np.concatenate(paths)
            box = np.r_[pts.min(axis=0), pts.max(axis=0)]
            clips = []
            for a, ka, v in self.placed[done:]:  # one step per part placed since
                rings, b = problem.nfp(a, ka, t, k)
                if (b[0] + v[0] > box[2]) or (b[2] + v[0] < box[0]):
                    continue
                if (b[1] + v[1] > box[3]) or (b[3] + v[1] < box[1]):
                    continue
                clips += [r + v for r in rings]
            paths = knfp.feasible(paths, clips)
        self.free[(t, k)] = (paths, len(self.placed))
        if not paths:
            return None
        return np.concatenate(paths)


def _lowest(right: np.ndarray, xy: np.ndarray, slack: int) -> int:
    """The candidate to take: of those that keep the used length within ``slack`` of the
    shortest, the lowest, then the leftmost. A hair further left must not beat a place far
    lower down (rounded corners that nest into each other would otherwise start a new
    column at the top of the sheet)."""
    near = np.flatnonzero(right <= right.min() + slack)
    return int(near[np.lexsort((xy[near, 0], xy[near, 1]))[0]])


def _evaluate(problem: _Problem, order: np.ndarray) -> tuple[float, np.ndarray]:
    """Bottom-left fill of the parts in ``order``: its score (sheets, then the last one's
    used length) and per part (sheet, turn, x, y) on the grid."""
    w = problem.sheet[0] * problem.scale
    sheet_area = problem.sheet[0] * problem.sheet[1]
    sheets: list[_Sheet] = []
    slack = int(_SLACK * min(w, problem.sheet[1] * problem.scale))
    out = np.zeros((problem.n, 4), dtype=np.int64)
    for i in order.tolist():  # one step per part
        t = int(problem.kind[i])
        placed = False
        for s, sh in enumerate([*sheets, None]):
            if sh is None:
                sh = _Sheet(sheet_area)
                sheets.append(sh)
            elif sh.room < problem.area[i] * (1 - 1e-9):
                continue
            bests = []
            for k in range(len(problem.angles)):  # one step per turn
                cand = sh.positions(problem, t, k)
                if cand is None:
                    continue
                shape = problem.shapes[t][k]
                right = np.maximum(cand[:, 0] + shape.right, sh.right)
                j = _lowest(right, cand, slack)
                bests.append((int(right[j]), int(cand[j, 1]), int(cand[j, 0]), k))
            if not bests:
                if s == len(sheets) - 1 and not sh.placed:
                    raise AssertionError("a part that fits an empty sheet found no room")
                continue
            rows = np.array(bests, dtype=np.int64)
            j = _lowest(rows[:, 0], rows[:, 2:0:-1], slack)
            k, v = int(rows[j, 3]), rows[j, 2:0:-1].copy()
            shape = problem.shapes[t][k]
            sh.placed.append((t, k, v))
            sh.room -= problem.area[i]
            sh.right = max(sh.right, int(v[0]) + shape.right)
            out[i] = (s, k, v[0], v[1])
            placed = True
            break
        assert placed
    return len(sheets) - 1 + sheets[-1].right / w, out


def nest(
    parts: Sequence[Sequence[np.ndarray]],
    sheet: tuple[float, float],
    spacing: float = 0.0,
    rotations: int = 4,
    seed: int = 0,
    effort: int = 1,
    tolerance: float | None = None,
) -> Nesting:
    """Put parts on ``sheet``-sized sheets without overlap, at least ``spacing`` apart.

    Parameters
    ----------
    parts : sequence of sequences of (m, 2) float
        Each part's rings: its outer boundary first, then its holes (any orientation).
    sheet : (width, height)
        The sheet, its corner at the origin.
    spacing : float
        Smallest distance between two parts (the kerf plus the web).
    rotations : int
        Equal turns allowed (1: none; 4: quarter turns).
    seed : int
        Seed of the search.
    effort : int
        Layouts tried (evaluations of bottom-left fill); 1 places the parts by decreasing
        area once.
    tolerance : float, optional
        The parts' outlines are simplified within this for the no-fit polygons (the growth
        covers it). Default: 1e-4 of the sheet's diagonal.

    Returns
    -------
    Nesting

    Raises
    ------
    PartTooLarge
        A part that fits the sheet at no allowed turn.
    ValueError
        Bad sizes or counts.
    """
    w, h = float(sheet[0]), float(sheet[1])
    if not (w > 0 and h > 0 and math.isfinite(w) and math.isfinite(h)):
        raise ValueError(f"the sheet must be two positive finite sizes, got {list(sheet)}")
    if not (spacing >= 0 and math.isfinite(spacing)):
        raise ValueError(f"the spacing must be zero or more, got {spacing}")
    if rotations < 1:
        raise ValueError(f"rotations must be 1 or more, got {rotations}")
    if effort < 1:
        raise ValueError(f"effort must be 1 or more evaluations, got {effort}")
    # two parts on one sheet are never farther apart than its diagonal: any spacing beyond
    # it gives each part a sheet of its own, as twice the diagonal does, on a finer grid
    spacing = min(spacing, 2 * math.hypot(w, h))
    polygons = [shapely.Polygon(r[0], list(r[1:])) for r in parts]
    if not polygons:
        z = np.zeros(0)
        return Nesting(np.zeros(0, np.int64), z, np.zeros((0, 2)), 0, 0.0, 0.0, 0)
    box = shapely.bounds(np.array(polygons, dtype=object))
    smallest = float(np.min(np.max(box[:, 2:] - box[:, :2], axis=1)))
    if tolerance is None:  # 1e-4 of the sheet, and never coarse next to the smallest part
        tol = min(1e-4 * math.hypot(w, h), 1e-3 * smallest)
    elif not (math.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"the tolerance must be positive, got {tolerance}")
    else:
        tol = float(tolerance)
    problem = _Problem(polygons, (w, h), spacing, rotations, tol)
    if tol * problem.scale < _FINEST:
        raise ValueError(
            f"the sheet ({w:.6g} x {h:.6g}) is too large for the nesting grid next to the "
            f"tolerance {tol:.3g} (the parts' smallest is {smallest:.3g}): the grid has 2**29 "
            "steps; scale the drawing, or give a coarser tolerance"
        )
    for t, turns in enumerate(problem.shapes):  # a part that fits at no turn is named
        if not any(s.fits for s in turns):
            i = int(np.flatnonzero(problem.kind == t)[0])
            lo, hi = shapely.bounds(polygons[i]).reshape(2, 2)
            size = hi - lo
            raise PartTooLarge(i, (float(size[0]), float(size[1])), (w, h))
    best_score, best, evaluations = _search(problem, seed, effort)
    sheet_of = best[:, 0]
    k = best[:, 1]
    angle = problem.angles[k]
    c, s = np.cos(angle), np.sin(angle)
    cx, cy = problem.centre[:, 0], problem.centre[:, 1]
    rc = np.c_[c * cx - s * cy, s * cx + c * cy]
    offset = best[:, 2:] / problem.scale - rc
    sheets = int(sheet_of.max()) + 1
    length = (best_score - (sheets - 1)) * w
    used = (sheets - 1) * w * h + length * h
    # the grid's rounding may make a sheet-sized part's used length a hair short
    util = min(1.0, float(problem.area.sum() / used)) if used > 0 else 0.0
    return Nesting(sheet_of, angle, offset, sheets, float(length), util, evaluations)


def _search(problem: _Problem, seed: int, effort: int) -> tuple[float, np.ndarray, int]:
    """The genetic search over orders: the best layout found in ``effort`` evaluations."""
    rng = np.random.default_rng(seed)
    n = problem.n
    first = np.argsort(-problem.area, kind="stable")
    memo: dict[bytes, tuple[float, np.ndarray]] = {}
    used = 0

    def evaluate(order: np.ndarray) -> tuple[float, np.ndarray]:
        nonlocal used
        used += 1
        key = problem.kind[order].tobytes()  # congruent parts swapped change nothing
        got = memo.get(key)
        if got is None:
            got = _evaluate(problem, order)
            memo[key] = got
        return got

    def mutate(order: np.ndarray) -> np.ndarray:
        child = order.copy()
        swaps = np.flatnonzero(rng.random(n - 1) < _MUTATION)
        for j in swaps.tolist():  # one step per swap
            child[j], child[j + 1] = child[j + 1], child[j]
        return child

    population = [(evaluate(first), first)]
    while used < min(effort, _POPULATION):
        o = mutate(first)
        population.append((evaluate(o), o))
    while used < effort and n > 1:
        population.sort(key=lambda e: e[0][0])
        weights = np.arange(len(population), 0, -1, dtype=np.float64)
        weights /= weights.sum()
        a, b = rng.choice(len(population), size=2, replace=False, p=weights)
        pa, pb = population[a][1], population[b][1]
        cut = int(rng.integers(1, n))
        head = pa[:cut]
        child = np.concatenate([head, pb[~np.isin(pb, head)]])
        child = mutate(child)
        population.append((evaluate(child), child))
        population = sorted(population, key=lambda e: e[0][0])[:_POPULATION]
    (score, placed), _ = min(population, key=lambda e: e[0][0])
    return score, placed, used
