"""Counter-based random numbers: ``rand(key, seed)`` as a pure hash of its arguments.

There is no generator state: the value for a key depends on the key and the seed alone, so
it is the same in whatever order, in whatever process and on whatever machine the keys are
evaluated (a graph's cached and recomputed parts agree). Keys and seeds are float64 (an
index ``i`` as well as a coordinate may be a key); their IEEE-754 bits are hashed, with -0
read as +0.

The hash is two independent chains of Chris Wellons' ``lowbias32`` integer hash (the
best-measured two-multiply 32-bit mixer of his hash-prospector search) over the key's two
32-bit words, each chain seeded by a hash of the seed; the two 32-bit results fill the 52
mantissa bits of a float in [1, 2), from which 1 is taken. 32-bit lanes because numpy
vectorizes 32-bit multiplies and 64-bit ones it does not (a splitmix64 finalizer in uint64
numpy is several times slower); the work runs in cache-sized chunks so each pass of the
chain stays in L2.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["hash32", "rand"]

_U = np.uint32
_M1 = _U(0x7FEB352D)
_M2 = _U(0x846CA68B)
_S16, _S15, _S12 = _U(16), _U(15), _U(12)
_EXP_ONE = _U(0x3FF00000)  # the high word of 1.0
_LANE = (_U(0x9E3779B9), _U(0x85EBCA6B))  # seeds the two chains apart
_CHUNK = 1 << 15


def _lowbias32(x: np.ndarray, t: np.ndarray) -> None:
    """``x = lowbias32(x)`` in place (``t``: scratch of the same shape)."""
    np.right_shift(x, _S16, out=t)
    np.bitwise_xor(x, t, out=x)
    np.multiply(x, _M1, out=x)
    np.right_shift(x, _S15, out=t)
    np.bitwise_xor(x, t, out=x)
    np.multiply(x, _M2, out=x)
    np.right_shift(x, _S16, out=t)
    np.bitwise_xor(x, t, out=x)


def hash32(values: Any) -> np.ndarray:
    """``lowbias32`` of uint32 ``values`` (a new array): the mixer, exposed for tests.

    Example
    -------
    >>> int(hash32(np.array([1], np.uint32))[0])
    1753845952
    """
    x = np.array(values, dtype=_U, ndmin=1)
    _lowbias32(x, np.empty_like(x))
    return x


def _words(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The low and high 32-bit words of float64 ``a`` (flat, contiguous), -0 read as +0."""
    w = (a.reshape(-1) + 0.0).astype("<f8", copy=False).view("<u4").reshape(-1, 2)
    return np.ascontiguousarray(w[:, 0]), np.ascontiguousarray(w[:, 1])


def _seed_lanes(seed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each chain's 32-bit starting value for each seed (the seed hashed twice per lane)."""
    lo, hi = _words(seed)
    lanes = []
    for k, c in enumerate(_LANE):
        first, second = (lo, hi) if k == 0 else (hi, lo)
        x = np.bitwise_xor(first, c)
        t = np.empty_like(x)
        _lowbias32(x, t)
        np.bitwise_xor(x, second, out=x)
        _lowbias32(x, t)
        lanes.append(x)
    return lanes[0], lanes[1]


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
        52 random bits each; NaN where the key or the seed is NaN.

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
        per_element = False
    else:
        k, s = (a.reshape(-1) for a in np.broadcast_arrays(k, s))
        shape = np.broadcast_shapes(np.shape(key), np.shape(seed))
        per_element = True
    n = k.size
    out = np.empty(n, "<f8")
    if n == 0:
        return out.reshape(shape)
    s1, s2 = _seed_lanes(np.ascontiguousarray(s))
    words = out.view("<u4").reshape(-1, 2)
    size = min(_CHUNK, n)
    lo, hi = np.empty(size, _U), np.empty(size, _U)
    a, b, t = np.empty(size, _U), np.empty(size, _U), np.empty(size, _U)
    buf = np.empty(size, "<f8")
    bw = buf.view("<u4").reshape(-1, 2)
    for start in range(0, n, size):
        stop = min(start + size, n)
        m = stop - start
        if m < size:
            lo, hi, a, b, t, buf = lo[:m], hi[:m], a[:m], b[:m], t[:m], buf[:m]
            bw = buf.view("<u4").reshape(-1, 2)
        np.add(k[start:stop], 0.0, out=buf)  # -0 -> +0
        np.copyto(lo, bw[:, 0])
        np.copyto(hi, bw[:, 1])
        c1 = s1[start:stop] if per_element else s1[0]
        c2 = s2[start:stop] if per_element else s2[0]
        np.bitwise_xor(lo, c1, out=a)
        _lowbias32(a, t)
        np.bitwise_xor(a, hi, out=a)
        _lowbias32(a, t)
        np.bitwise_xor(hi, c2, out=b)
        _lowbias32(b, t)
        np.bitwise_xor(b, lo, out=b)
        _lowbias32(b, t)
        np.right_shift(a, _S12, out=a)
        np.bitwise_or(a, _EXP_ONE, out=words[start:stop, 1])
        np.copyto(words[start:stop, 0], b)
    out -= 1.0
    if np.isnan(k.min()) or np.isnan(s.min()):  # min propagates NaN: one cheap pass
        out[np.isnan(k) | np.isnan(s)] = np.nan
    return out.astype(np.float64, copy=False).reshape(shape)
