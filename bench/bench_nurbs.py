"""NURBS kernel benchmark: ours vs scipy.interpolate.BSpline (compiled, non-rational only),
splipy and geomdl (pure Python).

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

from formgraph.kernels import nurbs as K

N_CP, DEGREE, N_PARAMS = 100, 3, 100_000
GRID, NET = 300, 20


def _curve(rng: np.random.Generator, n: int, degree: int) -> tuple:
    cp = rng.normal(size=(n, 3))
    w = rng.uniform(0.5, 2.0, n)
    inner = np.sort(rng.uniform(0, 1, n - degree - 1))
    knots = np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])
    return cp, degree, knots, w


def run(table) -> None:  # noqa: ANN001 - the harness's Table
    rng = np.random.default_rng(0)
    cp, p, knots, w = _curve(rng, N_CP, DEGREE)
    t = np.linspace(0.0, 1.0, N_PARAMS)

    # ---- curve, non-rational
    case = f"curve p=3, {N_CP} cp, {N_PARAMS:,} params"
    ours = table.time(case, "formgraph", lambda: K.curve_evaluate(cp, p, knots, None, t))

    def scipy_curve():
        from scipy.interpolate import BSpline

        spline = BSpline(knots, cp, p)
        return lambda: spline(t)

    table.time(case, "scipy BSpline", _lazy(scipy_curve))

    def splipy_curve():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(p + 1, knots), cp)
        return lambda: c(t)

    table.time(case, "splipy", _lazy(splipy_curve))

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

    table.time(case, "geomdl", _lazy(geomdl_curve(False)), repeat=1)

    # ---- curve, rational
    case_r = f"rational curve p=3, {N_CP} cp, {N_PARAMS:,} params"
    ours_r = table.time(case_r, "formgraph", lambda: K.curve_evaluate(cp, p, knots, w, t))

    def splipy_rcurve():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(p + 1, knots), K.homogeneous(cp, w), rational=True)
        return lambda: c(t)

    table.time(case_r, "splipy", _lazy(splipy_rcurve))
    table.time(case_r, "geomdl", _lazy(geomdl_curve(True)), repeat=1)
    if ours and ours_r:
        table.add(
            case_r,
            "formgraph non-rational",
            ours,
            f"rational / non-rational = {ours_r / ours:.2f}x",
        )

    # ---- surface on a grid
    net = rng.normal(size=(NET, NET, 3))
    net_w = rng.uniform(0.5, 2.0, (NET, NET))
    ku = K.clamped_uniform_knots(NET, 3)
    kv = _curve(rng, NET, 3)[2]
    g = np.linspace(0.0, 1.0, GRID)
    for rational in (False, True):
        ww = net_w if rational else None
        case_s = f"{'rational ' if rational else ''}surface {NET}x{NET} p=3, {GRID}x{GRID} grid"
        table.time(
            case_s, "formgraph", lambda ww=ww: K.surface_evaluate_grid(net, 3, 3, ku, kv, ww, g, g)
        )
        if not rational:

            def scipy_surface():
                from scipy.interpolate import BSpline

                def go():
                    bu = BSpline.design_matrix(g, ku, 3).toarray()
                    bv = BSpline.design_matrix(g, kv, 3).toarray()
                    return np.einsum("ai,ijd,bj->abd", bu, net, bv, optimize=True)

                return go

            table.time(case_s, "scipy design matrix", _lazy(scipy_surface))

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

        table.time(case_s, "splipy", _lazy(splipy_surface))

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

        table.time(case_s, "geomdl", _lazy(geomdl_surface), repeat=1)

    # ---- knot insertion and refinement
    case_k = f"insert knot (x2) into p=3 curve, {N_CP} cp"
    table.time(case_k, "formgraph", lambda: K.insert_knot(cp, p, knots, w, 0.4321, 2))

    def geomdl_insert():
        from geomdl import NURBS, operations

        c = NURBS.Curve()
        c.degree = p
        c.ctrlpts = cp.tolist()
        c.weights = w.tolist()
        c.knotvector = knots.tolist()
        return lambda: operations.insert_knot(copy.deepcopy(c), [0.4321], [2])

    table.time(case_k, "geomdl (incl. copy)", _lazy(geomdl_insert))

    def splipy_insert():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(p + 1, knots), K.homogeneous(cp, w), rational=True)
        return lambda: c.clone().insert_knot([0.4321, 0.4321])

    table.time(case_k, "splipy (incl. clone)", _lazy(splipy_insert))

    new = rng.uniform(0, 1, 1000)
    case_r2 = f"refine p=3 curve, {N_CP} cp, +1,000 knots"
    table.time(case_r2, "formgraph", lambda: K.refine_knots(cp, p, knots, w, new))

    def splipy_refine():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(p + 1, knots), K.homogeneous(cp, w), rational=True)
        return lambda: c.clone().insert_knot(new.tolist())

    table.time(case_r2, "splipy (incl. clone)", _lazy(splipy_refine))

    case_e = f"elevate degree 3->5, {N_CP} cp"
    table.time(case_e, "formgraph", lambda: K.elevate_degree(cp, p, knots, w, 2))

    def splipy_elevate():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(p + 1, knots), K.homogeneous(cp, w), rational=True)
        return lambda: c.clone().raise_order(2)

    table.time(case_e, "splipy (incl. clone)", _lazy(splipy_elevate))

    # ---- loft
    curves = []
    for i in range(10):
        c = _curve(rng, 200, 3)
        curves.append((c[0] + [0, 0, i], 3, c[2], None))
    case_l = "loft of 10 curves x 200 cp (distinct knots)"
    table.time(case_l, "formgraph", lambda: K.loft(curves))
    curves_same = [(c[0], 3, curves[0][2], None) for c in curves]
    table.time(
        "loft of 10 curves x 200 cp (shared knots)", "formgraph", lambda: K.loft(curves_same)
    )

    case_i = "interpolate 200 points, p=3"
    pts = np.cumsum(rng.normal(size=(200, 3)), axis=0)
    table.time(case_i, "formgraph", lambda: K.interpolate(pts, 3))

    def geomdl_interp():
        from geomdl import fitting

        pl = pts.tolist()
        return lambda: fitting.interpolate_curve(pl, 3)

    table.time(case_i, "geomdl", _lazy(geomdl_interp), repeat=1)

    # ---- interpolation of many points: the banded solve (a dense one would need 80 GB)
    big = 100_000
    tb = np.linspace(0, 60 * np.pi, big)
    pts_big = np.stack([np.cos(tb), np.sin(tb), np.sin(0.37 * tb)], -1)
    case_b = f"interpolate {big:,} points, p=3 (open)"
    table.time(case_b, "formgraph", lambda: K.interpolate(pts_big, 3), repeat=3)

    def scipy_interp():
        from scipy.interpolate import make_interp_spline

        u = K.interpolation_parameters(pts_big)
        knots_b = K.interpolate(pts_big, 3)[2]  # the same knots (A9.1's averaging)
        return lambda: make_interp_spline(u, pts_big, k=3, t=knots_b)

    table.time(case_b, "scipy make_interp_spline", _lazy(scipy_interp), repeat=3)
    table.time(
        f"interpolate {big:,} points, p=3 (closed)",
        "formgraph",
        lambda: K.interpolate(pts_big[: big - 1], 3, closed=True),
        repeat=3,
    )

    # ---- degree elevation by many degrees at once
    cp_e, _, knots_e, _ = _curve(rng, 1000, 3)
    case_e29 = "elevate degree 3->32, 1,000 cp"
    table.time(case_e29, "formgraph", lambda: K.elevate_degree(cp_e, 3, knots_e, None, 29))

    def splipy_elevate29():
        from splipy import BSplineBasis, Curve

        c = Curve(BSplineBasis(4, knots_e), cp_e)
        return lambda: c.clone().raise_order(29)

    table.time(case_e29, "splipy (incl. clone)", _lazy(splipy_elevate29), repeat=1)

    hx = np.linspace(0, 6 * np.pi, 512)
    path = np.stack([2 * np.cos(hx), 2 * np.sin(hx), hx / np.pi], -1)
    tang = np.stack([-2 * np.sin(hx), 2 * np.cos(hx), np.full_like(hx, 1 / np.pi)], -1)
    circ = K.circle(0.3)
    table.time(
        "sweep circle along helix, 512 stations", "formgraph", lambda: K.sweep(circ, path, tang)
    )


def _lazy(make):  # noqa: ANN001, ANN202
    """Build the reference lazily so that a missing library is reported, not raised."""
    state: dict = {}

    def call():
        if "fn" not in state:
            state["fn"] = make()
        return state["fn"]()

    return call
