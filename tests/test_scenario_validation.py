"""Strict scenario parsing: bad input raises a ValueError/TypeError that names the offending field.

Documents are built by loading scenarios/ideal.toml with tomllib (fixture ``ideal_document``) and
modifying one thing; :func:`plansim.config.parse_scenario` must then refuse it with a message
that names the field (checked with ``pytest.raises(..., match=...)``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from plansim.config import parse_scenario
from plansim.io.scenario_file import load_scenario, save_scenario
from plansim.model.environment import normal_gravity
from plansim.units import DEG, STANDARD_GRAVITY


def test_ideal_document_parses(ideal_document):
    scenario = parse_scenario(ideal_document)
    assert scenario.name == "ideal"
    assert scenario.trials == 20 and scenario.seed == 1
    assert scenario.environment.latitude == pytest.approx(math.radians(39.9), rel=1e-15)
    assert scenario.schedule.procedure == "jjf2003"
    # 12 positions + 3 axes × 9 rate points + 3 × (rest, rotating)
    assert len(scenario.schedule) == 12 + 27 + 6
    assert scenario.reduction.reference_gravity == pytest.approx(normal_gravity(math.radians(39.9), 50.0), rel=1e-15)


# ----------------------------------------------------------------------------- a custom schedule, by hand


def custom_segments(rates_deg=(-50.0, 0.0, 50.0), ups=("+x", "-x", "+y", "-y", "+z", "-z"), dwell="30 s"):
    """A minimal complete custom schedule as TOML tables: 6 positions, a rate test, the ω² test."""
    segments = [{"label": f"position {up} up", "test": "multi_position", "group": g, "up": up, "dwell": dwell}
                for g, up in zip(range(1, 7), ("+x", "-x", "+y", "-y", "+z", "-z")) if up in ups]
    for i, axis in enumerate("xyz"):
        for r in rates_deg:
            segments.append({"label": f"rate {axis} {r} deg/s", "test": "rate", "group": i, "up": f"+{axis}",
                             "rate": f"{r} deg/s", "rate_axis": f"+{axis}", "dwell": dwell})
    for i, axis in enumerate("xyz"):
        segments.append({"label": f"omega2 {axis} rest", "test": "omega_squared", "group": i, "up": f"+{axis}",
                         "rate": "0 deg/s", "rate_axis": f"+{axis}", "dwell": dwell})
        segments.append({"label": f"omega2 {axis} turning", "test": "omega_squared", "group": i, "up": f"+{axis}",
                         "rate": "100 deg/s", "rate_axis": f"+{axis}", "dwell": dwell})
    return segments


def with_custom_schedule(document, segments):
    document["schedule"] = {"procedure": "custom", "segments": segments}
    return document


def test_hand_written_custom_schedule_parses(ideal_document):
    scenario = parse_scenario(with_custom_schedule(ideal_document, custom_segments()))
    assert scenario.schedule.procedure == "custom"
    assert len(scenario.schedule) == 6 + 9 + 6
    turning = scenario.schedule.segments[-1]
    assert turning.rate == pytest.approx(100 * DEG, rel=1e-15) and turning.rate_axis == "+z"


# ----------------------------------------------------------------------------- bad input


def _set(path, value):
    """A modifier that sets document[a][b]…[z] = value (creating tables on the way)."""
    keys = path.split(".")

    def modify(document):
        node = document
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        node[keys[-1]] = value
        return document

    return modify


def _delete(path):
    keys = path.split(".")

    def modify(document):
        node = document
        for key in keys[:-1]:
            node = node[key]
        del node[keys[-1]]
        return document

    return modify


def _custom(**kwargs):
    def modify(document):
        return with_custom_schedule(document, custom_segments(**kwargs))

    return modify


def _custom_segment(index, key, value):
    def modify(document):
        segments = custom_segments()
        segments[index][key] = value
        return with_custom_schedule(document, segments)

    return modify


BAD_INPUT = [
    # unknown keys
    ("unknown top-level key", _set("montecarlo", {"trials": 10}), ValueError, r"unknown .*'montecarlo'"),
    ("unknown top-level scalar", _set("seed", 3), ValueError, r"unknown .*'seed'"),
    ("unknown key in [environment]", _set("environment.lattitude", "40 deg"), ValueError,
     r"\[environment\] has unknown key\(s\) 'lattitude'"),
    ("unknown key in [schedule]", _set("schedule.dwel", "30 s"), ValueError,
     r"\[schedule\] has unknown key\(s\) 'dwel'"),
    ("unknown key in [reduction]", _set("reduction.sign", "model"), ValueError,
     r"\[reduction\] has unknown key\(s\) 'sign'"),
    ("unknown key in [mimu.noise]", _set("mimu.noise.gyro_arw", "0.1 deg/sqrt(h)"), ValueError,
     r"\[mimu\.noise\] has unknown key\(s\) 'gyro_arw'"),
    ("unknown sub-table of [mimu]", _set("mimu.truths", {}), ValueError, r"\[mimu\] has unknown key\(s\) 'truths'"),
    ("unknown key in a custom segment", _custom_segment(0, "dwel", "30 s"), ValueError,
     r"schedule\.segments\[0\]\] has unknown key\(s\) 'dwel'"),
    # unknown parameter names
    ("unknown parameter in [mimu.truth]", _set("mimu.truth.Kgxq", 1.0), ValueError,
     r"\[mimu\.truth\] has unknown parameter\(s\) 'Kgxq'"),
    ("P has a zero diagonal: pxx is no parameter", _set("mimu.truth.pxx", "1 ug/(rad/s)^2"), ValueError,
     r"\[mimu\.truth\] has unknown parameter\(s\) 'pxx'"),
    ("unknown parameter in [mimu.truth_spread]", _set("mimu.truth_spread.bgx", "1 deg/h"), ValueError,
     r"\[mimu\.truth_spread\] has unknown parameter\(s\) 'bgx'"),
    # units
    ("wrong unit for latitude", _set("environment.latitude", "40 m"), ValueError,
     r"environment\.latitude = '40 m': unit 'm' is not a unit of angle; allowed: 'rad', 'deg'"),
    ("wrong unit for a truth parameter", _set("mimu.truth.Bgx", "0.12 m/s^2"), ValueError,
     r"mimu\.truth\.Bgx = '0\.12 m/s\^2': unit 'm/s\^2' is not a unit of angular_rate"),
    ("wrong unit for the rate points", _set("schedule.rate_points", ["-5 deg/s", "5 deg"]), ValueError,
     r"schedule\.rate_points\[1\] = '5 deg': unit 'deg' is not a unit of angular_rate"),
    ("bare number where a unit is needed", _set("environment.latitude", 40), ValueError,
     r"environment\.latitude = 40: a unit is required"),
    ("bare number for a bias", _set("mimu.truth.Bgx", 0.12), ValueError,
     r"mimu\.truth\.Bgx = 0\.12: a unit is required"),
    ("bare number for dwell", _set("schedule.dwell", 30), ValueError, r"schedule\.dwell = 30: a unit is required"),
    ("unit without a number", _set("environment.height", "m"), ValueError,
     r"environment\.height = 'm': expected '<number> <unit>'"),
    ("NaN latitude", _set("environment.latitude", "nan deg"), ValueError, r"environment\.latitude = 'nan deg'.*finite"),
    ("infinite bias", _set("mimu.truth.Bgx", "inf deg/s"), ValueError, r"mimu\.truth\.Bgx = 'inf deg/s'.*finite"),
    ("NaN scale factor", _set("mimu.truth.Kgxx", math.nan), ValueError, r"mimu\.truth\.Kgxx = nan.*finite"),
    ("latitude beyond the pole", _set("environment.latitude", "91 deg"), ValueError, r"environment\.latitude.*90 deg"),
    ("boolean for a quantity", _set("environment.height", True), TypeError, r"environment\.height"),
    # dwell
    ("negative dwell, custom segment", _custom(dwell="-1 s"), ValueError, r"dwell = -1\.0 s; it must be > 0"),
    ("zero dwell, custom segment", _custom(dwell="0 s"), ValueError, r"dwell = 0\.0 s; it must be > 0"),
    ("negative dwell, jjf2003 builder", _set("schedule.dwell", "-30 s"), ValueError,
     r"dwell = -30\.0 s; it must be > 0"),
    ("zero dwell, jjf2003 builder", _set("schedule.dwell", "0 s"), ValueError, r"dwell = 0\.0 s; it must be > 0"),
    ("negative settle, jjf2003 builder", _set("schedule.settle", "-1 s"), ValueError,
     r"settle = -1\.0 s; it must be >= 0"),
    # rate points
    ("one rate point", _set("schedule.rate_points", ["100 deg/s"]), ValueError,
     r"schedule\.rate_points = .*at least 2 distinct rate points"),
    ("two equal rate points", _set("schedule.rate_points", ["5 deg/s", "5 deg/s", "5 deg/s"]), ValueError,
     r"schedule\.rate_points = .*at least 2 distinct rate points"),
    ("rate points not a list", _set("schedule.rate_points", "5 deg/s"), TypeError, r"schedule\.rate_points"),
    ("one rate point, custom schedule", _custom(rates_deg=(20.0, 20.0)), ValueError,
     r"the rate test about x has 1 distinct rate point"),
    # position set
    ("rank-deficient position set (+x, -x, +y only)", _custom(ups=("+x", "-x", "+y")), ValueError,
     r"multi-position groups \[1, 2, 3\] give a rank-3 design matrix A; eq\. \(7\) needs rank 4"),
    ("no multi-position group at all", _custom(ups=()), ValueError, r"rank-0 design matrix A"),
    ("positions neither 6 nor 12", _set("schedule.positions", 8), ValueError,
     r"schedule\.positions = 8; allowed: 6 or 12"),
    ("unknown procedure", _set("schedule.procedure", "jjf1535"), ValueError,
     r"schedule\.procedure = 'jjf1535'; allowed: 'jjf2003', 'custom'"),
    ("custom schedule without segments", _set("schedule", {"procedure": "custom"}), ValueError, r"schedule\.segments"),
    ("omega-squared rate zero", _set("schedule.omega_squared_rate", "0 deg/s"), ValueError,
     r"schedule\.omega_squared_rate = 0\.0 rad/s; it must be > 0"),
    # error distributions
    ("error table with limit and k", _set("turntable.position_accuracy", {"limit": "10 arcsec", "k": 2}), ValueError,
     r"turntable\.position_accuracy = .*give \{limit = \.\.\.\}"),
    ("empty error table", _set("turntable.platform_tilt", {}), ValueError, r"turntable\.platform_tilt = \{\}"),
    ("error table with coverage factor 0", _set("turntable.position_accuracy",
                                                 {"expanded_uncertainty": "20 arcsec", "k": 0}), ValueError,
     r"turntable\.position_accuracy\.k = 0: the coverage factor must be a number > 0"),
    ("error table with a string coverage factor", _set("turntable.position_accuracy",
                                                        {"expanded_uncertainty": "20 arcsec", "k": "2"}), ValueError,
     r"turntable\.position_accuracy\.k = '2'"),
    ("error table with negative uncertainty",
     _set("turntable.axis_perpendicularity", {"standard_uncertainty": "-3 arcsec"}),
     ValueError, r"turntable\.axis_perpendicularity = .*must be >= 0"),
    ("error table with wrong unit", _set("turntable.position_accuracy", {"limit": "10 m"}), ValueError,
     r"turntable\.position_accuracy\.limit = '10 m': unit 'm' is not a unit of angle"),
    ("negative error limit, plain form", _set("turntable.position_repeatability", "-5 arcsec"), ValueError,
     r"turntable\.position_repeatability = .*must be >= 0"),
    # noise
    ("negative noise coefficient", _set("mimu.noise.gyro_angle_random_walk", "-0.1 deg/sqrt(h)"), ValueError,
     r"mimu\.noise\.gyro_angle_random_walk: noise coefficients must be >= 0"),
    ("negative noise coefficient in a per-axis list", _set("mimu.noise.accel_bias_instability",
                                                            ["20 ug", "-20 ug", "20 ug"]), ValueError,
     r"mimu\.noise\.accel_bias_instability: noise coefficients must be >= 0"),
    ("per-axis list of wrong length", _set("mimu.noise.accel_bias_instability", ["20 ug", "20 ug"]), ValueError,
     r"mimu\.noise\.accel_bias_instability: expected 3 values"),
    ("zero correlation time", _set("mimu.noise.markov_correlation_time", "0 s"), ValueError,
     r"mimu\.noise\.markov_correlation_time: must be > 0 s"),
    ("negative truth spread", _set("mimu.truth_spread.Bgx", "-1 deg/h"), ValueError,
     r"mimu\.truth_spread\.Bgx: a standard deviation must be >= 0"),
    # reduction
    ("unknown reference_gravity string", _set("reduction.reference_gravity", "lcoal"), ValueError,
     r"reduction\.reference_gravity = 'lcoal'.*or use 'local' or 'standard'"),
    ("reference_gravity bare number", _set("reduction.reference_gravity", 9.8), ValueError,
     r"reduction\.reference_gravity = 9\.8: a unit is required.*or use 'local' or 'standard'"),
    ("reference_gravity zero", _set("reduction.reference_gravity", "0 m/s^2"), ValueError,
     r"reduction\.reference_gravity = '0 m/s\^2': must be > 0"),
    ("unknown omega_squared_sign", _set("reduction.omega_squared_sign", "printed"), ValueError,
     r"reduction\.omega_squared_sign = 'printed'; allowed: 'model', 'as_printed'"),
    # monte carlo
    ("trials = 0", _set("monte_carlo.trials", 0), ValueError, r"monte_carlo\.trials = 0: must be >= 1"),
    ("trials a float", _set("monte_carlo.trials", 10.0), TypeError,
     r"monte_carlo\.trials = 10\.0: expected a whole number"),
    ("seed a string", _set("monte_carlo.seed", "1"), TypeError, r"monte_carlo\.seed = '1': expected a whole number"),
    ("seed a boolean", _set("monte_carlo.seed", True), TypeError, r"monte_carlo\.seed = True: expected a whole number"),
    ("seed negative", _set("monte_carlo.seed", -1), ValueError, r"monte_carlo\.seed = -1: must be >= 0"),
    # misc
    ("earth_rate not a boolean", _set("environment.earth_rate", "no"), TypeError,
     r"environment\.earth_rate = 'no': expected true or false"),
    ("acquisition bits out of range", _set("acquisition.bits", 64), ValueError, r"acquisition\.bits = 64"),
    ("name not a string", _set("name", 5), TypeError, r"name = 5: expected a string"),
    ("section not a table", _set("environment", "lab"), TypeError, r"\[environment\] must be a table"),
]


@pytest.mark.parametrize("modify, error, match", [case[1:] for case in BAD_INPUT], ids=[case[0] for case in BAD_INPUT])
def test_bad_input_names_the_field(ideal_document, modify, error, match):
    document = modify(ideal_document)
    with pytest.raises(error, match=match):
        parse_scenario(document)


def test_document_must_be_a_table():
    with pytest.raises(TypeError, match="expected a TOML table"):
        parse_scenario(["not", "a", "table"])


def test_load_scenario_of_missing_file_names_it(tmp_path):
    missing = tmp_path / "missing.toml"
    with pytest.raises(ValueError, match="no such file"):
        load_scenario(missing)


def test_load_scenario_of_invalid_toml_names_the_file(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[monte_carlo\ntrials = 3\n")
    with pytest.raises(ValueError, match=r"broken\.toml.*is not valid TOML"):
        load_scenario(path)


# ----------------------------------------------------------------------------- good input, each form


@pytest.mark.parametrize("value, expected", [
    ("local", normal_gravity(math.radians(39.9), 50.0)),
    ("standard", STANDARD_GRAVITY),
    ("9.8 m/s^2", 9.8),
    ("1 g", STANDARD_GRAVITY),
])
def test_reference_gravity_forms(ideal_document, value, expected):
    ideal_document["reduction"]["reference_gravity"] = value
    reduction = parse_scenario(ideal_document).reduction
    assert reduction.reference_gravity == pytest.approx(expected, rel=1e-15)
    assert reduction.reference_gravity_label == value


@pytest.mark.parametrize("table, kind, scale", [
    ("10 arcsec", "uniform", 10 * DEG / 3600),
    ({"limit": "10 arcsec"}, "uniform", 10 * DEG / 3600),
    ({"standard_uncertainty": "4 arcsec"}, "normal", 4 * DEG / 3600),
    ({"expanded_uncertainty": "20 arcsec", "k": 2}, "normal", 10 * DEG / 3600),
])
def test_error_distribution_forms(ideal_document, table, kind, scale):
    ideal_document["turntable"]["position_accuracy"] = table
    error = parse_scenario(ideal_document).turntable.position_accuracy
    assert error.kind == kind
    assert error.scale == pytest.approx(scale, rel=1e-14)
    # GUM 4.3.7: a ± a uniform limit has standard uncertainty a/√3; normal: the scale itself
    expected_u = scale / math.sqrt(3) if kind == "uniform" else scale
    assert error.standard_uncertainty == pytest.approx(expected_u, rel=1e-14)


# ----------------------------------------------------------------------------- round trip


def _assert_round_trip(document, tmp_path, rtol):
    # a name of the user's own: a file whose name key says a built-in's name is named by its stem instead
    # (test_a_saved_builtin_is_named_by_its_file)
    scenario = parse_scenario(document, name="round_trip")
    path = tmp_path / "x.toml"
    save_scenario(scenario, path)
    loaded = load_scenario(path)

    assert loaded.name == scenario.name
    assert len(loaded.schedule) == len(scenario.schedule)
    numbers = ("heading", "rate", "dwell", "settle", "sample_rate", "temperature")
    for a, b in zip(scenario.schedule.segments, loaded.schedule.segments):
        for key in ("label", "test", "group", "up", "rate_axis"):
            assert getattr(a, key) == getattr(b, key), (a.label, key)
        np.testing.assert_allclose([getattr(b, k) for k in numbers], [getattr(a, k) for k in numbers],
                                   rtol=rtol, atol=0, err_msg=a.label)
    np.testing.assert_array_equal(loaded.truth_nominal, scenario.truth_nominal)
    np.testing.assert_array_equal(loaded.truth_spread, scenario.truth_spread)
    assert loaded.reduction == scenario.reduction
    assert loaded.environment == scenario.environment
    assert (loaded.trials, loaded.seed) == (scenario.trials, scenario.seed)

    # saving the loaded scenario again writes the same file
    again = tmp_path / "y.toml"
    save_scenario(loaded, again)
    assert again.read_text() == path.read_text()


ROUND_TRIP_CASES = {
    "ideal": None,
    "6 positions": _set("schedule.positions", 6),
    "hand-written custom": _custom(),
    "rate points on a 12-digit degree grid": _set("schedule.rate_points",
                                                  ["-123.456789 deg/s", "0 deg/s", "0.5 deg/s"]),
}

# Numbers that need more than 12 significant digits: save_scenario writes repr() in SI, so they round-trip
NOT_TWELVE_DIGIT_CASES = {
    "temperature ramp": _set("schedule.temperature_end", "23.7 degC"),
    "rate points in rad/s and deg/h": _set("schedule.rate_points", ["-0.1 rad/s", "7 deg/h", "0.1 rad/s"]),
}


@pytest.mark.parametrize("modify", list(ROUND_TRIP_CASES.values()), ids=list(ROUND_TRIP_CASES))
def test_save_then_load_round_trip(ideal_document, tmp_path, modify):
    _assert_round_trip(modify(ideal_document) if modify else ideal_document, tmp_path, rtol=1e-12)


@pytest.mark.parametrize("modify", list(NOT_TWELVE_DIGIT_CASES.values()), ids=list(NOT_TWELVE_DIGIT_CASES))
def test_round_trip_to_1e_12(ideal_document, tmp_path, modify):
    _assert_round_trip(modify(ideal_document), tmp_path, rtol=1e-12)


def test_a_saved_builtin_is_named_by_its_file(tmp_path):
    scenario = load_scenario("ideal")
    save_scenario(scenario, tmp_path / "x.toml")
    loaded = load_scenario(tmp_path / "x.toml")
    assert loaded.name == "x" and "copied from built-in scenario 'ideal'" in loaded.source
    save_scenario(scenario, tmp_path / "ideal.toml")
    assert load_scenario(tmp_path / "ideal.toml").name == "ideal"


# ----------------------------------------------------------------------------- regressions (bugs found in review)


def test_temperature_start_alone_gives_a_constant_temperature(ideal_document):
    ideal_document["schedule"]["temperature_start"] = "25 degC"
    schedule = parse_scenario(ideal_document).schedule
    np.testing.assert_allclose([s.temperature for s in schedule.segments], 25.0, rtol=1e-15)


def test_negative_output_range_is_rejected(ideal_document):
    ideal_document["mimu"]["gyro_range"] = "-5 deg/s"
    with pytest.raises(ValueError, match=r"mimu\.gyro_range"):
        parse_scenario(ideal_document)


def test_segment_that_is_not_a_table_names_its_index(ideal_document):
    segments = custom_segments()
    segments[2] = "rate x 5 deg/s"
    with_custom_schedule(ideal_document, segments)
    with pytest.raises(TypeError, match=r"schedule\.segments\[2\]"):
        parse_scenario(ideal_document)


# ----------------------------------------------------------------------------- names


SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"


def _copy_builtin(tmp_path, builtin, stem, edit=None):
    text = (SCENARIOS / f"{builtin}.toml").read_text(encoding="utf-8")
    if edit:
        text = edit(text)
    path = tmp_path / f"{stem}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_copied_builtin_reports_the_files_own_name(tmp_path):
    """A new user copies jjf2003.toml to lab.toml and edits it; its `name` key still says "jjf2003".
    The run is of lab.toml: it must not report itself as the built-in (header, NetCDF attrs, plot title)."""
    path = _copy_builtin(tmp_path, "jjf2003", "lab", edit=lambda text: text.replace("trials = 20000", "trials = 50"))
    scenario = load_scenario(path)
    assert scenario.name == "lab"
    assert scenario.trials == 50
    # where it came from stays known
    assert "jjf2003" in scenario.source and "lab.toml" in scenario.source


def test_a_files_own_name_key_is_kept(tmp_path):
    path = _copy_builtin(tmp_path, "ideal", "lab", edit=lambda text: text.replace('name = "ideal"',
                                                                                 'name = "Lab B, unit 7"'))
    scenario = load_scenario(path)
    assert scenario.name == "Lab B, unit 7"
    assert "lab.toml" in scenario.source and "ideal" not in scenario.source


def test_a_file_without_a_name_key_is_named_by_its_stem(tmp_path):
    path = _copy_builtin(tmp_path, "ideal", "bench_7", edit=lambda text: text.replace('name = "ideal"\n', ""))
    assert load_scenario(path).name == "bench_7"


def test_a_builtin_reports_its_name_and_origin():
    scenario = load_scenario("jjf2003")
    assert scenario.name == "jjf2003" and scenario.source == "built-in scenario 'jjf2003'"


def test_parse_scenario_honours_the_name_argument(ideal_document):
    assert ideal_document["name"] == "ideal"
    assert parse_scenario(ideal_document, name="mine").name == "mine"
    assert parse_scenario(ideal_document).name == "ideal"
    del ideal_document["name"]
    assert parse_scenario(ideal_document).name == "unnamed"


def test_parse_scenario_checks_the_name_argument(ideal_document):
    with pytest.raises(TypeError, match=r"name = 5: expected a string"):
        parse_scenario(ideal_document, name=5)
    with pytest.raises(ValueError, match=r"name = '': expected a non-empty name"):
        parse_scenario(ideal_document, name="")


def test_the_run_of_a_copied_builtin_carries_the_files_name(tmp_path, capsys):
    """Header and NetCDF attributes of `plansim run lab.toml` (2 trials of the ideal world)."""
    import xarray as xr

    from plansim.cli import main

    path = _copy_builtin(tmp_path, "ideal", "lab")
    out = tmp_path / "r.nc"
    assert main(["run", str(path), "--trials", "2", "--out", str(out), "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "scenario 'lab'" in text and "scenario 'ideal'" not in text
    with xr.open_dataset(out) as results:
        assert results.attrs["scenario"] == "lab" and "'lab'" in results.attrs["title"]
        # where the scenario came from travels with the results (Scenario.source)
        assert "lab.toml" in results.attrs["scenario_source"] and "ideal" in results.attrs["scenario_source"]


# ----------------------------------------------------------------------------- repeated rate points


def test_a_repeated_rate_point_is_refused(ideal_document):
    ideal_document["schedule"]["rate_points"] = ["-100 deg/s", "-5 deg/s", "0 deg/s", "5 deg/s", "5 deg/s",
                                                 "100 deg/s"]
    with pytest.raises(ValueError, match=r"schedule\.rate_points\[4\] = '5 deg/s' repeats "
                                         r"schedule\.rate_points\[3\] = '5 deg/s'"):
        parse_scenario(ideal_document)


def test_a_repeated_rate_point_in_other_units_is_refused(ideal_document):
    ideal_document["schedule"]["rate_points"] = ["-1 deg/s", "1 deg/s", "3600 deg/h"]
    with pytest.raises(ValueError, match=r"schedule\.rate_points\[2\] = '3600 deg/h' repeats "
                                         r"schedule\.rate_points\[1\] = '1 deg/s'"):
        parse_scenario(ideal_document)


def test_a_repeated_rate_segment_in_a_custom_schedule_is_refused(ideal_document):
    segments = custom_segments(rates_deg=(-50.0, 0.0, 50.0, -50.0))
    with_custom_schedule(ideal_document, segments)
    with pytest.raises(ValueError, match=r"schedule\.segments\[9\] \('rate x -50\.0 deg/s'\): rate '-50\.0 deg/s' "
                                         r"repeats schedule\.segments\[6\] \('rate x -50\.0 deg/s'\) of the rate "
                                         r"test about x"):
        parse_scenario(ideal_document)


# ----------------------------------------------------------------------------- files that are not scenario files


def _png_bytes() -> bytes:
    return b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x00\x01\x00\x00\x00\x01\x08\x02\x00\x00\x00" + bytes(32)


GARBLED_SCENARIO_FILES = {
    "a PNG renamed .toml": (_png_bytes(), r"not UTF-8 text"),
    "random bytes": (np.random.default_rng(9).bytes(256), r"not UTF-8 text"),
    "UTF-16 text": ('name = "lab"\n'.encode("utf-16"), r"UTF-16 text.*save it as UTF-8"),
    "an empty file": (b"", r"is empty"),
    "comments only": (b"# to do\n\n", r"is empty"),
    "NUL bytes": (b"name = \"lab\"\n\x00\x00\x00\n", r"is not valid TOML"),
}


@pytest.mark.parametrize("data, match", list(GARBLED_SCENARIO_FILES.values()), ids=list(GARBLED_SCENARIO_FILES))
def test_a_garbled_scenario_file_is_a_value_error_naming_the_file(tmp_path, data, match):
    path = tmp_path / "lab.toml"
    path.write_bytes(data)
    with pytest.raises(ValueError, match=r"scenario file '.*lab\.toml'.*" + match) as caught:
        load_scenario(path)
    assert type(caught.value) is ValueError  # not a UnicodeDecodeError (a ValueError subclass without the file)


def test_a_utf8_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "lab.toml"
    path.write_bytes(b"\xef\xbb\xbf" + (SCENARIOS / "ideal.toml").read_bytes())
    assert load_scenario(path).trials == 20


def test_a_folder_is_not_a_scenario_file(tmp_path):
    folder = tmp_path / "lab.toml"
    folder.mkdir()
    with pytest.raises(ValueError, match=r"lab\.toml.*is a folder"):
        load_scenario(folder)
