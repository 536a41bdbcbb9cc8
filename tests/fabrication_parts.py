"""A fixed set of laser parts for nesting tests and benchmarks: rounded plates with holes,
discs, rings with room for a disc inside, L brackets, gears and slots; every part its own
curves, spread along x so none overlaps another."""

from __future__ import annotations

import numpy as np

import formgraph as fg


def _circle(r: float, x: float, y: float = 0.0) -> fg.NurbsCurve:
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=r, center=[x, y, 0])
    return g.evaluate("c")


def _rect(w: float, h: float, r: float, x: float) -> fg.NurbsCurve:
    g = fg.Graph()
    g.add("c", "curves.rectangle", size=[w, h], radius=r, center=[x, 0, 0])
    return g.evaluate("c")


def _poly(points: np.ndarray, x: float) -> fg.NurbsCurve:
    p = np.c_[points + [x, 0], np.zeros(len(points))]
    return fg.NurbsCurve.polyline(p, closed=True)


def _gear(r: float, teeth: int) -> np.ndarray:
    k = np.arange(teeth * 4)
    a = k * 2 * np.pi / (teeth * 4)
    rr = np.where((k // 2) % 2 == 0, r, 0.85 * r)
    return np.c_[np.cos(a) * rr, np.sin(a) * rr]


KINDS = ("plate", "disc", "ring", "bracket", "gear", "slot", "small disc", "square")


def part(kind: str, x: float) -> list[fg.NurbsCurve]:
    """One part's curves, centred at (x, 0)."""
    if kind == "plate":
        return [_rect(80, 30, 4, x), _circle(1.6, x - 34), _circle(1.6, x + 34)]
    if kind == "disc":
        return [_circle(20, x)]
    if kind == "ring":
        return [_circle(35, x), _circle(22, x)]
    if kind == "bracket":
        return [_poly(np.array([[0, 0], [60, 0], [60, 12], [12, 12], [12, 40], [0, 40.0]]), x)]
    if kind == "gear":
        return [_poly(_gear(25, 12), x)]
    if kind == "slot":
        return [_rect(120, 20, 10, x)]
    if kind == "small disc":
        return [_circle(10, x)]
    return [_rect(40, 40, 0, x), _circle(8, x)]


def benchmark_parts(count: int = 40) -> list[fg.NurbsCurve]:
    """``count`` parts, the kinds in turn, 150 apart along x."""
    out: list[fg.NurbsCurve] = []
    for i in range(count):
        out += part(KINDS[i % len(KINDS)], 150.0 * i)
    return out
