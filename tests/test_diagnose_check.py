"""plansim diagnose-check: the blind check's structure and seeding (fast), and its attributions at 10x (slow)."""

from __future__ import annotations

import json

import pytest

from plansim.checks.diagnose_check import case_seed, check_json, run_diagnose_check
from plansim.cli import main
from plansim.io.scenario_file import load_scenario


def test_seeds_depend_on_the_case_not_the_order():
    assert case_seed(0, "null", 3) == case_seed(0, "null", 3)
    assert len({case_seed(0, "null", i) for i in range(100)}) == 100
    assert case_seed(0, "null", 0) != case_seed(1, "null", 0) != case_seed(0, "bias_step/5.0", 0)


def test_a_small_null_run_and_its_report(tmp_path, capsys):
    """One linear_gaussian null through the command: the JSON is written atomically with the count of false alarms
    and its binomial bound; bad sizes and counts are refused."""
    out = tmp_path / "check.json"
    assert main(["diagnose-check", "linear_gaussian", "--null", "1", "--per-effect", "0", "--null-draws", "100",
                 "--out", str(out), "--quiet"]) == 0
    data = json.loads(out.read_text())
    assert data["null"]["recordings"] == 1 and data["null"]["false_alarms"] in (0, 1)
    assert data["effects"] == [] and data["out_of_catalogue"] == []
    assert "binomial_99_upper_count" in data["null"]
    assert check_json(run_diagnose_check.__globals__["CheckReport"]("x", 0.05))["null"] == {}
    assert main(["diagnose-check", "--sizes", "2,x", "--quiet"]) == 2
    assert "--sizes '2,x'" in capsys.readouterr().err
    with pytest.raises(ValueError, match="null = 0"):
        run_diagnose_check(load_scenario("linear_gaussian"), null=0)


@pytest.mark.slow
def test_at_ten_times_the_effects_are_attributed_and_the_lever_arm_never_is():
    """One jjf2003 recording per effect at 10x its noise-equivalent size (non-centrality 100: power ≈ 1 for each
    test): asymmetry, g²-sensitivity and K2 are attributed to themselves; the lever arm (aliased with P) never."""
    report = run_diagnose_check(load_scenario("jjf2003"), null=1, per_effect=1, sizes=(10.0,), null_draws=300)
    by = {(e["effect"], e["times_noise_equivalent"]): e for e in report.effects}
    for effect in ("gyro_scale_asymmetry", "gyro_g2_sensitivity", "accel_quadratic"):
        assert by[(effect, 10.0)]["attribution"] == 1.0, by[(effect, 10.0)]
    assert "lever_arm" not in "".join(by[("lever_arm", None)]["confusion"])
