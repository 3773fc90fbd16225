"""The dynamic tests' estimators: the three-parameter sine fit, the frequency response and the −3 dB bandwidth.

JJF 1537-2015 (gyroscope dynamic characteristics) 7.2.1 drives the gyro on an angular vibration table
at N ≥ 7 frequencies f_i across its working band, with a rate amplitude A of 10–30 % of its range,
records the table's signal and the gyro's output n ≥ 7 times per frequency and reduces each record by a
three-parameter sine fit at the known angular frequency ω_i = 2πf_i, eq. (6):

    y_ij = E_ij cos(ω_i t + φ_ij) + C_ij,

then, eq. (7)–(9),

    Ē_i = (1/n) Σ_j E_ij,        S_i = Ē_i / A,        K_i = S_i / S_0,

with S_0 the zero-frequency (static) sensitivity. The bandwidth is the frequency where the amplitude
response has fallen by 3 dB (JJF 1535-2015 3.7 and 7.2.15.2). Everything is in the gyro's output unit
(V, counts, or rad/s for a digital gyro), rates in rad/s, frequencies in Hz, phases in rad. Nothing here
simulates; :mod:`plansim.model.dynamics` holds the analytic responses the estimators are tested against.

==============================  ==================================================  ===========================
clause                          quantity                                            function
==============================  ==================================================  ===========================
JJF 1537 7.2.1 eq. (6)          E_ij, φ_ij, C_ij of one record                      :func:`sine_fit`
JJF 1537 7.2.1 eq. (7)–(9)      Ē_i, S_i, K_i; the phase response (7.2.3)           :func:`frequency_response`
JJF 1535 3.7, 7.2.15.2          the −3 dB bandwidth                                 :func:`bandwidth_3db`
JJF 1535 7.2.15.2               the −3 dB bandwidth of a curve fitted to K(f)       :func:`bandwidth_curve_fit`
JJF 1537 7.2.4 (title only)     the amplitude nonlinearity                          :func:`amplitude_nonlinearity`
JJF 1537 7.2.5–7.2.7 (titles)   a change of the mean output, with its Type A u      :func:`mean_change`
==============================  ==================================================  ===========================

The copy of JJF 1537-2015 this follows breaks off after eq. (9): 7.2.4–7.2.7 are known by their titles in
its Table 3 only (amplitude nonlinearity; output change under vibration; bias change before/after vibration;
before/after shock), and the two estimators for them are plansim's reading, stated in their docstrings.

References
----------
JJF 1537-2015, *Calibration Specification for Dynamic Characteristics of Gyroscopes*, 7.2.1, eq. (6)–(9).
JJF 1535-2015, *Calibration Specification for MEMS Gyroscopes*, 3.7 and 7.2.15.
IEEE Std 1057, *Standard for Digitizing Waveform Recorders* (the three-parameter least-squares sine fit
at a known frequency).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from plansim.estimate.jjf1535 import checked_array
from plansim.model.dynamics import one_number, positive_number, second_order_bandwidth

#: |H| = 1/√2 = −3.0103 dB, the half-power point: the default level of :func:`bandwidth_3db`
HALF_POWER = 1.0 / math.sqrt(2.0)
#: 10^(−3/20) = −3 dB exactly (0.12 % above 1/√2), for a reading of "3 dB" as the rounded figure
MINUS_3_DB = 10.0 ** (-3.0 / 20.0)
#: singular values of the sine fit's design matrix below this fraction of the largest count as zero: the
#: columns cos ωt, sin ωt, 1 are then taken as linearly dependent (variances magnified by > 1e20)
RANK_TOLERANCE = 1e-10


def wrap_phase(phase):
    """*phase* (rad) wrapped to (−π, π]: π − ((π − φ) mod 2π). A float for a scalar, else an array."""
    out = math.pi - np.mod(math.pi - np.asarray(phase, dtype=float), 2.0 * math.pi)
    return float(out) if out.ndim == 0 else out




@dataclass(frozen=True)
class SineFit:
    """The three-parameter sine fit of one record, y ≈ E cos(2πf t + φ) + C (JJF 1537-2015 eq. (6)).

    ``covariance`` is that of (E, φ, C) in this order, from the residual variance s² = Σr²/(N − 3) by the
    delta method (see :func:`sine_fit`); ``residual_rms`` is √(Σr²/N). φ refers to t = 0 of the record's
    time axis.
    """

    frequency: float  # f, Hz (given, not fitted)
    amplitude: float  # E ≥ 0, output unit
    phase: float  # φ ∈ (−π, π], rad
    offset: float  # C, output unit
    residual_rms: float  # √(Σ r²/N), output unit
    covariance: np.ndarray  # (3, 3): var/cov of (E, φ, C); nan but var(C) when E = 0
    samples: int  # N

    def fitted(self, t) -> np.ndarray:
        """E cos(2πf t + φ) + C at the times *t* (s)."""
        t = np.asarray(t, dtype=float)
        return self.amplitude * np.cos(2.0 * math.pi * self.frequency * t + self.phase) + self.offset

    @property
    def standard_uncertainties(self) -> np.ndarray:
        """u(E), u(φ), u(C): the square roots of the covariance's diagonal."""
        return np.sqrt(np.diag(self.covariance))


def sine_fit(t, y, frequency: float) -> SineFit:
    """Three-parameter least-squares sine fit at a known frequency (JJF 1537-2015 7.2.1 c), eq. (6)).

    The model y(t) ≈ E cos(ωt + φ) + C, ω = 2πf, is linear in (a, b, C) once written

        y ≈ a cos ωt + b sin ωt + C,        a = E cos φ,  b = −E sin φ,

    so it is solved by linear least squares (``scipy.linalg.lstsq`` on the N × 3 design matrix
    D = [cos ωt, sin ωt, 1], as IEEE Std 1057's three-parameter fit), and

        E = √(a² + b²),        φ = atan2(−b, a) wrapped to (−π, π].

    The covariance of (a, b, C) is s²(DᵀD)⁻¹ with the residual variance s² = Σr²/(N − 3); that of (E, φ, C)
    is J s²(DᵀD)⁻¹ Jᵀ (the delta method, JCGM 100 5.1.2) with the Jacobian

        ∂E/∂a = a/E,   ∂E/∂b = b/E,   ∂φ/∂a = b/E²,   ∂φ/∂b = −a/E²,   ∂C/∂C = 1.

    Over whole cycles of N equally spaced samples (DᵀD = diag(N/2, N/2, N)) and white noise of standard
    deviation σ this gives var(C) = σ²/N, var(E) = 2σ²/N and var(φ) = 2σ²/(N E²), to first order in σ/E.

    Parameters
    ----------
    t : (N,) array_like
        Sample times, s, finite and strictly increasing, N ≥ 4 (three parameters and one degree of
        freedom for s²).
    y : (N,) array_like
        The record (gyro output or the table's reference signal), finite.
    frequency : float
        f > 0, Hz, the table's known frequency.

    Returns
    -------
    SineFit

    Raises
    ------
    TypeError
        *t*, *y* or *frequency* is not numeric.
    ValueError
        The lengths differ, N < 4, a value is not finite, f ≤ 0, *t* is not strictly increasing, or the
        three columns are linearly dependent at these times (rank below 3 at :data:`RANK_TOLERANCE`; for
        example samples exactly at twice the frequency, where sin ωt vanishes at every sample).
    """
    t = checked_array("t", t, ndim=1, minimum=4)
    y = checked_array("y", y, ndim=1, minimum=4)
    if t.shape != y.shape:
        raise ValueError(f"t and y: expected the same length, got {t.size} and {y.size}")
    steps = np.diff(t)
    if not np.all(steps > 0):
        k = int(np.argmin(steps > 0))
        raise ValueError(f"t: expected strictly increasing times, got t[{k}] = {float(t[k])!r} then "
                         f"t[{k + 1}] = {float(t[k + 1])!r}")
    f = positive_number("frequency", frequency, "Hz")
    omega_t = 2.0 * math.pi * f * t
    design = np.column_stack((np.cos(omega_t), np.sin(omega_t), np.ones_like(t)))
    solution, _, rank, _ = scipy.linalg.lstsq(design, y, cond=RANK_TOLERANCE)
    if rank < 3:
        raise ValueError(f"frequency: at {f!r} Hz the columns cos ωt, sin ωt and 1 are linearly dependent at the "
                         f"sample times t (rank {rank}); the sine fit needs samples at distinct phases")
    a, b, c = (float(v) for v in solution)
    residuals = y - design @ solution
    rss = float(residuals @ residuals)
    n = t.size
    parameter_covariance = rss / (n - 3) * np.linalg.inv(design.T @ design)
    amplitude = math.hypot(a, b)
    if amplitude > 0:
        jacobian = np.array([[a / amplitude, b / amplitude, 0.0],
                             [b / amplitude**2, -a / amplitude**2, 0.0],
                             [0.0, 0.0, 1.0]])
        covariance = jacobian @ parameter_covariance @ jacobian.T
    else:  # φ undefined and E not differentiable: only var(C) is given
        covariance = np.full((3, 3), np.nan)
        covariance[2, 2] = parameter_covariance[2, 2]
    return SineFit(frequency=f, amplitude=amplitude, phase=wrap_phase(math.atan2(-b, a)), offset=c,
                   residual_rms=math.sqrt(rss / n), covariance=covariance, samples=n)


@dataclass(frozen=True)
class FrequencyResponse:
    """The amplitude and phase response at the table frequencies (JJF 1537-2015 7.2.1, eq. (7)–(9))."""

    frequencies: np.ndarray  # f_i, Hz
    mean_amplitudes: np.ndarray  # Ē_i, eq. (7), output unit
    sensitivities: np.ndarray  # S_i = Ē_i / A, eq. (8), output unit per rad/s
    ratios: np.ndarray  # K_i = S_i / |S_0|, eq. (9)
    phases: np.ndarray  # the mean of φ_out − φ_in over the repeats, (−π, π], rad (negative: the output lags)
    static_sensitivity: float  # S_0, output unit per rad/s
    repeats: int  # n
    ratio_std_of_mean: np.ndarray  # s(E_ij/Ā_i)/(√n |S_0|), nan for n = 1 (the Type A u(K_i))
    phase_std_of_mean: np.ndarray  # s(φ_out − φ_in)/√n, rad, nan for n = 1

    @property
    def gains_db(self) -> np.ndarray:
        """20 log₁₀ K_i, dB."""
        return 20.0 * np.log10(self.ratios)

    @property
    def phase_lags(self) -> np.ndarray:
        """−phases, rad: positive when the output lags the input."""
        return -self.phases


def _per_repeat(name: str, values, shape: tuple[int, int]) -> np.ndarray:
    """*values* (a scalar, one per frequency, or one per frequency and repeat) as an (m, n) array."""
    out = checked_array(name, values)
    if out.ndim == 1 and out.size == shape[0]:
        out = out[:, None]
    try:
        return np.broadcast_to(out, shape)
    except ValueError as exc:
        raise ValueError(f"{name}: expected one value, one per frequency ({shape[0]}) or an array of shape "
                         f"{shape}, got shape {out.shape}") from exc


def frequency_response(frequencies, amplitudes, phases, input_amplitude, static_sensitivity: float,
                       input_phases=0.0) -> FrequencyResponse:
    """The amplitude-frequency and phase-frequency responses from the sine fits (JJF 1537-2015 7.2.1).

    With the fits E_ij, φ_ij of the gyro's output at frequency f_i, repeat j (eq. (6)), and the table's
    rate amplitude A and phase φ_in,ij (the table's reference signal fitted the same way):

        Ē_i = (1/n) Σ_j E_ij                                   eq. (7)
        S_i = Ē_i / Ā_i                                        eq. (8)
        K_i = S_i / |S_0|                                      eq. (9)
        Δφ_i = (1/n) Σ_j wrap(φ_ij − φ_in,ij − π·[S_0 < 0])    the phase response (JJF 1537 7.2.3)

    Ā_i is the mean of the given input amplitudes at f_i; with the one amplitude A of eq. (8) it is A. A
    negative static sensitivity (an output that falls as the rate rises) is an inversion, not a delay: it
    is taken out of the phase, so a flat sensor gives K_i = 1 and Δφ_i = 0 whatever its sign. The phases
    are averaged on the branch where the repeats are contiguous (each difference is wrapped to within π of
    their circular mean, then averaged), so repeats on both sides of ±π average to ±π, not to 0.
    Δφ_i is arg H(j2πf_i) of the sensor's response, negative for a lag; it is known modulo 2π (use
    ``np.unwrap`` across increasing frequencies for a response that passes −π).

    The copy of JJF 1537-2015 this follows gives the phase clause (7.2.3) by its number only; the phase
    difference between output and input, averaged like eq. (7), is its reading here.

    Parameters
    ----------
    frequencies : (m,) array_like
        f_i > 0, Hz.
    amplitudes : (m,) or (m, n) array_like
        E_ij ≥ 0, the gyro output's fitted amplitudes, output unit (one column: n = 1).
    phases : same shape as *amplitudes*
        φ_ij, rad.
    input_amplitude : float, (m,) or (m, n) array_like
        A > 0, the table's rate amplitude, rad/s.
    static_sensitivity : float
        S_0 ≠ 0, the zero-frequency sensitivity (the static scale factor, JJF 1535 7.2.1), output unit per
        rad/s.
    input_phases : float, (m,) or (m, n) array_like, optional
        φ_in,ij, rad, the table signal's fitted phase on the same time axis; 0 by default.

    Returns
    -------
    FrequencyResponse
    """
    f = checked_array("frequencies", frequencies, ndim=1)
    if np.any(f <= 0):
        raise ValueError(f"frequencies: expected values > 0 Hz, got {f.tolist()}")
    E = checked_array("amplitudes", amplitudes)
    if E.ndim == 1:
        E = E[:, None]
    if E.ndim != 2 or E.shape[0] != f.size:
        raise ValueError(f"amplitudes: expected shape ({f.size},) or ({f.size}, n) for {f.size} frequencies, "
                         f"got {np.shape(amplitudes)}")
    if np.any(E < 0):
        raise ValueError(f"amplitudes: expected values ≥ 0 (E of eq. (6)), got {E.tolist()}")
    phi = checked_array("phases", phases)
    if phi.ndim == 1:
        phi = phi[:, None]
    if phi.shape != E.shape:
        raise ValueError(f"phases: expected the shape of amplitudes {np.shape(amplitudes)}, got {np.shape(phases)}")
    A = _per_repeat("input_amplitude", input_amplitude, E.shape)
    if np.any(A <= 0):
        raise ValueError(f"input_amplitude: expected values > 0 rad/s, got {np.asarray(input_amplitude).tolist()}")
    phi_in = _per_repeat("input_phases", input_phases, E.shape)
    S0 = one_number("static_sensitivity", static_sensitivity)
    if not (math.isfinite(S0) and S0 != 0):
        raise ValueError(f"static_sensitivity: expected a finite nonzero S_0, got {static_sensitivity!r}")

    n = E.shape[1]
    mean_A = A.mean(axis=1)
    mean_E = E.mean(axis=1)  # eq. (7)
    S = mean_E / mean_A  # eq. (8)
    K = S / abs(S0)  # eq. (9)

    difference = wrap_phase(phi - phi_in - (math.pi if S0 < 0 else 0.0))
    centre = np.angle(np.exp(1j * difference).mean(axis=1))
    deviations = wrap_phase(difference - centre[:, None])
    mean_phase = wrap_phase(centre + deviations.mean(axis=1))

    if n > 1:
        ratio_u = (E / mean_A[:, None]).std(axis=1, ddof=1) / math.sqrt(n) / abs(S0)
        phase_u = deviations.std(axis=1, ddof=1) / math.sqrt(n)
    else:
        ratio_u = phase_u = np.full(f.size, np.nan)
    return FrequencyResponse(frequencies=f, mean_amplitudes=mean_E, sensitivities=S, ratios=K,
                             phases=np.atleast_1d(mean_phase), static_sensitivity=S0, repeats=n,
                             ratio_std_of_mean=ratio_u, phase_std_of_mean=np.atleast_1d(phase_u))


def _checked_response(frequencies, ratios, level, minimum: int) -> tuple[np.ndarray, np.ndarray, float]:
    """(f, K, level) of a bandwidth estimator, each checked: f > 0 Hz strictly increasing, K ≥ 0 of the same
    length (at least *minimum*), 0 < level < 1; a bad one is a ValueError or TypeError naming it."""
    f = checked_array("frequencies", frequencies, ndim=1, minimum=minimum)
    K = checked_array("ratios", ratios, ndim=1, minimum=minimum)
    if f.shape != K.shape:
        raise ValueError(f"frequencies and ratios: expected the same length, got {f.size} and {K.size}")
    if np.any(f <= 0) or not np.all(np.diff(f) > 0):
        raise ValueError(f"frequencies: expected values > 0 Hz, strictly increasing, got {f.tolist()}")
    if np.any(K < 0):
        raise ValueError(f"ratios: expected values ≥ 0, got {K.tolist()}")
    lev = one_number("level", level)
    if not 0 < lev < 1:
        raise ValueError(f"level: expected 0 < level < 1 (1/√2 for −3 dB), got {level!r}")
    return f, K, lev


def bandwidth_3db(frequencies, ratios, level: float = HALF_POWER) -> float:
    """The −3 dB bandwidth: where the amplitude response K(f) first falls through *level*, Hz.

    JJF 1535-2015 3.7 defines the bandwidth as the frequency range over which the measured amplitude-
    frequency response has fallen by 3 dB, and 7.2.15.2 reads it from a curve fitted to the scale factor
    against frequency, without naming the curve. Here the curve is the straight line between the two
    measured points that straddle the level: with K_{k−1} > level ≥ K_k at the first such pair,

        f_3dB = f_{k−1} + (K_{k−1} − level)·(f_k − f_{k−1}) / (K_{k−1} − K_k).

    Its error, for a smooth response K(f) and f_3dB in (f_{k−1}, f_k), is at most

        max|K''| (f_3dB − f_{k−1})(f_k − f_3dB) / (2 min|K'|)

    over the interval (the interpolation remainder divided by the chord's slope); a point inserted either
    side of the expected bandwidth, as 7.2.15.1 b) asks, keeps it small.

    Parameters
    ----------
    frequencies : (m,) array_like
        f_i > 0, Hz, strictly increasing, m ≥ 2.
    ratios : (m,) array_like
        K_i, the amplitude response relative to the static sensitivity (eq. (9) of JJF 1537-2015), ≥ 0.
    level : float, optional
        The level in K: 1/√2 (−3.01 dB, half power; :data:`HALF_POWER`) by default, or
        :data:`MINUS_3_DB` = 10^(−3/20) for exactly −3 dB. 0 < level < 1.

    Raises
    ------
    ValueError
        The response does not cross the level downwards between the lowest and the highest frequency
        (already below it at the lowest: the bandwidth is below the measured band; never down to it: above),
        or a bad argument (named).
    """
    f, K, lev = _checked_response(frequencies, ratios, level, minimum=2)
    if K[0] < lev:
        raise ValueError(f"ratios: the response is already below the level {lev:.6g} at the lowest frequency "
                         f"{f[0]:.6g} Hz (K = {K[0]:.6g}); the bandwidth lies below the measured band")
    below = np.flatnonzero(K <= lev)
    if below.size == 0:
        raise ValueError(f"ratios: the response never falls to the level {lev:.6g} up to {f[-1]:.6g} Hz "
                         f"(smallest K = {K.min():.6g}); the bandwidth lies above the measured band")
    k = int(below[0])
    if k == 0:  # on the level at the lowest frequency
        return float(f[0])
    f0, f1, K0, K1 = f[k - 1], f[k], K[k - 1], K[k]
    return float(f0 + (K0 - lev) * (f1 - f0) / (K0 - K1))


#: the damping ratios the curve fit of :func:`bandwidth_curve_fit` starts from (the best fit of the three is kept)
CURVE_FIT_STARTS = (0.2, 0.7, 1.5)


@dataclass(frozen=True)
class CurveFitBandwidth:
    """The −3 dB bandwidth read from a second-order curve fitted to the amplitude response (JJF 1535 7.2.15.2).

    ``bandwidth`` Hz; the fitted curve's ``gain`` c, ``natural_frequency`` f_n (Hz) and ``damping`` ζ;
    ``residual_rms`` the r.m.s. of K_i − K̂(f_i); ``gradient`` (m,) ∂bandwidth/∂K_i (Hz per unit of K), the
    fit's first-order sensitivity for the GUM.
    """

    bandwidth: float
    gain: float
    natural_frequency: float
    damping: float
    residual_rms: float
    gradient: np.ndarray


def bandwidth_curve_fit(frequencies, ratios, level: float = HALF_POWER) -> CurveFitBandwidth:
    """The −3 dB bandwidth of a second-order curve fitted to the amplitude response (JJF 1535-2015 7.2.15.2).

    7.2.15.2: "with frequency as abscissa and the gyro's scale factor as ordinate, fit a curve; the frequency
    where the curve's scale factor has fallen by 3 dB is the gyro's working bandwidth". The specification does
    not name the curve; here it is the one-resonance low-pass of :mod:`plansim.model.dynamics` with a free gain,

        K̂(f) = c / √((1 − x²)² + (2ζx)²),        x = f/f_n,

    fitted by unweighted least squares in (ln c, ln f_n, ln ζ) (``scipy.optimize.least_squares``, started from
    ζ ∈ :data:`CURVE_FIT_STARTS` and f_n at the interpolated crossing, the best of the starts kept), and the
    bandwidth is where K̂ has fallen to *level* × its zero-frequency value c:

        f_3dB = f_n √(b + √(b² + 1/L² − 1)),        b = 1 − 2ζ²,  L = level,

    (:func:`plansim.model.dynamics.second_order_bandwidth` with the level). Unlike the chord of
    :func:`bandwidth_3db` it has no interpolation error for a one-resonance sensor; for a sensor that is not one
    (JJF 1537's two resonances), the curve's misfit becomes a bias, which the Monte Carlo of
    ``plansim run jjf1537`` shows. ``gradient`` is the fit's first-order sensitivity ∂f_3dB/∂K_i =
    ∇_θ f_3dB · (JᵀJ)⁻¹Jᵀ (J the residuals' Jacobian in θ = ln c, ln f_n, ln ζ; exact where the curve fits the
    data, first order otherwise).

    Parameters
    ----------
    frequencies : (m,) array_like
        f_i > 0, Hz, strictly increasing, m ≥ 4 (three parameters and one degree of freedom).
    ratios : (m,) array_like
        K_i ≥ 0 (JJF 1537-2015 eq. (9)).
    level : float, optional
        0 < level < 1, in K relative to the curve's zero-frequency value; 1/√2 by default.

    Raises
    ------
    ValueError
        A bad argument (named); the fit did not converge; or the fitted curve reaches the level outside the
        measured band (f_1 to f_m: an extrapolation, which the specification's procedure does not ask for).
    """
    import scipy.optimize

    f, K, lev = _checked_response(frequencies, ratios, level, minimum=4)
    if not np.any(K > 0):
        raise ValueError(f"ratios: expected values ≥ 0, not all 0, got {K.tolist()}")

    def curve(theta, x=f):
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # a flat response sends f_n to ∞
            c, fn, zeta = np.exp(theta)
            u = x / fn
            return c / np.sqrt((1.0 - u * u) ** 2 + (2.0 * zeta * u) ** 2)

    try:
        start_fn = bandwidth_3db(f, K / K[0], lev)
    except ValueError:
        start_fn = float(f[-1])
    best = None
    for zeta0 in CURVE_FIT_STARTS:
        theta0 = np.log([float(K[0]), start_fn, zeta0])
        fit = scipy.optimize.least_squares(lambda th: curve(th) - K, theta0, method="lm", xtol=1e-15, ftol=1e-15,
                                           gtol=1e-15, max_nfev=2000)
        usable = fit.success and np.all(np.isfinite(fit.x)) and np.all(np.isfinite(np.exp(fit.x)))
        if usable and np.isfinite(fit.cost) and (best is None or fit.cost < best.cost):
            best = fit
    if best is None:
        raise ValueError(f"ratios: the second-order curve fit did not converge on {K.tolist()}")
    c, fn, zeta = (float(v) for v in np.exp(best.x))
    bandwidth = second_order_bandwidth(fn, zeta, lev)
    if not f[0] <= bandwidth <= f[-1]:
        raise ValueError(f"ratios: the fitted curve (f_n = {fn:.6g} Hz, ζ = {zeta:.6g}) falls to the level {lev:.6g} "
                         f"at {bandwidth:.6g} Hz, outside the measured band {f[0]:.6g} to {f[-1]:.6g} Hz")
    # ∇_θ f_3dB by central differences of the closed form (θ = ln c, ln f_n, ln ζ; c does not enter)
    h = 1e-6
    grad_theta = np.array([0.0, bandwidth,  # ∂f_3dB/∂ln f_n = f_3dB
                           (second_order_bandwidth(fn, zeta * math.exp(h), lev)
                            - second_order_bandwidth(fn, zeta * math.exp(-h), lev)) / (2.0 * h)])
    gradient = grad_theta @ np.linalg.pinv(best.jac)
    return CurveFitBandwidth(bandwidth=bandwidth, gain=c, natural_frequency=fn, damping=zeta,
                             residual_rms=float(np.sqrt(np.mean(best.fun**2))), gradient=gradient)


@dataclass(frozen=True)
class SineFits:
    """:func:`sine_fit` of many records on one time axis: arrays of the records' shape (``amplitude``,
    ``phase``, ``offset``, ``residual_rms``), the frequency and N."""

    frequency: float
    amplitude: np.ndarray
    phase: np.ndarray
    offset: np.ndarray
    residual_rms: np.ndarray
    samples: int


def sine_fits(t, records, frequency: float) -> SineFits:
    """:func:`sine_fit` of every record of *records* (..., N) sampled at the same times *t* (N,), at once.

    The design matrix D = [cos ωt, sin ωt, 1] is the same for every record, so one least-squares solve with
    the records as right-hand sides gives each record's (a, b, C), hence E, φ, C, as :func:`sine_fit`
    computes them one by one (the same equations, JJF 1537-2015 eq. (6); their covariance is not formed
    here). For the Monte Carlo of :mod:`plansim.simulate.jjf1537`, where n repeats × the trials share t.

    Raises
    ------
    ValueError
        As :func:`sine_fit` (lengths, finiteness, ordering, f ≤ 0, rank below 3).
    """
    t = checked_array("t", t, ndim=1, minimum=4)
    y = np.asarray(records, dtype=float)
    if y.ndim < 1 or y.shape[-1] != t.size:
        raise ValueError(f"records: expected shape (..., {t.size}) for {t.size} sample times, got {y.shape}")
    if not np.all(np.isfinite(y)):
        raise ValueError("records: expected finite values, got nan or inf")
    if not np.all(np.diff(t) > 0):
        raise ValueError("t: expected strictly increasing times")
    f = positive_number("frequency", frequency, "Hz")
    omega_t = 2.0 * math.pi * f * t
    design = np.column_stack((np.cos(omega_t), np.sin(omega_t), np.ones_like(t)))
    rhs = y.reshape(-1, t.size).T
    solution, _, rank, _ = scipy.linalg.lstsq(design, rhs, cond=RANK_TOLERANCE)
    if rank < 3:
        raise ValueError(f"frequency: at {f!r} Hz the columns cos ωt, sin ωt and 1 are linearly dependent at the "
                         f"sample times t (rank {rank}); the sine fit needs samples at distinct phases")
    residuals = rhs - design @ solution
    a, b, c = solution
    shape = y.shape[:-1]
    return SineFits(frequency=f, amplitude=np.hypot(a, b).reshape(shape),
                    phase=np.asarray(wrap_phase(np.arctan2(-b, a))).reshape(shape), offset=c.reshape(shape),
                    residual_rms=np.sqrt(np.mean(residuals * residuals, axis=0)).reshape(shape), samples=t.size)


def amplitude_nonlinearity(input_amplitudes, mean_amplitudes) -> float:
    """The amplitude nonlinearity at one frequency (JJF 1537-2015 7.2.4, Table 3 item 4), dimensionless.

    At M ≥ 3 table amplitudes A_k the sensitivities S_k = Ē_k/A_k (eq. (7)–(8), Ē_k the mean fitted
    amplitude of the n records at A_k) are compared with their mean S̄ = (1/M) Σ_k S_k:

        γ = max_k |S_k − S̄| / |S̄|.

    The copy of JJF 1537 used here gives 7.2.4 by its title only; this is plansim's reading, the largest
    relative deviation of the sensitivity from its mean over the amplitudes (as the scale-factor
    nonlinearity of JJF 1535 eq. (6) is the largest deviation from the fitted line, relative). A linear
    sensor gives 0 whatever its scale factor and dynamics.
    """
    A = checked_array("input_amplitudes", input_amplitudes, ndim=1, minimum=3)
    E = checked_array("mean_amplitudes", mean_amplitudes, ndim=1, minimum=3)
    if A.shape != E.shape:
        raise ValueError(f"input_amplitudes and mean_amplitudes: expected the same length, got {A.size} and "
                         f"{E.size}")
    if np.any(A <= 0):
        raise ValueError(f"input_amplitudes: expected values > 0 rad/s, got {A.tolist()}")
    S = E / A
    mean = S.mean()
    if not mean != 0:
        raise ValueError(f"mean_amplitudes: the mean sensitivity is 0 (got {E.tolist()})")
    return float(np.max(np.abs(S - mean)) / abs(mean))


def mean_change(before, after) -> tuple[np.ndarray, np.ndarray]:
    """The change of the mean output from the record(s) *before* to *after* (last axis: samples), with its
    Type A standard uncertainty (JJF 1537-2015 7.2.6–7.2.7, Table 3 items 6–7, by their titles).

        Δ = ȳ_after − ȳ_before,        u(Δ) = √(s²_after/N_after + s²_before/N_before),

    s² the sample variances (ddof 1): the two records' means are independent and their noise white. The
    bias change across vibration or shock is Δ/S in rate units (S the scale factor). Arrays of the leading
    shape (floats for one record each).
    """
    b = checked_array("before", before, minimum=2)
    a = checked_array("after", after, minimum=2)
    for name, x in (("before", b), ("after", a)):
        if x.ndim == 0 or x.shape[-1] < 2:
            raise ValueError(f"{name}: expected at least 2 samples along the last axis, got shape {x.shape}")
    if b.shape[:-1] != a.shape[:-1]:
        raise ValueError(f"before and after: expected the same leading shape, got {b.shape} and {a.shape}")
    change = a.mean(axis=-1) - b.mean(axis=-1)
    u = np.sqrt(a.var(axis=-1, ddof=1) / a.shape[-1] + b.var(axis=-1, ddof=1) / b.shape[-1])
    return change, u


@dataclass(frozen=True)
class ShockResponse:
    """The output of one record across a shock (:func:`shock_response`), output unit and s."""

    peak: float  # the largest |y − level before| in the record
    saturated: bool  # a sample at the output's range
    recovery_time: float  # from the pulse's start to the last sample outside the band; nan: not back by the end


def shock_response(record, level_before: float, level_after: float, band: float, sample_rate: float,
                   output_range: float) -> ShockResponse:
    """The output across a shock: its peak departure from the level before, saturation, and the recovery time.

    The recovery time is the time from the record's first sample (the pulse's start) to the end of the last
    sample farther than *band* from *level_after* (the level the output settles to: the mean of the record
    after the shock); nan when the record's last sample is still outside (the output had not settled when the
    next record began: the settle time was too short). A laboratory chooses *band* from the noise at rest
    (plansim: 4 × its standard deviation plus one quantisation step).

    Parameters
    ----------
    record : (N,) array
        The output from the pulse's start, output unit.
    level_before, level_after : float
        The output's level before the shock and after it, output unit.
    band : float
        > 0, output unit.
    sample_rate : float
        Hz.
    output_range : float
        The output's saturation level (> 0): a sample with |y| >= it is saturated.
    """
    y = np.asarray(record, dtype=float)
    if y.ndim != 1 or y.size == 0 or not np.all(np.isfinite(y)):
        raise ValueError(f"record: expected a non-empty 1-D array of finite outputs, got shape {y.shape}")
    for name, value in (("band", band), ("sample_rate", sample_rate), ("output_range", output_range)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name}: expected a finite number > 0, got {value!r}")
    outside = np.flatnonzero(np.abs(y - level_after) > band)
    if outside.size and outside[-1] == y.size - 1:
        recovery = math.nan
    else:
        recovery = (outside[-1] + 1) / sample_rate if outside.size else 0.0
    return ShockResponse(peak=float(np.max(np.abs(y - level_before))),
                         saturated=bool(np.any(np.abs(y) >= output_range)), recovery_time=float(recovery))
