"""Global interpolation: B-spline curves (and columns of control nets) through given points.

Open interpolation is The NURBS Book's A9.1: parameters by chord length or centripetal
spacing (Eq. 9.4-9.6), knots by averaging (Eq. 9.8), and one linear system for all
coordinates. Closed interpolation is its periodic counterpart: a periodic knot vector
(knots at the parameters for odd degree, at their midpoints for even degree, so that the
Schoenberg-Whitney conditions hold) and a cyclic collocation system.

The systems are banded (at most p + 1 entries per row, next to the diagonal; for a closed
curve the band wraps around the corners) and solved by :mod:`.banded` in O(n) work and
memory: block cyclic reduction, with a bordered elimination of the wrapping corners.
Collocation matrices of B-splines are totally positive, so elimination is stable; 100,000
points interpolate in a fraction of a second.
"""

from __future__ import annotations

import numpy as np

from .banded import solve_banded_rows
from .basis import _basis_rows, find_spans
from .knots import respace

__all__ = ["fit_columns", "interpolate", "interpolation_parameters"]

_PARAMETRIZATIONS = ("chord", "centripetal", "uniform")


def interpolation_parameters(
    points: np.ndarray, closed: bool = False, parametrization: str = "chord"
) -> np.ndarray:
    """Parameters of the data points on [0, 1] (Eq. 9.4-9.6 of The NURBS Book).

    Parameters
    ----------
    points : (k, d) float
        Data points (or stacked rows of them: the distance between rows is the mean over
        the trailing axes, as for the sections of a loft, Eq. 10.8).
    closed : bool
        Include the closing segment from the last point back to the first; the k
        parameters then lie in [0, 1) and 1 stands for the first point again.
    parametrization : {"chord", "centripetal", "uniform"}

    Returns
    -------
    (k,) float
    """
    if parametrization not in _PARAMETRIZATIONS:
        raise ValueError(
            f"parametrization must be one of {', '.join(_PARAMETRIZATIONS)}, got "
            f"{parametrization!r}"
        )
    pts = np.asarray(points, dtype=np.float64)
    k = pts.shape[0]
    seq = np.concatenate([pts, pts[:1]]) if closed else pts
    u = np.empty(len(seq))
    u[0] = 0.0
    dist = u[1:]  # the steps' lengths, summed where they are (fresh memory costs faults)
    if seq.ndim == 2 and seq.shape[1] == 3:
        # points: coordinate by coordinate (no (k, 3) steps array, no reductions over a
        # short axis)
        np.subtract(seq[1:, 0], seq[:-1, 0], out=dist)
        dist *= dist
        tmp = np.subtract(seq[1:, 1], seq[:-1, 1])
        tmp *= tmp
        dist += tmp
        np.subtract(seq[1:, 2], seq[:-1, 2], out=tmp)
        tmp *= tmp
        dist += tmp
        np.sqrt(dist, out=dist)
    else:
        steps = seq[1:] - seq[:-1]
        s3 = steps.reshape(len(steps), -1, steps.shape[-1])
        dist[:] = np.linalg.norm(s3, axis=-1).mean(axis=1)
    if parametrization == "uniform":
        dist[:] = 1.0
    elif parametrization == "centripetal":
        np.sqrt(dist, out=dist)
    if np.any(dist == 0):
        i = int(np.argmax(dist == 0))
        j = (i + 1) % k
        raise ValueError(
            f"points {i} and {j} coincide; interpolation needs consecutive points to differ"
        )
    np.cumsum(dist, out=dist)
    u /= u[-1]
    return u[:k] if closed else u


def _averaged_knots(u: np.ndarray, degree: int) -> np.ndarray:
    """Clamped knots by averaging the parameters (Eq. 9.8)."""
    p = degree
    k = len(u)
    knots = np.empty(k + p + 1)
    knots[: p + 1] = 0.0
    knots[k:] = 1.0
    if k - p - 1 > 0:  # means of p consecutive parameters, by a running sum, in place
        inner = knots[p + 1 : k]
        run = np.cumsum(u[1 : k - 1])  # run[m] = u[1] + ... + u[m + 1]
        inner[0] = run[p - 1]
        np.subtract(run[p:], run[:-p], out=inner[1:])
        inner /= p
        np.maximum.accumulate(inner, out=inner)  # (rounding kept in order)
        np.clip(inner, 0.0, 1.0, out=inner)
    return knots


def _periodic_knots(u: np.ndarray, degree: int) -> np.ndarray:
    """Periodic knot vector of period 1 with k knots per period (k + 2p + 1 knots)."""
    p = degree
    k = len(u)
    ext = np.concatenate([u, [1.0]])
    base = u if p % 2 == 1 else 0.5 * (ext[:-1] + ext[1:])
    i = np.arange(-p, k + p + 1)
    return base[i % k] + np.floor_divide(i, k)


def fit_columns(
    values: np.ndarray, params: np.ndarray, degree: int, closed: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Interpolating B-spline coefficients of many columns at once (A9.1, open or periodic).

    Parameters
    ----------
    values : (k, ...) float
        Data at the k parameters; trailing axes are independent right-hand sides (the
        control points of loft sections, in homogeneous coordinates).
    params : (k,) float
        Increasing, in [0, 1] (open: from 0 to 1; closed: from 0, below 1).
    degree : int
        1 <= degree <= k - 1.
    closed : bool
        Periodic: the result's first ``degree`` control points are repeated at its end.

    Returns
    -------
    control : (k, ...) float; when closed (k + degree, ...) for odd degree and
        (k + 1 + degree, ...) for even degree
    knots : (len(control) + degree + 1,) float
        Domain [0, 1], with the data at ``params``. Closed even degrees get one knot more
        per period (the midpoints between the parameters, for Schoenberg-Whitney, plus 0
        so that the domain starts at the first data point), hence one more control point.
    """
    vals = np.asarray(values, dtype=np.float64)
    k = vals.shape[0]
    flat = vals.reshape(k, -1)
    p = degree
    if not closed:
        knots = _averaged_knots(params, p)
        ctrl = _fit_open(flat, params, p, knots)
        return ctrl.reshape(vals.shape), knots
    knots = _periodic_knots(params, p)
    t = params if p % 2 == 1 else np.where(params < knots[p], params + 1.0, params)
    cols, rows = _collocation_rows(p, knots, t)
    ctrl = solve_banded_rows(cols % k, rows, flat, cyclic=True)  # basis k + j is basis j
    if p % 2 == 0:
        ctrl, knots = _start_at_zero(ctrl, knots[p : p + k], p)
        k += 1
    ctrl = np.concatenate([ctrl, ctrl[:p]])
    return ctrl.reshape((k + p,) + vals.shape[1:]), knots


def _fit_open(flat: np.ndarray, params: np.ndarray, p: int, knots: np.ndarray) -> np.ndarray:
    """Open interpolation: scipy's compiled collocation and LAPACK's banded LU
    (``gbsv``, partial pivoting), checked by how far the curve misses the data at the
    parameters; where it misses by more than 1e-10 of the data's size (a nearly singular
    system, or data that is not finite) or the solve refuses, the rows' own solve decides
    (refinement, a dense solve when small, or a clear error)."""
    k = flat.shape[0]
    if k > 4 * (p + 1):
        try:
            with np.errstate(all="ignore"):
                ctrl, miss, scale = _collocation_solve(flat, params, p, knots)
            # a finite miss means finite control points: each one enters some row's miss
            if miss <= 1e-10 * max(scale, 1e-300):
                return ctrl
        except (ValueError, TypeError, AttributeError, np.linalg.LinAlgError):
            pass  # (scipy's internals moved, or it refused: the rows' solve decides)
    cols, rows = _collocation_rows(p, knots, params)
    return solve_banded_rows(cols, rows, flat)


def _scipy_coloc():
    """scipy's compiled collocation into band storage, if this scipy has it (else None)."""
    try:
        from scipy.interpolate import _dierckx

        return _dierckx._coloc
    except (ImportError, AttributeError):
        return None


_BLOCK = 8192  # rows of the miss computed at once (its temporaries stay in cache)


def _collocation_solve(
    flat: np.ndarray, params: np.ndarray, p: int, knots: np.ndarray
) -> tuple[np.ndarray, float, float]:
    """The interpolating coefficients, the largest miss at the parameters and the largest
    absolute datum.

    What ``make_interp_spline`` does (scipy's compiled collocation into LAPACK band storage,
    then ``gbsv``), with two differences. The solve gets only the diagonals that hold
    entries: scipy's storage has ``2 p + 1`` (``kl = ku = p``), but with averaged knots
    parameter ``u_i`` lies between knots ``i + 1`` and ``i + p`` (means of p parameters up
    to and from ``u_i``), so the band is at most ``p - 1`` wide on each side (cubic: 2 + 2;
    the diagonals are found from the entries, so rounding cannot hide one) and the
    elimination does less. And the band is kept so that the miss is a pass over
    its diagonals rather than an evaluation of the curve, done in blocks of rows whose
    temporaries stay in cache (at this size fresh memory costs more in page faults than the
    arithmetic). The answer is Fortran-ordered, where LAPACK leaves it (for up to 3
    columns a view of the collocation's array, which it keeps alive). The collocation
    routine is scipy's own, not public
    (``_dierckx._coloc`` since 1.15): where it is missing, the public
    ``make_interp_spline`` and an evaluation do the same.
    """
    coloc = _scipy_coloc()
    if coloc is None:
        from scipy.interpolate import make_interp_spline

        spline = make_interp_spline(params, flat, k=p, t=knots, check_finite=False)
        ctrl = np.asarray(spline.c)
        scale = float(np.abs(flat).max(initial=0.0))
        return ctrl, float(np.abs(spline(params) - flat).max(initial=0.0)), scale
    from scipy.linalg import get_lapack_funcs

    n = flat.shape[0]
    mid = 2 * p  # ab[mid + i - j, j] = A[i, j]: row mid - o holds the diagonal j - i = o
    ab = np.zeros((3 * p + 1, n), dtype=np.float64, order="F")
    coloc(np.ascontiguousarray(params), np.ascontiguousarray(knots), p, ab.T, 0)
    # A row's entries are p + 1 consecutive columns, the diagonal among them (Schoenberg-
    # Whitney: N_i(u_i) > 0), so the live diagonals are one run around 0: look from outside
    if not ab[mid].all():
        raise np.linalg.LinAlgError("the collocation matrix has a zero on its diagonal")
    ku = next(o for o in range(p, -1, -1) if ab[mid - o].any())
    kl = next(o for o in range(p, -1, -1) if ab[mid + o].any())
    # The live diagonals (offsets ku .. -kl) are kept, C-ordered, for the miss; the solve
    # gets them in LAPACK's storage of the narrow band, and (3 columns or fewer) the
    # right-hand sides after them, laid out in scipy's wider array's own memory (fresh
    # memory costs page faults: at this size more than the arithmetic).
    band = np.array(ab[mid - ku : mid + kl + 1])
    rows = 2 * kl + ku + 1
    lu = ab.reshape(-1, order="F")[: rows * n].reshape((rows, n), order="F")
    lu[:kl] = 0.0
    lu[kl:] = band
    if (rows + flat.shape[1]) * n <= ab.size:  # the right-hand sides fit the rest of it
        rhs = ab.reshape(-1, order="F")[rows * n : (rows + flat.shape[1]) * n]
        rhs = rhs.reshape(flat.shape, order="F")
        rhs[:] = flat
    else:
        rhs = np.array(flat, dtype=np.float64, order="F")
    (gbsv,) = get_lapack_funcs(("gbsv",), (lu, rhs))
    _, _, ctrl, info = gbsv(kl, ku, lu, rhs, overwrite_ab=True, overwrite_b=True)
    del lu, ab  # (the factors)
    if info != 0:
        raise np.linalg.LinAlgError("the collocation matrix is singular")
    misses, scales = [], []
    cols = ctrl.T  # (d, n), C-ordered: gbsv's answer is Fortran-ordered
    for a in range(0, n, _BLOCK):
        b = min(a + _BLOCK, n)
        acc = np.array(flat[a:b].T)
        scales.append(np.abs(acc).max())
        for o in range(-kl, ku + 1):  # rows i in [a, b) meet columns i + o
            i0, i1 = max(a, -o), min(b, n - o)
            if i1 > i0:
                acc[:, i0 - a : i1 - a] -= band[ku - o, i0 + o : i1 + o] * cols[:, i0 + o : i1 + o]
        misses.append(np.abs(acc).max())
    # np.max keeps a NaN (Python's max would drop it)
    return ctrl, float(np.max(misses)), float(np.max(scales))


def _collocation_rows(p: int, knots: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The non-zeros of the collocation matrix ``N_j(t_i)``: columns and values (k, p + 1)."""
    spans = find_spans(p, knots, t)
    vals = np.stack(_basis_rows(p, knots, spans, t), axis=1)
    return spans[:, None] - p + np.arange(p + 1), vals


def _start_at_zero(ctrl: np.ndarray, period: np.ndarray, p: int) -> tuple[np.ndarray, np.ndarray]:
    """Re-express a periodic spline (k distinct control points, knots ``period`` in one
    period, the first above 0) on the knots ``{0} + period mod 1``, so that its domain
    starts at parameter 0, the first data point. Exact: the new periodic knot vector
    refines the old one (:func:`~.nurbs_knots.respace` on three periods of the old curve).
    """
    k = len(period)
    i = np.arange(-k - p, 2 * k + p + 1)  # domain [period[0] - 1, period[0] + 2]
    old_knots = period[i % k] + np.floor_divide(i, k)
    old_ctrl = ctrl[np.arange(3 * k + p) % k]
    base = np.sort(np.concatenate([[0.0], np.mod(period, 1.0)]))
    j = np.arange(-p, k + 1 + p + 1)
    new_knots = base[j % (k + 1)] + np.floor_divide(j, k + 1)
    new_ctrl = respace(p, old_knots, old_ctrl, new_knots)
    return new_ctrl[: k + 1], new_knots


def interpolate(
    points: np.ndarray,
    degree: int = 3,
    closed: bool = False,
    parametrization: str = "chord",
) -> tuple[np.ndarray, int, np.ndarray, None]:
    """A B-spline curve through every point, in order (global interpolation, A9.1).

    Parameters
    ----------
    points : (k, 3) float
        At least 2 (open) or 3 (closed) points, consecutive points distinct. For a closed
        curve a last point equal to the first (within 1e-12 of the extent) is dropped: the
        curve closes by itself.
    degree : int
        Requested degree; it is capped at ``k - 1`` (the most k points determine), so 2
        points give a line and 3 points a parabola.
    closed : bool
        A periodic curve: it passes through every point and closes with the continuity of
        its degree (no corner at the first point).
    parametrization : {"chord", "centripetal", "uniform"}
        Spacing of the parameters: chord length, square root of chord length (fewer loops
        and cusps on uneven data), or equal.

    Returns
    -------
    control_points : (k, 3) float, or (k + degree, 3) closed (k + 1 + degree for even degree)
    degree : int
        The degree used (after the cap).
    knots : float array
        Domain [0, 1]; open curves are clamped and pass through the first and last point at
        0 and 1; closed curves start and end at the first point.
    weights : None
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must be an (n, 3) array, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        raise ValueError("points must be finite numbers")
    if isinstance(degree, bool) or int(degree) != degree or degree < 1:
        raise ValueError(f"degree must be a whole number >= 1, got {degree!r}")
    if closed and len(pts) > 1:
        extent = float(np.ptp(pts, axis=0).max())
        if np.linalg.norm(pts[0] - pts[-1]) <= 1e-12 * extent:
            pts = pts[:-1]  # the closing point repeats the first (up to rounding)
    need = 3 if closed else 2
    if len(pts) < need:
        kind = "a closed" if closed else "an open"
        raise ValueError(f"{kind} interpolating curve needs at least {need} points, got {len(pts)}")
    p = min(int(degree), len(pts) - 1)
    u = interpolation_parameters(pts, closed, parametrization)
    cp, knots = fit_columns(pts, u, p, closed)
    return cp, p, knots, None
