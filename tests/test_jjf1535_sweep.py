"""The JJF 1535 procedure's settings from the command line, and its sweep (``plansim sweep jjf1535``): how long a
session must be for the items to be good enough (docs/jjf1535.md, "Choosing the session")."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr

import plansim.runner
from plansim import cli
from plansim.estimate.jjf1535_items import ITEMS
from plansim.planning.grid import cell_seed, parse_grid
from plansim.planning.jjf1535_sweep import cheapest_cell, split_overrides, sweep_jjf1535
from plansim.report.jjf1535 import parse_targets
from plansim.runner import jjf1535_run
from plansim.schedule.jjf1535 import DEG, SETTING_KINDS, Jjf1535Settings, jjf1535_procedure
from plansim.simulate.overrides import jjf1535_settings

GRID = {"vary": {"procedure.repeats": [2, 4]}, "zip": {"procedure.minimum_rate": ["0.1 deg/s"]}}


def test_the_default_settings_are_the_default_procedure_and_every_setting_is_an_argument():
    import inspect

    assert Jjf1535Settings().procedure() == jjf1535_procedure(100.0 * DEG)
    arguments = set(inspect.signature(jjf1535_procedure).parameters)
    assert set(SETTING_KINDS) == arguments and set(SETTING_KINDS) <= {f for f in Jjf1535Settings.__dataclass_fields__}


def test_settings_are_read_with_their_units_and_checked_by_building_the_procedure():
    s = jjf1535_settings(["points=13", "minimum_rate=0.1 deg/s", "averaging_period=\"20 s\"", "repeats=4"])
    assert (s.points, s.repeats, s.averaging_period) == (13, 4, 20.0)
    assert s.minimum_rate == pytest.approx(0.1 * DEG) and s.overrides[0] == "points=13"
    procedure = s.procedure()
    assert len(procedure.room_runs) == 4 and len(procedure.room_runs[0].points) == 26
    with pytest.raises(ValueError, match="--procedure 'pointz=3': expected KEY=VALUE with KEY one of"):
        jjf1535_settings(["pointz=3"])
    with pytest.raises(ValueError, match="points expects an integer >= 11"):
        jjf1535_settings(["points=eleven"])
    with pytest.raises(ValueError, match="only 11 points"):  # the R5 series from 1 to 100 deg/s
        jjf1535_settings(["points=15"])
    with pytest.raises(ValueError, match="repeats"):
        jjf1535_settings(["repeats=1"])


def test_run_jjf1535_takes_procedure_settings(capsys):
    assert cli.main(["run", "jjf1535", "--trials", "20", "--seed", "1", "--quiet", "--procedure", "repeats=2",
                     "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["procedure_settings"] == ["repeats=2"]
    direct = jjf1535_run("jjf2003", trials=20, seed=1, procedure=jjf1535_settings(["repeats=2"]).procedure())
    k = [i["item"] for i in document["items"]].index("scale_factor")
    assert document["items"][k]["std_error"] == pytest.approx(np.std(
        direct.column("scale_factor") - direct.column("scale_factor", "truth"), ddof=1), rel=1e-12)
    assert cli.main(["run", "jjf1535", "--procedure", "points=3"]) == 2
    assert "expected a whole number >= 11" in capsys.readouterr().err


def test_a_sweep_cell_is_the_monte_carlo_of_its_settings_whatever_the_grid():
    """Each cell is jjf1535_run of its own settings with the seed of its own overrides: the same numbers whether
    the cell sits in a grid of one or of two."""
    one = sweep_jjf1535("jjf2003", {"vary": {"procedure.repeats": [4]}, "zip": GRID["zip"]}, trials=30, seed=7)
    two = sweep_jjf1535("jjf2003", GRID, trials=30, seed=7)
    a = one.isel({"procedure.repeats": 0, "zip": 0})
    b = two.sel({"procedure.repeats": 4}).isel(zip=0)
    for name in ("mc_U95", "std_error", "figure_std", "session_hours"):
        np.testing.assert_array_equal(a[name].values, b[name].values)
    cell = ["procedure.repeats=4", "procedure.minimum_rate=\"0.1 deg/s\""]
    direct = jjf1535_run("jjf2003", trials=30, seed=cell_seed(7, cell),
                         procedure=jjf1535_settings(split_overrides(cell)[0]).procedure())
    err = direct.column("nonlinearity") - direct.column("nonlinearity", "truth")
    assert float(b["mc_U95"].sel(item="nonlinearity")) == pytest.approx(np.quantile(np.abs(err), 0.95), rel=1e-12)
    assert float(b["session_hours"]) > float(two.sel({"procedure.repeats": 2}).isel(zip=0)["session_hours"])
    assert two["mc_U95"].attrs["units"] == "item_unit (SI)" and str(two["item_unit"].sel(item="bias").values) == \
        "rad/s"


def test_the_cheapest_cell_meets_every_target_and_is_the_shortest():
    ds = sweep_jjf1535("jjf2003", GRID, trials=30, seed=7)
    u95 = ds["mc_U95"].sel(item="asymmetry").isel(zip=0).values
    loose = float(u95.max()) * 1.01
    best = cheapest_cell(ds, {"asymmetry": loose})
    assert best["fields"]["procedure.repeats"] == 2  # both meet it: the shorter session wins
    tight = float(u95.min()) * 1.0001
    best = cheapest_cell(ds, {"asymmetry": tight})
    assert best["values"]["asymmetry"] <= tight and best["fields"]["procedure.repeats"] == \
        [2, 4][int(np.argmin(u95))]
    assert cheapest_cell(ds, {"asymmetry": float(u95.min()) * 0.5}) is None
    # an item with no true value is compared by the spread of its figure
    stability = cheapest_cell(ds, {"bias_stability": 1.0})
    assert math.isfinite(stability["values"]["bias_stability"])
    with pytest.raises(ValueError, match="not a JJF 1535 item"):
        cheapest_cell(ds, {"bias_stabilty": 1.0})


def test_targets_are_read_in_the_items_units():
    targets = parse_targets(["nonlinearity=100", "bias=5 deg/h"])
    assert targets["nonlinearity"] == pytest.approx(100e-6) and targets["bias"] == pytest.approx(5 * ITEMS["bias"][3])
    for bad, message in (("nonlinearity=100 deg/h", "nonlinearity is in ppm"),
                         ("linearity=1", "expected KEY=VALUE with KEY one of scale_factor"),
                         ("bias=-1", "positive"), ("bias=x", "not a number")):
        with pytest.raises(ValueError, match=message):
            parse_targets([bad])


def test_the_command_text_json_netcdf_and_figure(tmp_path, capsys):
    grid = tmp_path / "grid.toml"
    grid.write_text('[vary]\n"procedure.repeats" = [2, 4]\n[zip]\n"procedure.minimum_rate" = ["0.1 deg/s"]\n')
    out, plot = tmp_path / "s.nc", tmp_path / "s.png"
    assert cli.main(["sweep", "jjf1535", "--grid", str(grid), "--trials", "20", "--quiet", "--target",
                     "asymmetry=100000", "--out", str(out), "--plot", str(plot)]) == 0
    text = capsys.readouterr().out
    assert "Shortest session meeting every target (asymmetry <= 1e+05 ppm): procedure.repeats = 2" in text
    assert "procedure.minimum_rate" in text and out.exists() and plot.stat().st_size > 1000
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["mc_U95"].dims == ("procedure.repeats", "zip", "item")
    assert cli.main(["sweep", "jjf1535", "--grid", str(grid), "--trials", "20", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert len(document["cells"]) == 2 and document["best"] is None and document["targets"] == []
    assert {"item", "unit", "mean_error", "std_error", "mc_U95", "figure", "undetermined"} == \
        set(document["cells"][0]["items"][0])


def test_bad_sweeps_exit_2_before_any_work(tmp_path, capsys, monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the JJF 1535 Monte Carlo ran")

    monkeypatch.setattr(plansim.runner, "jjf1535_run", refuse)
    grid = tmp_path / "grid.toml"
    grid.write_text('[vary]\n"procedure.points" = [11, 30]\n')
    cases = [(["sweep", "jjf1535", "--grid", str(grid)], "sweep cell procedure.points=30"),
             (["sweep", "jjf1535", "--grid", str(grid), "--predict-only"], "--predict-only: not available"),
             (["sweep", "jjf1535", "--grid", str(grid), "--target", "x=1"], "--target 'x=1'"),
             (["sweep", "jjf2003", "--grid", str(grid), "--unit", "jjf2003"], "--unit: only with the procedure"),
             (["sweep", "jjf1535", "--grid", str(grid), "--trials", "1"], "--trials 1: must be >= 2")]
    for argv, message in cases:
        assert cli.main(argv) == 2, argv
        assert message in capsys.readouterr().err, argv
    assert parse_grid({"vary": {"procedure.points": [11]}}).size == 1


# ------------------------------------------------------------------------------------------ claims on JJF 1535 items

def test_claims_on_items_are_judged_by_their_coverage_of_the_truth(tmp_path, capsys):
    """A certificate's U per item against the Monte Carlo: coverage = trials with |error| <= U (relative for K), the
    half-width needed for 95 %, and the verdict; checked against the trials' errors computed here."""
    from plansim.io.claims import load_jjf1535_claims
    from plansim.uncertainty.jjf1535_claims import judge_jjf1535_claims

    path = tmp_path / "claims.toml"
    path.write_text("[jjf1535.scale_factor]\nU = 1.1e-3\nrelative = true\n\n[jjf1535.nonlinearity]\nU = 100\n")
    claims = load_jjf1535_claims(path)
    assert claims["nonlinearity"].expanded_uncertainty == pytest.approx(100e-6) and claims["scale_factor"].relative
    mc = jjf1535_run("jjf2003", trials=200, seed=3)
    rows = {r["item"]: r for r in judge_jjf1535_claims(mc, claims)}
    err = np.abs(mc.column("nonlinearity") - mc.column("nonlinearity", "truth"))
    assert rows["nonlinearity"]["coverage"] == pytest.approx(np.mean(err <= 100e-6))
    assert rows["nonlinearity"]["needed"] == pytest.approx(np.quantile(err, 0.95))
    assert rows["nonlinearity"]["verdict"].startswith("under-stated")  # the noise alone reads ~90 ppm (docs)
    rel = np.abs(mc.column("scale_factor") / mc.column("scale_factor", "truth") - 1.0)
    assert rows["scale_factor"]["coverage"] == pytest.approx(np.mean(rel <= 1.1e-3))
    assert cli.main(["run", "jjf1535", "--trials", "200", "--seed", "3", "--quiet", "--claims", str(path),
                     "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert [c["item"] for c in document["claims"]] == ["scale_factor", "nonlinearity"]
    assert document["claims"][0]["unit"] == "1 (relative)" and document["claims"][1]["unit"] == "1"  # ppm -> 1


def test_bad_claims_are_refused_naming_the_item(tmp_path, capsys):
    from plansim.uncertainty.jjf1535_claims import parse_jjf1535_claims

    for document, message in (({"items": {}}, "unknown section"), ({"jjf1535": {"linearity": {"U": 1}}},
                                                                     "unknown item"),
                              ({"jjf1535": {"bias_stability": {"U": 1}}}, "no true value"),
                              ({"jjf1535": {"bias": {"U": -1}}}, "expected a number > 0"),
                              ({"jjf1535": {"bias": {"U": 1, "p": 2}}}, r"expected U \(required\)"),
                              ({"jjf1535": {"bias": {"U": 1, "relative": "yes"}}}, "expected true or false"),
                              ({"jjf1535": {}}, "no claim")):
        with pytest.raises((ValueError, TypeError), match=message):
            parse_jjf1535_claims(document)
    assert cli.main(["run", "jjf2003", "--claims", str(tmp_path / "x.toml")]) == 2
    assert "--claims: only with the procedure jjf1535" in capsys.readouterr().err
    assert cli.main(["run", "jjf1535", "--claims", str(tmp_path / "missing.toml")]) == 2
    assert "no such file" in capsys.readouterr().err
