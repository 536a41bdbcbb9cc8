"""The compiled loop of :func:`formgraph.kernels.attributes.random.rand` (numba, cached on
disk): a key's bits hashed by SplitMix64's finalizer, one key at a time.

numpy needs thirteen passes over each chunk of keys (the mixer's eight, five around it);
the loop keeps a key in a register from its bits to its float. The same integer operations
(wrapping uint64 arithmetic), so the same numbers as :func:`.random.mix64` and the tests'
pure-Python reference.

Imported only when ``rand`` is asked for, so ``import formgraph`` never pays for numba; at
module level so numba's on-disk cache finds it again in a new process.
"""

from __future__ import annotations

import numba as nb
import numpy as np

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_ONE = np.uint64(0x3FF0000000000000)  # the bits of 1.0
_NEG_ZERO = np.uint64(0x8000000000000000)


@nb.njit(cache=True, nogil=True)
def fill(key_bits, stream, out_bits):
    """``out_bits[j]`` = the bits of ``1 + rand``, for the float64 keys whose bits are
    ``key_bits`` (-0 read as +0) and ``stream`` (one seed's constant, or one per key)."""
    per_key = len(stream) > 1
    for j in range(len(out_bits)):
        x = key_bits[j]
        if x == _NEG_ZERO:
            x = np.uint64(0)
        x ^= stream[j] if per_key else stream[0]
        x ^= x >> np.uint64(30)
        x *= _M1
        x ^= x >> np.uint64(27)
        x *= _M2
        x ^= x >> np.uint64(31)
        out_bits[j] = (x >> np.uint64(12)) | _ONE  # the top 52 bits: a float in [1, 2)
