"""Exact outlines back from a region boolean: runs of an exact curve's samples as its arcs.

A region boolean works on samples of the curves (chords within the tolerance). GEOS keeps
every input vertex it does not cut bit for bit, so each vertex of a result ring is either
a sample of an input curve — whose curve and parameter are known — or a new point where
two chords cross. A run of result vertices along one exact curve is that curve's arc
between the run's ends; each end is a crossing, found exactly by Newton's method on the two
exact curves (or on the curve and the straight segment it meets), started from where the
chords cross. The arc is cut out of the curve's Bezier pieces (The NURBS Book, A5.6) by de
Casteljau's algorithm on the homogeneous points, each piece put in standard form (end
weights 1, a Moebius reparametrization that keeps the curve), and the pieces and the
straight segments between them are joined into one NURBS curve (:class:`.io.chains.Chain`,
lower degrees raised exactly). Points on an arc are then on the exact curve (a circle's to
rounding), not within the tolerance of it.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..io.chains import Chain, line_piece
from ..nurbs import decompose_bezier
from .sampling import bezier_pieces, piece_jet

__all__ = ["Source", "SampleIndex", "exact_outline"]

_NEWTON = 30  # iterations at most (quadratic convergence from a tolerance away: a few)


@dataclass(frozen=True)
class Source:
    """One exact input curve and its sampling (closed, the closing point left out)."""

    control_points: np.ndarray
    degree: int
    knots: np.ndarray
    weights: np.ndarray | None
    samples: np.ndarray  # (m, 2)
    params: np.ndarray  # (m,)

    def jet(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """XY of the curve and of its first derivative at ``t`` (from the power form of
        its Bezier pieces: a few flops, not a general NURBS evaluation)."""
        coef, breaks = self._power
        k = min(max(int(np.searchsorted(breaks, t, side="right")) - 1, 0), len(breaks) - 2)
        width = breaks[k + 1] - breaks[k]
        pt, d = piece_jet(coef, k, (t - breaks[k]) / width)
        return pt, d / width

    @functools.cached_property
    def span(self) -> float:
        """The diagonal of the samples' box: the scale of rounding on this curve."""
        return float(np.hypot(*np.ptp(self.samples, axis=0)))

    @functools.cached_property
    def bezier(self) -> np.ndarray:
        """The curve's Bezier pieces in XY as homogeneous points (k, p + 1, 4) (A5.6)."""
        seg, sw = decompose_bezier(self.control_points, self.degree, self.knots, self.weights)
        w = np.ones(seg.shape[:2]) if sw is None else sw
        seg = seg.copy()
        seg[:, :, 2] = 0.0  # in the XY plane, as the region is
        return np.concatenate([seg * w[:, :, None], w[:, :, None]], axis=2)

    @functools.cached_property
    def _power(self) -> tuple[np.ndarray, np.ndarray]:
        coef = bezier_pieces(self.control_points, self.degree, self.knots, self.weights)
        n = len(self.control_points)
        return coef, np.unique(np.asarray(self.knots, dtype=np.float64)[self.degree : n + 1])

    @property
    def domain(self) -> tuple[float, float]:
        p, n = self.degree, len(self.control_points)
        return float(self.knots[p]), float(self.knots[n])


class SampleIndex:
    """Which source sample (curve, index) a point is, by exact coordinates, vectorized."""

    def __init__(self, sources: Sequence[Source]):
        pts = [s.samples for s in sources]
        self.curve = np.concatenate([np.full(len(p), i) for i, p in enumerate(pts)])
        self.index = np.concatenate([np.arange(len(p)) for p in pts])
        keys = _keys(np.concatenate(pts))
        self.order = np.argsort(keys, kind="stable")
        self.sorted = keys[self.order]

    def find(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per point its source curve and sample index, or -1 and -1."""
        keys = _keys(points)
        at = np.minimum(np.searchsorted(self.sorted, keys), len(self.sorted) - 1)
        hit = self.sorted[at] == keys
        k = self.order[at]
        return np.where(hit, self.curve[k], -1), np.where(hit, self.index[k], -1)


def _keys(points: np.ndarray) -> np.ndarray:
    """Each (x, y) as one 16-byte key: equal keys are equal doubles, bit for bit."""
    p = np.ascontiguousarray(points[:, :2], dtype=np.float64)
    return p.view(np.dtype((np.void, 16))).ravel()


def exact_outline(
    ring: np.ndarray, sources: Sequence[Source], index: SampleIndex, tol: float
) -> tuple[np.ndarray, int, np.ndarray, np.ndarray | None] | None:
    """The closed ring (m, 2) (its closing point left out) as exact NURBS arrays, its runs
    along exact sources rebuilt as their arcs; None if no run lies along one, or if a
    crossing made exact moves farther from the ring's than chords within ``tol`` of their
    curves can cross (then the ring is the outline, as a polyline).

    Vertices are looked up all at once; only the crossings (a few per ring) and the runs'
    ends are visited one by one.
    """
    m = len(ring)
    curve, idx = index.find(ring)
    param = np.full(m, np.nan)
    hit = curve >= 0
    for c in np.unique(curve[hit]):  # one step per source the ring meets
        at = curve == c
        param[at] = sources[c].params[idx[at]]
    nxt = np.roll(np.arange(m), -1)
    # segment i (vertex i to i + 1) lies along source c when both ends are samples of c...
    along = np.where(hit & (curve == curve[nxt]), curve, -1)
    # ... or one end is a crossing on c's chord beside the other end, a sample of c
    on: dict[tuple[int, int], float] = {}  # (crossing vertex, source) -> parameter
    for i in np.flatnonzero(~hit):  # the crossings: a few per ring
        for seg, k in ((i - 1) % m, (i - 1) % m), (i, (i + 1) % m):
            c = int(curve[k])
            if c < 0:
                continue
            t = on.get((i, c))
            if t is None:
                t = _on_chord(ring[i], sources[c], int(idx[k]))
                if t is None:
                    continue
                on[(i, c)] = t
            along[seg] = c
    if not (along >= 0).any():
        return None

    def t_at(i: int, c: int) -> float:
        return on[(i, c)] if (i, c) in on else float(param[i])

    point = np.array(ring, dtype=np.float64)
    # the ends of every run, made exact: on both curves, or on the curve and the segment;
    # chords within tol of curves that cross at an angle a cross within tol / sin(a) of
    # where the curves do, which bounds how far Newton may move a crossing
    ends = np.flatnonzero(along != np.roll(along, 1))
    for i in ends:  # the runs' ends: a few per ring
        before, after = int(along[(i - 1) % m]), int(along[i])
        if before >= 0 and after >= 0:
            t0, t1 = _meet(sources[before], sources[after], t_at(i, before), t_at(i, after))
            on[(i, before)], on[(i, after)] = t0, t1
            new, u = sources[before].jet(t0)
            v = sources[after].jet(t1)[1]
        else:
            c = before if before >= 0 else after
            other = point[(i + 1) % m] if after < 0 else point[(i - 1) % m]
            t = _meet_line(sources[c], t_at(i, c), point[i], other)
            on[(i, c)] = t
            new, u = sources[c].jet(t)
            v = other - point[i]
        sin = abs(u[0] * v[1] - u[1] * v[0]) / max(float(np.hypot(*u) * np.hypot(*v)), 1e-300)
        if not np.hypot(*(new - ring[i])) <= max(4.0 * tol / max(sin, 1e-6), tol):
            return None  # Newton went to another crossing: keep the polyline
        point[i] = new
    start = int(ends[0]) if len(ends) else 0
    order = np.roll(np.arange(m), -start)
    cuts = np.flatnonzero(np.diff(along[order])) + 1
    chain = Chain()
    for run in np.split(order, cuts):  # one step per run along a source, or straight run
        c = int(along[run[0]])
        if c < 0:
            for i in run:  # straight segments between crossings and polyline vertices
                a, b = point[i], point[(i + 1) % m]
                if not np.array_equal(a, b):
                    chain.add(line_piece(np.r_[a, 0.0], np.r_[b, 0.0]))
            continue
        verts = np.append(run, (run[-1] + 1) % m)
        ts = param[verts]
        for k in {0, len(verts) - 1, *np.flatnonzero(np.isnan(ts)).tolist()}:  # ends, crossings
            ts[k] = t_at(int(verts[k]), c)
        chain.add(_arc(sources[c], ts))
    return chain.curve()


def _on_chord(x: np.ndarray, src: Source, j: int) -> float | None:
    """The parameter of point ``x`` on the chord from sample j to a neighbour, if on one."""
    m = len(src.samples)
    hi = src.domain[1]
    best = None
    for step in (1, -1):
        k = (j + step) % m
        p, q = src.samples[j], src.samples[k]
        d = q - p
        den = float(d @ d)
        if den == 0:
            continue
        f = float((x - p) @ d) / den
        gap = float(np.hypot(*(x - p - f * d)))
        if -1e-9 <= f <= 1 + 1e-9 and (best is None or gap < best[0]):
            tj, tk = src.params[j], src.params[k]
            if step == 1 and k == 0:
                tk = hi  # the chord that closes the loop ends at the domain's end
            if step == -1 and j == 0:
                tj = hi
            best = (gap, tj + f * (tk - tj))
    if best is None:
        return None
    return best[1] if best[0] <= 1e-9 * max(src.span, 1e-300) else None


def _wrap(src: Source, t: float) -> float:
    lo, hi = src.domain
    return lo + (t - lo) % (hi - lo)


def _meet(a: Source, b: Source, s: float, t: float) -> tuple[float, float]:
    """Where curves a and b cross, by Newton's method on a(s) - b(t) = 0 from (s, t)."""
    for _ in range(_NEWTON):
        (pa, ja), (pb, jb) = a.jet(s), b.jet(t)
        r = pa - pb
        det = -ja[0] * jb[1] + jb[0] * ja[1]
        if det == 0:
            break
        ds = (-r[0] * jb[1] + jb[0] * r[1]) / det
        dt = (ja[0] * r[1] - ja[1] * r[0]) / det
        s, t = _wrap(a, s - ds), _wrap(b, t - dt)
        if abs(ds) + abs(dt) <= 1e-15 * (1 + abs(s) + abs(t)):
            break
    return s, t


def _meet_line(a: Source, t: float, x: np.ndarray, y: np.ndarray) -> float:
    """Where curve a crosses the line through x and y, by Newton's method from t."""
    d = y - x
    for _ in range(_NEWTON):
        pt, g = a.jet(t)
        r = pt - x
        df = g[0] * d[1] - g[1] * d[0]
        if df == 0:
            break
        step = (r[0] * d[1] - r[1] * d[0]) / df
        t = _wrap(a, t - step)
        if abs(step) <= 1e-15 * (1 + abs(t)):
            break
    return t


def _arc(src: Source, ts: np.ndarray) -> list[np.ndarray]:
    """The source curve from ts[0] through ts[1], ... to ts[-1] (running either way, maybe
    across its seam) as homogeneous Bezier pieces (k, p + 1, 4) in standard form."""
    lo, hi = src.domain
    period = hi - lo
    steps = np.diff(np.asarray(ts))
    steps = (steps + period / 2) % period - period / 2  # the short way between neighbours
    forward = steps.sum() > 0
    a = ts[0]
    b = a + steps.sum()
    first, last = (a, b) if forward else (b, a)  # first < last, maybe past hi
    pieces = src.bezier
    breaks = np.unique(np.asarray(src.knots)[src.degree : len(src.control_points) + 1])
    out = []
    for shift in (-period, 0.0, period):  # before the seam, within the domain, after it
        u0, u1 = max(first, lo + shift) - shift, min(last, hi + shift) - shift
        if u1 <= u0:
            continue
        for k in range(len(breaks) - 1):  # the curve's Bezier pieces: a handful
            s0, s1 = max(u0, breaks[k]), min(u1, breaks[k + 1])
            if s1 <= s0:
                continue
            w = breaks[k + 1] - breaks[k]
            out.append(_sub(pieces[k], (s0 - breaks[k]) / w, (s1 - breaks[k]) / w))
    if not forward:
        out = [q[::-1] for q in out[::-1]]
    return [_standard(q) for q in out]


def _sub(hw: np.ndarray, u0: float, u1: float) -> np.ndarray:
    """The homogeneous Bezier piece restricted to [u0, u1] of [0, 1] (de Casteljau)."""
    left = _split(hw, u1)[0] if u1 < 1 else hw
    return _split(left, u0 / u1)[1] if u0 > 0 else left


def _split(hw: np.ndarray, u: float) -> tuple[np.ndarray, np.ndarray]:
    rows = hw.copy()
    left, right = [rows[0]], [rows[-1]]
    while len(rows) > 1:  # degree steps
        rows = (1 - u) * rows[:-1] + u * rows[1:]
        left.append(rows[0])
        right.append(rows[-1])
    return np.array(left), np.array(right[::-1])


def _standard(hw: np.ndarray) -> np.ndarray:
    """The same rational Bezier with end weights 1 (w_i -> w_i lam^i / w_0)."""
    p = len(hw) - 1
    w0, wp = hw[0, 3], hw[-1, 3]
    lam = (w0 / wp) ** (1.0 / p)
    return hw * (lam ** np.arange(p + 1) / w0)[:, None]
