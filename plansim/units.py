"""Units at the edges: parse ``"0.15 deg/sqrt(h)"`` into SI floats, and back for display.

Everything inside plansim is SI (rad, s, m, m/s², rad/s, °C for temperature). Users write
quantities in a scenario file as strings ``"<number> <unit>"``; each field declares its *kind*
and only the units of that kind are accepted, so a wrong unit is an error that names the field,
the value and the units allowed, never a silently wrong number.

A hand-written table keeps this transparent and dependency-free: the set of units an inertial
calibration uses is small and fixed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

STANDARD_GRAVITY = 9.80665  # m/s², CGPM 1901 conventional value
DEG = math.pi / 180.0
ARCSEC = DEG / 3600.0
HOUR = 3600.0
MICRO_G = 1e-6 * STANDARD_GRAVITY
MILLI_G = 1e-3 * STANDARD_GRAVITY

#: unit tables per quantity kind: unit string -> factor to SI
KINDS: dict[str, dict[str, float]] = {
    "dimensionless": {"1": 1.0, "": 1.0, "ppm": 1e-6, "%": 1e-2},
    "angle": {"rad": 1.0, "deg": DEG, "arcmin": DEG / 60.0, "arcsec": ARCSEC},
    "angular_rate": {"rad/s": 1.0, "deg/s": DEG, "deg/h": DEG / HOUR},
    "acceleration": {"m/s^2": 1.0, "g": STANDARD_GRAVITY, "mg": MILLI_G, "ug": MICRO_G},
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": HOUR},
    "frequency": {"Hz": 1.0, "kHz": 1e3},
    "length": {"m": 1.0, "cm": 1e-2, "mm": 1e-3},
    "temperature": {"degC": 1.0},
    # G: gyro output per specific force, SI rad/s per m/s^2
    "rate_per_acceleration": {
        "rad/s/(m/s^2)": 1.0,
        "deg/s/g": DEG / STANDARD_GRAVITY,
        "deg/h/g": DEG / HOUR / STANDARD_GRAVITY,
    },
    # g² sensitivity, rad/s per (m/s^2)^2
    "rate_per_acceleration_squared": {
        "rad/s/(m/s^2)^2": 1.0,
        "deg/s/g^2": DEG / STANDARD_GRAVITY**2,
        "deg/h/g^2": DEG / HOUR / STANDARD_GRAVITY**2,
    },
    # P: accelerometer output per squared rate, m/s^2 per (rad/s)^2 = m/rad^2
    "acceleration_per_rate_squared": {
        "(m/s^2)/(rad/s)^2": 1.0,
        "g/(rad/s)^2": STANDARD_GRAVITY,
        "mg/(rad/s)^2": MILLI_G,
        "ug/(rad/s)^2": MICRO_G,
    },
    # one-sided acceleration power spectral density, (m/s^2)^2/Hz (random vibration, docs/dynamic.md)
    "acceleration_psd": {"(m/s^2)^2/Hz": 1.0, "g^2/Hz": STANDARD_GRAVITY**2},
    # g³ sensitivity, rad/s per (m/s^2)^3
    "rate_per_acceleration_cubed": {
        "rad/s/(m/s^2)^3": 1.0,
        "deg/h/g^3": DEG / HOUR / STANDARD_GRAVITY**3,
    },
    # accelerometer K2: output per squared input, 1/(m/s^2)
    "per_acceleration": {"1/(m/s^2)": 1.0, "ug/g^2": 1e-6 / STANDARD_GRAVITY, "1/g": 1.0 / STANDARD_GRAVITY},
    # gyro nonlinearity coefficients: quadratic 1/(rad/s), cubic 1/(rad/s)^2
    "per_rate": {"1/(rad/s)": 1.0, "1/(deg/s)": 1.0 / DEG, "ppm/(deg/s)": 1e-6 / DEG},
    "per_rate_squared": {"1/(rad/s)^2": 1.0, "1/(deg/s)^2": 1.0 / DEG**2, "ppm/(deg/s)^2": 1e-6 / DEG**2},
    # IEEE Std 952 Allan-variance coefficients
    "angle_random_walk": {"rad/sqrt(s)": 1.0, "deg/sqrt(h)": DEG / 60.0, "deg/s/sqrt(Hz)": DEG,
                          "deg/h/sqrt(Hz)": DEG / HOUR},
    "velocity_random_walk": {"m/s/sqrt(s)": 1.0, "m/s/sqrt(h)": 1.0 / 60.0, "ug/sqrt(Hz)": MICRO_G,
                             "m/s^2/sqrt(Hz)": 1.0},
    "rate_random_walk": {"rad/s/sqrt(s)": 1.0, "deg/h/sqrt(h)": DEG / HOUR / 60.0, "deg/s/sqrt(s)": DEG},
    "acceleration_random_walk": {"m/s^2/sqrt(s)": 1.0, "ug/sqrt(s)": MICRO_G, "m/s/sqrt(h)/h": 1.0 / 60.0 / HOUR},
    "per_temperature": {"1/degC": 1.0, "ppm/degC": 1e-6},
    "angular_rate_per_temperature": {"rad/s/degC": 1.0, "deg/h/degC": DEG / HOUR, "deg/s/degC": DEG},
    "acceleration_per_temperature": {"m/s^2/degC": 1.0, "mg/degC": MILLI_G, "ug/degC": MICRO_G},
}


def allowed_units(kind: str) -> str:
    """Comma-separated list of the units accepted for *kind* (for error messages)."""
    return ", ".join(repr(u) for u in KINDS[kind] if u)


def parse_quantity(value: object, kind: str, field: str) -> float:
    """Return the SI value of a scalar quantity.

    Parameters
    ----------
    value : str or int or float
        ``"<number> <unit>"``; a bare number is accepted only for dimensionless kinds.
    kind : str
        Key of :data:`KINDS`.
    field : str
        Dotted scenario path, used in error messages.

    Raises
    ------
    TypeError
        If *value* is neither a number nor a string.
    ValueError
        Unknown unit for this kind, unparsable number, or NaN/inf.
    """
    table = KINDS[kind]
    if isinstance(value, bool):
        raise TypeError(f"{field}: expected a quantity like '1.0 {next(iter(table))}', got the boolean {value!r}")
    if isinstance(value, (int, float)):
        if kind != "dimensionless":
            raise ValueError(
                f"{field} = {value!r}: a unit is required; write it as '<number> <unit>' "
                f"with one of {allowed_units(kind)}"
            )
        number, unit = float(value), ""
    elif isinstance(value, str):
        text = value.strip()
        head, _, tail = text.partition(" ")
        try:
            number = float(head)
        except ValueError:
            raise ValueError(
                f"{field} = {value!r}: expected '<number> <unit>' with one of {allowed_units(kind)}"
            ) from None
        unit = tail.strip()
    else:
        raise TypeError(f"{field} = {value!r}: expected a string '<number> <unit>', got {type(value).__name__}")
    if unit not in table:
        raise ValueError(f"{field} = {value!r}: unit {unit!r} is not a unit of {kind}; allowed: {allowed_units(kind)}")
    if not math.isfinite(number):
        raise ValueError(f"{field} = {value!r}: the number must be finite (not NaN or infinity)")
    return number * table[unit]


def parse_vector(value: object, kind: str, field: str, length: int = 3) -> np.ndarray:
    """A per-axis quantity: one string for all axes, or a list of *length* strings."""
    if isinstance(value, (list, tuple)):
        if len(value) != length:
            raise ValueError(f"{field}: expected {length} values (x, y, z), got {len(value)}")
        return np.array([parse_quantity(v, kind, f"{field}[{i}]") for i, v in enumerate(value)])
    return np.full(length, parse_quantity(value, kind, field))


def parse_matrix(value: object, kind: str, field: str) -> np.ndarray:
    """A 3×3 quantity given as a list of three rows of three strings."""
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise ValueError(f"{field}: expected 3 rows of 3 quantities, got {value!r}")
    return np.array([parse_vector(row, kind, f"{field}[{i}]") for i, row in enumerate(value)])


def format_quantity(si_value: float, kind: str, unit: str) -> str:
    """Inverse of :func:`parse_quantity`: ``"<number> <unit>"`` for a scenario file."""
    number = si_value / KINDS[kind][unit]
    text = f"{number:.12g}"
    return f"{text} {unit}" if unit else text


def to_unit(si_values: float | np.ndarray | Sequence[float], kind: str, unit: str):
    """Convert SI values to *unit* (of *kind*) for display."""
    return np.asarray(si_values) / KINDS[kind][unit]
