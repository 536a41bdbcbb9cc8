"""Shared helpers of the NURBS kernel tests: random curves and their geomdl twins."""

from __future__ import annotations

import numpy as np
from geomdl import NURBS, BSpline

from formgraph.kernels import nurbs as K

T = np.linspace(0.0, 1.0, 101)


def random_curve(rng, degree, n=None, rational=True, unclamped=False):
    n = n if n is not None else degree + 1 + int(rng.integers(0, 6))
    cp = rng.normal(size=(n, 3))
    w = rng.uniform(0.3, 3.0, n) if rational else None
    if unclamped:
        knots = np.sort(rng.uniform(-1, 2, n + degree + 1))
        knots = K.reparametrize(knots, 0.0, 1.0, degree)
    else:
        inner = np.sort(rng.uniform(0.0, 1.0, n - degree - 1))
        knots = np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])
    return cp, degree, knots, w


def geomdl_curve(cp, degree, knots, w):
    c = NURBS.Curve() if w is not None else BSpline.Curve()
    c.degree = degree
    c.ctrlpts = cp.tolist()
    if w is not None:
        c.weights = w.tolist()
    c.knotvector = knots.tolist()
    return c


def geomdl_surface(cp, pu, pv, ku, kv, w):
    s = NURBS.Surface()
    s.degree_u, s.degree_v = pu, pv
    s.ctrlpts_size_u, s.ctrlpts_size_v = cp.shape[:2]
    s.ctrlpts = cp.reshape(-1, 3).tolist()
    s.weights = (np.ones(cp.shape[:2]) if w is None else w).reshape(-1).tolist()
    s.knotvector_u, s.knotvector_v = ku.tolist(), kv.tolist()
    return s


def shape_error(a, b, t=T):
    return float(np.abs(K.curve_evaluate(*a, t) - K.curve_evaluate(*b, t)).max())
