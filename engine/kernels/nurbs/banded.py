"""Banded and cyclic-banded linear systems, solved in O(n) work and memory.

The collocation matrix of interpolation (The NURBS Book A9.1) has at most ``p + 1``
non-zeros per row, next to the diagonal: banded for an open curve, banded with the
corners filled in ("cyclic-banded") for a closed one. A dense solve of it costs n^3 and n^2
memory (20,000 points: minutes and gigabytes); these solvers cost a few passes over the
n x band entries.

- Open systems: the band is cut into B x B blocks (B = 32, or the bandwidth if larger),
  which makes the matrix block tridiagonal, and the blocks are eliminated in order (block
  LU, the "block Thomas" algorithm): each step is one batched LAPACK solve of a B x B block
  with partial pivoting inside it, so n / B steps run one after the other, each vectorized
  over its B rows. (Cyclic reduction would need only log n steps, but it pivots on blocks
  that are not leading principal blocks, and on collocation matrices of very uneven
  spacing it loses all accuracy; elimination in order keeps the pivots totally positive.)
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

__all__ = ["solve_banded_rows"]

_DENSE_UP_TO = 48  # below this many unknowns a dense solve is as cheap and simplest
_DENSE_FALLBACK_UP_TO = 3000  # a failed fast solve is redone dense up to this size
_BLOCK = 32  # rows per elimination step: big enough to amortize the step, small for LAPACK


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
    """``A @ x`` from the rows' entries."""
    return np.einsum("iw,iwr->ir", vals, x[cols])


def _solve(cols: np.ndarray, vals: np.ndarray, f: np.ndarray, cyclic: bool) -> np.ndarray:
    n = f.shape[0]
    if n <= _DENSE_UP_TO:
        return np.linalg.solve(_dense(cols, vals, n), f)
    if not cyclic:
        return _solve_open(cols, vals, f)
    return _solve_cyclic(cols, vals, f)


def _solve_open(cols: np.ndarray, vals: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Block elimination of the banded matrix cut into B x B blocks (B >= the bandwidth)."""
    n = f.shape[0]
    rows = np.broadcast_to(np.arange(n)[:, None], cols.shape)
    live = vals != 0
    reach = np.abs(cols - rows)[live]
    band = max(1, int(reach.max(initial=0)))
    size = max(_BLOCK, band)
    m = -(-n // size)
    # per block row: left, diagonal, right neighbour (entries summed: bincount, not add.at)
    ri, ci, v = rows[live], cols[live], vals[live]
    flat = np.ravel_multi_index(
        (ri // size, ci // size - ri // size + 1, ri % size, ci % size), (m, 3, size, size)
    )
    blocks = np.bincount(flat, weights=v, minlength=m * 3 * size * size)
    blocks = blocks.reshape(m, 3, size, size)
    pad = m * size - n
    if pad:  # identity rows for the unknowns past the end
        k = np.arange(size - pad, size)
        blocks[-1, 1, k, k] = 1.0
    F = np.zeros((m * size, f.shape[1]))
    F[:n] = f
    # the coupling blocks are zero but for a band x band corner: left blocks in their top
    # right, right blocks in their bottom left
    L = blocks[:, 0, :band, size - band :]
    U = blocks[:, 2, size - band :, :band]
    x = _block_tridiagonal(L, blocks[:, 1], U, F.reshape(m, size, -1))
    return x.reshape(m * size, -1)[:n]


def _block_tridiagonal(L: np.ndarray, D: np.ndarray, U: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Solve ``L_i x_{i-1} + D_i x_i + U_i x_{i+1} = F_i`` by block LU in order.

    D : (m, B, B); F : (m, B, r); L, U : (m, c, c), the only non-zero corners of the
    coupling blocks (L_i's top right, acting on the last c unknowns of block i - 1; U_i's
    bottom left, acting on the first c of block i + 1). Each step eliminates one block of
    B rows (a B x B solve with partial pivoting inside the block): the pivot blocks are
    Schur complements of leading principal blocks, which stay totally positive for a
    collocation matrix, so the elimination is stable. The steps depend on each other; each
    is vectorized over its block, and only c x c corners pass from one to the next.
    """
    m, size, c = D.shape[0], D.shape[1], L.shape[1]
    r = F.shape[2]
    G = np.zeros((m, size, c))  # D'_i^-1 U_i (only U's first c columns are non-zero)
    Y = np.empty_like(F)  # D'_i^-1 F'_i
    rhs = np.zeros((size, c + r))
    for i in range(m):  # one block of rows per step
        d = D[i]
        rhs[:, c:] = F[i]
        rhs[:, :c] = 0.0
        rhs[size - c :, :c] = U[i]
        if i:
            d = d.copy()
            d[:c, :c] -= L[i] @ G[i - 1, size - c :]
            rhs[:c, c:] -= L[i] @ Y[i - 1, size - c :]
        sol = np.linalg.solve(d, rhs)
        G[i], Y[i] = sol[:, :c], sol[:, c:]
    x = np.empty_like(F)
    x[-1] = Y[-1]
    for i in range(m - 2, -1, -1):
        x[i] = Y[i] - G[i] @ x[i + 1, :c]
    return x


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
