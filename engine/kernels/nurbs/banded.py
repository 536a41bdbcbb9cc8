"""Banded and cyclic-banded linear systems, solved in O(n) work and O(log n) array steps.

The collocation matrix of interpolation (The NURBS Book A9.1) has at most ``p + 1``
non-zeros per row, next to the diagonal: banded for an open curve, banded with the
corners filled in ("cyclic-banded") for a closed one. A dense solve of it costs n^3 and n^2
memory (20,000 points: minutes and gigabytes); these solvers cost a few passes over the
n x band entries.

- Open systems: the band is cut into b x b blocks (b the half bandwidth), which makes the
  matrix block tridiagonal, and the blocks are solved by block cyclic reduction (Hockney
  1965; Buzbee, Golub and Nielson, SIAM J. Numer. Anal. 7, 1970): each level eliminates
  every other block row at once (batched ``numpy.linalg.solve`` of b x b blocks, with
  partial pivoting inside each block), so the work is vectorized over the rows and only
  log2(n / b) levels run one after the other.
- Cyclic systems: the unknowns are renumbered so that the band sits on the diagonal, and
  the last b unknowns are split off (a bordered system, block elimination with a b x b
  Schur complement): what remains is an open banded system with b + 1 right-hand sides.

Collocation matrices of B-splines are totally positive (de Boor, *A Practical Guide to
Splines*, XIII), so elimination needs no pivoting across blocks; each answer is checked by
its residual (computed from the rows, O(n)) and refined once when it is not at rounding
level; a system the blocks cannot solve accurately (a tiny pivot) is solved dense when it
is small, and refused otherwise.
"""

from __future__ import annotations

import numpy as np

__all__ = ["solve_banded_rows"]

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
            # largest entries are off its middle): LAPACK's pivoting solves it
            try:
                x = np.linalg.solve(_dense(cols, vals, n), flat)
                ok = True
            except np.linalg.LinAlgError:
                ok = False
    if not ok or not np.all(np.isfinite(x)):
        raise ValueError("the interpolation system is singular (points too close together?)")
    return x.reshape(b.shape)


def _small(r, cols, vals, x, f, tol: float) -> bool:
    """Whether the residual r is within ``tol`` of the size of the terms it sums (a
    normwise backward error per right-hand side: ||r|| <= tol (||A|| ||x|| + ||f||))."""
    if not np.all(np.isfinite(r)):
        return False
    norm_a = float(np.abs(vals).sum(axis=1).max(initial=0.0))
    scale = norm_a * np.abs(x).max(axis=0, initial=0.0) + np.abs(f).max(axis=0, initial=0.0)
    return bool(np.all(np.abs(r).max(axis=0, initial=0.0) <= tol * scale))


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
    """Block cyclic reduction of the banded matrix cut into b x b blocks."""
    n = f.shape[0]
    rows = np.broadcast_to(np.arange(n)[:, None], cols.shape)
    live = vals != 0
    reach = np.abs(cols - rows)[live]
    bw = max(1, int(reach.max(initial=0)))
    m = -(-n // bw)
    blocks = np.zeros((m, 3, bw, bw))  # per block row: left, diagonal, right neighbour
    ri, ci, v = rows[live], cols[live], vals[live]
    np.add.at(blocks, (ri // bw, ci // bw - ri // bw + 1, ri % bw, ci % bw), v)
    pad = m * bw - n
    if pad:  # identity rows for the unknowns past the end
        k = np.arange(bw - pad, bw)
        blocks[-1, 1, k, k] = 1.0
    F = np.zeros((m * bw, f.shape[1]))
    F[:n] = f
    x = _block_cyclic_reduction(blocks[:, 0], blocks[:, 1], blocks[:, 2], F.reshape(m, bw, -1))
    return x.reshape(m * bw, -1)[:n]


def _block_cyclic_reduction(
    L: np.ndarray, D: np.ndarray, U: np.ndarray, F: np.ndarray
) -> np.ndarray:
    """Solve the block tridiagonal system ``L_i x_{i-1} + D_i x_i + U_i x_{i+1} = F_i``.

    L, D, U : (m, b, b); F : (m, b, r); ``L_0`` and ``U_{m-1}`` are ignored. Each level
    eliminates the odd block rows using their diagonal blocks, halving the system.
    """
    m, b = D.shape[0], D.shape[1]
    if b == 1:  # scalar blocks (a tridiagonal system): plain products and quotients
        return _scalar_cyclic_reduction(L[:, 0, 0], D[:, 0, 0], U[:, 0, 0], F[:, 0])[:, None]
    if m == 1:
        return np.linalg.solve(D[0], F[0])[None]
    mo, me = m // 2, (m + 1) // 2
    sol = np.linalg.solve(D[1::2], np.concatenate([L[1::2], U[1::2], F[1::2]], axis=2))
    XL, XU, XF = sol[..., :b], sol[..., b : 2 * b], sol[..., 2 * b :]
    Le, De, Ue, Fe = L[0::2], D[0::2].copy(), U[0::2], F[0::2].copy()
    newL, newU = np.zeros_like(De), np.zeros_like(De)
    j = np.arange(mo)  # even row 2j has the odd row 2j + 1 on its right
    right = Ue[:mo] @ sol  # [U XL | U XU | U XF], one product for the three
    De[j] -= right[..., :b]
    Fe[j] -= right[..., 2 * b :]
    jr = j[j + 1 < me]  # ... which has an even row 2j + 2 on its right
    newU[jr] = -right[jr, :, b : 2 * b]
    jl = np.arange(1, me)  # even row 2j has the odd row 2j - 1 on its left
    left = Le[1:me] @ sol[: me - 1]
    De[jl] -= left[..., b : 2 * b]
    Fe[jl] -= left[..., 2 * b :]
    newL[jl] = -left[..., :b]
    xe = _block_cyclic_reduction(newL, De, newU, Fe)
    xo = XF - XL @ xe[:mo]
    xo[jr] -= XU[jr] @ xe[jr + 1]
    x = np.empty((m, b, F.shape[2]))
    x[0::2], x[1::2] = xe, xo
    return x


def _scalar_cyclic_reduction(
    L: np.ndarray, D: np.ndarray, U: np.ndarray, F: np.ndarray
) -> np.ndarray:
    """:func:`_block_cyclic_reduction` for 1 x 1 blocks: L, D, U (m,), F (m, r)."""
    m = D.shape[0]
    if m == 1:
        return F / D[0]
    mo, me = m // 2, (m + 1) // 2
    inv = 1.0 / D[1::2]
    XL, XU, XF = L[1::2] * inv, U[1::2] * inv, F[1::2] * inv[:, None]
    Le, De, Ue, Fe = L[0::2], D[0::2].copy(), U[0::2], F[0::2].copy()
    newL, newU = np.zeros(me), np.zeros(me)
    j = np.arange(mo)
    De[j] -= Ue[j] * XL
    Fe[j] -= Ue[j, None] * XF
    jr = j[j + 1 < me]
    newU[jr] = -Ue[jr] * XU[jr]
    jl = np.arange(1, me)
    De[jl] -= Le[jl] * XU[jl - 1]
    Fe[jl] -= Le[jl, None] * XF[jl - 1]
    newL[jl] = -Le[jl] * XL[jl - 1]
    xe = _scalar_cyclic_reduction(newL, De, newU, Fe)
    xo = XF - XL[:, None] * xe[:mo]
    xo[jr] -= XU[jr, None] * xe[jr + 1]
    x = np.empty((m, F.shape[1]))
    x[0::2], x[1::2] = xe, xo
    return x


def _solve_cyclic(cols: np.ndarray, vals: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Renumber so the band is on the diagonal, split off the last b unknowns, eliminate."""
    n = f.shape[0]
    rows = np.arange(n)[:, None]
    # shift: the median offset of each row's largest entry puts the band on the diagonal
    main = cols[np.arange(n), np.argmax(np.abs(vals), axis=1)]
    s = int(np.median((main - rows[:, 0]) % n))
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
