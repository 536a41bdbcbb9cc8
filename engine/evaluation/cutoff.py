"""Early cutoff: whether a node recomputed to the output it had before.

A node whose inputs changed but whose output did not keeps its previous identity, so its
descendants stay cached (:meth:`formgraph.evaluation.run.Run.cutoff_identity`). The two
outputs are compared directly rather than hashed: as equal :func:`~.cache.digest` s would
say, but the new output is not hashed at all, and a changed one (a slider step moves
every vertex) differs in its first few numbers.
"""

from __future__ import annotations

import enum
from typing import Any

import numpy as np

from ..geometry import Geometry
from .cache import digest

__all__ = ["same_content"]


def same_content(a: Any, b: Any) -> bool:
    """Whether two node outputs have the same content, as equal :func:`~.cache.digest` s
    would say: arrays bit for bit, floats by their hex (as cache keys write them), a
    geometry by its fingerprint; False for a value with no content to compare."""
    try:
        return _same(a, b)
    except _Unsure:
        da = digest(a)
        return da is not None and da == digest(b)
    except (TypeError, NotImplementedError):  # no content to compare (plain callables)
        return False


class _Unsure(Exception):
    """A part :func:`_same` does not compare itself: the digests decide."""


def _same(a: Any, b: Any) -> bool:
    if a is b:
        return True
    ta = type(a)
    if ta is not type(b):
        raise _Unsure
    if ta is np.ndarray:
        if a.dtype != b.dtype or a.shape != b.shape:
            return False
        if a.dtype.hasobject:
            raise _Unsure
        x, y = _bits(a), _bits(b)
        return bool(np.array_equal(x[:64], y[:64]) and np.array_equal(x, y))
    if ta is float:
        return a.hex() == b.hex()
    if ta in (str, int, bool) or a is None:
        return a == b
    if ta in (list, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if ta is dict:
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, Geometry):
        return _same(a.fingerprint(), b.fingerprint())
    if isinstance(a, enum.Enum):
        return a == b
    raise _Unsure


def _bits(a: np.ndarray) -> np.ndarray:
    """The array's bytes as unsigned integers of its item size (a flat view, or copy)."""
    flat = np.ascontiguousarray(a).reshape(-1)
    size = flat.dtype.itemsize
    return flat.view(f"u{size}") if size in (1, 2, 4, 8) else flat.view(np.uint8)
