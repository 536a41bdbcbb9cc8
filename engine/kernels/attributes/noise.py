"""Gradient noise: Ken Perlin's improved noise (2002) in three dimensions, vectorized.

``noise(x, y, z)`` is smooth (C2: the quintic fade 6t^5 - 15t^4 + 10t^3), zero at every
lattice point, varies on a scale of one unit, and uses Perlin's fixed reference permutation,
so it is the same everywhere and forever. The 12 cube-edge gradients of the reference
implementation (16 with four repeated) are folded into three tables indexed by the hashed
corner, so each corner costs three gathers and a dot product. The raw noise of this kind
stays below about 1.04 in magnitude; it is scaled by :data:`SCALE` so its extremes reach
about 0.995 and clipped to [-1, 1] (the clip only guards the bound, it never acts in
practice, see tests).

"Improving Noise", K. Perlin, SIGGRAPH 2002; reference code at mrl.nyu.edu/~perlin/noise.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["PERMUTATION", "SCALE", "noise"]

PERMUTATION = np.array(
    [151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30,
     69, 142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94,
     252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171,
     168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122,
     60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161,
     1, 216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159,
     86, 164, 100, 109, 198, 173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147,
     118, 126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183,
     170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129,
     22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228,
     251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239,
     107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4,
     150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215,
     61, 156, 180],
    dtype=np.int64,
)  # fmt: skip

# The reference grad(hash, x, y, z) as a table: hash & 15 -> gradient.
_GRADIENTS = np.array(
    [[1, 1, 0], [-1, 1, 0], [1, -1, 0], [-1, -1, 0], [1, 0, 1], [-1, 0, 1], [1, 0, -1],
     [-1, 0, -1], [0, 1, 1], [0, -1, 1], [0, 1, -1], [0, -1, -1], [1, 1, 0], [0, -1, 1],
     [-1, 1, 0], [0, -1, -1]],
    dtype=np.float64,
)  # fmt: skip

_P = np.concatenate([PERMUTATION, PERMUTATION])  # p[i + 1] without wrapping
# the gradient of the corner whose last hash step reads p[j], for j in 0..511
_GX, _GY, _GZ = (np.ascontiguousarray(_GRADIENTS[_P & 15, k]) for k in range(3))

SCALE = 0.96  # raw extremes ~1.036 (found by optimisation, see tests) -> ~0.995
_CHUNK = 1 << 13  # the ~60 temporaries of a chunk stay in L2


def _fade(t: np.ndarray) -> np.ndarray:
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def _chunk(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    fx, fy, fz = np.floor(x), np.floor(y), np.floor(z)
    ix = fx.astype(np.int64) & 255
    iy = fy.astype(np.int64) & 255
    iz = fz.astype(np.int64) & 255
    x, y, z = x - fx, y - fy, z - fz
    u, v, w = _fade(x), _fade(y), _fade(z)
    a = _P[ix] + iy
    b = _P[ix + 1] + iy
    aa, ab = _P[a] + iz, _P[a + 1] + iz
    ba, bb = _P[b] + iz, _P[b + 1] + iz
    x1, y1, z1 = x - 1.0, y - 1.0, z - 1.0

    def corner(h: np.ndarray, px: np.ndarray, py: np.ndarray, pz: np.ndarray) -> np.ndarray:
        return _GX[h] * px + _GY[h] * py + _GZ[h] * pz

    def lerp(t: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return lo + t * (hi - lo)

    n00 = lerp(u, corner(aa, x, y, z), corner(ba, x1, y, z))
    n10 = lerp(u, corner(ab, x, y1, z), corner(bb, x1, y1, z))
    n01 = lerp(u, corner(aa + 1, x, y, z1), corner(ba + 1, x1, y, z1))
    n11 = lerp(u, corner(ab + 1, x, y1, z1), corner(bb + 1, x1, y1, z1))
    return lerp(w, lerp(v, n00, n10), lerp(v, n01, n11))


def raw_noise(x: Any, y: Any, z: Any) -> np.ndarray:
    """Perlin's improved noise exactly as the reference code computes it (unscaled)."""
    x, y, z = np.broadcast_arrays(*(np.asarray(c, np.float64) for c in (x, y, z)))
    shape = x.shape
    x, y, z = (c.reshape(-1) for c in (x, y, z))
    out = np.empty(x.size)
    for s in range(0, x.size, _CHUNK):
        out[s : s + _CHUNK] = _chunk(x[s : s + _CHUNK], y[s : s + _CHUNK], z[s : s + _CHUNK])
    return out.reshape(shape)


def noise(x: Any, y: Any = 0.0, z: Any = 0.0) -> np.ndarray:
    """Smooth gradient noise in [-1, 1] at the points ``(x, y, z)`` (broadcast together):
    0.96 (:data:`SCALE`) times Perlin's improved noise as his 2002 reference code computes
    it (:func:`raw_noise`), whose extremes reach about 1.036, so that it stays in [-1, 1].
    Divide by 0.96 to compare with the reference or with libraries that follow it.

    Parameters
    ----------
    x, y, z : float or array of float
        Where to sample; the noise varies on a scale of about one unit (multiply the
        coordinates to make it finer).

    Returns
    -------
    ndarray of float64, the broadcast shape
        0 at integer lattice points; NaN where a coordinate is not finite.

    Example
    -------
    >>> float(noise(1.0, 2.0, 3.0)), bool(abs(noise(0.5, 0.25, 0.1)) > 0)
    (0.0, True)
    """
    x, y, z = np.broadcast_arrays(*(np.asarray(c, np.float64) for c in (x, y, z)))
    finite = np.isfinite(x) & np.isfinite(y) & np.isfinite(z)
    if finite.all():
        return np.clip(raw_noise(x, y, z) * SCALE, -1.0, 1.0)
    out = np.full(x.shape, np.nan)
    out[finite] = np.clip(raw_noise(x[finite], y[finite], z[finite]) * SCALE, -1.0, 1.0)
    return out
