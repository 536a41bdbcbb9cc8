"""Banded and cyclic-banded linear systems, solved in O(n) work and memory.

The collocation matrix of interpolation (The NURBS Book A9.1) has at most ``p + 1``
non-zeros per row, next to the diagonal: banded for an open curve, banded with the
corners filled in ("cyclic-banded") for a closed one. A dense solve of it costs n^3 and n^2
memory (20,000 points: minutes and gigabytes); these solvers cost a few passes over the
n x band entries.

- Open systems: LAPACK's banded LU with partial pivoting (``gbsv``, through
  ``scipy.linalg.solve_banded``), on the rows laid out in LAPACK's band storage: one
  compiled pass, ``2 kl + ku + 1`` numbers an unknown. (This replaced a block elimination
  in numpy -- n / 32 small dense solves one after another, 96 numbers an unknown, ten
  times slower at 100,000 points; cyclic reduction would need only log n steps, but it
  pivots on blocks that are not leading principal blocks, and on collocation matrices of
  very uneven spacing it loses all accuracy.)
- Cyclic systems: the unknowns are renumbered so that the band sits on the diagonal, and
  the last b unknowns are split off (a bordered system, block elimination with a b x b
  Schur complement): what remains is an open banded system with b more right-hand sides.

Collocation matrices of B-splines are totally positive (de Boor, *A Practical Guide to
Splines*, XIII), so elimination needs no pivoting across blocks; each answer is checked by
its residual (computed from the rows, O(n): for interpolation, how far the curve misses
the data) and refined once when it is not at rounding level; a system whose answer still
misses by more than 1e-8 of the data's size is solved dense when it is small, and refused
otherwise (such systems are nearly singular: LAPACK's dense solve does no better).
"""

from __future__ import annotations

import numpy as np

__all__ = ["banded_entries", "solve_banded_rows"]

_DENSE_UP_TO = 48  # below this many unknowns a dense solve is as cheap and simplest
_DENSE_FALLBACK_UP_TO = 3000  # a failed fast solve is redone dense up to this size


def solve_banded_rows(
    cols: np.ndarray, vals: np.ndarray, rhs: np.ndarray, cyclic: bool = False
) -> np.ndarray:
    """Solve ``A x = rhs`` for a square matrix given by its rows' few non-zeros.

    Parameters
    ----------
    cols : (n, w) int
        Column of each stored entry of row i (in ``[0, n)``; repeats are added up).
    vals : (n, w) float
        The entries; ``A[i, cols[i, j]] += vals[i, j]``.
    rhs : (n, ...) float
        Right-hand sides; trailing axes are independent columns.
    cyclic : bool
        The band wraps around (columns are near their row modulo n), as for a closed curve.

    Returns
    -------
    (n, ...) float

    Raises
    ------
    ValueError
        If the matrix is singular (the solution is not finite).
    """
    cols = np.asarray(cols, dtype=np.int64)
    vals = np.asarray(vals, dtype=np.float64)
    b = np.asarray(rhs, dtype=np.float64)
    n = b.shape[0]
    flat = b.reshape(n, -1)
    with np.errstate(all="ignore"):
        try:
            x = _solve(cols, vals, flat, cyclic)
            r = flat - _apply(cols, vals, x)
            if not _small(r, cols, vals, x, flat, 1e-13):
                x = x + _solve(cols, vals, r, cyclic)  # one step of iterative refinement
                r = flat - _apply(cols, vals, x)
            ok = _small(r, cols, vals, x, flat, 1e-8)
        except np.linalg.LinAlgError:
            ok = False
        if not ok and n <= _DENSE_FALLBACK_UP_TO:
            # a pivot of the block elimination was too small (possible when the band's
            # largest entries are off its middle): LAPACK's pivoting may solve it
            try:
                x = np.linalg.solve(_dense(cols, vals, n), flat)
                ok = _small(flat - _apply(cols, vals, x), cols, vals, x, flat, 1e-8)
            except np.linalg.LinAlgError:
                ok = False
    if not ok or not np.all(np.isfinite(x)):
        raise ValueError(
            "the interpolation system is singular or too ill-conditioned to solve (are the "
            "points very unevenly spaced? a lower degree or centripetal spacing helps)"
        )
    return x.reshape(b.shape)


def _small(r, cols, vals, x, f, tol: float) -> bool:
    """Whether the residual r is within ``tol`` of the right-hand side's size.

    For interpolation the residual is exactly how far the curve misses the data at the
    parameters, so this is the test that matters (a backward error relative to ``|A||x|``
    would pass garbage on a nearly singular system, where ``x`` is huge)."""
    if not np.all(np.isfinite(r)):
        return False
    scale = float(np.abs(f).max(initial=0.0))
    return bool(np.abs(r).max(initial=0.0) <= tol * max(scale, 1e-300))


def _dense(cols: np.ndarray, vals: np.ndarray, n: int) -> np.ndarray:
    A = np.zeros((n, n))
    np.add.at(A, (np.repeat(np.arange(n), cols.shape[1]), cols.ravel()), vals.ravel())
    return A


def _apply(cols: np.ndarray, vals: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``A @ x`` from the rows' entries (a compiled sparse product: the gathered
    ``x[cols]`` of an einsum would be ``width`` times the size of ``x``)."""
    from scipy.sparse import csr_array

    n, w = cols.shape
    indptr = np.arange(0, n * w + 1, w, dtype=np.int64)
    a = csr_array((vals.reshape(-1), cols.reshape(-1), indptr), shape=(n, x.shape[0]))
    return a @ x


def _solve(cols: np.ndarray, vals: np.ndarray, f: np.ndarray, cyclic: bool) -> np.ndarray:
    n = f.shape[0]
    if n <= _DENSE_UP_TO:
        return np.linalg.solve(_dense(cols, vals, n), f)
    if not cyclic:
        return _solve_open(cols, vals, f)
    return _solve_cyclic(cols, vals, f)


def _solve_open(cols: np.ndarray, vals: np.ndarray, f: np.ndarray) -> np.ndarray:
    """LAPACK's banded LU (``gbsv``, partial pivoting inside the band) on the rows' entries
    laid out in LAPACK's band storage: ``kl + ku + 1`` rows of n (plus ``kl`` rows of
    fill-in room), so ``2 kl + ku + 1`` numbers an unknown."""
    from scipy.linalg import solve_banded

    n = f.shape[0]
    rows = np.broadcast_to(np.arange(n)[:, None], cols.shape)
    live = vals != 0
    offset = (cols - rows)[live]  # j - i
    ku = max(0, int(offset.max(initial=0)))
    kl = max(0, -int(offset.min(initial=0)))
    # Band storage: ab[ku + i - j, j] = A[i, j]; repeated entries add up (bincount).
    flat = (ku - offset) * n + cols[live]
    ab = np.bincount(flat, weights=vals[live], minlength=(kl + ku + 1) * n)
    ab = ab.reshape(kl + ku + 1, n)
    return solve_banded((kl, ku), ab, f, overwrite_ab=True, overwrite_b=False, check_finite=False)


def banded_entries(n: int, width: int, rhs: int, cyclic: bool = False) -> int:
    """Float entries `solve_banded_rows` holds at once for ``n`` unknowns, ``width``
    stored entries a row and ``rhs`` right-hand sides: what a caller should charge against
    a budget before asking for the solve.

    The band (``2 kl + ku + 1 <= 3 width`` rows of LAPACK storage), the rows' columns and
    values (twice: the sparse matrix of the residual check copies them), the right-hand
    sides, the solution, its correction and the residual; a closed system solves
    ``rhs + width`` right-hand sides and keeps its border's copies too (measured with
    tracemalloc at a million points, cubic, 3 columns: 35 numbers a point open, 53
    closed; charged: 48 and 70).
    """
    if cyclic:
        return int(n) * (7 * width + 6 * (rhs + width))
    return int(n) * (9 * width + 4 * rhs)


def _solve_cyclic(cols: np.ndarray, vals: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Renumber so the band is on the diagonal, split off the last b unknowns, eliminate."""
    n = f.shape[0]
    rows = np.arange(n)[:, None]
    # shift: the median offset of each row's largest entry puts the band on the diagonal
    main = cols[np.arange(n), np.argmax(np.abs(vals), axis=1)]
    s = int(np.median((main - rows[:, 0] + n // 2) % n - n // 2)) % n  # signed offsets
    c = (cols - s) % n  # unknown j of the renumbered system is unknown (j + s) % n
    off = (c - rows + n // 2) % n - n // 2  # cyclic offset in [-n/2, n/2)
    live = vals != 0
    bw = max(1, int(np.abs(off[live]).max(initial=0)))
    if n <= 4 * bw + 8:
        A = np.zeros((n, n))
        np.add.at(A, (np.broadcast_to(rows, c.shape)[live], c[live]), vals[live])
        return np.roll(np.linalg.solve(A, f), s, axis=0)
    n1 = n - bw
    in_t = (np.broadcast_to(rows, c.shape) < n1) & (c < n1)
    top = rows[:, 0] < n1
    # T: the open banded part (rows and unknowns 0 .. n1-1); E: its columns of unknowns n1..
    ct = np.where(in_t, c, np.broadcast_to(rows, c.shape))[:n1]
    vt = np.where(in_t, vals, 0.0)[:n1]
    E = np.zeros((n1, bw))
    edge = (~in_t & live)[:n1]
    ei, ej = np.nonzero(edge)
    np.add.at(E, (ei, c[:n1][edge] - n1), vals[:n1][edge])
    rhs = np.concatenate([f[top], E], axis=1)
    Y = _solve_open(ct, vt, rhs)
    Yf, W = Y[:, : f.shape[1]], Y[:, f.shape[1] :]
    # G, H: the last bw rows, on unknowns 0 .. n1-1 and n1 .. n-1
    cb, vb = c[n1:], vals[n1:]
    G = np.zeros((bw, n1))
    H = np.zeros((bw, bw))
    gi, gj = np.nonzero(cb < n1)
    np.add.at(G, (gi, cb[gi, gj]), vb[gi, gj])
    hi, hj = np.nonzero(cb >= n1)
    np.add.at(H, (hi, cb[hi, hj] - n1), vb[hi, hj])
    z = np.linalg.solve(H - G @ W, f[n1:] - G @ Yf)
    x = np.concatenate([Yf - W @ z, z])
    return np.roll(x, s, axis=0)
