"""Immutable ``bytes`` buffers filled in place: what a frozen array of many bytes is built on.

A frozen array (:func:`~formgraph.geometry.base.frozen_array`) views an immutable ``bytes``
object, so nobody can make it writable again. ``ndarray.tobytes`` makes that object by
copying an array that must exist first, in the final dtype (for a cast, a second copy), and
a file read in chunks is joined into it (a second copy again). Here CPython is asked for a
new, uninitialised ``bytes`` object (``PyBytes_FromStringAndSize(NULL, n)``: the C API's own
way to build one, filled before anyone else can see it) and the values are written straight
into it: a kernel's output (:func:`fill_frozen`), a cast (:func:`fill_bytes`), a file's
contents (:func:`filled_bytes`). The ``bytes`` object is handed out only once filled; the
writable view used to fill it never leaves this module.

(Advising huge pages for these buffers was measured and left out: where the kernel compacts
memory on such a fault, 72 MB took 190 ms to fault in instead of 35.)

Where CPython's C API is unavailable, the same functions fill a numpy array or a
``bytearray`` and copy it once: the values are the same either way.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["MIN_BYTES", "fill_bytes", "fill_frozen", "filled_bytes", "frozen_arange"]

MIN_BYTES = 1 << 20  # below this a copy costs less than the ctypes calls


def _bytes_api() -> Any:
    try:
        new = ctypes.pythonapi.PyBytes_FromStringAndSize
    except (AttributeError, OSError):  # not CPython
        return None
    new.restype = ctypes.py_object
    new.argtypes = [ctypes.c_void_p, ctypes.c_ssize_t]
    return new


_NEW_BYTES = _bytes_api()


def _new_bytes(nbytes: int) -> tuple[bytes, Any]:
    """A new uninitialised ``bytes`` object and a ctypes array over its contents."""
    buf = _NEW_BYTES(None, nbytes)
    address = np.frombuffer(buf, np.uint8).ctypes.data
    return buf, (ctypes.c_uint8 * nbytes).from_address(address)


def fill_frozen(shape: Any, dtype: Any, fill: Callable[[np.ndarray], None]) -> np.ndarray:
    """A frozen array of ``shape`` and ``dtype`` that ``fill(out)`` writes: a kernel's output
    made straight into its immutable buffer, never copied there afterwards.

    ``fill`` receives a writable C-ordered array and must write every element; it must not
    keep the array (it is the only way to change the result). Returns the read-only array,
    backed by ``bytes`` like every frozen array
    (:func:`~formgraph.geometry.base.is_frozen`).
    """
    dtype = np.dtype(dtype)
    shape = tuple(int(n) for n in np.atleast_1d(shape)) if np.ndim(shape) else (int(shape),)
    nbytes = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
    if _NEW_BYTES is None or nbytes < MIN_BYTES or dtype.hasobject:
        out = np.empty(shape, dtype)
        fill(out)
        return np.frombuffer(out.tobytes(), dtype).reshape(shape)
    buf, raw = _new_bytes(nbytes)
    out = np.frombuffer(raw, dtype).reshape(shape)
    fill(out)
    del out, raw  # the only writable views: gone before the bytes are handed out
    return np.frombuffer(buf, dtype).reshape(shape)


def frozen_arange(count: int, step: int = 1) -> np.ndarray:
    """``0, step, 2 step, ...`` (``count`` int64 values), frozen and made in place: the
    face offsets of a triangle mesh (``step`` 3), the face indices of a triangle soup."""
    return fill_frozen(count, np.int64, lambda out: _arange(out, step))


def _arange(out: np.ndarray, step: int, block: int = 1 << 16) -> None:
    """``out[:] = 0, step, 2 step, ...`` a block at a time (no temporary of its size)."""
    ramp = np.arange(0, step * block, step, dtype=np.int64)
    for start in range(0, len(out), block):
        part = out[start : start + block]
        np.add(ramp[: len(part)], step * start, out=part)


def filled_bytes(nbytes: int, fill: Callable[[memoryview], int]) -> bytes:
    """A new ``bytes`` object of at most ``nbytes`` that ``fill(view)`` writes, e.g. a
    file's contents read by one ``readinto`` (no list of chunks joined: no second copy).

    ``fill`` receives a writable memoryview of ``nbytes`` and returns how many bytes it
    wrote from the start; the result is cut to that many (a copy only when it fell short).
    It must not keep the view.
    """
    if _NEW_BYTES is None or nbytes < MIN_BYTES:
        scratch = bytearray(nbytes)
        with memoryview(scratch) as view:
            n = fill(view)
        return bytes(scratch[:n]) if n < nbytes else bytes(scratch)
    buf, raw = _new_bytes(nbytes)
    with memoryview(raw).cast("B") as view:
        n = fill(view)
    del raw
    return buf if n == nbytes else buf[:n]


def fill_bytes(values: np.ndarray, dtype: Any) -> bytes | None:
    """A new ``bytes`` object holding ``values`` cast to ``dtype`` in C order (what
    ``np.asarray(values, dtype).tobytes()`` returns), or None where this Python cannot build
    one in place (the caller then copies with ``tobytes``).

    Parameters
    ----------
    values : ndarray
        Any shape and layout; cast as ``astype`` casts (``unsafe``).
    dtype : numpy dtype
        The element type of the bytes.
    """
    dtype = np.dtype(dtype)
    nbytes = values.size * dtype.itemsize
    if _NEW_BYTES is None or nbytes < MIN_BYTES or dtype.hasobject or values.dtype.hasobject:
        return None
    buf, raw = _new_bytes(nbytes)
    target = np.frombuffer(raw, dtype).reshape(values.shape)
    np.copyto(target, values, casting="unsafe")
    del target, raw  # the only writable views: gone before the bytes are handed out
    return buf
