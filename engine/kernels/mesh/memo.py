"""Connectivity reused while only the positions change: a small memo keyed by the faces.

A slider that moves points (a tube's thickness, a twist, a relaxation step) hands the mesh
kernels new vertices on the same faces, and their connectivity work (edge tables,
components, boundary loops) comes out the same each time. :func:`by_faces` keeps the last
few results of each kind with a copy of the faces they came from; a call with equal faces
(compared array to array, never by a hash that could collide) gets the kept result.

Only what depends on the faces alone goes through it, never positions; the arrays kept
are read-only, so a caller cannot change a result another call gets.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np

__all__ = ["MIN_CORNERS", "by_faces", "clear"]

T = TypeVar("T")

#: below this many face corners the work is cheaper than keeping it
MIN_CORNERS = 4096
#: results kept per kind (the meshes one step of a slider passes through)
PER_KIND = 2
#: the largest faces array kept (corners): larger meshes are recomputed, not copied
MAX_CORNERS = 4_000_000

_lock = threading.Lock()
_kept: dict[str, list[tuple[np.ndarray, np.ndarray, int, Any]]] = {}
hits = 0  # calls answered from the memo (the tests read it)


def by_faces(
    kind: str, face_indices: np.ndarray, face_offsets: np.ndarray, n: int, compute: Callable[[], T]
) -> T:
    """``compute()``, or the result kept for the same ``kind``, faces and vertex count.

    Parameters
    ----------
    kind : str
        What is computed (one name per function of the faces).
    face_indices, face_offsets : int arrays
        The faces the result depends on (and nothing else but ``n``).
    n : int
        The number of vertices.
    compute : callable
        Makes the result from the faces; an exception it raises is not kept.
    """
    global hits
    fi, fo = np.asarray(face_indices), np.asarray(face_offsets)
    if not MIN_CORNERS <= fi.size <= MAX_CORNERS:
        return compute()
    with _lock:
        entries = _kept.setdefault(kind, [])
        for i, (kfi, kfo, kn, value) in enumerate(entries):
            if kn == n and kfi.shape == fi.shape and kfo.shape == fo.shape:
                if np.array_equal(kfo, fo) and np.array_equal(kfi, fi):
                    entries.insert(0, entries.pop(i))
                    hits += 1
                    return value
    value = _frozen(compute())
    with _lock:
        entries = _kept.setdefault(kind, [])
        entries.insert(0, (fi.copy(), fo.copy(), n, value))
        del entries[PER_KIND:]
    return value


def clear() -> None:
    """Forget every kept result."""
    with _lock:
        _kept.clear()


def _frozen(value: Any) -> Any:
    """``value`` with its arrays (also inside tuples and lists) made read-only."""
    if isinstance(value, np.ndarray):
        value.flags.writeable = False
    elif isinstance(value, (tuple, list)):
        for v in value:
            _frozen(v)
    return value
