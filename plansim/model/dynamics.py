"""Analytic frequency responses of a sensor: the second-order low-pass, JJF 1537's two resonances, the −3 dB bandwidth.

A rate gyro whose sense path behaves as one second-order system (one resonance of natural frequency
f_n = ω_n/2π and damping ratio ζ) has the transfer function

    H(s) = ω_n² / (s² + 2ζω_n s + ω_n²),                                    H(0) = 1,

from the input rate to the output rate. JJF 1537-2015 eq. (3) (and JJF 1535-2015 eq. (3)) write the
MEMS gyro as the product of two such resonances, the drive and the sense mode; the one-resonance form
here is the simpler low-pass of the two the dynamic tests are checked against. At s = jω, with
x = f/f_n,

    |H| = 1/√((1 − x²)² + (2ζx)²),        arg H = −atan2(2ζx, 1 − x²) ∈ (−π, 0],

and |H| = 1/√2 (−3.01 dB, half power) at

    x² = 1 − 2ζ² + √((1 − 2ζ²)² + 1),

so f_3dB = f_n for ζ = 1/√2 (the Butterworth response, |H| = 1/√(1 + x⁴)). Frequencies are in Hz
(f = ω/2π) throughout, like the table frequencies f_i of JJF 1537 7.2.1.

JJF 1537-2015 eq. (3)'s two-resonance form is :func:`two_resonance_response`, and :class:`SensorDynamics`
holds one of the three models (flat, one resonance, two) with its H(s) as polynomials for the simulator
(:mod:`plansim.simulate.vibration_table` discretises them) and its bandwidth. These are the truth the estimators of
:mod:`plansim.estimate.dynamic` are tested against.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def one_number(name: str, value, unit: str = "") -> float:
    """*value* as a float, or a ``TypeError`` naming *name*, the value and (where given) the *unit* it is read in
    for anything that is not one number (a string, a bool, a list)."""
    read_in = f" ({unit})" if unit else ""
    if isinstance(value, (str, bytes, bool)):
        raise TypeError(f"{name}: expected one number{read_in}, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name}: expected one number{read_in}, got {value!r}") from exc


def positive_number(name: str, value, unit: str = "") -> float:
    """:func:`one_number`, and a ``ValueError`` naming the same unless it is finite and > 0."""
    out = one_number(name, value, unit)
    if not (math.isfinite(out) and out > 0):
        raise ValueError(f"{name}: expected a finite number > 0{' ' + unit if unit else ''}, got {value!r}")
    return out


def _frequencies(frequencies) -> np.ndarray:
    try:
        out = np.asarray(frequencies, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"frequencies: expected numbers (Hz), got {frequencies!r}") from exc
    if not np.all(np.isfinite(out)) or np.any(out < 0):
        raise ValueError(f"frequencies: expected finite values ≥ 0 Hz, got {frequencies!r}")
    return out


def second_order_response(frequencies, natural_frequency: float, damping: float) -> np.ndarray:
    """H(j2πf) of the second-order low-pass H(s) = ω_n²/(s² + 2ζω_n s + ω_n²), complex, H(0) = 1.

    Parameters
    ----------
    frequencies : array_like
        f ≥ 0, Hz.
    natural_frequency : float
        f_n = ω_n/2π > 0, Hz.
    damping : float
        ζ > 0, dimensionless.

    Returns
    -------
    ndarray of complex
        1/(1 − x² + 2jζx) with x = f/f_n, the shape of *frequencies*.
    """
    f = _frequencies(frequencies)
    x = f / positive_number("natural_frequency", natural_frequency)
    return 1.0 / (1.0 - x * x + 2j * positive_number("damping", damping) * x)


def second_order_magnitude(frequencies, natural_frequency: float, damping: float) -> np.ndarray:
    """|H| = 1/√((1 − x²)² + (2ζx)²), x = f/f_n: the ratio of the output amplitude to the static one
    (the K_i of JJF 1537-2015 eq. (9) for this sensor)."""
    f = _frequencies(frequencies)
    x = f / positive_number("natural_frequency", natural_frequency)
    zeta = positive_number("damping", damping)
    return 1.0 / np.sqrt((1.0 - x * x) ** 2 + (2.0 * zeta * x) ** 2)


def second_order_phase(frequencies, natural_frequency: float, damping: float) -> np.ndarray:
    """arg H = −atan2(2ζx, 1 − x²) ∈ (−π, 0], rad, x = f/f_n: the output's phase relative to the input
    rate's (negative: the output lags), continuous in f through the resonance (−π/2 at f = f_n)."""
    f = _frequencies(frequencies)
    x = f / positive_number("natural_frequency", natural_frequency)
    zeta = positive_number("damping", damping)
    return -np.arctan2(2.0 * zeta * x, 1.0 - x * x)


def second_order_bandwidth(natural_frequency: float, damping: float, level: float | None = None) -> float:
    """The frequency where |H| falls to *level*: f_n·√(b + √(b² + 1/level² − 1)), b = 1 − 2ζ², Hz.

    From |H|⁻² = (1 − x²)² + 4ζ²x² = 1/level², a quadratic in x² with one positive root (1/level² − 1 > 0). It is
    the only frequency where |H| = level on the way down (for ζ < 1/√2 the response first rises above 1 at the
    resonance), so at the default, 1/√2 (−3.01 dB, half power: 1/level² − 1 = 1 exactly), it is the bandwidth of
    JJF 1535-2015 3.7: f_n √(1 − 2ζ² + √((1 − 2ζ²)² + 1)). ζ = 1/√2 gives f_n.
    """
    f_n = positive_number("natural_frequency", natural_frequency)
    b = 1.0 - 2.0 * positive_number("damping", damping) ** 2
    excess = 1.0
    if level is not None:
        lev = one_number("level", level)
        if not 0 < lev < 1:
            raise ValueError(f"level: expected 0 < level < 1 (None: 1/√2, half power), got {level!r}")
        excess = 1.0 / (lev * lev) - 1.0
    return f_n * math.sqrt(b + math.sqrt(b * b + excess))


def two_resonance_response(frequencies, sense_frequency: float, sense_damping: float, drive_frequency: float,
                           drive_damping: float) -> np.ndarray:
    """H(j2πf) of JJF 1537-2015 eq. (3)'s form: the product of the drive- and the sense-mode resonances.

    JJF 1537-2015 5 (and JJF 1535-2015 eq. (3)) model the vibratory gyro as two coupled second-order
    systems, the drive mode (mass M_d, damping D_d, stiffness K_d) and the sense mode (M_s, D_s, K_s), the
    Coriolis force 2M_sΩẋ_d coupling the rate Ω into the sense mode; the rate-to-output transfer function is
    the product of the two resonances. Normalised to H(0) = 1 (the static gain is the scale factor's),

        H(s) = ω_d²/(s² + 2ζ_d ω_d s + ω_d²) · ω_s²/(s² + 2ζ_s ω_s s + ω_s²),

    ω_d = 2πf_d, ω_s = 2πf_s, ζ = D/(2√(MK)) of each mode. The product of two
    :func:`second_order_response`; complex, the shape of *frequencies* (Hz).
    """
    return (second_order_response(frequencies, sense_frequency, sense_damping)
            * second_order_response(frequencies, drive_frequency, drive_damping))


def static_nonlinearity_harmonics(amplitude, even: float, odd: float) -> tuple[np.ndarray, np.ndarray]:
    """The mean and the fundamental of g(v) = v + c₂v² + c₃v³ for v = a cos θ over whole cycles.

    The sensor's optional amplitude nonlinearity (:func:`plansim.kernels.dynamics.sine_records`) acts on
    the rate after the dynamics, v = a cos θ with a = A|H(j2πf)|. From cos²θ = (1 + cos 2θ)/2 and
    cos³θ = (3 cos θ + cos 3θ)/4,

        g(a cos θ) = c₂a²/2 + (a + 3c₃a³/4) cos θ + (c₂a²/2) cos 2θ + (c₃a³/4) cos 3θ,

    so over whole cycles the mean is c₂a²/2 (the rectification, JJF 1537-2015 7.2.5's output change under
    vibration) and the fundamental's amplitude, which the sine fit of eq. (6) reads, is a + 3c₃a³/4 (the even
    term adds none: the amplitude nonlinearity of 7.2.4 comes from the odd term). Returns (mean,
    fundamental) in rad/s, arrays of *amplitude*'s shape (rad/s); c₂ in (rad/s)⁻¹, c₃ in (rad/s)⁻².
    """
    a = np.asarray(amplitude, dtype=float)
    c2, c3 = one_number("even", even), one_number("odd", odd)
    return 0.5 * c2 * a * a, a + 0.75 * c3 * a**3


#: the sensor models of :class:`SensorDynamics`
SENSOR_MODELS = ("flat", "second_order", "two_resonance")


@dataclass(frozen=True)
class SensorDynamics:
    """The gyro's rate-to-output dynamics, normalised to H(0) = 1 (the static gain is the scale factor's).

    ``model``: ``"flat"`` (H = 1, an ideal sensor), ``"second_order"`` (:func:`second_order_response` with
    ``natural_frequency`` f_n and ``damping`` ζ) or ``"two_resonance"`` (JJF 1537-2015 eq. (3),
    :func:`two_resonance_response`: the sense mode f_n, ζ times the drive mode ``drive_frequency``,
    ``drive_damping``). Frequencies in Hz, dampings dimensionless.
    """

    model: str = "second_order"
    natural_frequency: float = 100.0
    damping: float = 0.6
    drive_frequency: float = 400.0
    drive_damping: float = 0.7

    def __post_init__(self):
        if self.model not in SENSOR_MODELS:
            raise ValueError(f"model: expected one of {', '.join(SENSOR_MODELS)}, got {self.model!r}")
        for name, unit in (("natural_frequency", "Hz"), ("damping", ""), ("drive_frequency", "Hz"),
                           ("drive_damping", "")):
            object.__setattr__(self, name, positive_number(name, getattr(self, name), unit))

    def response(self, frequencies) -> np.ndarray:
        """H(j2πf), complex, at *frequencies* (Hz)."""
        if self.model == "flat":
            return np.ones(np.shape(_frequencies(frequencies)), dtype=complex)
        out = second_order_response(frequencies, self.natural_frequency, self.damping)
        if self.model == "two_resonance":
            out = out * second_order_response(frequencies, self.drive_frequency, self.drive_damping)
        return out

    def polynomials(self) -> tuple[np.ndarray, np.ndarray]:
        """H(s) = B(s)/A(s) as coefficient arrays in descending powers of s (s in rad/s)."""
        b, a = np.array([1.0]), np.array([1.0])
        if self.model == "flat":
            return b, a
        modes = [(self.natural_frequency, self.damping)]
        if self.model == "two_resonance":
            modes.append((self.drive_frequency, self.drive_damping))
        for f_n, zeta in modes:
            w = 2.0 * math.pi * f_n
            b = np.polymul(b, [w * w])
            a = np.polymul(a, [1.0, 2.0 * zeta * w, w * w])
        return b, a

    def bandwidth(self) -> float:
        """The first frequency where |H| falls through 1/√2 (−3.01 dB), Hz; inf for the flat sensor.

        :func:`second_order_bandwidth` in closed form; for the two resonances the first downward crossing on
        a grid of 1/2000 of the lower resonance, refined by Brent's method to 1e-12 relative.
        """
        if self.model == "flat":
            return math.inf
        if self.model == "second_order":
            return second_order_bandwidth(self.natural_frequency, self.damping)
        level = 1.0 / math.sqrt(2.0)
        step = min(self.natural_frequency, self.drive_frequency) / 2000.0
        grid = np.arange(1, 200001) * step  # up to 100 × the lower resonance: |H| < 1e-4 there
        below = np.flatnonzero(np.abs(self.response(grid)) <= level)
        k = int(below[0])
        lo, hi = (grid[k - 1] if k > 0 else 0.0), grid[k]
        import scipy.optimize

        return float(scipy.optimize.brentq(lambda f: abs(self.response(f)) - level, lo, hi, xtol=1e-300,
                                           rtol=1e-12))


def half_sine(peak: float, duration: float, sample_rate: float, samples: int) -> np.ndarray:
    """A half-sine shock pulse sampled from its start: a(t_k) = peak · sin(π t_k / duration) for
    0 <= t_k < duration, 0 after; t_k = k / sample_rate, k = 0 … samples − 1.

    The half-sine is the classical shock waveform of the shock-test standards (IEC 60068-2-27, GJB 150.18,
    MIL-STD-810 method 516): a peak and a duration (e.g. 50 g, 11 ms). Its mean over the pulse is 2·peak/π and
    its velocity change 2·peak·duration/π.

    Parameters
    ----------
    peak : float
        Peak acceleration, m/s² (any sign; 0: no pulse).
    duration : float
        s, > 0.
    sample_rate : float
        Hz, > 0.
    samples : int
        Samples to return (>= 0).
    """
    peak = one_number("peak", peak, "m/s^2")
    duration = positive_number("duration", duration, "s")
    sample_rate = positive_number("sample_rate", sample_rate, "Hz")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 0:
        raise ValueError(f"samples: expected an integer >= 0, got {samples!r}")
    t = np.arange(int(samples)) / sample_rate
    return np.where(t < duration, peak * np.sin(np.pi * np.minimum(t, duration) / duration), 0.0)
