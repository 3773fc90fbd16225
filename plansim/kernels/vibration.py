"""Shaped Gaussian noise for the vibration experiment, the same numbers whatever the chunking.

A stationary Gaussian process with a given one-sided PSD is white noise through a finite impulse
response (FIR) filter h of L taps (designed in :func:`plansim.model.vibration.shaping_filter`):

    x[n] = Σ_{m=0}^{L−1} h[m] · w[n + m],        w[j] ~ N(0, 1) independent,

so that the PSD of x is |H(f)|² · 2/f_s (one-sided) and its variance Σ h². Sample j of the white
sequence w is the draw j mod B of block j // B (B = ``block``), each block a stream of its own,
``seed_stream(key, j // B, stream)`` (:mod:`plansim.kernels.random`). Any sample x[n] is then a
function of (key, stream, n) alone: a record computed in one call or in chunks of any size is the
same, bit for bit (the sum over m always runs in the same order).

Plain SI arrays; the result is written into a preallocated output.
"""

from __future__ import annotations

from plansim.kernels.options import jit
from plansim.kernels.random import normal, seed_stream


@jit
def white_blocks(key, stream, block, start, out):
    """out[k] = w[start + k]: the standard normal numbers start … start + len(out) − 1 of *stream*.

    Each block of *block* numbers is drawn from its own stream ``seed_stream(key, block index, stream)``;
    only the blocks the range touches are drawn (whole, since a stream is sequential).
    """
    n = out.shape[0]
    if n == 0:
        return
    first = start // block
    last = (start + n - 1) // block
    for b in range(first, last + 1):
        st = seed_stream(key, b, stream)
        base = b * block
        for q in range(block):
            z, st = normal(st)
            j = base + q - start
            if 0 <= j < n:
                out[j] = z


@jit
def shaped_noise(key, stream, taps, block, start, white, out):
    """out[k] = Σ_m taps[m] · w[start + k + m] (see the module docstring), k = 0 … len(out) − 1.

    Parameters
    ----------
    key : ndarray of uint64, (4,)
        The root key (:func:`plansim.kernels.random.root_key`).
    stream : int
        The sub-stream of this process (one per axis and per noise source).
    taps : ndarray, (L,)
        The FIR filter h, in the unit of the output per unit white noise.
    block : int
        Numbers per block of the white sequence (fixed for a record, never the chunk size).
    start : int
        Index of the first output sample in the record, ≥ 0.
    white : ndarray, (len(out) + L − 1,)
        Scratch for the white numbers.
    out : ndarray, (n,)
        The shaped samples, written in place.
    """
    n = out.shape[0]
    L = taps.shape[0]
    white_blocks(key, stream, block, start, white[:n + L - 1])
    for k in range(n):
        acc = 0.0
        for m in range(L):
            acc += taps[m] * white[k + m]
        out[k] = acc
