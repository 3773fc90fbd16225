"""The command line as a user runs it: `plansim run`, `plansim scenarios`, `plansim record`."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

from plansim.cli import main
from plansim.io.recording import read_recording


def run_cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_scenarios_lists_the_built_ins(capsys):
    code, out, _ = run_cli(capsys, "scenarios")
    assert code == 0
    names = [line.split()[0] for line in out.splitlines()]
    assert "jjf2003" in names and "ideal" in names


def test_run_json_has_the_documented_keys(capsys):
    code, out, _ = run_cli(capsys, "run", "ideal", "--trials", "3", "--seed", "2", "--json", "--quiet")
    assert code == 0
    doc = json.loads(out)
    assert {p["name"] for p in doc["parameters"]} >= {"Kgxx", "Bgx", "gxx", "Kaxx", "Bax", "pyx"}
    for p in doc["parameters"]:
        assert set(p) == {"name", "unit", "mean_error", "std_error"}
    assert [a["item"] for a in doc["appendix_a"]] == ["A.1", "A.2", "A.3", "A.4", "A.5"]
    for a in doc["appendix_a"]:
        assert {"item", "budget_uc", "budget_U", "mc_u", "mc_U95", "coverage"} <= set(a)
    # the ideal scenario: zero-noise identity, so every error is (numerically) zero
    kg = next(p for p in doc["parameters"] if p["name"] == "Kgxx")
    assert abs(kg["mean_error"]) < 1e-9


def test_run_writes_netcdf_and_figure(capsys, tmp_path):
    out, fig = tmp_path / "r.nc", tmp_path / "f.png"
    code, text, _ = run_cli(capsys, "run", "ideal", "--trials", "3", "--out", str(out), "--plot", str(fig), "--quiet")
    assert code == 0
    assert "Appendix A" in text and "Kgxx" in text
    with xr.open_dataset(out) as ds:
        assert ds.attrs["scenario"] == "ideal" and ds.attrs["seed"] == 1 and ds.attrs["trials"] == 3
        assert list(ds["parameter"].values[:2]) == ["Kgxx", "Kgxy"]
        assert np.all(np.isfinite(ds["error"].values))
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png", "r.nc"]  # no temporary left


@pytest.mark.parametrize("argv, fragment", [
    (["run", "no-such-scenario"], "no such file and no built-in scenario"),
    (["run", "ideal", "--out", "missing-folder/r.nc"], "does not exist"),
    (["run", "ideal", "--out", "r.txt"], "must end in .nc"),
    (["run", "ideal", "--plot", "f.jpeg"], "must end in .png"),
    (["run", "ideal", "--trials", "0"], "--trials 0"),
    (["run", "ideal", "--seed", "-1"], "--seed -1"),
])
def test_bad_input_is_a_clear_error_and_writes_nothing(capsys, tmp_path, monkeypatch, argv, fragment):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, *argv)
    assert code == 2
    assert fragment in err and err.startswith("plansim: error:")
    assert list(tmp_path.iterdir()) == []


def test_a_bad_scenario_file_names_the_field_and_writes_nothing(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    bad = tmp_path / "bad.toml"
    bad.write_text('[environment]\nlatitude = "40 m"\n')
    code, _, err = run_cli(capsys, "run", str(bad), "--out", "r.nc")
    assert code == 2 and "environment.latitude" in err and "'deg'" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_record_writes_a_readable_recording(capsys, tmp_path, suffix):
    path = tmp_path / f"rec{suffix}"
    code, out, _ = run_cli(capsys, "record", "ideal", "--out", str(path), "--trial", "1")
    assert code == 0 and "wrote recording" in out
    rec = read_recording(path)
    assert rec.samples.shape[1] == 6 and rec.attrs["trial"] == 1


def test_the_installed_console_script_runs():
    exe = shutil.which("plansim")
    if exe is None:
        pytest.skip("the plansim console script is not on PATH (package not installed with pip)")
    done = subprocess.run([exe, "scenarios"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and "jjf2003" in done.stdout
    done = subprocess.run([sys.executable, "-m", "plansim.cli", "run", "--help"], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0 and "--trials" in done.stdout


def test_a_seed_beyond_32_bits_is_written_to_netcdf(capsys, tmp_path):
    out = tmp_path / "r.nc"
    code, _, err = run_cli(capsys, "run", "ideal", "--trials", "2", "--seed", str(2**40 + 3), "--out", str(out),
                           "--quiet")
    assert code == 0, err
    with xr.open_dataset(out) as ds:
        assert int(ds.attrs["seed"]) == 2**40 + 3


def test_a_custom_segment_without_up_is_an_error_naming_it(tmp_path):
    import tomllib

    from plansim.config import parse_scenario
    from plansim.io.scenario_file import builtin_scenarios

    with open(builtin_scenarios()["ideal"], "rb") as fh:
        doc = tomllib.load(fh)
    doc["schedule"] = {"procedure": "custom", "segments": [{"label": "p", "test": "multi_position", "group": 1}]}
    with pytest.raises(ValueError, match=r"schedule\.segments\[0\]\.up is required"):
        parse_scenario(doc)


def test_run_with_too_few_trials_does_not_call_a_budget_supported(capsys):
    code, out, _ = run_cli(capsys, "run", "ideal", "--trials", "3", "--json", "--quiet")
    assert code == 0
    verdicts = [a["verdict"] for a in json.loads(out)["appendix_a"]]
    assert all(v.startswith("too few trials to judge") for v in verdicts), verdicts
    code, out, _ = run_cli(capsys, "run", "ideal", "--trials", "3", "--quiet")
    assert code == 0 and "supported" not in out and "too few trials to judge (9 < 171)" in out
