"""The sensor's dynamics on the sample path: an IIR filter, and the gyro records of an angular vibration table.

A discrete transfer function H(z) = (b₀ + b₁z⁻¹ + … + b_p z⁻ᵖ)/(1 + a₁z⁻¹ + … + a_p z⁻ᵖ) (a₀ = 1; the
coefficients come from :mod:`plansim.simulate.vibration_table`, which discretises the continuous model of
:mod:`plansim.model.dynamics`) is run in the transposed direct form II, the form of
``scipy.signal.lfilter``:

    y[k] = b₀ x[k] + s₀,
    s_i  = b_{i+1} x[k] − a_{i+1} y[k] + s_{i+1}     (i = 0 … p − 2),
    s_{p−1} = b_p x[k] − a_p y[k].

The state s (p numbers) is all the filter remembers: it is read from and written back to the caller's
array, so a record filtered in chunks, the state carried from one chunk to the next, is the record
filtered in one call, bit for bit (the same operations in the same order on every sample).

Plain SI arrays (s, rad/s, rad); outputs are written into preallocated arrays.
"""

from __future__ import annotations

import math

from plansim.kernels.options import inline_jit, jit
from plansim.kernels.quantiser import quantise
from plansim.kernels.vibration import white_blocks


@inline_jit
def _df2t_step(b, a, state, x):
    """One sample of the transposed direct form II (module docstring); *state* updated in place."""
    p = state.shape[0]
    y = b[0] * x + (state[0] if p > 0 else 0.0)
    for i in range(p - 1):
        state[i] = b[i + 1] * x - a[i + 1] * y + state[i + 1]
    if p > 0:
        state[p - 1] = b[p] * x - a[p] * y
    return y


@jit
def iir_filter(b, a, x, state, out):
    """out[k] = the filter (b, a) applied to x[k], continuing from *state* (updated in place).

    Parameters
    ----------
    b, a : ndarray, (p + 1,)
        Numerator and denominator of H(z), a[0] = 1 (the caller normalises).
    x : ndarray, (n,)
        Input samples.
    state : ndarray, (p,)
        The transposed direct form II state (zeros: the filter at rest), updated in place.
    out : ndarray, (n,)
        Output samples, written in place (may not alias *x*).
    """
    for k in range(x.shape[0]):
        out[k] = _df2t_step(b, a, state, x[k])


@jit
def sine_records(b, a, states, amplitudes, omega, phases, dt, first, scale, biases, sigma, step, output_range,
                 key, streams, block, white, out, even=0.0, odd=0.0):
    """Gyro records on an angular vibration table: out[r, k] for record r and sample index first + k.

    The table's rate about the sensitive axis is ω_r(t) = A_r cos(Ω t + φ_r) at t = i·Δt for the sample index
    i = first + k (i < 0: the run-in before the record, whose output is filtered and then discarded). The
    gyro's output is

        y = Q(S · g((H ω)[i]) + B_r + σ w_r[i]),        g(v) = v + c₂ v² + c₃ v³,

    H the filter (b, a) continuing from ``states[r]``, g the static amplitude nonlinearity after the dynamics
    (c₂ = *even*, c₃ = *odd*, in (rad/s)⁻¹ and (rad/s)⁻²; both 0 by default: the linear sensor), S the scale
    factor, B_r the bias of record r, w_r the standard
    normal sequence of stream ``streams[r]`` (drawn block by block, :func:`plansim.kernels.vibration.white_blocks`,
    so w_r[i] depends only on (key, stream, i)), and Q the saturation at ± *output_range* and the quantiser of
    step *step* (:func:`plansim.kernels.quantiser.quantise`; step 0: none). Samples with i < 0 are written as
    nan. Every sample is a function of its index and the state carried in: chunks of any size give the same
    numbers.

    Parameters
    ----------
    b, a : ndarray, (p + 1,)
        The discrete filter, a[0] = 1.
    states : ndarray, (R, p)
        One filter state per record, updated in place.
    amplitudes : ndarray, (R,)
        A_r, rad/s: the table's actual rate amplitude of each record (a table's amplitude error included).
    omega : float
        Ω = 2πf (rad/s).
    phases : ndarray, (R,)
        φ_r, rad, the table's phase at i = 0.
    dt : float
        Δt, s.
    first : int
        The sample index of out[:, 0] (negative in the run-in).
    scale, sigma, step, output_range : float
        S (output unit per rad/s), σ (output unit), the quantisation step (0: none) and the range.
    biases : ndarray, (R,)
        B_r, output unit: each record's bias (a drift between records included).
    even, odd : float
        c₂, c₃ of g (above), 0 for a linear sensor.
    key : ndarray of uint64, (4,)
        The root key (:func:`plansim.kernels.random.root_key`).
    streams : ndarray of int64, (R,)
        The noise stream of each record.
    block : int
        Numbers per block of the white sequence (fixed for a run, never the chunk size).
    white : ndarray, (n + block,)
        Scratch.
    out : ndarray, (R, n)
        The records, written in place.
    """
    rows, n = out.shape
    inverse_step = 1.0 / step if step > 0.0 else 0.0
    kept = first if first > 0 else 0            # the first index ≥ 0 in this chunk
    skip = kept - first                         # run-in samples at the start of this chunk
    count = n - skip if n > skip else 0
    for r in range(rows):
        state = states[r]
        if count > 0:
            white_blocks(key, streams[r], block, kept, white[:count])
        for k in range(n):
            i = first + k
            v = _df2t_step(b, a, state, amplitudes[r] * math.cos(omega * (i * dt) + phases[r]))
            if i < 0:
                out[r, k] = math.nan
            else:
                out[r, k] = _gyro_output(v, even, odd, scale, biases[r], sigma * white[k - skip], step, inverse_step,
                                         output_range)


@inline_jit
def _gyro_output(v, even, odd, scale, bias, noise, step, inverse_step, output_range):
    """The output of one sample: Q(S·g(v) + B + noise), g(v) = v + c₂v² + c₃v³ (:func:`sine_records`)."""
    if even != 0.0 or odd != 0.0:
        v = v + v * v * (even + odd * v)
    return quantise(scale * v + bias + noise, output_range, step, inverse_step, output_range)


@jit
def input_records(b, a, states, inputs, first, scale, biases, sigma, step, output_range, key, streams, block, white,
                  out, even=0.0, odd=0.0):
    """Gyro records driven by one input common to every record: out[r, k] for sample index first + k ≥ 0.

    As :func:`sine_records`, with the sensor's input (rad/s) given sample by sample, ``inputs[k]`` for sample
    first + k, instead of a table's sinusoid: y = Q(S · g((H x)[i]) + B_r + σ w_r[i]), H continuing from
    ``states[r]``. A half-sine shock reaches the gyro this way (:func:`plansim.simulate.jjf1537_items.shock_records`):
    its input is the rate its g-sensitivity reads from the pulse's acceleration. Chunks of any size give the
    same numbers (the state is carried, the white sequence indexed by i).

    Parameters
    ----------
    inputs : ndarray, (n,)
        x at sample first + k, rad/s.
    first : int
        The sample index of out[:, 0], >= 0.
    Others
        As :func:`sine_records`.
    """
    rows, n = out.shape
    inverse_step = 1.0 / step if step > 0.0 else 0.0
    for r in range(rows):
        state = states[r]
        white_blocks(key, streams[r], block, first, white[:n])
        for k in range(n):
            v = _df2t_step(b, a, state, inputs[k])
            out[r, k] = _gyro_output(v, even, odd, scale, biases[r], sigma * white[k], step, inverse_step,
                                     output_range)
