"""NURBS: ours through the public API (``NurbsCurve.evaluate``, ``NurbsSurface.evaluate_grid``
and the ``nurbs.*`` nodes on a curve moved a hair each call), the kernel beside, against
scipy.interpolate.BSpline (compiled, non-rational only), splipy and geomdl (pure Python).

Cases: a degree-3 curve with 100 control points at 100,000 parameters (non-rational and
rational); a 20 x 20 degree-3 surface on a 300 x 300 grid (both); knot insertion and
refinement; a loft of 10 curves with 200 control points each (different knot vectors,
so the compatibility step has real work: 10 x ~2,000 control points); interpolation of
100,000 points (banded solve; scipy's make_interp_spline on the same knots, also banded);
elevation of a 1,000-point cubic by 29 degrees in one step.

Gotchas of the references: geomdl wants lists and parameters in [0, 1] and mutates the
curve in insert_knot (we time it on a fresh copy); splipy's BSplineBasis takes the order
(degree + 1), rational points in homogeneous form, and surface control points with u
varying fastest.
"""

from __future__ import annotations

import copy

import numpy as np
from harness import through

import formgraph as fg
from formgraph.kernels import nurbs as K

N_CP, DEGREE, N_PARAMS = 100, 3, 100_000
GRID, NET = 300, 20


def _curve(rng: np.random.Generator, n: int, degree: int) -> tuple:
    cp = rng.normal(size=(n, 3))
    w = rng.uniform(0.5, 2.0, n)
    inner = np.sort(rng.uniform(0, 1, n - degree - 1))
    knots = np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])
    return cp, degree, knots, w


def _moved_curve(cp, p, knots, w=None):
    """A NurbsCurve param moved a hair each call (a new value: the node runs)."""
    return lambda k: fg.NurbsCurve(cp * (1 + k * 1e-12), p, knots, w)


def run(table) -> None:  # noqa: ANN001 - the harness's Table
    rng = np.random.default_rng(0)
    cp, p, knots, w = _curve(rng, N_CP, DEGREE)
    t = np.linspace(0.0, 1.0, N_PARAMS)
    curve, rcurve = fg.NurbsCurve(cp, p, knots), fg.NurbsCurve(cp, p, knots, w)

    def scipy_curve():
        from scipy.interpolate import BSpline

        spline = BSpline(knots, cp, p)
        return lambda: spline(t)

    def splipy_curve(rational: bool):
        def make():
            from splipy import BSplineBasis, Curve

            if rational:
                c = Curve(BSplineBasis(p + 1, knots), K.homogeneous(cp, w), rational=True)
            else:
                c = Curve(BSplineBasis(p + 1, knots), cp)
            return lambda: c(t)

        return make

    def geomdl_curve(rational: bool):
        def make():
            from geomdl import NURBS, BSpline

            c = NURBS.Curve() if rational else BSpline.Curve()
            c.degree = p
            c.ctrlpts = cp.tolist()
            if rational:
                c.weights = w.tolist()
            c.knotvector = knots.tolist()
            tl = t.tolist()
            return lambda: c.evaluate_list(tl)

        return make

    table.compare(
        f"NurbsCurve.evaluate, p=3, {N_CP} cp, {N_PARAMS:,} params",
        api=lambda: curve.evaluate(t),
        kernel=lambda: K.curve_evaluate(cp, p, knots, None, t),
        references={
            "scipy BSpline": _lazy(scipy_curve),
            "splipy": _lazy(splipy_curve(False)),
            "geomdl": _lazy(geomdl_curve(False)),
        },
        rounds=3,
    )
    table.compare(
        f"NurbsCurve.evaluate, rational, p=3, {N_CP} cp, {N_PARAMS:,} params",
        api=lambda: rcurve.evaluate(t),
        kernel=lambda: K.curve_evaluate(cp, p, knots, w, t),
        references={"splipy": _lazy(splipy_curve(True)), "geomdl": _lazy(geomdl_curve(True))},
        rounds=3,
    )

    # ---- surface on a grid
    net = rng.normal(size=(NET, NET, 3))
    net_w = rng.uniform(0.5, 2.0, (NET, NET))
    ku = K.clamped_uniform_knots(NET, 3)
    kv = _curve(rng, NET, 3)[2]
    g = np.linspace(0.0, 1.0, GRID)
    for rational in (False, True):
        ww = net_w if rational else None
        surface = fg.NurbsSurface(net, 3, 3, ku, kv, ww)
        refs = {}
        if not rational:

            def scipy_surface():
                from scipy.interpolate import BSpline

                def go():
                    bu = BSpline.design_matrix(g, ku, 3).toarray()
                    bv = BSpline.design_matrix(g, kv, 3).toarray()
                    return np.einsum("ai,ijd,bj->abd", bu, net, bv, optimize=True)

                return go

            refs["scipy design matrix"] = _lazy(scipy_surface)

        def splipy_surface(ww=ww):
            from splipy import BSplineBasis, Surface

            pts = K.homogeneous(net, ww)
            s = Surface(
                BSplineBasis(4, ku),
                BSplineBasis(4, kv),
                pts.transpose(1, 0, 2).reshape(-1, pts.shape[-1]),
                rational=ww is not None,
            )
            return lambda: s(g, g)

        def geomdl_surface(ww=ww):
            from geomdl import NURBS

            s = NURBS.Surface()
            s.degree_u = s.degree_v = 3
            s.ctrlpts_size_u = s.ctrlpts_size_v = NET
            s.ctrlpts = net.reshape(-1, 3).tolist()
            s.weights = (np.ones((NET, NET)) if ww is None else ww).reshape(-1).tolist()
            s.knotvector_u, s.knotvector_v = ku.tolist(), kv.tolist()
            uv = [(a, b) for a in g.tolist() for b in g.tolist()]
            return lambda: s.evaluate_list(uv)

        refs["splipy"] = _lazy(splipy_surface)
        refs["geomdl"] = _lazy(geomdl_surface)
        table.compare(
            f"NurbsSurface.evaluate_grid, {'rational ' if rational else ''}{NET}x{NET} p=3, "
            f"{GRID}x{GRID} grid",
            api=lambda surface=surface: surface.evaluate_grid(g, g),
            kernel=lambda ww=ww: K.surface_evaluate_grid(net, 3, 3, ku, kv, ww, g, g),
            references=refs,
            rounds=3,
        )

    # ---- knot insertion and refinement
    def geomdl_insert():
        from geomdl import NURBS, operations

        c = NURBS.Curve()
        c.degree = p
        c.ctrlpts = cp.tolist()
        c.weights = w.tolist()
        c.knotvector = knots.tolist()
        return lambda: operations.insert_knot(copy.deepcopy(c), [0.4321], [2])

    def splipy_insert():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(p + 1, knots), K.homogeneous(cp, w), rational=True)
        return lambda: c.clone().insert_knot([0.4321, 0.4321])

    table.compare(
        f"nurbs.insert_knot (x2) into a rational p=3 curve, {N_CP} cp",
        api=through(
            "nurbs.insert_knot", {"c": _moved_curve(cp, p, knots, w)}, curve="=c", t=0.4321, times=2
        ),
        kernel=lambda: K.insert_knot(cp, p, knots, w, 0.4321, 2),
        references={
            "geomdl (incl. copy)": _lazy(geomdl_insert),
            "splipy (incl. clone)": _lazy(splipy_insert),
        },
        rounds=5,
    )

    new = rng.uniform(0, 1, 1000)

    def splipy_refine():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(p + 1, knots), K.homogeneous(cp, w), rational=True)
        return lambda: c.clone().insert_knot(new.tolist())

    table.compare(
        f"refine a rational p=3 curve, {N_CP} cp, +1,000 knots",
        api=lambda: K.refine_knots(cp, p, knots, w, new),
        references={"splipy (incl. clone)": _lazy(splipy_refine)},
        rounds=3,
        note="the kernel (formgraph.kernels.nurbs.refine_knots): no node inserts many at once",
    )

    def splipy_elevate():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(p + 1, knots), K.homogeneous(cp, w), rational=True)
        return lambda: c.clone().raise_order(2)

    table.compare(
        f"nurbs.elevate_degree 3->5, rational, {N_CP} cp",
        api=through(
            "nurbs.elevate_degree", {"c": _moved_curve(cp, p, knots, w)}, curve="=c", times=2
        ),
        kernel=lambda: K.elevate_degree(cp, p, knots, w, 2),
        references={"splipy (incl. clone)": _lazy(splipy_elevate)},
        rounds=5,
    )

    # ---- loft
    curves = []
    for i in range(10):
        c = _curve(rng, 200, 3)
        curves.append((c[0] + [0, 0, i], 3, c[2], None))
    params = {f"c{i}": _moved_curve(*c) for i, c in enumerate(curves)}
    table.compare(
        "nurbs.loft of 10 curves x 200 cp (distinct knots)",
        api=through("nurbs.loft", params, curves=[f"={n}" for n in params]),
        kernel=lambda: K.loft(curves),
        rounds=5,
    )
    curves_same = [(c[0], 3, curves[0][2], None) for c in curves]
    params = {f"c{i}": _moved_curve(*c) for i, c in enumerate(curves_same)}
    table.compare(
        "nurbs.loft of 10 curves x 200 cp (shared knots)",
        api=through("nurbs.loft", params, curves=[f"={n}" for n in params]),
        kernel=lambda: K.loft(curves_same),
        rounds=5,
    )

    pts = np.cumsum(rng.normal(size=(200, 3)), axis=0)

    def geomdl_interp():
        from geomdl import fitting

        pl = pts.tolist()
        return lambda: fitting.interpolate_curve(pl, 3)

    moved = {"p": lambda k: fg.Points(pts * (1 + k * 1e-12))}
    table.compare(
        "nurbs.interpolate 200 points, p=3",
        api=through("nurbs.interpolate", moved, points="=p"),
        kernel=lambda: K.interpolate(pts, 3),
        references={"geomdl": _lazy(geomdl_interp)},
        rounds=5,
    )

    # ---- interpolation of many points: the banded solve (a dense one would need 80 GB)
    big = 100_000
    tb = np.linspace(0, 60 * np.pi, big)
    pts_big = np.stack([np.cos(tb), np.sin(tb), np.sin(0.37 * tb)], -1)

    def scipy_interp():
        from scipy.interpolate import make_interp_spline

        u = K.interpolation_parameters(pts_big)
        knots_b = K.interpolate(pts_big, 3)[2]  # the same knots (A9.1's averaging)
        return lambda: make_interp_spline(u, pts_big, k=3, t=knots_b)

    moved_big = {"p": lambda k: fg.Points(pts_big * (1 + k * 1e-12))}
    table.compare(
        f"nurbs.interpolate {big:,} points, p=3 (open)",
        api=through("nurbs.interpolate", moved_big, points="=p"),
        kernel=lambda: K.interpolate(pts_big, 3),
        references={"scipy make_interp_spline (the same knots)": _lazy(scipy_interp)},
        rounds=3,
    )
    closed_pts = pts_big[: big - 1]
    table.compare(
        f"nurbs.interpolate {big:,} points, p=3 (closed)",
        api=through(
            "nurbs.interpolate",
            {"p": lambda k: fg.Points(closed_pts * (1 + k * 1e-12))},
            points="=p",
            closed=True,
        ),
        kernel=lambda: K.interpolate(closed_pts, 3, closed=True),
        rounds=3,
    )

    # ---- degree elevation by many degrees at once
    cp_e, _, knots_e, _ = _curve(rng, 1000, 3)

    def splipy_elevate29():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(4, knots_e), cp_e)
        return lambda: c.clone().raise_order(29)

    table.compare(
        "nurbs.elevate_degree 3->32, 1,000 cp",
        api=through(
            "nurbs.elevate_degree", {"c": _moved_curve(cp_e, 3, knots_e)}, curve="=c", times=29
        ),
        kernel=lambda: K.elevate_degree(cp_e, 3, knots_e, None, 29),
        references={"splipy (incl. clone)": _lazy(splipy_elevate29)},
        rounds=1,
        warmup=False,
    )

    hx = np.linspace(0, 6 * np.pi, 512)
    path = np.stack([2 * np.cos(hx), 2 * np.sin(hx), hx / np.pi], -1)
    tang = np.stack([-2 * np.sin(hx), 2 * np.cos(hx), np.full_like(hx, 1 / np.pi)], -1)
    circ = K.circle(0.3)
    helix = fg.NurbsCurve(*K.interpolate(path, 3))
    table.compare(
        "nurbs.sweep of a circle along a helix, 512 stations",
        api=through(
            "nurbs.sweep",
            {"r": lambda k: fg.NurbsCurve(*K.circle(0.3 * (1 + k * 1e-12)))},
            profile="=r",
            path=helix,
            stations=512,
        ),
        kernel=lambda: K.sweep(circ, path, tang),
        rounds=5,
        note="the path a cubic through 512 helix points (the kernel: those points, tangents)",
    )


def _lazy(make):  # noqa: ANN001, ANN202
    """Build the reference lazily so that a missing library is reported, not raised."""
    state: dict = {}

    def call():
        if "fn" not in state:
            state["fn"] = make()
        return state["fn"]()

    return call
