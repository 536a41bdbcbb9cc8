"""The compiled loop of :func:`formgraph.kernels.attributes.noise.noise` (numba, cached on
disk): Perlin's improved noise a point at a time, in the reference's operation order.

numpy's version (:func:`.noise._chunk`) makes some sixty temporaries a chunk and gathers
each corner's hash and gradient through ``np.take``; the loop keeps one point's values in
registers and reads the two 512-entry tables from L1. It does the same floating-point
operations in the same order (``floor``, the quintic fade, the gradient dot products summed
as the reference sums them, the lerps as ``lo + t * (hi - lo)``), with fused multiply-adds
off (numba's default ``fastmath=False``), so its values are numpy's bit for bit (tests).

Imported only when noise is asked for, so ``import formgraph`` never pays for numba; at
module level so numba's on-disk cache finds it again in a new process.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True, inline="always")
def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@nb.njit(cache=True, inline="always")
def _corner(gx, gy, gz, h, px, py, pz):
    return (gx[h] * px + gy[h] * py) + gz[h] * pz


@nb.njit(cache=True, inline="always")
def _lerp(t, lo, hi):
    return lo + t * (hi - lo)


@nb.njit(cache=True, nogil=True)
def fill(x, y, z, p, gx, gy, gz, scale, out):
    """``out[i]`` = the noise at ``(x[i], y[i], z[i])`` times ``scale``, clipped to [-1, 1]
    (``scale`` 0: the raw noise, unclipped); NaN where a coordinate is not finite.

    ``p`` is the permutation twice over (512 entries), ``gx, gy, gz`` the gradient of the
    corner whose last hash step reads ``p[j]``."""
    for i in range(len(out)):
        xi, yi, zi = x[i], y[i], z[i]
        if not (math.isfinite(xi) and math.isfinite(yi) and math.isfinite(zi)):
            out[i] = np.nan
            continue
        fx, fy, fz = math.floor(xi), math.floor(yi), math.floor(zi)
        ix = np.int64(fx) & 255
        iy = np.int64(fy) & 255
        iz = np.int64(fz) & 255
        xf, yf, zf = xi - fx, yi - fy, zi - fz
        u, v, w = _fade(xf), _fade(yf), _fade(zf)
        a = p[ix] + iy
        b = p[ix + 1] + iy
        aa = p[a] + iz
        ab = p[a + 1] + iz
        ba = p[b] + iz
        bb = p[b + 1] + iz
        x1, y1, z1 = xf - 1.0, yf - 1.0, zf - 1.0
        n00 = _lerp(u, _corner(gx, gy, gz, aa, xf, yf, zf), _corner(gx, gy, gz, ba, x1, yf, zf))
        n10 = _lerp(u, _corner(gx, gy, gz, ab, xf, y1, zf), _corner(gx, gy, gz, bb, x1, y1, zf))
        n01 = _lerp(
            u, _corner(gx, gy, gz, aa + 1, xf, yf, z1), _corner(gx, gy, gz, ba + 1, x1, yf, z1)
        )
        n11 = _lerp(
            u, _corner(gx, gy, gz, ab + 1, xf, y1, z1), _corner(gx, gy, gz, bb + 1, x1, y1, z1)
        )
        r = _lerp(w, _lerp(v, n00, n10), _lerp(v, n01, n11))
        if scale != 0.0:
            r = min(max(r * scale, -1.0), 1.0)
        out[i] = r
