"""Analytic frequency responses of a sensor: the second-order low-pass and its −3 dB bandwidth.

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

Nothing here is simulated yet: these are the truth the estimators of :mod:`plansim.estimate.dynamic`
are tested against.
"""

from __future__ import annotations

import math

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


def second_order_bandwidth(natural_frequency: float, damping: float) -> float:
    """The frequency where |H| = 1/√2 (−3.01 dB): f_n·√(1 − 2ζ² + √((1 − 2ζ²)² + 1)), Hz.

    From |H|⁻² = (1 − x²)² + 4ζ²x² = 2, a quadratic in x² with one positive root. It is the only
    frequency where |H| = 1/√2 on the way down (for ζ < 1/√2 the response first rises above 1 at the
    resonance), so it is the bandwidth of JJF 1535-2015 3.7. ζ = 1/√2 gives f_n.
    """
    f_n = positive_number("natural_frequency", natural_frequency)
    b = 1.0 - 2.0 * positive_number("damping", damping) ** 2
    return f_n * math.sqrt(b + math.sqrt(b * b + 1.0))
