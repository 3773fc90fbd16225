"""Rates beyond the range: a schedule that drives an output past the gyro range or the acquisition
full scale is refused when the scenario loads, unless the file asks for saturation on purpose
(``acquisition.allow_saturation = true``); then :func:`plansim.config.saturation_report` says which
channels clip and by how much.

Before this check a scenario with rate points beyond the range loaded without complaint and its
Kg came out 60-75 % low (the saturated outputs flatten the line fit of JJF 2003 eq. (5)); the only
sign was a NetCDF attribute naming the simulation path.
"""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import pytest

from plansim.config import parse_scenario, saturation_report
from plansim.io.scenario_file import load_scenario
from test_scenario_validation import custom_segments, with_custom_schedule

JJF2003 = Path(__file__).resolve().parent.parent / "scenarios" / "jjf2003.toml"
with open(JJF2003, "rb") as _fh:
    _JJF2003_DOCUMENT = tomllib.load(_fh)


@pytest.fixture
def jjf2003_document() -> dict:
    """scenarios/jjf2003.toml: gyro range and 12-bit full scale 125 °/s, Kgxx 1.0021, Bgx 0.12 °/s."""
    return copy.deepcopy(_JJF2003_DOCUMENT)


WIDE_RATES = ["-400 deg/s", "-200 deg/s", "-50 deg/s", "0 deg/s", "50 deg/s", "200 deg/s", "400 deg/s"]


def test_a_rate_point_beyond_the_gyro_range_is_refused(jjf2003_document):
    jjf2003_document["schedule"]["rate_points"] = WIDE_RATES
    # the first rate point beyond the range, named with its value and the limit in the user's units
    with pytest.raises(ValueError, match=r"schedule\.rate_points\[0\] = '-400 deg/s': gyro gx would output up to "
                                         r"40[0-9]\.[0-9] deg/s .*mimu\.gyro_range = '125 deg/s'.*allow_saturation"):
        parse_scenario(jjf2003_document)


def test_a_rate_point_at_the_range_itself_is_refused_because_scale_factor_and_bias_add(jjf2003_document):
    """125 °/s on a 125 °/s gyro: Kgxx 1.0021 (+3σ spread) and Bgx 0.12 °/s (+3σ) put the output above."""
    jjf2003_document["schedule"]["rate_points"] = ["-125 deg/s", "0 deg/s", "125 deg/s"]
    with pytest.raises(ValueError, match=r"schedule\.rate_points\[0\] = '-125 deg/s': gyro gx would output up to "
                                         r"125\.[0-9] deg/s.*largest rate .* 12[34]\.[0-9] deg/s"):
        parse_scenario(jjf2003_document)
    # just inside: 124 °/s stays below 125 °/s (tests/test_paths.py runs this schedule)
    jjf2003_document["schedule"]["rate_points"] = ["-124 deg/s", "124 deg/s"]
    assert saturation_report(parse_scenario(jjf2003_document)) == []


def test_the_omega_squared_rate_beyond_the_range_is_refused(jjf2003_document):
    jjf2003_document["schedule"]["omega_squared_rate"] = "3 rad/s"
    with pytest.raises(ValueError, match=r"schedule\.omega_squared_rate = '3 rad/s': gyro gx would output up to "
                                         r"3\.0[0-9]* rad/s .*mimu\.gyro_range = '125 deg/s' \(2\.18[0-9]* rad/s\)"):
        parse_scenario(jjf2003_document)


def test_the_acquisition_full_scale_is_a_limit_only_when_it_quantises(ideal_document):
    ideal_document["acquisition"] = {"bits": 12, "gyro_full_scale": "60 deg/s", "accel_full_scale": "8 g"}
    with pytest.raises(ValueError, match=r"schedule\.rate_points\[0\] = '-100 deg/s'.*acquisition\.gyro_full_scale "
                                         r"= '60 deg/s'"):
        parse_scenario(ideal_document)
    ideal_document["acquisition"]["bits"] = 0  # no acquisition model: the full scale clips nothing
    assert parse_scenario(ideal_document).acquisition.bits == 0


def test_a_custom_segment_beyond_the_range_names_the_segment(ideal_document):
    ideal_document["mimu"]["gyro_range"] = "2 rad/s"
    with_custom_schedule(ideal_document, custom_segments(rates_deg=(-50.0, 0.0, 150.0)))
    with pytest.raises(ValueError, match=r"schedule\.segments\[8\]\.rate = '150\.0 deg/s': gyro gx .*"
                                         r"mimu\.gyro_range = '2 rad/s' \(114\.[0-9] deg/s\)"):
        parse_scenario(ideal_document)


def test_an_accelerometer_range_below_gravity_is_refused(ideal_document):
    ideal_document["mimu"]["accel_range"] = "0.5 g"
    with pytest.raises(ValueError, match=r"mimu\.accel_range = '0\.5 g': accelerometer ax would output up to "
                                         r"1\.00[0-9]* g at rest .*'pos1a"):
        parse_scenario(ideal_document)


def test_allow_saturation_loads_and_the_report_names_each_clipped_channel(jjf2003_document):
    jjf2003_document["schedule"]["rate_points"] = WIDE_RATES
    jjf2003_document["acquisition"]["allow_saturation"] = True
    scenario = parse_scenario(jjf2003_document)
    assert scenario.acquisition.allow_saturation
    lines = saturation_report(scenario)
    assert [line.split(":")[0] for line in lines] == ["gx", "gy", "gz"]
    # each line: the output bound, the limit and its field, by how much, and in which segments
    assert "up to 40" in lines[0] and "deg/s" in lines[0] and "125 deg/s" in lines[0]
    assert "4 of 39 segments" in lines[0] and "rate x -400 deg/s" in lines[0]
    assert "mimu.gyro_range" in lines[0] or "acquisition.gyro_full_scale" in lines[0]
    assert "% over" in lines[0]


def test_the_built_in_scenarios_do_not_saturate():
    for name in ("jjf2003", "ideal", "linear_gaussian", "coarse_quantisation"):
        scenario = load_scenario(name)
        assert not scenario.acquisition.allow_saturation
        assert saturation_report(scenario) == [], name


def test_allow_saturation_must_be_a_boolean(ideal_document):
    ideal_document["acquisition"]["allow_saturation"] = "yes"
    with pytest.raises(TypeError, match=r"acquisition\.allow_saturation = 'yes': expected true or false"):
        parse_scenario(ideal_document)


def test_the_run_says_which_channels_saturate_and_by_how_much(jjf2003_document, tmp_path, capsys):
    """With saturation allowed, `plansim run` prints the clipped channels (text and --json), since the
    estimates of their parameters are biased (Kg 60-75 % low here); a run that does not saturate prints none."""
    import json

    import tomli_w

    from plansim.cli import main

    jjf2003_document["schedule"]["rate_points"] = WIDE_RATES
    jjf2003_document["acquisition"]["allow_saturation"] = True
    path = tmp_path / "wide.toml"
    path.write_bytes(tomli_w.dumps(jjf2003_document).encode())
    assert main(["run", str(path), "--trials", "2", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "Saturation" in text and "allow_saturation" in text
    assert "gx: output up to" in text and "gy: output up to" in text and "gz: output up to" in text
    assert main(["run", str(path), "--trials", "2", "--quiet", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert len(payload["saturation"]) == 3 and payload["saturation"][0].startswith("gx: output up to")
    assert main(["run", "ideal", "--trials", "2", "--quiet", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["saturation"] == []
