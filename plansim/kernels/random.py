"""Per-trial random streams for the kernels: xoshiro256** with a ziggurat normal.

Reproducibility whatever the thread count or chunking: every trial owns a stream whose state is
derived from ``(seed, trial index)`` alone (``numpy.random.SeedSequence`` gives the root key,
splitmix64 expands it per trial, as the xoshiro authors recommend for seeding). A trial draws its
numbers in a fixed order, so trial *i* gives the same numbers in any chunk on any thread.

A stream is a value, a tuple of four uint64 words, threaded through the kernels:
``z, stream = normal(stream)``. Numba then keeps it in registers and inlines the draw; held in an
array, it cost a memory round trip and a reference count per draw (5.8 ns against 2.2 ns a
normal, measured on the machine of docs/performance.md).

References
----------
- D. Blackman, S. Vigna, "Scrambled linear pseudorandom number generators", ACM TOMS 47 (2021).
- J. A. Doornik, "An improved ziggurat method to generate normal random samples" (2005): the
  128-block ZIGNOR variant used here, with the tail by Marsaglia's method.
"""

from __future__ import annotations

import math

import numpy as np

from plansim.kernels.options import jit

_U64 = np.uint64
_GOLDEN = _U64(0x9E3779B97F4A7C15)
_MIX1 = _U64(0xBF58476D1CE4E5B9)
_MIX2 = _U64(0x94D049BB133111EB)
_TO_UNIT = 1.0 / 9007199254740992.0  # 2**-53
# rotation amounts of xoshiro256** as int64 scalars: a Python int would be typed as a literal and
# compile :func:`_rotl` once per amount (LLVM still folds them into the inlined rotation)
_ROTATE_OUTPUT = np.int64(7)
_ROTATE_STATE = np.int64(45)

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
def seed_stream(key, trial, stream):
    """The random stream of trial number *trial*, sub-stream *stream*, of root *key*.

    A stream is a tuple of four uint64 words (the xoshiro256** state), passed by value: every
    draw takes a stream and returns ``(value, stream)``. As a value it lives in registers; as an
    array it cost a memory round trip and a reference count per draw, 2.5× the draw itself.
    """
    x = key[0] ^ _splitmix64(_U64(trial) ^ key[1])
    x = x ^ _splitmix64(_U64(stream) ^ key[2])
    x = x ^ key[3]
    s0 = _splitmix64(x)
    s1 = _splitmix64(s0)
    s2 = _splitmix64(s1)
    s3 = _splitmix64(s2)
    if s0 == 0 and s1 == 0 and s2 == 0 and s3 == 0:
        s0 = _GOLDEN
    return (s0, s1, s2, s3)


@jit
def _rotl(x, k):
    return (x << _U64(k)) | (x >> _U64(64 - k))


@jit
def next_u64(stream):
    """xoshiro256** step: ``(64 random bits, stream)``."""
    s0, s1, s2, s3 = stream
    result = _rotl(s1 * _U64(5), _ROTATE_OUTPUT) * _U64(9)
    t = s1 << _U64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, _ROTATE_STATE)
    return result, (s0, s1, s2, s3)


@jit
def uniform(stream):
    """Uniform on [0, 1) with 53 random bits: ``(u, stream)``."""
    r, stream = next_u64(stream)
    # via int64: LLVM's uint64 -> double conversion is several times slower
    return np.int64(r >> _U64(11)) * _TO_UNIT, stream


@jit
def uniform_open(stream):
    """Uniform on (0, 1) (for logarithms): ``(u, stream)``."""
    r, stream = next_u64(stream)
    return (np.int64(r >> _U64(11)) + 0.5) * _TO_UNIT, stream


@jit
def _normal_slow(u, i, stream):
    """The ziggurat beyond its rectangles (about 1 draw in 80): the wedge test, the tail beyond R
    (Marsaglia 1964), and new draws until one is accepted."""
    zig_x = ZIG_X
    while True:
        if i == 0:
            while True:
                a, stream = uniform_open(stream)
                b, stream = uniform_open(stream)
                x = math.log(a) / _ZIG_R
                y = math.log(b)
                if -2.0 * y >= x * x:
                    break
            return (x - _ZIG_R if u < 0.0 else _ZIG_R - x), stream
        x = u * zig_x[i]
        f0 = math.exp(-0.5 * (zig_x[i] * zig_x[i] - x * x))
        f1 = math.exp(-0.5 * (zig_x[i + 1] * zig_x[i + 1] - x * x))
        a, stream = uniform(stream)
        if f1 + a * (f0 - f1) < 1.0:
            return x, stream
        r, stream = next_u64(stream)
        u = np.int64(r >> _U64(11)) * (2.0 * _TO_UNIT) - 1.0
        i = np.int64(r & _U64(127))
        if abs(u) < ZIG_RATIO[i]:
            return u * zig_x[i], stream


@jit
def normal(stream):
    """Standard normal by the ZIGNOR ziggurat: ``(z, stream)``; one 64-bit draw ~99 % of the time.

    The fast path is small so that LLVM inlines it into the caller's loop; the rest is
    :func:`_normal_slow`. The tables are module constants (numba freezes them into the code).
    """
    r, stream = next_u64(stream)
    u = np.int64(r >> _U64(11)) * (2.0 * _TO_UNIT) - 1.0
    i = np.int64(r & _U64(127))
    if abs(u) < ZIG_RATIO[i]:
        return u * ZIG_X[i], stream
    return _normal_slow(u, i, stream)


@jit
def draw_error(stream, kind, scale):
    """One draw of a table or fixture error: ``kind`` 0 = uniform on ±scale, 1 = normal with σ = scale;
    returns ``(error, stream)``.

    A draw is always consumed, whatever the scale, so that switching one error on or off does
    not change the numbers any other error gets (common random numbers between scenarios).
    """
    if kind == 0:
        u, stream = uniform(stream)
        return scale * (2.0 * u - 1.0), stream
    z, stream = normal(stream)
    return scale * z, stream
