"""Sorting integer keys with their positions: the one sort behind edge tables and welds.

A mesh's edges, twins and duplicate vertices are all found by sorting an int64 key per
element and reading runs of equal keys. NumPy sorts values several times faster than it
argsorts them (its value sort is vectorized, its argsort compares through the index), so
where the key and the element's position fit one int64 together, the position rides in the
low bits of the key and one value sort gives both the sorted keys and the permutation.
"""

from __future__ import annotations

import numpy as np

__all__ = ["mix64", "sort_keys"]


def sort_keys(key: np.ndarray, key_bound: int) -> tuple[np.ndarray, np.ndarray]:
    """A stable argsort of non-negative int64 keys, and the keys in that order.

    Parameters
    ----------
    key : (m,) int64
        Every key in ``[0, key_bound)``.
    key_bound : int
        An upper bound on the keys (what decides whether key and position share a word).

    Returns
    -------
    order : (m,) int64
        Positions sorted by key, equal keys in position order (as ``kind="stable"``).
    sorted_keys : (m,) int64
        ``key[order]``.

    Example
    -------
    >>> order, skey = sort_keys(np.array([5, 2, 5, 0]), 6)
    >>> order.tolist(), skey.tolist()
    ([3, 1, 0, 2], [0, 2, 5, 5])
    """
    key = np.asarray(key, dtype=np.int64)
    m = key.size
    shift = max(int(m - 1).bit_length(), 1)
    if int(max(key_bound - 1, 0)).bit_length() + shift <= 63:
        packed = key << shift
        packed |= np.arange(m, dtype=np.int64)
        packed.sort(kind="stable")  # (all distinct: stable only for its speed on runs)
        order = packed & ((1 << shift) - 1)
        packed >>= shift
        return order, packed
    order = np.argsort(key, kind="stable")
    return order, key[order]


def mix64(x: np.ndarray) -> np.ndarray:
    """The splitmix64 finalizer (Steele et al. 2014): a bijection of 64-bit words."""
    with np.errstate(over="ignore"):
        x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        return x ^ (x >> np.uint64(31))
