"""Frozen buffers filled in place (``kernels.buffers``) and the checks frozen arrays rest on:
the same bytes as ``tobytes``, immutable, and never made writable again."""

from __future__ import annotations

import numpy as np
import pytest

from formgraph.geometry import frozen_array, is_frozen
from formgraph.geometry.base import all_finite
from formgraph.kernels import buffers


def _cannot_be_made_writable(a: np.ndarray) -> None:
    with pytest.raises(ValueError):
        a.flags.writeable = True
    with pytest.raises(ValueError):
        a[...] = 0


@pytest.mark.parametrize(
    "make",
    [
        lambda: np.random.default_rng(0).random((300_000, 3)),  # 7 MB float64
        lambda: np.random.default_rng(1).random((400_000, 3)).astype(np.float32),  # a cast
        lambda: np.random.default_rng(2).random((3, 500_000)).T,  # not C-contiguous
        lambda: np.arange(600_000, dtype=np.int32),
    ],
)
def test_fill_bytes_is_tobytes(make):
    values = make()
    for dtype in (np.float64, np.int64):
        want = np.asarray(values, dtype=dtype).tobytes()
        got = buffers.fill_bytes(values, dtype)
        assert got is None or got == want  # None only where this Python cannot
    a = frozen_array(values)
    assert is_frozen(a) and a.flags.c_contiguous and a.shape == values.shape
    np.testing.assert_array_equal(a, values.astype(np.float64))
    _cannot_be_made_writable(a)


def test_fill_frozen_large_and_small():
    for n in (10, 1 << 18):  # below and above MIN_BYTES (8 bytes each)
        a = buffers.fill_frozen(
            n, np.float64, lambda out, n=n: np.multiply(np.arange(n), 2.0, out=out)
        )
        assert is_frozen(a) and a.shape == (n,)
        assert a[-1] == 2.0 * (n - 1) and a[0] == 0.0
        _cannot_be_made_writable(a)
    b = buffers.fill_frozen((4, 3), np.int64, lambda out: out.fill(7))
    assert b.shape == (4, 3) and (b == 7).all() and is_frozen(b)


def test_a_failed_fill_hands_out_nothing():
    def fill(out):
        raise RuntimeError("half written")

    with pytest.raises(RuntimeError, match="half written"):
        buffers.fill_frozen(1 << 18, np.float64, fill)


def test_all_finite_is_isfinite_all():
    big = np.full(10, 1e308)  # finite values whose sum overflows: the exact test decides
    assert all_finite(big)
    assert all_finite(np.r_[big, -big])  # inf - inf in the sum: NaN, still all finite
    assert all_finite(np.zeros(0))
    for bad in (np.nan, np.inf, -np.inf):
        a = np.arange(1000.0)
        a[517] = bad
        assert not all_finite(a)
        assert not all_finite(a.reshape(100, 10))


@pytest.mark.parametrize("count, step", [(0, 3), (5, 1), (200_001, 3), (1 << 17, 1)])
def test_frozen_arange_is_arange(count, step):
    a = buffers.frozen_arange(count, step)
    assert a.dtype == np.int64 and is_frozen(a)
    np.testing.assert_array_equal(a, np.arange(0, step * count, step))
    _cannot_be_made_writable(a)
