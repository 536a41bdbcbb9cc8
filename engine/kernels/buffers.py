"""Immutable ``bytes`` buffers filled in place: what a frozen array of many bytes is built on.

A frozen array (:func:`~formgraph.geometry.base.frozen_array`) views an immutable ``bytes``
object, so nobody can make it writable again. ``ndarray.tobytes`` makes that object by
copying into memory fresh from the allocator, touched 4 KiB page by 4 KiB page (about 2,000
page faults for 8 MB, 40-60 % of the copy's time), and needs the array in the final dtype
first (a second copy for a cast). :func:`fill_bytes` instead asks CPython for a new,
uninitialised ``bytes`` object (``PyBytes_FromStringAndSize(NULL, n)``: the C API's own way
to build one, filled before anyone else can see it), advises the kernel to back it with huge
pages where Linux allows (``madvise(MADV_HUGEPAGE)``, as numpy does for its own large
arrays), and casts the values straight into it. The ``bytes`` object is handed out only once
filled; the writable view used to fill it never leaves this module.

Where any of that is unavailable (another Python, no ``libc``), :func:`fill_bytes` returns
None and the caller copies with ``tobytes``: the values are the same either way.
"""

from __future__ import annotations

import ctypes
import sys
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["MIN_BYTES", "fill_bytes", "fill_frozen"]

MIN_BYTES = 1 << 20  # below this the page faults saved do not pay for the ctypes calls
_HUGE = 1 << 21  # a transparent huge page on x86-64 and arm64 (Linux)
_MADV_HUGEPAGE = 14  # <linux/mman.h>


def _bytes_api() -> Any:
    try:
        new = ctypes.pythonapi.PyBytes_FromStringAndSize
    except (AttributeError, OSError):  # not CPython
        return None
    new.restype = ctypes.py_object
    new.argtypes = [ctypes.c_void_p, ctypes.c_ssize_t]
    return new


def _madvise() -> Any:
    if not sys.platform.startswith("linux"):
        return None
    try:
        fn = ctypes.CDLL(None, use_errno=True).madvise
    except (AttributeError, OSError):
        return None
    fn.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
    fn.restype = ctypes.c_int
    return fn


_NEW_BYTES = _bytes_api()
_MADVISE = _madvise()


def _new_bytes(nbytes: int) -> tuple[bytes, Any]:
    """A new uninitialised ``bytes`` object and a ctypes array over its contents."""
    buf = _NEW_BYTES(None, nbytes)
    address = np.frombuffer(buf, np.uint8).ctypes.data
    if _MADVISE is not None:  # whole huge pages inside the buffer; only advice, never fatal
        start = -(-address // _HUGE) * _HUGE
        stop = (address + nbytes) // _HUGE * _HUGE
        if stop > start:
            _MADVISE(start, stop - start, _MADV_HUGEPAGE)
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
