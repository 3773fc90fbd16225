"""JJF 1535-2015 (single-axis MEMS gyroscope): the data reductions of clause 7.2, eq. (4)–(27).

Every function takes the *measured* quantities the clause names, in the gyro's output unit (for example
mV, or counts, or rad/s for a digital gyro) and the table's input rate in rad/s, and returns the figure the
clause defines. Outputs in the gyro's unit divided by a scale factor K (output unit per rad/s) are rates in
rad/s. Nothing here simulates; :mod:`plansim.estimate` holds reductions only.

==========  ==========================================  ===================================
clause      item                                        function
==========  ==========================================  ===================================
7.2.1       scale factor, eq. (4)–(5)                   :func:`rate_point_mean`, :func:`scale_factor_fit`
7.2.2       scale-factor nonlinearity, eq. (6)–(7)      :func:`scale_factor_nonlinearity`
7.2.3       scale-factor asymmetry, eq. (8)–(9)         :func:`scale_factor_asymmetry`
7.2.4       scale-factor repeatability, eq. (10)        :func:`scale_factor_repeatability`
7.2.5       scale-factor temperature sensitivity (11)   :func:`temperature_sensitivity`
7.2.6       threshold, eq. (12)–(13)                    :func:`threshold`
7.2.7       resolution, eq. (14)                        :func:`resolution`
7.2.8       bias, eq. (15)–(17)                         :func:`bias`
7.2.9       warm-up time                                :func:`warm_up_time`
7.2.10      bias stability, eq. (18)–(19)               :func:`bias_stability`
7.2.11      bias repeatability, eq. (20)                :func:`bias_repeatability`
7.2.12      bias acceleration (g) sensitivity           :func:`bias_g_sensitivity`
7.2.13      angle random walk, eq. (21)–(26)            :func:`allan_polynomial_fit`
7.2.14      bias temperature sensitivity, eq. (27)      :func:`temperature_sensitivity`
==========  ==========================================  ===================================

The specification's 50 % criterion of eq. (13) and (14) is :data:`THRESHOLD_CRITERION`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.estimate.jjf2003 import line_fit

#: eq. (13)/(14): an input (increment) counts when the measured output (increment) is within 50 % of the
#: fitted line's
THRESHOLD_CRITERION = 0.5
#: eq. (25): the powers m of τ in the Allan-variance polynomial σ²(τ) = Σ A_m τ^m
ALLAN_POWERS = (-2, -1, 0, 1, 2)


def checked_array(name: str, values, ndim: int | None = None, minimum: int = 1) -> np.ndarray:
    """*values* as a float array, checked: numbers (``TypeError``), *ndim* dimensions when given, at least *minimum*
    values, every one finite (``ValueError``, naming *name*). Shared by the estimators of this layer."""
    try:
        out = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name}: expected numbers, got {values!r}") from exc
    if ndim is not None and out.ndim != ndim:
        raise ValueError(f"{name}: expected a {ndim}-dimensional array, got shape {out.shape}")
    if out.size < minimum:
        raise ValueError(f"{name}: expected at least {minimum} values, got {out.size}")
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{name}: every value must be finite, got {values!r}")
    return out


def rate_point_mean(samples) -> np.ndarray:
    """Eq. (4): F̄_j = (1/N) Σ_m F_jm, the mean of the N samples at each rate point (last axis)."""
    return checked_array("samples", samples).mean(axis=-1)


@dataclass(frozen=True)
class LineFit:
    """Eq. (5): F_j = K·Ω_j + F0 + v_j fitted by least squares."""

    scale_factor: float  # K, output unit per rad/s
    zero: float  # F0, output unit
    residuals: np.ndarray  # v_j = F̄_j − (K Ω_j + F0)

    def fitted(self, rates) -> np.ndarray:
        """F̂ = K·Ω + F0 at the given rates (rad/s)."""
        return self.scale_factor * np.asarray(rates, dtype=float) + self.zero


def scale_factor_fit(rates, outputs) -> LineFit:
    """Eq. (5) by least squares (the same line fit as JJF 2003 eq. (4)–(5)).

    Parameters
    ----------
    rates : (n,) array
        Table input rates Ω_j, rad/s (at least two distinct).
    outputs : (n,) array
        Mean gyro outputs F̄_j at them (eq. (4)), the at-rest output already subtracted (7.2.1.1 d)).
    """
    rates = checked_array("rates", rates, ndim=1, minimum=2)
    outputs = checked_array("outputs", outputs, ndim=1, minimum=2)
    if rates.shape != outputs.shape:
        raise ValueError(f"rates and outputs: expected the same length, got {rates.size} and {outputs.size}")
    K, F0 = line_fit(rates, outputs)
    K, F0 = float(K), float(F0)
    return LineFit(K, F0, outputs - (K * rates + F0))


def scale_factor_nonlinearity(rates, outputs) -> float:
    """Eq. (6): K_ψ = max_j |F̄_j − F̂_j| / (K·(Ω_max+ − Ω_max−)), one calibration; eq. (7) is the mean of
    this over the Q calibrations (``np.mean`` of the per-run values). Dimensionless (× 1e6 for ppm)."""
    fit = scale_factor_fit(rates, outputs)
    rates = np.asarray(rates, dtype=float)
    span = fit.scale_factor * (rates.max() - rates.min())
    if not span > 0:
        raise ValueError("rates: eq. (6) needs a positive fitted span K·(Ω_max+ − Ω_max−)")
    return float(np.max(np.abs(fit.residuals)) / abs(span))


def scale_factor_asymmetry(rates, outputs) -> float:
    """Eq. (8): K_u = |K+ − K−| / K̄, with K+ and K− fitted by eq. (5) over the positive and the negative rates
    (each with the zero-rate point when there is one) and K̄ = (K+ + K−)/2; eq. (9) is its mean over Q runs."""
    rates = checked_array("rates", rates, ndim=1, minimum=2)
    outputs = checked_array("outputs", outputs, ndim=1, minimum=2)
    positive, negative = rates >= 0, rates <= 0
    if np.count_nonzero(rates > 0) < 1 or np.count_nonzero(rates < 0) < 1 or min(positive.sum(), negative.sum()) < 2:
        raise ValueError(f"rates {rates.tolist()}: eq. (8) needs at least two points on each side (zero counts)")
    k_plus = scale_factor_fit(rates[positive], outputs[positive]).scale_factor
    k_minus = scale_factor_fit(rates[negative], outputs[negative]).scale_factor
    return float(abs(k_plus - k_minus) / (0.5 * (k_plus + k_minus)))


def scale_factor_repeatability(scale_factors) -> float:
    """Eq. (10): K_r = (1/K̄)·sqrt(Σ (K_m − K̄)²/(Q − 1)) over Q calibrations, the unit powered off between."""
    K = checked_array("scale_factors", scale_factors, ndim=1, minimum=2)
    return float(np.std(K, ddof=1) / abs(K.mean()))


def temperature_sensitivity(values, temperatures, room_index: int = 0, relative: bool = True) -> float:
    """Eq. (11) (relative=True): max_i |(K_i − K_m)/(K_m (T_i − T_m))|, 1/°C; eq. (27) (relative=False):
    max_i |(B_i − B_m)/(T_i − T_m)|, unit of B per °C. Index *room_index* is the room-temperature point m."""
    x = checked_array("values", values, ndim=1, minimum=2)
    T = checked_array("temperatures", temperatures, ndim=1, minimum=2)
    if x.shape != T.shape:
        raise ValueError(f"values and temperatures: expected the same length, got {x.size} and {T.size}")
    if not 0 <= room_index < x.size:
        raise ValueError(f"room_index = {room_index}: allowed 0 to {x.size - 1}")
    others = np.arange(x.size) != room_index
    dT = T[others] - T[room_index]
    if np.any(dT == 0):
        raise ValueError(f"temperatures {T.tolist()}: every other point must differ from room temperature")
    change = x[others] - x[room_index]
    if relative:
        change = change / x[room_index]
    return float(np.max(np.abs(change / dT)))


def _first_failure(inputs: np.ndarray, measured: np.ndarray, expected: np.ndarray) -> float:
    """The smallest input, going down the decreasing *inputs*, before which every input met the 50 % criterion."""
    order = np.argsort(-np.abs(inputs))
    candidate = math.nan
    for j in order:
        if expected[j] == 0:
            raise ValueError("inputs: an input of zero has no expected output to compare against")
        if abs(measured[j] - expected[j]) / abs(expected[j]) <= THRESHOLD_CRITERION:
            candidate = abs(float(inputs[j]))
        else:
            break
    return candidate


def threshold(scale_factor: float, rates, outputs, zero_outputs) -> float:
    """Eq. (12)–(13): going down the decreasing small rates Ω_j of one direction, the smallest |Ω_j| down to which
    the measured output less the zero-rate output, F̄_j − F̄_0,j, is within 50 % of F*_j = K·Ω_j (rad/s).

    Give each direction's rates in turn and take the larger (7.2.6.1 e)); NaN when even the largest rate
    fails the criterion.
    """
    rates = checked_array("rates", rates, ndim=1)
    outputs = checked_array("outputs", outputs, ndim=1)
    zero = np.broadcast_to(checked_array("zero_outputs", zero_outputs), rates.shape)
    return _first_failure(rates, outputs - zero, float(scale_factor) * rates)


def resolution(scale_factor: float, increments, output_increments) -> float:
    """Eq. (14): going down the decreasing rate increments ΔΩ_j about a base rate (20–50 × the threshold), the
    smallest |ΔΩ_j| down to which the measured output increment ΔF_j is within 50 % of ΔF̂_j = K·ΔΩ_j (rad/s).
    One direction per call; the resolution is the larger of the two directions (7.2.7.1 f))."""
    increments = checked_array("increments", increments, ndim=1)
    output_increments = checked_array("output_increments", output_increments, ndim=1)
    return _first_failure(increments, output_increments, float(scale_factor) * increments)


def bias(scale_factor: float, outputs) -> float:
    """Eq. (15)–(16): B0 = F̄/K, F̄ the mean of the at-rest outputs (rad/s); eq. (17): the mean over Q runs."""
    return float(rate_point_mean(outputs)) / float(scale_factor)


def bias_stability(scale_factor: float, outputs, samples_per_period: int) -> float:
    """Eq. (18): B_s = (1/K)·sqrt(Σ_j (F̄_j − F̄)²/(N/P − 1)), F̄_j the means over consecutive periods of P
    samples (the averaging time) and F̄ their mean (rad/s); eq. (19) is the mean over Q runs."""
    F = checked_array("outputs", outputs, ndim=1)
    P = int(samples_per_period)
    if P < 1 or F.size // P < 2:
        raise ValueError(f"samples_per_period = {samples_per_period}: need 1 <= P and at least two periods in "
                         f"{F.size} samples")
    periods = F[: (F.size // P) * P].reshape(-1, P).mean(axis=1)
    return float(np.std(periods, ddof=1) / abs(float(scale_factor)))


def bias_repeatability(biases) -> float:
    """Eq. (20): B_r = sqrt(Σ (B0m − B̄0)²/(Q − 1)) over Q bias calibrations (unit powered off between)."""
    return float(np.std(checked_array("biases", biases, ndim=1, minimum=2), ddof=1))


def bias_g_sensitivity(scale_factor: float, up_outputs, down_outputs, gravity: float) -> float:
    """7.2.12: (F̄_up − F̄_down)/(2g)/K for one axis pointing up then down (rad/s per m/s²); the gyro's figure is
    the largest magnitude over the X, Y and Z axes."""
    if not gravity > 0:
        raise ValueError(f"gravity = {gravity!r}: must be > 0 (m/s^2)")
    up, down = rate_point_mean(up_outputs), rate_point_mean(down_outputs)
    return float((up - down) / (2.0 * gravity) / float(scale_factor))


def warm_up_time(times, rates, specified_stability: float, samples_per_period: int) -> float:
    """7.2.9: the time from power-on until the bias stability meets its specified value (s).

    The stability of eq. (18) is evaluated on the record from each period boundary on; the warm-up time is the
    first boundary from which it is ≤ *specified_stability* (rad/s), with at least 10 periods left to evaluate
    it on. *rates* are outputs already divided by K. NaN when it never is. The specification averages this over
    repeated power-ons.
    """
    t = checked_array("times", times, ndim=1)
    w = checked_array("rates", rates, ndim=1)
    if t.shape != w.shape:
        raise ValueError(f"times and rates: expected the same length, got {t.size} and {w.size}")
    P = int(samples_per_period)
    n = w.size // P
    if P < 1 or n < 10:
        raise ValueError(f"samples_per_period = {samples_per_period}: need at least 10 periods in {w.size} samples")
    periods = w[: n * P].reshape(n, P).mean(axis=1)
    for start in range(0, n - 9):
        if np.std(periods[start:], ddof=1) <= specified_stability:
            return float(t[start * P] - t[0])
    return math.nan


@dataclass(frozen=True)
class AllanPolynomial:
    """Eq. (25): σ²(τ) = Σ_{m=−2}^{2} A_m τ^m; ARW = sqrt(A₋₁), eq. (26)."""

    coefficients: dict  # m -> A_m (SI: rad²/s² · s^-m)
    angle_random_walk: float  # rad/√s; NaN when A₋₁ < 0 (the fit does not support a white-noise term)

    def variance(self, tau) -> np.ndarray:
        tau = np.asarray(tau, dtype=float)
        return sum(a * tau**m for m, a in self.coefficients.items())


def allan_polynomial_fit(tau, allan_variance) -> AllanPolynomial:
    """Eq. (25)–(26): the Allan variance σ²(τ) (eq. (21)–(24): ``allantools.oadev`` squared) fitted by ordinary
    least squares with the five terms A₋₂τ⁻² (quantisation), A₋₁τ⁻¹ (angle random walk), A₀ (bias
    instability), A₁τ (rate random walk), A₂τ² (rate ramp); ARW = sqrt(A₋₁).

    Parameters
    ----------
    tau : (n,) array
        Averaging times, s (at least five distinct).
    allan_variance : (n,) array
        σ²(τ), (rad/s)².
    """
    tau = checked_array("tau", tau, ndim=1, minimum=len(ALLAN_POWERS))
    avar = checked_array("allan_variance", allan_variance, ndim=1, minimum=len(ALLAN_POWERS))
    if tau.shape != avar.shape or np.any(tau <= 0):
        raise ValueError("tau and allan_variance: expected positive τ and one variance per τ")
    design = np.column_stack([tau**m for m in ALLAN_POWERS])
    scale = np.linalg.norm(design, axis=0)  # columns span decades: scale for a well-conditioned solve
    coefficients, *_ = np.linalg.lstsq(design / scale, avar, rcond=None)
    coefficients = coefficients / scale
    A = dict(zip(ALLAN_POWERS, (float(c) for c in coefficients)))
    arw = math.sqrt(A[-1]) if A[-1] >= 0 else math.nan
    return AllanPolynomial(A, arw)
