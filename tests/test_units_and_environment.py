"""Units at the edges (plansim.units) and the laboratory (plansim.model.environment).

Expected SI values are written from first principles (π/180 per degree, 3600 s per hour,
√3600 = 60 √s per √h, 1 g = 9.80665 m/s²), not from the library's own tables.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plansim.config import Environment
from plansim.model.environment import EARTH_RATE, earth_rate_enu, normal_gravity
from plansim.units import (
    KINDS,
    STANDARD_GRAVITY,
    allowed_units,
    format_quantity,
    parse_matrix,
    parse_quantity,
    parse_vector,
    to_unit,
)

PI = math.pi
G0 = 9.80665  # m/s², standard gravity (3rd CGPM, 1901)

# (kind, text, SI value worked out by hand)
CONVERSIONS = [
    ("dimensionless", "0.5", 0.5),
    ("dimensionless", "250 ppm", 250e-6),
    ("dimensionless", "0.05 %", 5e-4),
    ("dimensionless", "2 1", 2.0),
    ("angle", "1 rad", 1.0),
    ("angle", "90 deg", PI / 2),
    ("angle", "30 arcmin", 0.5 * PI / 180),
    ("angle", "10 arcsec", 10 * PI / 180 / 3600),
    ("angular_rate", "15 deg/h", 15 * PI / 180 / 3600),
    ("angular_rate", "100 deg/s", 100 * PI / 180),
    ("angular_rate", "-2 rad/s", -2.0),
    ("acceleration", "1 g", G0),
    ("acceleration", "3 mg", 3e-3 * G0),
    ("acceleration", "50 ug", 50e-6 * G0),
    ("acceleration", "9.8 m/s^2", 9.8),
    ("time", "30 s", 30.0),
    ("time", "11 ms", 0.011),
    ("time", "2 min", 120.0),
    ("time", "1.5 h", 5400.0),
    ("frequency", "100 Hz", 100.0),
    ("frequency", "2 kHz", 2000.0),
    ("length", "5 mm", 5e-3),
    ("length", "3 cm", 3e-2),
    ("length", "50 m", 50.0),
    ("temperature", "25 degC", 25.0),
    # G: (°/h)/g = (π/180/3600 rad/s)/(9.80665 m/s²)
    ("rate_per_acceleration", "18 deg/h/g", 18 * PI / 180 / 3600 / G0),
    ("rate_per_acceleration", "0.01 deg/s/g", 0.01 * PI / 180 / G0),
    ("rate_per_acceleration", "1e-5 rad/s/(m/s^2)", 1e-5),
    ("rate_per_acceleration_squared", "2 deg/h/g^2", 2 * PI / 180 / 3600 / G0**2),
    ("rate_per_acceleration_squared", "1 deg/s/g^2", PI / 180 / G0**2),
    ("rate_per_acceleration_squared", "3 rad/s/(m/s^2)^2", 3.0),
    ("acceleration_psd", "0.04 g^2/Hz", 0.04 * G0**2),
    ("acceleration_psd", "2 (m/s^2)^2/Hz", 2.0),
    ("rate_per_acceleration_cubed", "0.01 deg/h/g^3", 0.01 * PI / 180 / 3600 / G0**3),
    ("rate_per_acceleration_cubed", "3 rad/s/(m/s^2)^3", 3.0),
    # P: µg/(rad/s)² = 1e-6·9.80665 m/s² per (rad/s)²
    ("acceleration_per_rate_squared", "40 ug/(rad/s)^2", 40e-6 * G0),
    ("acceleration_per_rate_squared", "2 mg/(rad/s)^2", 2e-3 * G0),
    ("acceleration_per_rate_squared", "0.5 g/(rad/s)^2", 0.5 * G0),
    ("acceleration_per_rate_squared", "1e-4 (m/s^2)/(rad/s)^2", 1e-4),
    # K2: a' [µg] = K2 [µg/g²] · a² [g²]  ->  a'[m/s²] = K2·1e-6·g0 · (a[m/s²]/g0)² = (K2·1e-6/g0)·a²
    ("per_acceleration", "20 ug/g^2", 20e-6 / G0),
    ("per_acceleration", "0.001 1/g", 1e-3 / G0),
    ("per_acceleration", "2e-5 1/(m/s^2)", 2e-5),
    ("per_rate", "100 ppm/(deg/s)", 100e-6 / (PI / 180)),
    ("per_rate", "1e-4 1/(deg/s)", 1e-4 / (PI / 180)),
    ("per_rate", "2e-3 1/(rad/s)", 2e-3),
    ("per_rate_squared", "1 ppm/(deg/s)^2", 1e-6 / (PI / 180) ** 2),
    ("per_rate_squared", "1e-7 1/(deg/s)^2", 1e-7 / (PI / 180) ** 2),
    ("per_rate_squared", "4e-6 1/(rad/s)^2", 4e-6),
    # ARW: °/√h = (π/180 rad)/(√3600 √s) = π/180/60 rad/√s
    ("angle_random_walk", "0.15 deg/sqrt(h)", 0.15 * PI / 180 / 60),
    ("angle_random_walk", "0.01 deg/s/sqrt(Hz)", 0.01 * PI / 180),
    ("angle_random_walk", "9 deg/h/sqrt(Hz)", 9 * PI / 180 / 3600),
    ("angle_random_walk", "1e-4 rad/sqrt(s)", 1e-4),
    # VRW: (m/s)/√h = (m/s)/(60 √s)
    ("velocity_random_walk", "0.06 m/s/sqrt(h)", 0.06 / 60),
    ("velocity_random_walk", "100 ug/sqrt(Hz)", 100e-6 * G0),
    ("velocity_random_walk", "1e-3 m/s^2/sqrt(Hz)", 1e-3),
    ("velocity_random_walk", "2e-4 m/s/sqrt(s)", 2e-4),
    # RRW: (°/h)/√h = π/180/3600 rad/s per 60 √s
    ("rate_random_walk", "3 deg/h/sqrt(h)", 3 * PI / 180 / 3600 / 60),
    ("rate_random_walk", "1e-4 deg/s/sqrt(s)", 1e-4 * PI / 180),
    ("rate_random_walk", "3e-7 rad/s/sqrt(s)", 3e-7),
    ("acceleration_random_walk", "5 ug/sqrt(s)", 5e-6 * G0),
    ("acceleration_random_walk", "0.36 m/s/sqrt(h)/h", 0.36 / 60 / 3600),
    ("acceleration_random_walk", "1e-5 m/s^2/sqrt(s)", 1e-5),
    ("per_temperature", "50 ppm/degC", 50e-6),
    ("per_temperature", "1e-4 1/degC", 1e-4),
    ("angular_rate_per_temperature", "0.5 deg/h/degC", 0.5 * PI / 180 / 3600),
    ("angular_rate_per_temperature", "1e-3 deg/s/degC", 1e-3 * PI / 180),
    ("angular_rate_per_temperature", "2e-6 rad/s/degC", 2e-6),
    ("acceleration_per_temperature", "10 ug/degC", 10e-6 * G0),
    ("acceleration_per_temperature", "0.1 mg/degC", 0.1e-3 * G0),
    ("acceleration_per_temperature", "3e-4 m/s^2/degC", 3e-4),
]


@pytest.mark.parametrize("kind, text, expected", CONVERSIONS, ids=[f"{k}:{t}" for k, t, _ in CONVERSIONS])
def test_parse_quantity_known_conversion(kind, text, expected):
    assert parse_quantity(text, kind, "field") == pytest.approx(expected, rel=1e-14, abs=0)


def test_every_kind_and_unit_is_covered_by_a_hand_worked_conversion():
    covered = {(kind, text.partition(" ")[2].strip()) for kind, text, _ in CONVERSIONS}
    for kind, table in KINDS.items():
        for unit in table:
            if unit == "":  # the bare number, covered by "0.5"
                continue
            assert (kind, unit) in covered, f"no hand-worked conversion for {unit!r} ({kind})"


def test_standard_gravity_is_the_cgpm_value():
    assert STANDARD_GRAVITY == 9.80665
    assert parse_quantity("1 g", "acceleration", "f") == 9.80665


def test_parse_quantity_accepts_numbers_only_for_dimensionless():
    assert parse_quantity(1.0021, "dimensionless", "mimu.truth.Kgxx") == 1.0021
    assert parse_quantity(3, "dimensionless", "f") == 3.0
    with pytest.raises(ValueError, match=r"mimu\.truth\.Bgx = 0\.1: a unit is required.*'rad/s', 'deg/s', 'deg/h'"):
        parse_quantity(0.1, "angular_rate", "mimu.truth.Bgx")


def test_parse_quantity_tolerates_extra_spaces():
    assert parse_quantity("  15   deg/h ", "angular_rate", "f") == pytest.approx(15 * PI / 180 / 3600, rel=1e-15)


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_unknown_unit_names_field_and_allowed_list(kind):
    listed = ", ".join(repr(u) for u in KINDS[kind] if u)
    with pytest.raises(ValueError) as info:
        parse_quantity("1 furlong/fortnight", kind, "some.field")
    message = str(info.value)
    assert message.startswith("some.field = '1 furlong/fortnight'")
    assert f"is not a unit of {kind}; allowed: {listed}" in message
    assert allowed_units(kind) == listed


def test_unknown_unit_message_for_angular_rate_is_explicit():
    allowed = r"allowed: 'rad/s', 'deg/s', 'deg/h'$"
    with pytest.raises(ValueError, match=r"unit 'rpm' is not a unit of angular_rate; " + allowed):
        parse_quantity("10 rpm", "angular_rate", "schedule.omega_squared_rate")


@pytest.mark.parametrize("value", ["nan deg", "NaN deg", "inf deg", "-inf deg", math.nan, math.inf])
def test_non_finite_numbers_are_rejected(value):
    kind = "angle" if isinstance(value, str) else "dimensionless"
    with pytest.raises(ValueError, match=r"environment\.latitude = .*must be finite"):
        parse_quantity(value, kind, "environment.latitude")


@pytest.mark.parametrize("value, error, match", [
    (True, TypeError, r"f: expected a quantity like .*boolean True"),
    (None, TypeError, r"f = None: expected a string '<number> <unit>', got NoneType"),
    (["1 deg"], TypeError, r"f = \['1 deg'\]: expected a string"),
    ("deg", ValueError, r"f = 'deg': expected '<number> <unit>'"),
    ("", ValueError, r"f = '': expected '<number> <unit>'"),
    ("1deg", ValueError, r"f = '1deg': expected '<number> <unit>'"),
])
def test_malformed_quantities(value, error, match):
    with pytest.raises(error, match=match):
        parse_quantity(value, "angle", "f")


def test_parse_vector_and_matrix():
    np.testing.assert_allclose(parse_vector("2 mg", "acceleration", "f"), [2e-3 * G0] * 3, rtol=1e-15)
    np.testing.assert_allclose(parse_vector(["1 deg", "2 deg", "-3 deg"], "angle", "f"),
                               np.array([1, 2, -3]) * PI / 180, rtol=1e-15)
    with pytest.raises(ValueError, match=r"f\[1\] = '2 m'"):
        parse_vector(["1 deg", "2 m", "3 deg"], "angle", "f")
    with pytest.raises(ValueError, match=r"f: expected 3 values \(x, y, z\), got 2"):
        parse_vector(["1 deg", "2 deg"], "angle", "f")
    m = parse_matrix([["1 mm", "0 mm", "0 mm"], ["0 mm", "2 cm", "0 mm"], ["0 mm", "0 mm", "3 m"]], "length", "arm")
    np.testing.assert_allclose(m, np.diag([1e-3, 2e-2, 3.0]), rtol=1e-15)
    with pytest.raises(ValueError, match=r"arm\[2\]\[0\] = '1 s'"):
        parse_matrix([["0 m"] * 3, ["0 m"] * 3, ["1 s", "0 m", "0 m"]], "length", "arm")
    with pytest.raises(ValueError, match=r"arm: expected 3 rows of 3 quantities"):
        parse_matrix([["0 m"] * 3], "length", "arm")


@pytest.mark.parametrize("kind, text, expected", CONVERSIONS, ids=[f"{k}:{t}" for k, t, _ in CONVERSIONS])
def test_format_quantity_inverts_parse_quantity(kind, text, expected):
    unit = text.partition(" ")[2].strip()
    formatted = format_quantity(expected, kind, unit)
    assert parse_quantity(formatted, kind, "f") == pytest.approx(expected, rel=1e-11)
    assert to_unit(expected, kind, unit) == pytest.approx(float(text.split()[0]), rel=1e-14)


# ----------------------------------------------------------------------------- normal gravity (WGS 84)

# NIMA TR8350.2 (3rd ed., amendment 1, 2000), Table 3.4 and eq. (4-1): WGS 84 normal gravity
GAMMA_EQUATOR = 9.7803253359  # m/s²
GAMMA_POLE = 9.8321849378  # m/s²
K_SOMIGLIANA = 0.00193185265241
E2 = 0.00669437999013
FREE_AIR_GRADIENT = 0.3086e-5  # m/s² per m (0.3086 mGal/m), decrease with height


def somigliana(latitude, gamma_e=GAMMA_EQUATOR, k=K_SOMIGLIANA, e2=E2):
    s2 = math.sin(latitude) ** 2
    return gamma_e * (1 + k * s2) / math.sqrt(1 - e2 * s2)


def test_normal_gravity_at_the_equator_is_the_published_value():
    assert normal_gravity(0.0) == GAMMA_EQUATOR  # sin 0 = 0: the constant itself


def test_normal_gravity_at_the_poles_is_the_published_value():
    # γe(1 + k)/√(1 − e²) = 9.83218493786 with the published k and e²; TR8350.2 prints 9.8321849378.
    # The published constants are themselves rounded, so agreement is to one unit in the last
    # published digit (1e-10 m/s²), not to half a unit.
    for latitude in (PI / 2, -PI / 2):
        assert abs(normal_gravity(latitude) - GAMMA_POLE) < 1e-10
    assert round(normal_gravity(PI / 2), 9) == round(GAMMA_POLE, 9)


@pytest.mark.parametrize("latitude_deg", [0.0, 15.0, 30.0, 39.9, 45.0, 60.0, 75.0, 90.0, -39.9])
def test_normal_gravity_is_somigliana(latitude_deg):
    latitude = math.radians(latitude_deg)
    assert normal_gravity(latitude) == pytest.approx(somigliana(latitude), rel=1e-15)


def test_normal_gravity_at_45_degrees():
    # WGS 84 (γe = 9.7803253359): γ(45°) = 9.7803253359·(1 + k/2)/√(1 − e²/2) = 9.8061977694 m/s²
    g45 = normal_gravity(PI / 4)
    assert g45 == pytest.approx(somigliana(PI / 4), rel=1e-15)
    assert round(g45, 7) == 9.8061978
    # the often-quoted 9.806199 m/s² is the GRS 80 / pre-2000 WGS 84 value (γe = 9.7803267714,
    # k = 0.00193185138639); the two differ by 1.4e-6 m/s², the change of γe
    old = somigliana(PI / 4, gamma_e=9.7803267714, k=0.00193185138639)
    assert round(old, 6) == 9.806199
    assert g45 == pytest.approx(9.806199, abs=1.5e-6)


@pytest.mark.parametrize("height", [-100.0, 0.0, 50.0, 1000.0, 2000.0])
def test_free_air_gradient(height):
    # normal gravity decreases by 0.3086 mGal per metre: 1000 m -> −3.086e-3 m/s²
    latitude = math.radians(39.9)
    assert normal_gravity(latitude, height) - normal_gravity(latitude) == pytest.approx(
        -FREE_AIR_GRADIENT * height, rel=1e-9, abs=1e-15)


def test_environment_gravity_and_earth_rate_switch():
    env = Environment(latitude=math.radians(39.9), height=50.0, earth_rate=True)
    assert env.gravity == normal_gravity(math.radians(39.9), 50.0)
    np.testing.assert_array_equal(env.earth_rate_vector, earth_rate_enu(math.radians(39.9)))
    off = Environment(latitude=math.radians(39.9), height=50.0, earth_rate=False)
    np.testing.assert_array_equal(off.earth_rate_vector, np.zeros(3))


# ----------------------------------------------------------------------------- Earth rate


def test_earth_rate_is_the_wgs84_constant():
    assert EARTH_RATE == 7.292115e-5  # rad/s, WGS 84 defining constant ω = 7 292 115 × 10⁻¹¹ rad/s


def test_earth_rate_in_degrees_per_hour():
    # 7.292115e-5 rad/s × (180/π) °/rad × 3600 s/h = 15.0410669 °/h
    per_hour = EARTH_RATE * 180 / PI * 3600
    assert round(per_hour, 6) == 15.041067
    assert round(per_hour, 5) == 15.04107  # the textbook chapter's 15.04107 °/h (docs/specification.md)
    assert parse_quantity("15.041067 deg/h", "angular_rate", "f") == pytest.approx(EARTH_RATE, rel=1e-7)


def test_earth_rate_period_is_a_sidereal_day_not_the_textbook_value():
    # 2π/ω = 86 164.10 s = 23 h 56 min 4.10 s: one (stellar) sidereal day, 23 h 56 min 4.09 s to
    # within 0.01 s. ω is a defining constant, truncated to 7 digits (half a unit in its last digit
    # is 0.5e-11/7.292115e-5 ≈ 7e-8 relative, about 0.006 s of the day).
    period = 2 * PI / EARTH_RATE
    assert round(period, 2) == 86164.10
    assert abs(period - (23 * 3600 + 56 * 60 + 4.09)) < 0.02
    # the textbook chapter's "23 h 59 min 57.33 s" = 86 397.33 s (its §6.2) would give
    # 360° × 3600/86 397.33 = 15.0005 °/h, not 15.04107 °/h
    textbook = 360.0 / ((23 * 3600 + 59 * 60 + 57.33) / 3600)
    assert round(textbook, 4) == 15.0005
    assert abs(textbook - EARTH_RATE * 180 / PI * 3600) > 0.04


@pytest.mark.parametrize("latitude_deg", [0.0, 30.0, 39.9, 45.0, 90.0, -30.0])
def test_earth_rate_enu_components(latitude_deg):
    # ENU: Ω·[0, cos φ, sin φ]; east component zero, north positive, up has the sign of φ
    phi = math.radians(latitude_deg)
    w = earth_rate_enu(phi)
    np.testing.assert_allclose(w, [0.0, EARTH_RATE * math.cos(phi), EARTH_RATE * math.sin(phi)], rtol=1e-15, atol=1e-22)
    assert np.linalg.norm(w) == pytest.approx(EARTH_RATE, rel=1e-15)


def test_earth_rate_enu_at_30_degrees_by_hand():
    # φ = 30°: cos = √3/2, sin = 1/2 -> north 15.0410669·0.8660254 = 13.025946 °/h,
    #                                   up    15.0410669·0.5       =  7.520533 °/h
    w = earth_rate_enu(PI / 6) * 180 / PI * 3600  # °/h
    assert w[0] == 0.0
    assert w[1] == pytest.approx(13.025946, abs=1e-6)
    assert w[2] == pytest.approx(7.520533, abs=1e-6)


def test_the_stored_gauss_markov_allan_peak_is_the_computed_one():
    """GM_ALLAN_PEAK (the σ of the bias-instability stand-in depends on it) is written down to spare
    every run the import of scipy.optimize; recomputed here, it must agree to the last digits."""
    from plansim.simulate.arguments import GM_ALLAN_PEAK, gauss_markov_allan_peak

    assert GM_ALLAN_PEAK == pytest.approx(gauss_markov_allan_peak(), rel=1e-12)
    assert GM_ALLAN_PEAK == pytest.approx(0.6174, abs=5e-5)  # the value docs/model.md quotes
