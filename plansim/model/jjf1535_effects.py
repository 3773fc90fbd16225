"""The gyro effects JJF 1535-2015 measures and plansim's eq. (1) leaves out: dead zone, resolution, warm-up, turn-on.

JJF 1535-2015 (single-axis MEMS gyro) reports four items that mean nothing for a unit whose output follows its
input linearly and whose bias is the same at every power-on (clause 3 and 7.2; docs/jjf1535.md):

- **threshold** (7.2.6, eq. (12)–(13)): the smallest input rate the gyro responds to. plansim's model: a *dead
  zone* d, the gyro's input rate w along its input axis gives no output change while |w| < d
  (:func:`input_response`);
- **resolution** (7.2.7, eq. (14)): the smallest input-rate *increment* the gyro responds to. plansim's model: the
  input is read in steps of r, ``r·floor(w/r + 1/2)`` (a mid-tread staircase; :func:`input_response`). A
  staircase with a level at zero also gives no output for |w| < r/2: a resolution r alone is a dead zone of r/2;
- **warm-up time** (7.2.9): the time from power-on until the bias stability meets its specified value. plansim's
  model: after each power-on the output carries the transient ``A·exp(−t/τ)`` (A in the output's unit, rad/s;
  t the time since power-on; :func:`exponential_segment_mean` gives its mean over a segment's samples);
- **bias repeatability** (3.2, 7.2.11, eq. (20)): the agreement of the bias between power cycles. plansim's
  model: at each power-on the output takes a turn-on bias drawn from N(0, σ_on²) and held until power-off.

The scenario fields are ``[mimu.effects]`` ``gyro_dead_zone``, ``gyro_resolution``, ``gyro_warm_up_amplitude``,
``gyro_warm_up_time_constant`` and ``gyro_turn_on_bias`` (docs/scenario-file.md); every one is 0 (off) unless set.
The dead zone and the resolution act on the input rate (before the scale factor and the noise, which is
added at the output); the warm-up and the turn-on bias add to the output, as the bias Bg of eq. (1) does. Plain
numpy, SI.
"""

from __future__ import annotations

import numpy as np


def input_response(rates, dead_zone: float, resolution: float) -> np.ndarray:
    """The input rate the gyro responds to: the dead zone, then the resolution's staircase (rad/s).

    ``u = 0 if |w| < dead_zone else w`` (7.2.6: below the threshold the output does not change), then
    ``r·floor(u/r + 1/2)`` if ``resolution = r > 0`` (7.2.7: the output changes in steps of r of input; an input
    exactly half-way between two levels takes the upper one). Both 0: the rates unchanged.

    Parameters
    ----------
    rates : array
        Input rates w along the gyro's input axis, rad/s.
    dead_zone, resolution : float
        d >= 0 and r >= 0, rad/s.
    """
    w = np.asarray(rates, dtype=float)
    if not (dead_zone >= 0 and resolution >= 0):
        raise ValueError(f"dead_zone = {dead_zone!r}, resolution = {resolution!r}: both must be >= 0 (rad/s)")
    out = np.where(np.abs(w) < dead_zone, 0.0, w) if dead_zone > 0 else w.copy()
    if resolution > 0:
        out = resolution * np.floor(out / resolution + 0.5)
    return out


def exponential_segment_mean(start, samples, sample_period, amplitude: float, time_constant: float) -> np.ndarray:
    """The mean of ``A·exp(−t/τ)`` over a segment's samples t = start + k·Δt, k = 0 … n − 1, in closed form.

    ``A·exp(−t0/τ)·(1 − q^n)/(n·(1 − q))`` with q = exp(−Δt/τ), written with ``expm1`` so that Δt ≪ τ keeps its
    digits. 0 where A = 0.

    Parameters
    ----------
    start : array
        Time of each segment's first sample since power-on, s (>= 0).
    samples : array
        n, samples per segment (>= 1).
    sample_period : array
        Δt, s.
    amplitude, time_constant : float
        A (unit of the output) and τ > 0 (s) when A ≠ 0.
    """
    t0 = np.asarray(start, dtype=float)
    n = np.asarray(samples, dtype=float)
    dt = np.asarray(sample_period, dtype=float)
    if amplitude == 0:
        return np.zeros(np.broadcast(t0, n, dt).shape)
    if not time_constant > 0:
        raise ValueError(f"time_constant = {time_constant!r}: must be > 0 s when the amplitude is set")
    ratio = np.expm1(-n * dt / time_constant) / (n * np.expm1(-dt / time_constant))
    return amplitude * np.exp(-t0 / time_constant) * ratio


def own_axis_response(rates, gain: float, kg: float, quadratic: float = 0.0, cubic: float = 0.0,
                      asymmetry: float = 0.0) -> np.ndarray:
    """The gyro's output from the input rate w along its own axis (rad/s): ``gain·w + n2·w² + n3·w³ + ½·α·Kg·|w|``.

    The own-axis terms of :func:`plansim.kernels.physics.gyro_output` in numpy, with *gain* the scale factor at the
    segment's temperature (Kg_ii·(1 + κ·ΔT)), *kg* = Kg_ii, *quadratic* n2 (1/(rad/s)), *cubic* n3 (1/(rad/s)²) and
    *asymmetry* α (docs/model.md): what the JJF 1535 effects' correction (:mod:`plansim.simulate.jjf1535_effects`)
    and the items' true values (:func:`plansim.estimate.jjf1535_items.true_items`) both read.
    """
    x = np.asarray(rates, dtype=float)
    half_alpha = 0.5 * asymmetry * kg
    return gain * x + quadratic * x**2 + cubic * x**3 + half_alpha * np.abs(x)
