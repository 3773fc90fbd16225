"""A data sheet the data contradict: which entry, what the data alone say, and the fit once it is restated.

A lab fits a JJF 2003 recording of its unit, the multi-position test at 6 positions and the rate tests (scenario
``linear_gaussian``, ``schedule.positions=6``), with the unit's data sheet stated in its scenario file:
``[reduction] data_sheet_ba = "1 ug"``, far tighter than this unit's accelerometer biases (about 10³ µg). Where
the data leave a direction to the data sheet, the fit carries it as a prior (docs/fitting.md, Identifiability).
The data-sheet conflict test, a χ² per parameter group of eq. (2) (JJF 2003 §5.2), names the entry the data
contradict. The fit gives what the data alone put that group at, with u. The lab restates the entry from those
figures (three times the largest |Ba| the data give) and fits again; nothing is contradicted then, and Bax is
the data's.

    python docs/examples/data_sheet_conflict.py [SEED]
"""

from __future__ import annotations

import sys

from plansim.fit import fit_recording, resolve_site, scenario_fit_options
from plansim.fit.identify import describe_conflict
from plansim.io.scenario_file import load_scenario
from plansim.model.parameters import PARAMETER_INDEX
from plansim.runner import simulate_and_record

UG = 9.80665e-6  # m/s^2 per µg
SIX = "schedule.positions=6"


def fit_with(recording, data_sheet_ba: str):
    """The recording fitted as `plansim fit REC --scenario lab.toml` does, the lab's file stating Ba's data sheet."""
    lab = load_scenario("linear_gaussian", overrides=(SIX, f'reduction.data_sheet_ba="{data_sheet_ba}"'))
    return fit_recording(recording, resolve_site(scenario=lab), **scenario_fit_options(lab))


def report(fit, stated: str) -> None:
    k = PARAMETER_INDEX["Bax"]
    print(f"data sheet Ba = {stated}: chi2/dof {fit.chi2:.4g}/{fit.chi2_dof}; "
          f"Bax = {fit.joint.estimate[k] / UG:.1f} ± {fit.joint.u[k] / UG:.2g} ug")
    for group, entry in fit.data_sheet_conflict.items():
        print(f"  {group:3s} {describe_conflict(entry)}")
    if not fit.data_sheet_conflict:
        print("  the data determine every direction more tightly than the data sheet: it is not carried as a prior")


def main(seed: int) -> None:
    recording = simulate_and_record(load_scenario("linear_gaussian", overrides=(SIX,)), seed=seed)
    first = fit_with(recording, "1 ug")
    report(first, "1 ug")
    contradicted = [group for group, entry in first.data_sheet_conflict.items() if entry["contradicted"]]
    print("contradicted:", ", ".join(contradicted) or "none")
    if "Ba" not in contradicted:
        return
    alone = first.data_sheet_conflict["Ba"]["data_alone"]
    restated = f"{3 * max(abs(estimate) for estimate, _ in alone.values()) / UG:.0f} ug"
    second = fit_with(recording, restated)
    report(second, restated)
    print("contradicted:", ", ".join(g for g, e in second.data_sheet_conflict.items() if e["contradicted"]) or "none")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2)
