"""--set KEY=VALUE: a scenario field overridden on the command line, checked exactly as the file is."""

from __future__ import annotations

import json

import numpy as np
import pytest
import tomli_w
import xarray as xr

from plansim.cli import main
from plansim.io.scenario_file import (
    apply_overrides,
    builtin_scenarios,
    load_scenario,
    parse_override,
)


@pytest.mark.parametrize("text, key, value", [
    ("schedule.dwell=60 s", ("schedule", "dwell"), "60 s"),  # the quotes a shell took away
    ('schedule.dwell="60 s"', ("schedule", "dwell"), "60 s"),
    ("schedule.positions=6", ("schedule", "positions"), 6),
    ("acquisition.bits = 0", ("acquisition", "bits"), 0),
    ("environment.earth_rate=false", ("environment", "earth_rate"), False),
    ('schedule.rate_points=["-100 deg/s", "100 deg/s"]', ("schedule", "rate_points"), ["-100 deg/s", "100 deg/s"]),
])
def test_an_override_is_a_dotted_key_and_a_toml_value(text, key, value):
    assert parse_override(text) == (key, value)


def test_the_overridden_scenario_is_the_edited_file(tmp_path):
    """Overrides give the same scenario as the file edited by hand, and say so in source and overrides."""
    import tomllib

    document = tomllib.loads(builtin_scenarios()["jjf2003"].read_text())
    document["schedule"]["dwell"] = "60 s"
    document["schedule"]["positions"] = 6
    document["mimu"]["truth"]["Kgxx"] = "1.001 1"
    edited = tmp_path / "edited.toml"
    edited.write_bytes(tomli_w.dumps(document).encode())
    by_file = load_scenario(str(edited))
    by_set = load_scenario("jjf2003", ["schedule.dwell=60 s", "schedule.positions=6", "mimu.truth.Kgxx=1.001 1"])
    assert by_set.schedule == by_file.schedule
    assert np.array_equal(by_set.truth_nominal, by_file.truth_nominal)
    assert by_set.schedule.segments[0].dwell == 60.0 and by_set.truth_nominal[0] == 1.001
    assert by_set.overrides == ("schedule.dwell=60 s", "schedule.positions=6", "mimu.truth.Kgxx=1.001 1")
    assert "with schedule.dwell=60 s" in by_set.source
    assert load_scenario("jjf2003").overrides == ()


@pytest.mark.parametrize("text, message", [
    ("schedule.dwel=60 s", "unknown key.*'dwel'.*with schedule.dwel=60 s"),
    ("schedule.dwell=-1 s", "dwell = -1.0 s; it must be > 0"),
    ("mimu.truth.Kgxx=abc", "mimu.truth.Kgxx"),
    ("schedule=6", "schedule is a table; set one of its keys"),
    ("schedule.dwell.x=1", "schedule.dwell is a value"),
    ("schedule.dwell", "expected KEY=VALUE"),
    ("=6", "expected KEY=VALUE"),
    ("schedule..dwell=6", "expected KEY=VALUE"),
])
def test_bad_overrides_are_refused_naming_the_field(text, message):
    with pytest.raises(ValueError, match=message):
        load_scenario("jjf2003", [text])


def test_overrides_leave_the_document_they_were_given_alone():
    document = {"schedule": {"dwell": "30 s"}}
    changed = apply_overrides(document, ["schedule.dwell=60 s", "mimu.effects.gyro_asymmetry=[0.001, 0, 0]"])
    assert document == {"schedule": {"dwell": "30 s"}}
    assert changed["schedule"]["dwell"] == "60 s" and changed["mimu"]["effects"]["gyro_asymmetry"] == [0.001, 0, 0]
    with pytest.raises(TypeError, match="expected text KEY=VALUE"):
        parse_override(6)


def test_run_reports_its_overrides_in_the_header_the_json_and_the_file(tmp_path, capsys):
    out = tmp_path / "r.nc"
    assert main(["run", "ideal", "--trials", "3", "--quiet", "--set", "schedule.dwell=10 s", "--out", str(out)]) == 0
    assert "Overrides (--set): schedule.dwell=10 s" in capsys.readouterr().out
    with xr.open_dataset(out) as results:
        assert results.attrs["scenario_overrides"] == "schedule.dwell=10 s"
        assert "dwell = \"10 s\"" in results.attrs["scenario_toml"]
    assert main(["run", "ideal", "--trials", "3", "--quiet", "--json", "--set", "schedule.positions=6"]) == 0
    assert json.loads(capsys.readouterr().out)["overrides"] == ["schedule.positions=6"]
    assert main(["run", "ideal", "--trials", "3", "--set", "schedule.dwel=3"]) == 2
    assert "unknown key" in capsys.readouterr().err
    assert not list(tmp_path.glob(".*.part"))
