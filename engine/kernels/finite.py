"""Whether float arrays are finite, in one pass over the data (no boolean temporary)."""

from __future__ import annotations

import numpy as np

__all__ = ["all_finite"]


def all_finite(a: np.ndarray) -> bool:
    """Whether every value of float array ``a`` is finite, in one pass and no temporary when
    they are: a sum is finite only if every term is (a NaN or an infinity makes it NaN or
    infinite); only a sum that overflows, or a bad value, takes the exact test."""
    if a.size == 0:
        return True
    with np.errstate(all="ignore"):
        if np.isfinite(np.add.reduce(a, axis=None)):
            return True
    return bool(np.isfinite(a).all())
