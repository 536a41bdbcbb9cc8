"""Kernels for per-element variation: rand (counter-based hash) and noise (Perlin's improved
noise), against pure-Python references of the published algorithms and by their statistics."""

from __future__ import annotations

import math
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from formgraph.kernels.attributes import noise as noise_mod
from formgraph.kernels.attributes.noise import PERMUTATION, noise, raw_noise
from formgraph.kernels.attributes.random import mix64, rand

ROOT = Path(__file__).resolve().parents[1]

# --- pure-Python references ------------------------------------------------------------


MASK = (1 << 64) - 1


def mix13(z: int) -> int:
    """SplitMix64's finalizer (Stafford's Mix13), written from its published definition."""
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def bits(v: float) -> int:
    return struct.unpack("<Q", struct.pack("<d", v + 0.0))[0]


def rand_reference(key: float, seed: float = 0.0) -> float:
    stream = mix13((bits(seed) + 0x9E3779B97F4A7C15) & MASK)
    top52 = mix13(bits(key) ^ stream) >> 12
    return struct.unpack("<d", struct.pack("<Q", 0x3FF0000000000000 | top52))[0] - 1.0


_P = list(PERMUTATION) * 2


def perlin_reference(x: float, y: float, z: float) -> float:
    """Perlin's improved noise, line by line from his reference Java code."""

    def fade(t):
        return t * t * t * (t * (t * 6 - 15) + 10)

    def lerp(t, a, b):
        return a + t * (b - a)

    def grad(h, x, y, z):
        h &= 15
        u = x if h < 8 else y
        v = y if h < 4 else (x if h in (12, 14) else z)
        return (u if h & 1 == 0 else -u) + (v if h & 2 == 0 else -v)

    X, Y, Z = (math.floor(c) & 255 for c in (x, y, z))
    x, y, z = x - math.floor(x), y - math.floor(y), z - math.floor(z)
    u, v, w = fade(x), fade(y), fade(z)
    A = _P[X] + Y
    AA, AB = _P[A] + Z, _P[A + 1] + Z
    B = _P[X + 1] + Y
    BA, BB = _P[B] + Z, _P[B + 1] + Z
    return lerp(
        w,
        lerp(
            v,
            lerp(u, grad(_P[AA], x, y, z), grad(_P[BA], x - 1, y, z)),
            lerp(u, grad(_P[AB], x, y - 1, z), grad(_P[BB], x - 1, y - 1, z)),
        ),
        lerp(
            v,
            lerp(u, grad(_P[AA + 1], x, y, z - 1), grad(_P[BA + 1], x - 1, y, z - 1)),
            lerp(u, grad(_P[AB + 1], x, y - 1, z - 1), grad(_P[BB + 1], x - 1, y - 1, z - 1)),
        ),
    )


# --- rand ------------------------------------------------------------------------------


def test_mix64_is_splitmix64s_finalizer():
    x = np.random.default_rng(0).integers(0, 2**64, 500, dtype=np.uint64)
    assert mix64(x).tolist() == [mix13(int(v)) for v in x]
    # SplitMix64 seeded with 0: its first outputs, as published with the algorithm
    state = np.uint64(0x9E3779B97F4A7C15) * np.arange(1, 4, dtype=np.uint64)
    assert [hex(int(v)) for v in mix64(state)] == [
        "0xe220a8397b1dcdaf",
        "0x6e789e6aa1b965f4",
        "0x6c45d188009454f",
    ]


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(allow_nan=False), min_size=1, max_size=20),
    st.floats(allow_nan=False),
)
def test_rand_matches_the_reference_hash_for_any_keys(keys, seed):
    got = rand(np.array(keys), seed)
    assert got.tolist() == [rand_reference(k, seed) for k in keys]
    assert np.all((got >= 0) & (got < 1))


def test_rand_is_uniform_by_ks():
    n = 200_000
    for seed in (0, 1, 7.5):
        for keys in (np.arange(n, dtype=float), np.arange(n) * 0.001, -np.arange(n) - 0.5):
            assert stats.kstest(rand(keys, seed), "uniform").pvalue > 1e-3


def test_rand_neighbours_are_independent():
    n = 200_000
    r = rand(np.arange(n, dtype=float))
    assert abs(np.corrcoef(r[:-1], r[1:])[0, 1]) < 4 / math.sqrt(n)
    # pairs (r[i], r[i+1]) fill the unit square evenly (10 x 10 cells, chi-square)
    cells = np.floor(r[:-1] * 10) * 10 + np.floor(r[1:] * 10)
    counts = np.bincount(cells.astype(int), minlength=100)
    assert stats.chisquare(counts).pvalue > 1e-3
    # and so do (rand(i, 0), rand(i, 1)): streams of neighbouring seeds
    s = rand(np.arange(n, dtype=float), 1)
    cells = np.floor(r * 10) * 10 + np.floor(s * 10)
    assert stats.chisquare(np.bincount(cells.astype(int), minlength=100)).pvalue > 1e-3
    # every mantissa bit is a fair coin
    bits = (r * 2.0**52).astype(np.uint64)
    ones = np.array([((bits >> np.uint64(b)) & np.uint64(1)).sum() for b in range(52)])
    assert np.all(np.abs(ones - n / 2) < 5 * math.sqrt(n / 4))


def test_a_seed_changes_everything():
    keys = np.arange(50_000, dtype=float)
    a, b = rand(keys, 0), rand(keys, 1)
    assert not np.any(a == b)
    assert abs(stats.spearmanr(a, b).statistic) < 0.03
    # a one-ulp change of a key is a new number too
    c = rand(np.nextafter(keys, np.inf), 0)
    assert not np.any(a == c)


def test_rand_is_pure_whatever_else_is_evaluated():
    n = (1 << 15) * 2 + 123  # crosses the kernel's chunk boundaries
    keys = np.random.default_rng(3).normal(size=n) * 1e3
    whole = rand(keys, 5)
    perm = np.random.default_rng(4).permutation(n)
    np.testing.assert_array_equal(rand(keys[perm], 5), whole[perm])
    np.testing.assert_array_equal(rand(keys[1000:2000], 5), whole[1000:2000])
    assert rand(float(keys[17]), 5).item() == whole[17]
    # a seed per element is the same as each seed alone
    seeds = np.arange(n) % 3
    per = rand(keys, seeds)
    for s in range(3):
        np.testing.assert_array_equal(per[seeds == s], rand(keys[seeds == s], s))
    assert rand(0.0) == rand(-0.0)


def test_rand_shapes_and_nan():
    assert rand(np.zeros((2, 3)), [0, 1, 2]).shape == (2, 3)
    assert rand(np.zeros(0)).shape == (0,)
    r = rand([1.0, np.nan, 2.0])
    assert np.isnan(r[1]) and np.isfinite(r[[0, 2]]).all()
    assert np.isnan(rand(1.0, np.nan))


# --- noise -----------------------------------------------------------------------------


def test_noise_is_perlins_improved_noise():
    p = np.random.default_rng(5).uniform(-300, 300, (2000, 3))
    ref = np.array([perlin_reference(*q) for q in p])
    np.testing.assert_array_equal(raw_noise(p[:, 0], p[:, 1], p[:, 2]), ref)
    np.testing.assert_allclose(noise(*p.T), np.clip(ref * noise_mod.SCALE, -1, 1))
    lattice = np.random.default_rng(6).integers(-1000, 1000, (100, 3)).astype(float)
    assert np.all(noise(*lattice.T) == 0)


def test_noise_is_bounded_and_reaches_near_its_bounds():
    from scipy.optimize import minimize

    rng = np.random.default_rng(7)
    p = rng.uniform(0, 256, (400_000, 3))
    raw = raw_noise(*p.T)
    extremes = []
    for sign in (1.0, -1.0):
        for q in p[np.argsort(-sign * raw)[:30]]:
            res = minimize(lambda v, s=sign: -s * raw_noise(*v), q, method="Nelder-Mead")
            extremes.append(-res.fun)
    top = max(extremes)
    assert 1.0 < top < 1.0 / noise_mod.SCALE  # the scale keeps the true extremes inside
    scaled = noise(*p.T)
    assert np.all(np.abs(scaled) <= 1.0) and np.abs(scaled).max() > 0.8


def test_noise_is_lipschitz_smooth_and_varied():
    rng = np.random.default_rng(8)
    p = rng.uniform(-100, 100, (100_000, 3))
    d = rng.normal(size=(100_000, 3))
    d *= 1e-4 / np.linalg.norm(d, axis=1)[:, None]
    n0, n1 = noise(*p.T), noise(*(p + d).T)
    slope = np.abs(n1 - n0) / 1e-4
    # the gradient of improved noise is bounded (a few units); nothing jumps
    assert slope.max() < 4.0
    # C2: second differences shrink as h^2
    for h in (1e-2, 1e-3):
        e = np.array([h, 0, 0])
        second = noise(*(p + e).T) - 2 * n0 + noise(*(p - e).T)
        assert np.abs(second).max() < 40 * h * h
    assert n0.std() > 0.15 and abs(n0.mean()) < 0.01
    # varied: points a unit apart are nearly uncorrelated
    far = noise(*(p + [1.5, 0.5, 2.5]).T)
    assert abs(np.corrcoef(n0, far)[0, 1]) < 0.05


def test_noise_nan_and_broadcast():
    assert noise(np.zeros((4, 5)) + 0.3, 0.2, 0.1).shape == (4, 5)
    out = noise([0.5, np.inf, np.nan], 0.1, 0.2)
    assert np.isfinite(out[0]) and np.isnan(out[1:]).all()


def test_rand_and_noise_are_the_same_in_another_process():
    code = (
        "import numpy as np, hashlib;"
        "from formgraph.kernels.attributes.random import rand;"
        "from formgraph.kernels.attributes.noise import noise;"
        "k = np.linspace(-50, 50, 10007);"
        "print(hashlib.sha256(rand(k, 3).tobytes() + noise(k, k * 0.3, -k).tobytes())"
        ".hexdigest())"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    k = np.linspace(-50, 50, 10007)
    import hashlib

    here = hashlib.sha256(rand(k, 3).tobytes() + noise(k, k * 0.3, -k).tobytes()).hexdigest()
    assert out.stdout.strip() == here


@pytest.mark.parametrize("n", [1, 5, 1 << 15, (1 << 15) + 1])
def test_chunk_edges(n):
    keys = np.arange(n, dtype=float) * 0.37
    got = rand(keys)
    pick = np.unique(np.r_[0, n - 1, np.arange(0, n, max(1, n // 40))])
    assert got[pick].tolist() == [rand_reference(keys[j]) for j in pick]
    assert noise(keys, 0.5, 0.25)[pick].tolist() == [
        noise_mod.SCALE * perlin_reference(keys[j], 0.5, 0.25) for j in pick
    ]


def test_noise_says_it_is_perlins_reference_times_its_scale():
    # the factor between noise and Perlin's reference, measured where nothing is clipped,
    # is the one its doc and the manual state
    p = np.random.default_rng(8).uniform(-50, 50, (500, 3))
    ref = np.array([perlin_reference(*q) for q in p])
    some = np.abs(ref) > 0.1
    np.testing.assert_allclose(noise(*p.T)[some] / ref[some], 0.96, rtol=1e-15)
    assert "0.96 (:data:`SCALE`) times Perlin's improved noise" in " ".join(noise.__doc__.split())
    manual = " ".join((ROOT / "docs" / "attributes.md").read_text().split())
    assert "`noise(x, [y], [z])` is 0.96 times Ken Perlin's improved gradient noise" in manual
