"""How well do the moves of a hand-held session calibrate the gyros? (docs/fitting.md, "Moves between poses")

Simulates hand-held multi-position sessions (``plansim.simulate.hand_session``: 24 poses over the sphere, 5 s
rests, 3 s moves of two rotations each, a consumer MEMS unit: gyro 0.3 deg/sqrt(h), accelerometer
100 ug/sqrt(Hz) at 100 Hz), fits each one (``plansim.fit.fit_recording``) and reports how often the 95 %
interval of each Kg entry from the moves (k from its effective degrees of freedom) covers the truth, the
r.m.s. of (estimate - truth)/u, and the mean chi2/dof of the moves. The cross-couplings are compared with
Kg_ij - (Ka_ij - Ka_ji)/2, what poses placed by hand let the moves see.

    python docs/examples/hand_session_coverage.py [SESSIONS] [PUSH_M_S2]

The figures in docs/fitting.md come from ``100`` and ``60 3.0`` (seeds 100 onwards).
"""

from __future__ import annotations

import math
import sys

import numpy as np
from scipy.stats import t as student

from plansim.fit import fit_recording
from plansim.fit.moves import KG_INDEX
from plansim.fit.site import Site
from plansim.io.recording import Recording
from plansim.model.parameters import PARAMETER_INDEX
from plansim.simulate.hand_session import consumer_unit, hand_session, spread_poses

SITE = Site(math.radians(45.0), 100.0, earth_rate=False)


def main(sessions: int, push: float) -> None:
    covered, z, chi2 = [], [], []
    for trial in range(sessions):
        theta = consumer_unit(100 + trial, ka_cross=5e-4)
        s = hand_session(theta, spread_poses(24, seed=trial), seed=trial, gravity=SITE.gravity, gyro_noise=8.7e-4,
                         accel_noise=9.8e-3, push=push)
        moves = fit_recording(Recording(s.samples, s.schedule, {"source": "simulated"}), SITE).moves
        Kg, Ka = theta[KG_INDEX].reshape(3, 3), theta[[PARAMETER_INDEX[f"Ka{a}{b}"] for a in "xyz"
                                                        for b in "xyz"]].reshape(3, 3)
        error = moves.method.estimate[KG_INDEX] - (Kg - (Ka - Ka.T) / 2.0).ravel()
        u = moves.method.u[KG_INDEX]
        covered.append(np.abs(error) <= student.ppf(0.975, moves.method.dof[KG_INDEX]) * u)
        z.append(error / u)
        chi2.append(moves.chi2 / moves.chi2_dof)
        print(f"session {trial}: chi2/dof {chi2[-1]:.2f}", file=sys.stderr)
    covered, z = np.array(covered), np.array(z)
    print("entry  " + " ".join(f"{n:>6s}" for n in ("xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz")))
    print("cover  " + " ".join(f"{v:6.2f}" for v in covered.mean(axis=0)))
    print("rms z  " + " ".join(f"{v:6.2f}" for v in np.sqrt(np.mean(z**2, axis=0))))
    print(f"pooled coverage {covered.mean():.3f} over {covered.size} intervals; mean chi2/dof of the moves "
          f"{np.mean(chi2):.3f} ({sessions} sessions, push {push:g} m/s^2)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 20, float(sys.argv[2]) if len(sys.argv) > 2 else 0.0)
