"""Per-trial random streams for the kernels: xoshiro256** with a ziggurat normal.

Reproducibility whatever the thread count or chunking: every trial owns a stream whose state is
derived from ``(seed, trial index)`` alone (``numpy.random.SeedSequence`` gives the root key,
splitmix64 expands it per trial, as the xoshiro authors recommend for seeding). A trial draws its
numbers in a fixed order, so trial *i* gives the same numbers in any chunk on any thread.

References
----------
- D. Blackman, S. Vigna, "Scrambled linear pseudorandom number generators", ACM TOMS 47 (2021).
- J. A. Doornik, "An improved ziggurat method to generate normal random samples" (2005): the
  128-block ZIGNOR variant used here, with the tail by Marsaglia's method.
"""

from __future__ import annotations

import math

import numpy as np

from plansim._jit import jit

_U64 = np.uint64
_GOLDEN = _U64(0x9E3779B97F4A7C15)
_MIX1 = _U64(0xBF58476D1CE4E5B9)
_MIX2 = _U64(0x94D049BB133111EB)
_TO_UNIT = 1.0 / 9007199254740992.0  # 2**-53

# ZIGNOR tables (Doornik 2005): 128 blocks
_ZIG_C = 128
_ZIG_R = 3.442619855899
_ZIG_V = 9.91256303526217e-3


def _ziggurat_tables() -> tuple[np.ndarray, np.ndarray]:
    x = np.zeros(_ZIG_C + 1)
    f = math.exp(-0.5 * _ZIG_R * _ZIG_R)
    x[0] = _ZIG_V / f
    x[1] = _ZIG_R
    x[_ZIG_C] = 0.0
    for i in range(2, _ZIG_C):
        x[i] = math.sqrt(-2.0 * math.log(_ZIG_V / x[i - 1] + f))
        f = math.exp(-0.5 * x[i] * x[i])
    ratio = x[1:] / x[:-1]
    return x, ratio


ZIG_X, ZIG_RATIO = _ziggurat_tables()


def root_key(seed: int) -> np.ndarray:
    """Four 64-bit words from ``SeedSequence(seed)``: the root of every per-trial stream."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"seed = {seed!r}: expected a non-negative integer")
    if seed < 0:
        raise ValueError(f"seed = {seed!r}: expected a non-negative integer")
    return np.random.SeedSequence(int(seed)).generate_state(4, dtype=np.uint64)


@jit
def _splitmix64(x):
    z = x + _GOLDEN
    z = (z ^ (z >> _U64(30))) * _MIX1
    z = (z ^ (z >> _U64(27))) * _MIX2
    return z ^ (z >> _U64(31))


@jit
def seed_trial(key, trial, stream, state):
    """Fill *state* (4 × uint64) for trial number *trial* and sub-stream *stream* of root *key*."""
    x = key[0] ^ _splitmix64(_U64(trial) ^ key[1])
    x = x ^ _splitmix64(_U64(stream) ^ key[2])
    x = x ^ key[3]
    for j in range(4):
        x = _splitmix64(x)
        state[j] = x
    if state[0] == 0 and state[1] == 0 and state[2] == 0 and state[3] == 0:
        state[0] = _GOLDEN


@jit
def _rotl(x, k):
    return (x << _U64(k)) | (x >> _U64(64 - k))


@jit
def next_u64(state):
    """xoshiro256** step."""
    result = _rotl(state[1] * _U64(5), 7) * _U64(9)
    t = state[1] << _U64(17)
    state[2] ^= state[0]
    state[3] ^= state[1]
    state[1] ^= state[2]
    state[0] ^= state[3]
    state[2] ^= t
    state[3] = _rotl(state[3], 45)
    return result


@jit
def uniform(state):
    """Uniform on [0, 1) with 53 random bits."""
    # via int64: LLVM's uint64 -> double conversion is several times slower
    return np.int64(next_u64(state) >> _U64(11)) * _TO_UNIT


@jit
def uniform_open(state):
    """Uniform on (0, 1) (for logarithms)."""
    return (np.int64(next_u64(state) >> _U64(11)) + 0.5) * _TO_UNIT


@jit
def normal(state):
    """Standard normal by the ZIGNOR ziggurat (one 64-bit draw ~97 % of the time).

    The tables are module constants (numba freezes them into the code): passed as array
    arguments they cost a reference-count round trip per call, several times the draw itself.
    """
    zig_x = ZIG_X
    zig_ratio = ZIG_RATIO
    while True:
        r = next_u64(state)
        u = np.int64(r >> _U64(11)) * (2.0 * _TO_UNIT) - 1.0
        i = np.int64(r & _U64(127))
        if abs(u) < zig_ratio[i]:
            return u * zig_x[i]
        if i == 0:
            # tail beyond R (Marsaglia 1964)
            while True:
                x = math.log(uniform_open(state)) / _ZIG_R
                y = math.log(uniform_open(state))
                if -2.0 * y >= x * x:
                    break
            return x - _ZIG_R if u < 0.0 else _ZIG_R - x
        x = u * zig_x[i]
        f0 = math.exp(-0.5 * (zig_x[i] * zig_x[i] - x * x))
        f1 = math.exp(-0.5 * (zig_x[i + 1] * zig_x[i + 1] - x * x))
        if f1 + uniform(state) * (f0 - f1) < 1.0:
            return x


@jit
def draw_error(state, kind, scale):
    """One draw of a table or fixture error: ``kind`` 0 = uniform on ±scale, 1 = normal with σ = scale.

    A draw is always consumed, whatever the scale, so that switching one error on or off does
    not change the numbers any other error gets (common random numbers between scenarios).
    """
    if kind == 0:
        return scale * (2.0 * uniform(state) - 1.0)
    return scale * normal(state)
