"""Exact parametric lengths: the 100-turn helix's arc length through ``curves.parametric``
-> ``curves.measure`` (the curve new each call: its z scaled by a param moved a hair),
(forward-mode derivatives of the expressions, adaptive Gauss-Legendre to 1e-12) against
scipy's ``integrate.quad`` on the hand-written speed, both to their tolerance; the error of
each against 200 pi sqrt(1.01) is in the note; and a damped wiggle whose speed varies,
against quad on its hand-written speed.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

import formgraph as fg
from formgraph.geometry import ParametricCurve
from formgraph.kernels.curves import measure as kmeasure
from formgraph.kernels.curves.adaptive import refine_breaks
from formgraph.language.bound import Bound
from formgraph.language.expr import compile_expression

TURNS = 100
EXACT = 2 * math.pi * TURNS * math.sqrt(1.01)


def _wiggle() -> ParametricCurve:
    texts = ("t", "sin(40 * t) * exp(-t)", "t**2 / 3")
    fx, fy, fz = (Bound(compile_expression(t), {}) for t in texts)
    return ParametricCurve(fx, fy, fz, (0.0, 3.0), 256)


def wiggle_scipy() -> float:
    from scipy.integrate import quad

    def speed(t: float) -> float:
        dy = 40 * math.cos(40 * t) * math.exp(-t) - math.sin(40 * t) * math.exp(-t)
        return math.sqrt(1 + dy * dy + (2 * t / 3) ** 2)

    return quad(speed, 0, 3, limit=5000, epsabs=0, epsrel=1e-12)[0]


def _helix() -> ParametricCurve:
    fx, fy, fz = (Bound(compile_expression(t), {}) for t in ("cos(t)", "sin(t)", "t / 10"))
    return ParametricCurve(fx, fy, fz, (0.0, 2 * math.pi * TURNS), 256)


def ours(curve: ParametricCurve) -> float:
    breaks = np.linspace(*curve.domain, 257)
    breaks = refine_breaks(lambda t: np.linalg.norm(curve.derivative(t), axis=1), breaks)
    return kmeasure.length_and_area(curve.evaluate, curve.derivative, breaks, False)[0]


def with_scipy() -> float:
    from scipy.integrate import quad

    def speed(t: float) -> float:
        return math.sqrt(math.sin(t) ** 2 + math.cos(t) ** 2 + 0.01)

    return quad(speed, 0, 2 * math.pi * TURNS, limit=5000, epsabs=0, epsrel=1e-12)[0]


def _graph(x: str, y: str, z: str, t1: float):
    """``curves.parametric`` -> ``curves.measure``, the param ``a`` (1 + a hair more each
    call) scaling the curve's z: the curve is new each call, so the measure runs."""
    g = fg.Graph()
    g.add_param("a", 1.0)
    g.add("c", "curves.parametric", x=x, y=y, z=z, t=[0.0, t1], samples=256)
    g.add("m", "curves.measure", curve="@c")
    steps = itertools.count(1)
    return lambda: g.evaluate("m", a=1.0 + next(steps) * 1e-15).length


def run(table) -> None:
    curve = _helix()
    err = abs(ours(curve) - EXACT) / EXACT
    try:
        ref = abs(with_scipy() - EXACT) / EXACT
    except ImportError:
        ref = float("nan")
    helix = _graph("=cos(t)", "=sin(t)", "=a * t / 10", 2 * math.pi * TURNS)
    table.compare(
        f"curves.measure of a {TURNS}-turn helix's length, to 1e-12",
        api=helix,
        kernel=lambda: ours(curve),
        references={"scipy quad (the speed written by hand)": with_scipy},
        notes={"scipy quad (the speed written by hand)": f"rel. error {ref:.1e}"},
        rounds=5,
        note=f"through curves.parametric; rel. error {err:.1e}",
    )
    wiggle = _wiggle()
    try:
        ref_len = wiggle_scipy()
        note = f"differs from quad by {abs(ours(wiggle) - ref_len) / ref_len:.1e}"
    except ImportError:
        note = ""
    table.compare(
        "curves.measure of a damped sin(40 t) wiggle's length, to 1e-12",
        api=_graph("=t", "=sin(40 * t) * exp(-t)", "=a * t**2 / 3", 3.0),
        kernel=lambda: ours(wiggle),
        references={"scipy quad (the speed written by hand)": wiggle_scipy},
        rounds=5,
        note=note,
    )
