"""Closing the loop on a recording that hides an effect the lab's model lacks (docs/closing-the-loop.md).

A unit whose x gyro has a scale-factor asymmetry (different scale factors for positive and negative rates,
which JJF 2003 eq. (1) does not have) is calibrated by the JJF 2003 schedule; the recording is diagnosed with
the lab's scenario, which knows the lever arms but not the asymmetry. The diagnosis names the effect, says how
reliably this schedule tells it from its nearest rival, refits, and reports the error before and after.

    python docs/examples/hidden_effect.py [ASYMMETRY] [SEED]

(defaults 1.2e-4 and 5: the worked example of docs/closing-the-loop.md, as ``plansim record`` and
``plansim diagnose`` run it from the command line).
"""

from __future__ import annotations

import dataclasses
import sys

import numpy as np

from plansim import load_scenario, simulate_and_record
from plansim.diagnose.procedure import diagnose, scenario_diagnose_options
from plansim.fit import resolve_site
from plansim.report.diagnose import diagnose_report


def main(asymmetry: float, seed: int) -> None:
    lab = load_scenario("jjf2003")  # what the lab knows
    effects = dataclasses.replace(lab.effects, gyro_asymmetry=np.array([asymmetry, 0.0, 0.0]))
    unit = dataclasses.replace(lab, effects=effects)  # what the unit does
    recording = simulate_and_record(unit, seed=seed, trial=0)
    result = diagnose(recording, resolve_site(scenario=lab), **scenario_diagnose_options(lab))
    print(diagnose_report(result))
    print(f"\ninjected: gyro_scale_asymmetry x = {asymmetry:g}; named: {', '.join(result.selected) or 'nothing'}")


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 1.2e-4, int(sys.argv[2]) if len(sys.argv) > 2 else 5)
