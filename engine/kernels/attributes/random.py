"""Counter-based random numbers: ``rand(key, seed)`` as a pure hash of its arguments.

There is no generator state: the value for a key depends on the key and the seed alone, so
it is the same in whatever order, in whatever process and on whatever machine the keys are
evaluated (a graph's cached and recomputed parts agree). Keys and seeds are float64 (an
index ``i`` as well as a coordinate may be a key); their IEEE-754 bits are hashed, with -0
read as +0.

The hash is SplitMix64's output function (Steele, Lea and Flood 2014; its finalizer is
"Mix13" of David Stafford's search for murmur-style 64-bit mixers): the seed's
bits plus the golden-ratio gamma are mixed into a 64-bit stream constant, once per seed;
each key's bits XOR that constant are mixed once more, and the top 52 bits of the result
are the mantissa of a float in [1, 2), from which 1 is taken (exact). One 64-bit lane per
key, hashed in a compiled loop (:mod:`.random_jit`, numba: thirteen numpy passes over the
keys took about twice its time). (The first version ran two 32-bit ``lowbias32`` chains per key:
twice the work; a 53-bit float would need an int-to-float conversion, slower than the
mantissa trick.)

``VERSION`` names the hash: it is part of every cache key (a change of the values must bump
it, so no cached result made with the old numbers is reused).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..buffers import fill_frozen

__all__ = ["VERSION", "mix64", "rand"]

VERSION = 2  # 1: two lowbias32 chains; 2: SplitMix64's Mix13 (both 52 bits)

_U = np.uint64
_M1 = _U(0xBF58476D1CE4E5B9)
_M2 = _U(0x94D049BB133111EB)
_S30, _S27, _S31, _S12 = _U(30), _U(27), _U(31), _U(12)
_GAMMA = _U(0x9E3779B97F4A7C15)  # SplitMix64's increment: 2**64 / the golden ratio
_ONE = _U(0x3FF0000000000000)  # the bits of 1.0


def _mix(x: np.ndarray, t: np.ndarray) -> None:
    """``x = Mix13(x)`` in place (``t``: scratch of the same shape)."""
    np.right_shift(x, _S30, out=t)
    np.bitwise_xor(x, t, out=x)
    np.multiply(x, _M1, out=x)
    np.right_shift(x, _S27, out=t)
    np.bitwise_xor(x, t, out=x)
    np.multiply(x, _M2, out=x)
    np.right_shift(x, _S31, out=t)
    np.bitwise_xor(x, t, out=x)


def mix64(values: Any) -> np.ndarray:
    """SplitMix64's finalizer (Stafford's Mix13) of uint64 ``values`` (a new array): the
    mixer, exposed for tests.

    Example
    -------
    >>> hex(int(mix64(np.array([0x9E3779B97F4A7C15], np.uint64))[0]))
    '0xe220a8397b1dcdaf'
    """
    x = np.array(values, dtype=_U, ndmin=1)
    _mix(x, np.empty_like(x))
    return x


def _stream(seed: np.ndarray) -> np.ndarray:
    """Each seed's 64-bit stream constant: Mix13 of its bits plus the gamma."""
    x = (seed.reshape(-1) + 0.0).astype("<f8").view("<u8") + _GAMMA  # -0 -> +0
    _mix(x, np.empty_like(x))
    return x


def rand(key: Any, seed: Any = 0.0) -> np.ndarray:
    """Uniform numbers on [0, 1) hashed from ``key`` and ``seed`` (broadcast together).

    Parameters
    ----------
    key : float or array of float
        What the number belongs to, e.g. an element's index. Equal keys give equal numbers;
        any change to a key, or to the seed, gives an unrelated one.
    seed : float or array of float, default 0
        Picks one of many independent streams.

    Returns
    -------
    ndarray of float64, the broadcast shape of ``key`` and ``seed``
        52 random bits each (multiples of 2**-52); NaN where the key or the seed is NaN.
        Read-only (frozen, as an attribute keeps it).

    Example
    -------
    >>> r = rand(np.arange(4.0))
    >>> bool(np.all((0 <= r) & (r < 1))), rand(3.0).item() == float(r[3])
    (True, True)
    """
    k = np.asarray(key, np.float64)
    s = np.asarray(seed, np.float64)
    if s.ndim == 0 or s.size == 1:  # one seed for all: hashed once
        shape = k.shape if s.ndim == 0 else np.broadcast_shapes(k.shape, s.shape)
        k = np.broadcast_to(k, shape).reshape(-1)
        s = s.reshape(1)
    else:
        k, s = (a.reshape(-1) for a in np.broadcast_arrays(k, s))
        shape = np.broadcast_shapes(np.shape(key), np.shape(seed))
    if k.size == 0:
        return np.empty(shape, "<f8")
    stream = _stream(s)
    # made straight into a frozen buffer: an attribute's values are kept as they are
    return fill_frozen(k.size, "<f8", lambda out: _fill(out, k, s, stream)).reshape(shape)


def _fill(out: np.ndarray, k: np.ndarray, s: np.ndarray, stream: np.ndarray) -> None:
    """``out[j] = rand(k[j], s[j])`` (``s`` and ``stream``: one seed, or one per key)."""
    from .random_jit import fill  # numba, imported when rand is first asked for

    fill(np.ascontiguousarray(k).view("<u8"), stream, out.view("<u8"))
    out -= 1.0  # exact: [1, 2) -> [0, 1)
    if np.isnan(k.min()) or np.isnan(s.min()):  # min propagates NaN: one cheap pass
        out[np.isnan(k) | np.isnan(s)] = np.nan
