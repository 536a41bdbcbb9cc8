"""Tensor-product NURBS surfaces: evaluation, grids, first partials and normals.

Points at scattered (u, v) use A3.5/A4.3 of The NURBS Book vectorized over all parameter
pairs; grids sum the same non-zero basis terms one direction at a time, over whole rows
and columns of the grid. Rational surfaces are evaluated in homogeneous coordinates.
"""

from __future__ import annotations

import numpy as np

from .basis import (
    CHUNK,
    _basis_from_table,
    _basis_rows,
    _span_table,
    basis_function_derivatives,
    basis_workspace,
    domain_spans,
    find_spans,
)
from .curve import homogeneous, project
from .knots import is_clamped, respace

__all__ = [
    "basis_matrix",
    "clamp_surface",
    "surface_derivatives",
    "surface_evaluate",
    "surface_evaluate_grid",
    "surface_normals",
]


def basis_matrix(degree: int, knots: np.ndarray, t: np.ndarray, n: int) -> np.ndarray:
    """Dense collocation matrix ``B[i, j] = N_j(t[i])`` (A2.2 for all parameters).

    Parameters
    ----------
    degree : int
    knots : (n + degree + 1,) float
    t : (m,) float
    n : int
        Number of control points.

    Returns
    -------
    B : (m, n) float
        At most ``degree + 1`` non-zeros per row, summing to 1.
    """
    knots = np.asarray(knots, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64).reshape(-1)
    spans = find_spans(degree, knots, t)
    rows = _basis_rows(degree, knots, spans, t)
    B = np.zeros((t.shape[0], n))
    r = np.arange(t.shape[0])
    for k in range(degree + 1):
        B[r, spans - degree + k] = rows[k]
    return B


def surface_evaluate(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
    u: float | np.ndarray,
    v: float | np.ndarray,
) -> np.ndarray:
    """Surface points at parameter pairs ``(u, v)``, broadcast together (A3.5, A4.3).

    Parameters
    ----------
    control_points : (nu, nv, 3) float
    degree_u, degree_v : int
    knots_u : (nu + degree_u + 1,) float
    knots_v : (nv + degree_v + 1,) float
    weights : (nu, nv) float or None
    u, v : float or array
        Broadcast to a common shape ``S``.

    Returns
    -------
    points : S + (3,) float
    """
    uu, vv = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    shape = uu.shape
    pw = homogeneous(control_points, weights)
    (out,) = _tensor_sums(pw, degree_u, degree_v, knots_u, knots_v, uu.reshape(-1),
                          vv.reshape(-1), derivatives=False)  # fmt: skip
    if weights is not None:
        out = out[:3] / out[3]
    return out.T.reshape(shape + (3,))


def _tensor_sums(
    pw: np.ndarray,
    pu: int,
    pv: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    derivatives: bool,
) -> tuple[np.ndarray, ...]:
    """``sum_ab Nu_a(u) Nv_b(v) pw[su-pu+a, sv-pv+b]`` (and with dNu or dNv) for all pairs.

    Blocks of parameters (cache-sized), coordinates first: each coordinate of the control
    net is a flat array read with 1-D gathers, so every operation is a long, contiguous
    array operation. Returns ``(d, m)`` arrays: the sum, then (with ``derivatives``) its
    u and v partials.
    """
    nu, nv, d = pw.shape
    ku = np.asarray(knots_u, dtype=np.float64)
    kv = np.asarray(knots_v, dtype=np.float64)
    coords = np.ascontiguousarray(np.moveaxis(pw, -1, 0)).reshape(d, nu * nv)
    tab_u, first_u = _span_table(pu, ku)
    tab_v, first_v = _span_table(pv, kv)
    last_u = domain_spans(pu, ku)[1]
    last_v = domain_spans(pv, kv)[1]
    m = u.shape[0]
    outs = [np.empty((d, m)) for _ in range(3 if derivatives else 1)]
    work_u = basis_workspace(pu, min(CHUNK, m))
    work_v = basis_workspace(pv, min(CHUNK, m))
    for s0 in range(0, m, CHUNK):
        sl = slice(s0, s0 + CHUNK)
        uc, vc = u[sl], v[sl]
        su = np.clip(np.searchsorted(ku, uc, side="right") - 1, first_u, last_u)
        sv = np.clip(np.searchsorted(kv, vc, side="right") - 1, first_v, last_v)
        if derivatives:
            du = basis_function_derivatives(pu, ku, su, uc, 1).transpose(0, 2, 1)
            dv = basis_function_derivatives(pv, kv, sv, vc, 1).transpose(0, 2, 1)
            Nu, dNu, Nv, dNv = du[0], du[1], dv[0], dv[1]
        else:
            Nu = _basis_from_table(pu, np.take(tab_u, su - first_u, axis=1), uc, work_u)
            Nv = _basis_from_table(pv, np.take(tab_v, sv - first_v, axis=1), vc, work_v)
        base = (su - pu) * nv + (sv - pv)
        for c in range(d):
            P = coords[c]
            acc = [None] * len(outs)
            for a in range(pu + 1):
                row = base + a * nv
                g = [P.take(row + b) for b in range(pv + 1)]
                inner = sum(Nv[b] * g[b] for b in range(pv + 1))
                terms = [Nu[a] * inner]
                if derivatives:
                    terms += [dNu[a] * inner, Nu[a] * sum(dNv[b] * g[b] for b in range(pv + 1))]
                for i, t in enumerate(terms):
                    acc[i] = t if acc[i] is None else acc[i] + t
            for i in range(len(outs)):
                outs[i][c, sl] = acc[i]
    return tuple(outs)


def surface_evaluate_grid(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
    u: np.ndarray,
    v: np.ndarray,
) -> np.ndarray:
    """Surface points on the grid ``u x v``: ``S[i, j] = S(u[i], v[j])``.

    The tensor-product form of A3.5/A4.3, one direction at a time. A direction of few
    control points is a BLAS product with its collocation matrix (:func:`basis_matrix`);
    one of many (a sweep's hundreds of stations) sums only the ``degree + 1`` non-zero
    terms of each grid line, as whole-array operations over the grid: ``O((p + 1) a b)``
    work instead of the product's ``O(a n b)``, and no BLAS threads for a busy machine to
    keep waiting. With one of each, the direction that leaves the smaller grid in between
    goes first.

    Parameters
    ----------
    control_points : (nu, nv, 3) float
    degree_u, degree_v : int
    knots_u, knots_v : float arrays
    weights : (nu, nv) float or None
    u : (a,) float
    v : (b,) float

    Returns
    -------
    points : (a, b, 3) float
    """
    u = np.asarray(u, dtype=np.float64).reshape(-1)
    v = np.asarray(v, dtype=np.float64).reshape(-1)
    ku = np.asarray(knots_u, dtype=np.float64)
    kv = np.asarray(knots_v, dtype=np.float64)
    pw = homogeneous(control_points, weights)
    nu, nv, d = pw.shape
    # coordinates first, (d, nu, nv): the sums run along contiguous rows (a trailing axis
    # of 3 or 4 would make numpy's inner loops 3 elements long)
    per_coord = np.ascontiguousarray(np.moveaxis(pw, -1, 0))
    passes = {"u": (degree_u, ku, u, nu, 1), "v": (degree_v, kv, v, nv, 2)}
    out = per_coord
    for direction, banded in _plan(nu, nv, u.size, v.size, degree_u, degree_v):
        out = _sum_over(out, *passes[direction], banded)
    if weights is not None:
        out = out[:3] / out[3]
    return np.moveaxis(out, 0, -1)


#: how many multiply-adds of a BLAS product take the time of one element of a numpy
#: operation over a whole array (measured here: the tube's 9 x 256 net on a 65 x 257 grid,
#: and a 20 x 20 net on a 300 x 300 one, each at its faster plan)
BLAS_SPEEDUP = 16.0


def _plan(
    nu: int, nv: int, a: int, b: int, pu: int, pv: int
) -> tuple[tuple[str, bool], tuple[str, bool]]:
    """The cheapest way to the grid: the two directions in order, each either a product
    with its dense collocation matrix (False) or a sum over its band (True).

    A dense pass costs ``n / BLAS_SPEEDUP`` per element of its result, a banded one
    ``3 (p + 1)`` (a gather, a product and a sum per basis function). Ties keep the
    order of the plain products, u first."""
    sizes = {"u": (nu, a, pu), "v": (nv, b, pv)}

    def cost(n: int, p: int, out: int, banded: bool) -> float:
        return out * (3.0 * (p + 1) if banded else n / BLAS_SPEEDUP)

    options = []
    for order in (("u", "v"), ("v", "u")):
        (n1, m1, p1), (n2, m2, p2) = sizes[order[0]], sizes[order[1]]
        between = m1 * n2  # the grid after the first pass
        for b1 in (False, True):
            for b2 in (False, True):
                total = cost(n1, p1, between, b1) + cost(n2, p2, m1 * m2, b2)
                options.append((total, len(options), ((order[0], b1), (order[1], b2))))
    return min(options)[2]


def _sum_over(
    a: np.ndarray, degree: int, knots: np.ndarray, t: np.ndarray, n: int, axis: int, banded: bool
) -> np.ndarray:
    """The sum over ``axis`` (running over the ``n`` control points) with the basis
    functions at ``t`` (A2.2): ``a`` with ``axis`` running over ``t`` instead."""
    if not banded:
        matrix = basis_matrix(degree, knots, t, n)
        return matrix @ a if axis == 1 else a @ matrix.T
    spans = find_spans(degree, knots, t)
    shape = [1, 1, 1]
    shape[axis] = t.size
    rows = _basis_rows(degree, knots, spans, t)
    first = spans - degree
    out = a.take(first, axis=axis) * rows[0].reshape(shape)
    for k in range(1, degree + 1):
        out += a.take(first + k, axis=axis) * rows[k].reshape(shape)
    return out


def surface_derivatives(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
    u: float | np.ndarray,
    v: float | np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points and first partial derivatives (A3.6; rational by A4.4), broadcast over (u, v).

    Returns
    -------
    S, Su, Sv : S + (3,) float each
        Point, dS/du and dS/dv.
    """
    uu, vv = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    shape = uu.shape
    uf, vf = uu.reshape(-1), vv.reshape(-1)
    ku = np.asarray(knots_u, dtype=np.float64)
    kv = np.asarray(knots_v, dtype=np.float64)
    pw = homogeneous(control_points, weights)
    a, au, av = _tensor_sums(pw, degree_u, degree_v, ku, kv, uf, vf, derivatives=True)
    if weights is None:
        s, s_u, s_v = a, au, av
    else:
        w, wu, wv = a[3], au[3], av[3]
        s = a[:3] / w
        s_u = (au[:3] - wu * s) / w
        s_v = (av[:3] - wv * s) / w
    s, s_u, s_v = s.T, s_u.T, s_v.T
    return s.reshape(shape + (3,)), s_u.reshape(shape + (3,)), s_v.reshape(shape + (3,))


def surface_normals(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
    u: float | np.ndarray,
    v: float | np.ndarray,
) -> np.ndarray:
    """Unit normals ``Su x Sv / |Su x Sv|`` at parameter pairs broadcast together.

    Where the cross product vanishes (a pole, e.g. a revolved profile touching the axis,
    or a collapsed edge), the normal is taken a tiny step into the domain, which is its
    limit along that direction; where it still vanishes it is returned as zeros.

    Returns
    -------
    normals : S + (3,) float
    """
    args = (control_points, degree_u, degree_v, knots_u, knots_v, weights)
    uu, vv = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    _, s_u, s_v = surface_derivatives(*args, uu, vv)
    n = np.cross(s_u, s_v)
    length = np.linalg.norm(n, axis=-1)
    scale = max(float(np.abs(control_points).max()), 1e-300) ** 2
    bad = length <= 1e-14 * scale
    if np.any(bad):
        ku = np.asarray(knots_u, dtype=np.float64)
        kv = np.asarray(knots_v, dtype=np.float64)
        nu_, nv_ = np.shape(control_points)[:2]
        u0, u1 = ku[degree_u], ku[nu_]
        v0, v1 = kv[degree_v], kv[nv_]
        hu, hv = 1e-7 * (u1 - u0), 1e-7 * (v1 - v0)
        ub = uu[bad]
        vb = vv[bad]
        ub = np.where(ub + hu <= u1, ub + hu, ub - hu)
        vb = np.where(vb + hv <= v1, vb + hv, vb - hv)
        _, bu, bv = surface_derivatives(*args, ub, vb)
        n[bad] = np.cross(bu, bv)
        length[bad] = np.linalg.norm(n[bad], axis=-1)
    safe = np.where(length > 0, length, 1.0)
    return n / safe[..., None]


def clamp_surface(
    control_points: np.ndarray,
    degree_u: int,
    degree_v: int,
    knots_u: np.ndarray,
    knots_v: np.ndarray,
    weights: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """The same surface on knot vectors clamped in u and v (:func:`clamp` along each axis
    that is not).

    Returns
    -------
    (control_points (nu, nv, 3), knots_u, knots_v, weights (nu, nv) or None)
    """
    pw = homogeneous(np.asarray(control_points, dtype=np.float64), weights)
    ku = np.asarray(knots_u, dtype=np.float64)
    kv = np.asarray(knots_v, dtype=np.float64)
    out = [ku, kv]
    for axis, d in enumerate((degree_u, degree_v)):
        k = out[axis]
        if is_clamped(d, k):
            continue
        a, b = k[d], k[len(k) - d - 1]
        tau = np.concatenate([[a] * (d + 1), k[(k > a) & (k < b)], [b] * (d + 1)])
        pw = np.moveaxis(respace(d, k, np.moveaxis(pw, axis, 0), tau), 0, axis)
        out[axis] = tau
    cp, w = project(pw, weights is not None)
    return cp, out[0], out[1], w
